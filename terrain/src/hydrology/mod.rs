//! Water that drains: rivers, lakes and dry lake beds from the terrain's own hydrology.
//!
//! Two levels, coarse to fine, as the rest of the pipeline:
//! - **the network** ([`Basins`]) on a grid of [`CELL_METRES`] cells: each square tile of
//!   [`TILE`] cells is drained inside a window [`MARGIN`] cells wider on every side, where
//!   depressions are filled by a priority flood, closed basins become lakes where their
//!   inflow beats their evaporation and dry lake beds where it does not, and discharge
//!   (m³/s, from precipitation by the Budyko curve) accumulates downstream
//!   ([`drainage`]). Tiles do not overlap, so each cell has exactly one answer; the margin
//!   makes that answer the one a whole-world computation would give for every basin smaller
//!   than it.
//! - **the blocks** ([`Rivers`]): every river cell's course is a smooth curve through
//!   jittered nodes, joined to its neighbours' at the midpoints of the cells' links, so
//!   tributaries meet their river and courses cross tile and chunk borders whole. A river's
//!   width and depth grow with its discharge; it cuts its channel and a valley into the
//!   relief; its water surface falls along it from the network's levels.
//!
//! All pure functions of (seed, settings, position): any order, any thread count, the same
//! bits.

pub mod continental;
pub mod drainage;
mod rivers;
mod stitch;

use std::sync::Arc;

use crate::infinite::{Source, WindowFn, WindowIndex, WindowLayout};
use crate::resample;
use crate::tile::{Rect, Tile};
pub use drainage::Kind;
pub use rivers::{
    flared_width_m, water_width_m, Course, Rivers, WaterColumns, DRY_BED_DEPTH_M, ESTUARY_FLARE, RIVER_DISCHARGE,
    RIVER_DISTANCE_MAX_M,
};
pub use stitch::Stitched;

/// Size of a cell of the drainage network, metres.
pub const CELL_METRES: f64 = 1000.0;
/// Side of a drained tile, cells.
pub const TILE: i64 = 32;
/// Cells of context drained around a tile on every side: basins up to about this many
/// cells from a tile are whole in its window.
pub const MARGIN: i64 = 48;

/// Channels of the network grid.
pub mod grid {
    /// Direction code of the downstream neighbour ([`super::drainage::D8`]), or −1.
    pub const DOWN: usize = 0;
    /// Discharge leaving the cell, m³/s.
    pub const DISCHARGE: usize = 1;
    /// Water level, metres ([`super::drainage::Drainage::level`]).
    pub const LEVEL: usize = 2;
    /// [`super::Kind`] code.
    pub const KIND: usize = 3;
    /// The filled surface, metres ([`super::drainage::Drainage::filled`]): strictly falls
    /// along every path.
    pub const FILLED: usize = 4;
    /// Number of channels.
    pub const COUNT: usize = 5;
}

/// Channels of the network's inputs, one value per cell.
pub mod input {
    /// Elevation, metres.
    pub const ELEVATION: usize = 0;
    /// Annual precipitation, mm.
    pub const PRECIPITATION: usize = 1;
    /// Annual mean temperature, °C.
    pub const TEMPERATURE: usize = 2;
    /// Number of channels.
    pub const COUNT: usize = 3;
}

/// Cells around a tile drained on the fine inputs (the finest learned stage); beyond them
/// the window's margin is drained on the coarse grid's relief, which only has to bring the
/// right water to the tile, at a small part of the cost of running the learned stage there.
pub const NEAR: i64 = 8;
/// Cells over which the fine inputs fade into the coarse ones at the edge of [`NEAR`].
const BLEND: i64 = 4;

/// The drainage network as a window function: one non-overlapping tile per window.
pub struct Basins {
    /// Elevation and climate on the network's grid ([`input`] channels) from the finest
    /// stage: the tile and [`NEAR`] cells around it.
    pub fine: Arc<dyn Source>,
    /// The same from the coarse grid: the rest of the margin.
    pub coarse: Arc<dyn Source>,
    /// The continent's drainage on the coarse grid of `coarse_metres`
    /// ([`continental::Continental`]): how far water must rise to leave the window's edge,
    /// and how far a breached basin's outlet cuts the relief down.
    pub continental: Arc<dyn Source>,
    /// Cell size of `continental`, metres.
    pub coarse_metres: f64,
}

impl WindowFn for Basins {
    fn name(&self) -> &str {
        "basins"
    }

    fn channels(&self) -> usize {
        grid::COUNT
    }

    fn layout(&self) -> WindowLayout {
        WindowLayout::square(TILE, TILE, 0)
    }

    fn eval(&self, windows: &[WindowIndex]) -> Vec<Tile> {
        windows.iter().map(|&i| self.tile(self.layout().rect(i))).collect()
    }
}

impl Basins {
    /// The network over `rect`, drained in `rect` grown by [`MARGIN`].
    pub fn tile(&self, rect: Rect) -> Tile {
        let context = rect.pad(MARGIN);
        let near = rect.pad(NEAR);
        let mut t = self.coarse.query(context);
        let fine = self.fine.query(near);
        let n = context.area();
        for y in near.y0..near.y1() {
            for x in near.x0..near.x1() {
                let inside = (y - near.y0).min(near.y1() - 1 - y).min(x - near.x0).min(near.x1() - 1 - x);
                let w = ((inside + 1) as f32 / BLEND as f32).min(1.0);
                let i = ((y - context.y0) * context.w + (x - context.x0)) as usize;
                for c in 0..input::COUNT {
                    let f = fine.get(c, y, x);
                    let v = &mut t.data[c * n + i];
                    *v = if w >= 1.0 { f } else { *v + w * (f - *v) };
                }
            }
        }
        let ratio = CELL_METRES / self.coarse_metres;
        let continent =
            resample::bilinear(&self.continental.query(resample::source_rect(&context, ratio, 0)), ratio, context);
        for (e, cut) in t.data[input::ELEVATION * n..(input::ELEVATION + 1) * n]
            .iter_mut()
            .zip(continent.channel(continental::channel::LOWER))
        {
            *e -= cut;
        }
        // The continent's trunk rivers, burned in: from the coarse cells whose links can
        // cross the window.
        let factor = (self.coarse_metres / CELL_METRES).round() as i64;
        let trunks = self.continental.query(resample::source_rect(&context, ratio, 0).pad(1));
        let mut inflow = vec![0.0; n];
        continental::burn(
            &trunks,
            factor,
            context,
            &mut t.data[input::ELEVATION * n..(input::ELEVATION + 1) * n],
            &mut inflow,
        );
        let d = drainage::drain(&drainage::Inputs {
            h: context.h as usize,
            w: context.w as usize,
            cell_m: CELL_METRES,
            elevation: t.channel(input::ELEVATION),
            precipitation: t.channel(input::PRECIPITATION),
            temperature: t.channel(input::TEMPERATURE),
            inflow: Some(&inflow),
            edge_rise: Some(continent.channel(continental::channel::RISE)),
        });
        let mut out = Tile::zeros(grid::COUNT, context);
        for i in 0..n {
            out.data[grid::DOWN * n + i] = f32::from(d.down[i]);
            out.data[grid::DISCHARGE * n + i] = d.discharge[i];
            out.data[grid::LEVEL * n + i] = d.level[i];
            out.data[grid::KIND * n + i] = d.kind[i] as u8 as f32;
            out.data[grid::FILLED * n + i] = d.filled[i];
        }
        out.crop(rect)
    }
}

#[cfg(test)]
mod tests;
