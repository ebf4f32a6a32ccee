//! What the drainage network is computed from, on its own grid of
//! [`hydrology::CELL_METRES`](crate::hydrology::CELL_METRES) (or the continent's drainage, on
//! the coarse grid): the finest stage's elevation
//! averaged onto it, with the erosion filter's octaves the grid holds (so rivers follow the
//! same big gullies the blocks get), and the climate model's precipitation and temperature.

use std::sync::Arc;

use crate::climate::{precipitation, temperature_at};
use crate::encoding::box_downsample;
use crate::erosion::{octaves_between, ErosionFilter, Lattice};
use crate::hydrology::input;
use crate::infinite::Source;
use crate::layout::sketch;
use crate::resample;
use crate::tile::{Rect, Tile};

use super::finest::carve_cell;
use super::COARSE_METRES;

/// The network's inputs ([`input`] channels), on cells of `cell_metres`.
pub struct NetworkInputs {
    /// Size of a cell, metres: [`CELL_METRES`] for the network, the coarse grid's for the
    /// continent's drainage.
    pub cell_metres: f64,
    /// The elevation it starts from (the finest stage that ran, or the coarse grid's), on its
    /// grid of `base_metres`.
    pub base: Arc<dyn Source>,
    /// Pixel size of `base`, metres: divides `cell_metres`, or is coarser.
    pub base_metres: f64,
    /// The erosion filter.
    pub erosion: ErosionFilter,
    /// The climate sketch on the coarse grid.
    pub sketch: Arc<dyn Source>,
    /// Precipitation on the coarse grid.
    pub precipitation: Arc<dyn Source>,
    /// Shift of every temperature, °C.
    pub temperature_offset_c: f32,
    /// Temperature drop with height, °C/km.
    pub lapse_c_per_km: f32,
}

impl NetworkInputs {
    /// Elevation (metres) of the cells of `rect`: box means of a finer base grid, or a cubic
    /// of a coarser one.
    fn mean_elevation(&self, rect: Rect) -> Tile {
        if self.base_metres > self.cell_metres {
            let ratio = self.cell_metres / self.base_metres;
            return resample::cubic(&self.base.query(resample::source_rect(&rect, ratio, 1)), ratio, rect);
        }
        let f = (self.cell_metres / self.base_metres).round().max(1.0) as i64;
        let fine = self.base.query(Rect::new(rect.y0 * f, rect.x0 * f, rect.h * f, rect.w * f));
        let data = box_downsample(fine.channel(0), fine.rect.h as usize, fine.rect.w as usize, f as usize);
        Tile::from_data(1, rect, data)
    }
}

impl Source for NetworkInputs {
    fn channels(&self) -> usize {
        input::COUNT
    }

    fn query(&self, rect: Rect) -> Tile {
        let padded = rect.pad(1);
        let mean = self.mean_elevation(padded);
        let e = |y: i64, x: i64| f64::from(mean.get(0, y, x));
        let g = self.cell_metres;
        // Octaves of two cells and longer: what this grid can hold.
        let octaves = octaves_between(2.0 * g, f64::INFINITY);
        let mut out = Tile::zeros(input::COUNT, rect);
        let n = rect.area();
        let ratio = g / COARSE_METRES;
        let coarse = resample::source_rect(&rect, ratio, 0);
        let rain = resample::bilinear(&self.precipitation.query(coarse), ratio, rect);
        let climate = resample::bilinear(&self.sketch.query(coarse), ratio, rect);
        let mut lattice = Lattice::default();
        let mut i = 0;
        for y in rect.y0..rect.y1() {
            for x in rect.x0..rect.x1() {
                let elevation = carve_cell(&self.erosion, &mut lattice, &e, g, (y, x), octaves.clone()).0 as f32;
                out.data[input::ELEVATION * n + i] = elevation;
                out.data[input::PRECIPITATION * n + i] = rain.channel(precipitation::ANNUAL_MM)[i];
                let t0 = climate.channel(sketch::SEA_LEVEL_TEMPERATURE)[i] + self.temperature_offset_c;
                out.data[input::TEMPERATURE * n + i] = temperature_at(t0, elevation, self.lapse_c_per_km);
                i += 1;
            }
        }
        out
    }
}
