//! The continent's drainage on the coarse grid, judged in windows of about 2,500 km (512 km
//! tiles with 1,024 km of margin), wide enough to hold a river's whole way to the sea: which
//! basins are breached by their outlet and how deep the cut, which are closed (too dry to
//! spill) and how deep they fill, and the trunk rivers that carry the continent's water.
//!
//! The network's windows ([`super::Basins`], 128 km) are too small to decide this: a window's
//! edge was a free outlet, so a basin wider than the margin drained out of one tile's window
//! and filled in its neighbour's, the two disagreed where they met, and the stitching ended
//! such water in a pit — all the water of an inland region. And the relief's own basins at
//! this scale are closed nearly everywhere (noise has pits at every scale; Earth's have been
//! cut through by their outlets): filled, they covered a quarter of an inland region with
//! lake. So here a wet basin is breached (its outlet cut down until it drains, Soille's
//! carving) unless it is deep and small (kept as a lake, [`LAKE_KEEP_DEPTH_M`]), a dry one is
//! filled, and three things are handed down to the network's windows:
//! the cut lowers the elevation they drain, the fill raises their edges
//! ([`super::drainage::Inputs::edge_rise`]), and the trunk rivers are burned in ([`burn`]) so
//! that every window sees the same way to the sea. Measured on an inland region 300 km from
//! the sea: before the trunks, every river ended in a pit where two windows met; with
//! continental tiles of 128 km and 512 km margins, the continent's own tiles disagreed where
//! a trunk crossed them (a rise of 18 m), hence the wider ones.

use std::sync::Arc;

use crate::infinite::{Source, WindowFn, WindowIndex, WindowLayout};
use crate::tile::{Rect, Tile};

use super::drainage::{breach, drain, runoff_mm, Inputs, Kind, D8, NO_DOWN, SECONDS_PER_YEAR};
use super::input;

/// A wet basin at least this deep (its spill level over its lowest cell, metres) and at
/// most [`LAKE_KEEP_MAX_CELLS`] across is kept as a lake, not breached: Earth's outlets cut
/// through the shallow sills of noise, not through the rim of a deep basin (Crater Lake,
/// Baikal, the Alpine lakes). Every wet basin breached left an inland region 0.10 % lake
/// (Earth: 1.8 %, HydroLAKES).
pub const LAKE_KEEP_DEPTH_M: f32 = 60.0;
/// The widest wet basin kept as a lake, coarse cells (40 km at 8 km): with no limit, the
/// relief's continental basins, hundreds of kilometres across, were kept — an inland region
/// became 10.4 % lake and none of it drained to the sea (network windows, 128 km, cannot
/// see past such a basin; the trunk rivers are what carry water across it).
pub const LAKE_KEEP_MAX_CELLS: usize = 5;

/// Side of a drained tile, coarse cells.
pub const TILE: i64 = 64;
/// Coarse cells drained around a tile on every side.
pub const MARGIN: i64 = 128;

/// Channels of the continent's drainage.
pub mod channel {
    /// How far the water must rise to leave the cell, metres: the depth under a dry
    /// (endorheic) basin's filled surface, 0 elsewhere.
    pub const RISE: usize = 0;
    /// How far the cell is cut down by a breached basin's outlet, metres.
    pub const LOWER: usize = 1;
    /// Direction code of the downstream neighbour on the carved surface
    /// ([`super::super::drainage::D8`]), or −1.
    pub const DOWN: usize = 2;
    /// The carved surface, metres: strictly falls downstream.
    pub const CARVED: usize = 3;
    /// Discharge leaving the cell along the carved surface, m³/s.
    pub const DISCHARGE: usize = 4;
    /// Number of channels.
    pub const COUNT: usize = 5;
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
                    inflow: None,
                    edge_rise: None,
                });
                let dry: Vec<bool> = d.kind.iter().map(|&k| k == Kind::Dry).collect();
                // Dry basins and kept lakes hold their water: not cut into. A kept lake's
                // water still flows on through its outlet; a dry basin's ends in it.
                let kept = kept_lakes(h, w, e, &d.level, &d.kind);
                let closed: Vec<bool> = dry.iter().zip(&kept).map(|(&a, &b)| a || b).collect();
                let cut = breach(h, w, e, &d.filled, &closed);
                // Discharge along the carved surface; a dry basin's water ends in it.
                let n = h * w;
                let area = self.cell_metres * self.cell_metres;
                let mut discharge = vec![0.0f64; n];
                for &c in cut.order.iter().rev() {
                    if e[c] >= 0.0 {
                        let mm = runoff_mm(t.channel(input::PRECIPITATION)[c], t.channel(input::TEMPERATURE)[c]);
                        discharge[c] += mm / 1000.0 * area / SECONDS_PER_YEAR;
                    }
                    if dry[c] || cut.down[c] == NO_DOWN {
                        continue;
                    }
                    let (dy, dx) = D8[cut.down[c] as usize];
                    let m = ((c / w) as i64 + dy) as usize * w + ((c % w) as i64 + dx) as usize;
                    discharge[m] += discharge[c];
                }
                let mut data = vec![0.0; channel::COUNT * n];
                for i in 0..n {
                    if closed[i] {
                        data[channel::RISE * n + i] = (d.filled[i] - e[i]).max(0.0);
                    }
                    data[channel::LOWER * n + i] = cut.lower[i];
                    data[channel::DOWN * n + i] = if dry[i] { f32::from(NO_DOWN) } else { f32::from(cut.down[i]) };
                    data[channel::CARVED * n + i] = cut.carved[i];
                    data[channel::DISCHARGE * n + i] = discharge[i] as f32;
                }
                Tile::from_data(channel::COUNT, context, data).crop(rect)
            })
            .collect()
    }
}

/// The cells of the wet basins kept as lakes ([`LAKE_KEEP_DEPTH_M`], [`LAKE_KEEP_MAX_CELLS`])
/// of a drained `h` × `w` window: each lake (its [`Kind::Lake`] cells and the shallower
/// ones under the same level, 8-connected) whole, or not at all.
fn kept_lakes(h: usize, w: usize, e: &[f32], level: &[f32], kind: &[Kind]) -> Vec<bool> {
    let n = h * w;
    let mut seen = vec![false; n];
    let mut kept = vec![false; n];
    for start in 0..n {
        if seen[start] || kind[start] != Kind::Lake {
            continue;
        }
        let surface = level[start];
        let (mut cells, mut stack) = (vec![start], vec![start]);
        seen[start] = true;
        while let Some(c) = stack.pop() {
            let (cy, cx) = ((c / w) as i64, (c % w) as i64);
            for &(dy, dx) in &D8 {
                let (ny, nx) = (cy + dy, cx + dx);
                if ny < 0 || nx < 0 || ny >= h as i64 || nx >= w as i64 {
                    continue;
                }
                let m = ny as usize * w + nx as usize;
                if !seen[m] && level[m] == surface && e[m] < surface {
                    seen[m] = true;
                    cells.push(m);
                    stack.push(m);
                }
            }
        }
        let depth = cells.iter().map(|&c| surface - e[c]).fold(0.0, f32::max);
        let span = |f: &dyn Fn(usize) -> usize| {
            let (lo, hi) = cells.iter().fold((usize::MAX, 0), |(lo, hi), &c| (lo.min(f(c)), hi.max(f(c))));
            hi - lo + 1
        };
        if depth >= LAKE_KEEP_DEPTH_M && span(&|c| c / w).max(span(&|c| c % w)) <= LAKE_KEEP_MAX_CELLS {
            for c in cells {
                kept[c] = true;
            }
        }
    }
    kept
}

/// Discharge from which the continent's rivers are burned into the network's relief, m³/s:
/// trunks some tens of kilometres apart, so that every basin between two of them is
/// narrower than a network window's margin.
pub const TRUNK_M3S: f32 = 20.0;
/// How far under the carved surface a trunk's channel is burned, metres: below the 1 km
/// relief's small bumps across a lowland (measured: 5 and 15 m drain an inland region alike).
pub const BURN_DEPTH_M: f32 = 5.0;

/// Burns the continent's trunk rivers into the elevation of `cells` (a window of the network,
/// row-major) from the continent's drainage `continent` on cells `factor` times larger:
/// each trunk link, centre to centre, is drawn as a chain of cells whose height falls from
/// one carved height to the next ([`BURN_DEPTH_M`] under it), the classic stream burning of
/// hydrology. Every window burns the same chains, so every window sees the same way down to
/// the sea. Where a trunk enters the window from outside, its discharge is added to
/// `inflow` at the first cell it burns inside the window's edge, so big rivers carry their whole basin's water.
pub fn burn(continent: &Tile, factor: i64, cells: Rect, elevation: &mut [f32], inflow: &mut [f32]) {
    let f = factor as f64;
    let centre = |cy: i64, cx: i64| ((cy as f64 + 0.5) * f, (cx as f64 + 0.5) * f);
    let inside = |y: i64, x: i64| y >= cells.y0 && y < cells.y1() && x >= cells.x0 && x < cells.x1();
    let r = continent.rect;
    for cy in r.y0..r.y1() {
        for cx in r.x0..r.x1() {
            let code = continent.get(channel::DOWN, cy, cx) as i8;
            let q = continent.get(channel::DISCHARGE, cy, cx);
            if code == NO_DOWN || q < TRUNK_M3S {
                continue;
            }
            // The continent's own tiles may disagree where they meet, as the network's do:
            // a link whose carved surface does not fall goes to the lowest neighbour below
            // instead (the network's stitching rule), or is not burned.
            let carved =
                |y: i64, x: i64| r.contains_rect(&Rect::new(y, x, 1, 1)).then(|| continent.get(channel::CARVED, y, x));
            let ha = continent.get(channel::CARVED, cy, cx);
            let (dy, dx) = D8[code as usize];
            let falls = carved(cy + dy, cx + dx).is_some_and(|h| h < ha);
            let Some(((dy, dx), hb)) = (if falls {
                Some(((dy, dx), carved(cy + dy, cx + dx).unwrap_or(ha)))
            } else {
                D8.iter()
                    .filter_map(|&(dy, dx)| carved(cy + dy, cx + dx).filter(|&h| h < ha).map(|h| ((dy, dx), h)))
                    .min_by(|a, b| a.1.total_cmp(&b.1))
            }) else {
                continue;
            };
            let (ny, nx) = (cy + dy, cx + dx);
            let (a, b) = (centre(cy, cx), centre(ny, nx));
            let from_outside = !inside(a.0.floor() as i64, a.1.floor() as i64);
            let mut entered = false;
            // Steps of at most half a cell: the chain is 8-connected.
            let steps = (2.0 * f * if dy != 0 && dx != 0 { std::f64::consts::SQRT_2 } else { 1.0 }).ceil() as i64;
            for s in 0..=steps {
                let t = s as f64 / steps as f64;
                let (y, x) = ((a.0 + t * (b.0 - a.0)).floor() as i64, (a.1 + t * (b.1 - a.1)).floor() as i64);
                if !inside(y, x) {
                    continue;
                }
                let i = ((y - cells.y0) * cells.w + (x - cells.x0)) as usize;
                let h = ha + t as f32 * (hb - ha) - BURN_DEPTH_M;
                elevation[i] = elevation[i].min(h);
                // Not on the window's edge: those cells are its outlets, water added there
                // would leave at once.
                let edge = y == cells.y0 || x == cells.x0 || y == cells.y1() - 1 || x == cells.x1() - 1;
                if from_outside && !entered && !edge {
                    inflow[i] += q;
                    entered = true;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A continent of 4 × 4 coarse cells with one trunk along row 1, west to east, its carved
    /// surface `carved` at columns 0…3; the link from column 2 rises when `carved[3]` does.
    fn continent(carved: [f32; 4]) -> Tile {
        let rect = Rect::new(0, 0, 4, 4);
        let mut t = Tile::zeros(channel::COUNT, rect);
        let n = rect.area();
        for i in 0..n {
            t.data[channel::DOWN * n + i] = f32::from(NO_DOWN);
            t.data[channel::CARVED * n + i] = 500.0;
        }
        for (x, &h) in carved.iter().enumerate() {
            let i = 4 + x;
            t.data[channel::CARVED * n + i] = h;
            t.data[channel::DISCHARGE * n + i] = 100.0;
            t.data[channel::DOWN * n + i] = if x < 3 { 4.0 } else { f32::from(NO_DOWN) };
        }
        t
    }

    #[test]
    fn deep_small_wet_basins_are_kept_as_lakes_and_the_rest_breached() {
        // 12 × 12 cells of 8 km at 200 m, its edge the outlet at 150 m, with three pits: deep
        // and small (rows 2–4, columns 2–4, at 100 m), deep and wide (rows 7–8, columns 1–10),
        // shallow (rows 2–3, columns 7–8, at 170 m).
        let (h, w) = (12, 12);
        let mut e = vec![200.0f32; h * w];
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                if y == 0 || x == 0 || y == h - 1 || x == w - 1 {
                    e[i] = 150.0;
                } else if (2..5).contains(&y) && (2..5).contains(&x) || (7..9).contains(&y) && (1..11).contains(&x) {
                    e[i] = 100.0;
                } else if (2..4).contains(&y) && (7..9).contains(&x) {
                    e[i] = 170.0;
                }
            }
        }
        let n = h * w;
        let d = drain(&Inputs {
            h,
            w,
            cell_m: 8000.0,
            elevation: &e,
            precipitation: &vec![2000.0; n],
            temperature: &vec![5.0; n],
            inflow: None,
            edge_rise: None,
        });
        let kept = kept_lakes(h, w, &e, &d.level, &d.kind);
        let small: Vec<usize> = (2..5).flat_map(|y| (2..5).map(move |x| y * w + x)).collect();
        assert!(small.iter().all(|&i| kept[i]), "the deep small basin is kept whole");
        assert_eq!(kept.iter().filter(|&&k| k).count(), small.len(), "nothing else is kept: {kept:?}");
        // Kept, it is not cut into; the wide one is breached through its rim.
        let cut = breach(h, w, &e, &d.filled, &kept);
        assert!(small.iter().all(|&i| cut.lower[i] == 0.0 && cut.carved[i] >= d.level[i] - 0.01));
        assert!(cut.lower.iter().any(|&l| l >= 50.0), "the wide basin's rim is cut down");
    }

    #[test]
    fn a_trunk_is_burned_as_an_unbroken_falling_chain_and_brings_its_water_in() {
        // Fine cells 8 to a coarse one; the window starts east of the trunk's first centre.
        let cells = Rect::new(0, 8, 32, 24);
        let mut elevation = vec![100.0; cells.area()];
        let mut inflow = vec![0.0; cells.area()];
        burn(&continent([60.0, 50.0, 40.0, 30.0]), 8, cells, &mut elevation, &mut inflow);
        let at = |y: i64, x: i64| elevation[((y - cells.y0) * cells.w + x - cells.x0) as usize];
        // Row 12 holds the centres of coarse row 1: burned from the window's edge (x 8) to the
        // last centre (x 28), falling all the way, 15 m under the carved surface.
        let chain: Vec<f32> = (8..=28).map(|x| at(12, x)).collect();
        assert!(chain.windows(2).all(|w| w[1] < w[0]), "{chain:?}");
        // (A cell takes the lowest sample in it: up to one cell's fall, 1.25 m, under the line.)
        let under = |h: f32, carved: f32| (0.0..1.3).contains(&(carved - BURN_DEPTH_M - h));
        assert!(under(at(12, 12), 50.0) && under(at(12, 28), 30.0), "{} {}", at(12, 12), at(12, 28));
        assert_eq!((at(12, 29), at(11, 20), at(13, 20)), (100.0, 100.0, 100.0), "only the chain is burned");
        // The trunk enters the window from the west: its water comes in just inside the edge.
        let i = |y: i64, x: i64| ((y - cells.y0) * cells.w + x - cells.x0) as usize;
        assert_eq!(inflow[i(12, 9)], 100.0);
        assert_eq!(inflow.iter().sum::<f32>(), 100.0);
        // A link whose carved surface rises (two continent tiles disagreeing) is not burned.
        let mut raised = vec![100.0; cells.area()];
        burn(&continent([60.0, 50.0, 40.0, 45.0]), 8, cells, &mut raised, &mut vec![0.0; cells.area()]);
        let at = |y: i64, x: i64| raised[i(y, x)];
        assert!(at(12, 18) < 100.0 && at(12, 24) == 100.0, "{} {}", at(12, 18), at(12, 24));
    }
}
