//! The continent's drainage on the coarse grid, judged in windows of about a thousand
//! kilometres, wide enough to hold a river's whole way to the sea: which basins are breached
//! by their outlet and how deep the cut, and which are closed (too dry to spill) and how
//! deep they fill.
//!
//! The network's windows ([`super::Basins`], 128 km) are too small to decide this: a window's
//! edge was a free outlet, so a basin wider than the margin drained out of one tile's window
//! and filled in its neighbour's, the two disagreed where they met, and the stitching ended
//! such water in a pit — all the water of an inland region. And the relief's own basins at
//! this scale are closed nearly everywhere (noise has pits at every scale; Earth's have been
//! cut through by their outlets): filled, they covered a quarter of an inland region with
//! lake. So a wet basin is breached here (its outlet cut down until it drains, Soille's
//! carving), a dry one is filled, and both are handed down to the network's windows: the cut
//! lowers the elevation they drain and the fill raises their edges
//! ([`super::drainage::Inputs::edge_rise`]).

use std::sync::Arc;

use crate::infinite::{Source, WindowFn, WindowIndex, WindowLayout};
use crate::tile::Tile;

use super::drainage::{breach, drain, Inputs, Kind};
use super::input;

/// Side of a drained tile, coarse cells.
pub const TILE: i64 = 16;
/// Coarse cells drained around a tile on every side.
pub const MARGIN: i64 = 64;

/// Channels of the continent's drainage.
pub mod channel {
    /// How far the water must rise to leave the cell, metres: the depth under a dry
    /// (endorheic) basin's filled surface, 0 elsewhere.
    pub const RISE: usize = 0;
    /// How far the cell is cut down by a breached basin's outlet, metres.
    pub const LOWER: usize = 1;
    /// Number of channels.
    pub const COUNT: usize = 2;
}

/// The continent's drainage as a window function on the coarse grid.
pub struct Continental {
    /// The network's inputs ([`input`] channels) on the coarse grid.
    pub inputs: Arc<dyn Source>,
    /// Cell size of the coarse grid, metres.
    pub cell_metres: f64,
}

impl WindowFn for Continental {
    fn name(&self) -> &str {
        "continental"
    }

    fn channels(&self) -> usize {
        channel::COUNT
    }

    fn layout(&self) -> WindowLayout {
        WindowLayout::square(TILE, TILE, 0)
    }

    fn eval(&self, windows: &[WindowIndex]) -> Vec<Tile> {
        windows
            .iter()
            .map(|&i| {
                let rect = self.layout().rect(i);
                let context = rect.pad(MARGIN);
                let t = self.inputs.query(context);
                let (h, w) = (context.h as usize, context.w as usize);
                let e = t.channel(input::ELEVATION);
                let d = drain(&Inputs {
                    h,
                    w,
                    cell_m: self.cell_metres,
                    elevation: e,
                    precipitation: t.channel(input::PRECIPITATION),
                    temperature: t.channel(input::TEMPERATURE),
                    edge_rise: None,
                });
                let closed: Vec<bool> = d.kind.iter().map(|&k| k == Kind::Dry).collect();
                let lower = breach(h, w, e, &d.filled, &closed);
                let n = h * w;
                let mut data = vec![0.0; channel::COUNT * n];
                for i in 0..n {
                    if closed[i] {
                        data[channel::RISE * n + i] = (d.filled[i] - e[i]).max(0.0);
                    }
                    data[channel::LOWER * n + i] = lower[i];
                }
                Tile::from_data(channel::COUNT, context, data).crop(rect)
            })
            .collect()
    }
}
