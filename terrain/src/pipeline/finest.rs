//! The model grid (4 blocks a pixel, at any world scale): the finest stage that ran,
//! resampled to it by a cubic, with the erosion filter's octaves that the grid holds well
//! (wavelengths of [`SHORTEST_ON_GRID_PIXELS`] pixels and more).

use std::sync::Arc;

use crate::erosion::{octaves_between, ErosionFilter, Lattice, SHORTEST_ON_GRID_PIXELS};
use crate::infinite::Source;
use crate::resample;
use crate::tile::{Rect, Tile};

/// Channel: elevation, metres.
pub const ELEVATION: usize = 0;
/// Channel: slope of the smooth relief under the erosion filter (m/m), which sets the
/// amplitude of the octaves carved at the block grid too.
pub const SLOPE: usize = 1;

/// The model grid's elevation source.
pub struct Finest {
    base: Arc<dyn Source>,
    ratio: f64,
    metres: f64,
    erosion: ErosionFilter,
    octaves: std::ops::Range<u32>,
}

impl Finest {
    /// The model grid of `metres` pixels over `base` (a grid of `base_metres` pixels).
    pub fn new(base: Arc<dyn Source>, base_metres: f64, metres: f64, erosion: ErosionFilter) -> Finest {
        Finest {
            base,
            ratio: metres / base_metres,
            metres,
            erosion,
            octaves: octaves_between(SHORTEST_ON_GRID_PIXELS * metres, f64::INFINITY),
        }
    }
}

impl Source for Finest {
    fn channels(&self) -> usize {
        2
    }

    fn query(&self, rect: Rect) -> Tile {
        let padded = rect.pad(1);
        let base = resample::cubic(&self.base.query(resample::source_rect(&padded, self.ratio, 1)), self.ratio, padded);
        let e = |y: i64, x: i64| f64::from(base.get(0, y, x));
        let g = self.metres;
        let mut out = Tile::zeros(2, rect);
        let n = rect.area();
        let mut lattice = Lattice::default();
        let mut i = 0;
        for y in rect.y0..rect.y1() {
            for x in rect.x0..rect.x1() {
                let (elevation, slope) = carve_cell(&self.erosion, &mut lattice, &e, g, (y, x), self.octaves.clone());
                out.data[i] = elevation as f32;
                out.data[n + i] = slope as f32;
                i += 1;
            }
        }
        out
    }
}

/// The erosion filter's `octaves` carved into cell (`y`, `x`) of a grid of `g`-metre cells
/// whose elevation (metres) `e` gives, with the slope (m/m) from central differences over its
/// neighbours: (carved elevation, slope). Shared by every grid the filter is carved on.
pub(super) fn carve_cell(
    erosion: &ErosionFilter,
    lattice: &mut Lattice,
    e: &impl Fn(i64, i64) -> f64,
    g: f64,
    (y, x): (i64, i64),
    octaves: std::ops::Range<u32>,
) -> (f64, f64) {
    let gradient = ((e(y, x + 1) - e(y, x - 1)) / (2.0 * g), (e(y + 1, x) - e(y - 1, x)) / (2.0 * g));
    let slope = gradient.0.hypot(gradient.1);
    let (xm, zm) = ((x as f64 + 0.5) * g, (y as f64 + 0.5) * g);
    (e(y, x) + erosion.apply_with(lattice, xm, zm, slope, gradient, octaves).height, slope)
}
