//! The network with its tiles joined.
//!
//! Each tile is drained in its own window ([`Basins`](super::Basins)), so where a river
//! crosses a tile border the two windows may disagree on the filled surface, and a link that
//! falls in one window can rise in the other — enough, at a flat border, for water to go
//! round in a loop. Two rules join them:
//!
//! 1. **Links fall.** Every link that crosses a tile border must fall on the filled surface
//!    each cell's own tile gives; one that does not is sent to the lowest neighbour below the
//!    cell instead. The filled surface is compared, not the water level, because a lake's or
//!    a filled flat's level is one number over all its cells: compared by level, every lake a
//!    tile border crosses was cut into pits.
//! 2. **Pits spill.** A cell with no neighbour below it (a pit where two windows meet; one
//!    tile drained it into a basin its neighbour fills higher) spills into its lowest
//!    neighbour, and the path on from there is cut down under the pit — its filled surface
//!    and water level lowered, as an outlet erodes — until the path falls below the pit on
//!    its own. A pit whose path does not within [`SPILL_STEPS`] cells stays a one-cell lake,
//!    the water's end. Before this, every river of an inland region ended in such a pit.
//!
//! The filled surface then strictly falls along every link (lowering a cell only steepens
//! the links into it, and each cut path falls by [`EPSILON_M`] a cell), so every path ends
//! and no river runs uphill. Each cell's answer depends on the per-tile network within
//! `2 · SPILL_STEPS + 3` cells, which the tile's window covers whatever is asked first.

use std::sync::Arc;

use super::drainage::{Kind, D8, NO_DOWN};
use super::{grid, TILE};
use crate::infinite::{Source, WindowFn, WindowIndex, WindowLayout};
use crate::tile::{Rect, Tile};

/// Longest path, in cells, cut down under a pit: kept within the neighbouring tiles'
/// windows (`2 · SPILL_STEPS + 3 ≤ TILE`). Short, because a joined window reads the per-tile
/// network this far around it: with 6 cells an 8-cell window reads 2 × 2 drained tiles, with
/// 14 it read 3 × 3, each of them the core around it (docs/benchmarks.md, "A shorter spill").
pub const SPILL_STEPS: i64 = 6;
/// Side of the joined network's windows, cells. Each cell's answer is the same whatever
/// window holds it, so small windows only spare the per-tile network around a query.
pub const STITCH_TILE: i64 = 8;
/// Fall of a cut path per cell, metres (as the drainage's flats).
const EPSILON_M: f32 = 1e-3;

/// The joined network, one tile per window (behind the engine's cache).
pub struct Stitched {
    /// The per-tile network ([`super::Basins`] behind the engine's cache).
    pub basins: Arc<dyn Source>,
}

impl WindowFn for Stitched {
    fn name(&self) -> &str {
        "stitched"
    }

    fn channels(&self) -> usize {
        grid::COUNT
    }

    fn layout(&self) -> WindowLayout {
        WindowLayout::square(STITCH_TILE, STITCH_TILE, 0)
    }

    fn eval(&self, windows: &[WindowIndex]) -> Vec<Tile> {
        windows.iter().map(|&i| self.tile(self.layout().rect(i))).collect()
    }
}

impl Stitched {
    /// The joined network over `rect`.
    pub fn tile(&self, rect: Rect) -> Tile {
        let region = rect.pad(2 * SPILL_STEPS + 2);
        let (linked, pits) = link(&self.basins.query(region.pad(1)), region);
        let mut out = linked.clone();
        let reach = rect.pad(SPILL_STEPS + 1);
        let n = region.area();
        for &p in pits.iter().filter(|p| reach.contains_rect(&Rect::new(p.0, p.1, 1, 1))) {
            if !spill(&linked, p, &mut out) {
                let i = ((p.0 - region.y0) * region.w + (p.1 - region.x0)) as usize;
                out.data[grid::KIND * n + i] = Kind::Lake as u8 as f32;
            }
        }
        out.crop(rect)
    }
}

/// The direction code of the link from `(y, x)`, if any.
fn down(t: &Tile, y: i64, x: i64) -> Option<(i64, i64)> {
    let code = t.get(grid::DOWN, y, x) as i8;
    (code != NO_DOWN).then(|| (y + D8[code as usize].0, x + D8[code as usize].1))
}

/// Rule 1 over `region` (from the per-tile network over `region` grown by one): links that
/// cross tiles fall, and the pits where none can (left without a link).
fn link(t: &Tile, region: Rect) -> (Tile, Vec<(i64, i64)>) {
    let mut out = t.crop(region);
    let tile = |y: i64, x: i64| (y.div_euclid(TILE), x.div_euclid(TILE));
    let n = region.area();
    let mut pits = Vec::new();
    for y in region.y0..region.y1() {
        for x in region.x0..region.x1() {
            let Some((ty, tx)) = down(t, y, x) else { continue };
            let own = t.get(grid::FILLED, y, x);
            if tile(y, x) == tile(ty, tx) || t.get(grid::FILLED, ty, tx) < own {
                continue;
            }
            let lower = D8
                .iter()
                .enumerate()
                .map(|(k, &(ny, nx))| (k, t.get(grid::FILLED, y + ny, x + nx)))
                .filter(|&(_, f)| f < own)
                .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
            let i = ((y - region.y0) * region.w + (x - region.x0)) as usize;
            match lower {
                Some((k, _)) => out.data[grid::DOWN * n + i] = k as f32,
                None => {
                    out.data[grid::DOWN * n + i] = f32::from(NO_DOWN);
                    pits.push((y, x));
                }
            }
        }
    }
    (out, pits)
}

/// Rule 2 for the pit `p` of `linked`, written into `out` (which other pits' cuts may have
/// lowered already: cuts combine by their minimum, in any order): into the lowest neighbour
/// whose path can be cut down under it. False when none can.
fn spill(linked: &Tile, p: (i64, i64), out: &mut Tile) -> bool {
    let region = linked.rect;
    let inside = |c: (i64, i64)| region.contains_rect(&Rect::new(c.0, c.1, 1, 1));
    let filled = |c: (i64, i64)| linked.get(grid::FILLED, c.0, c.1);
    let mut ways: Vec<(usize, (i64, i64))> =
        D8.iter().enumerate().map(|(k, &(dy, dx))| (k, (p.0 + dy, p.1 + dx))).filter(|&(_, c)| inside(c)).collect();
    ways.sort_by(|a, b| filled(a.1).total_cmp(&filled(b.1)).then(a.0.cmp(&b.0)));
    let Some((k, cut)) = ways.into_iter().find_map(|(k, c)| cut_under(linked, p, c).map(|cut| (k, cut))) else {
        return false;
    };
    let n = region.area();
    let index = |c: (i64, i64)| ((c.0 - region.y0) * region.w + (c.1 - region.x0)) as usize;
    let pit_level = linked.get(grid::LEVEL, p.0, p.1);
    for (c, f) in cut {
        let i = index(c);
        out.data[grid::FILLED * n + i] = out.data[grid::FILLED * n + i].min(f);
        out.data[grid::LEVEL * n + i] = out.data[grid::LEVEL * n + i].min(pit_level);
    }
    out.data[grid::DOWN * n + index(p)] = k as f32;
    true
}

/// The cells of the path from `c` on, each with the filled height it is cut down to, until
/// the path falls under the pit `p` on its own; `None` when it does not within
/// [`SPILL_STEPS`] cells, leaves the cells every tile sees, comes back to the pit, or would
/// lower a lake.
fn cut_under(linked: &Tile, p: (i64, i64), mut c: (i64, i64)) -> Option<Vec<((i64, i64), f32)>> {
    let region = linked.rect;
    let filled = |c: (i64, i64)| linked.get(grid::FILLED, c.0, c.1);
    let level = |c: (i64, i64)| linked.get(grid::LEVEL, c.0, c.1);
    let (pit_filled, pit_level) = (filled(p), level(p));
    let mut cut = Vec::new();
    let mut carried = pit_filled - EPSILON_M;
    while filled(c) >= carried || level(c) > pit_level {
        let water = Kind::from_code(linked.get(grid::KIND, c.0, c.1));
        if c == p || cut.len() as i64 >= SPILL_STEPS || (water != Kind::Land && level(c) > pit_level) {
            return None;
        }
        cut.push((c, carried));
        carried -= EPSILON_M;
        c = down(linked, c.0, c.1).filter(|n| region.contains_rect(&Rect::new(n.0, n.1, 1, 1)))?;
    }
    Some(cut)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A per-tile network given whole: land flowing east everywhere, filled surface falling
    /// 0.1 m a cell in tile column 0 and `slope` a cell in tile column 1, which starts 1.1 m
    /// higher than column 0 ends: every cell of column 0's last column is a pit.
    struct Given(Tile);

    impl Source for Given {
        fn channels(&self) -> usize {
            grid::COUNT
        }

        fn query(&self, rect: Rect) -> Tile {
            self.0.crop(rect)
        }
    }

    fn eastward(slope: f32) -> Stitched {
        let rect = Rect::new(-64, -64, 192, 192);
        let mut t = Tile::zeros(grid::COUNT, rect);
        let n = rect.area();
        for y in rect.y0..rect.y1() {
            for x in rect.x0..rect.x1() {
                let f = if x < TILE { 50.0 - 0.1 * x as f32 } else { 48.0 - slope * (x - TILE) as f32 };
                let i = ((y - rect.y0) * rect.w + (x - rect.x0)) as usize;
                t.data[grid::DOWN * n + i] = 4.0; // east
                t.data[grid::DISCHARGE * n + i] = 1.0;
                t.data[grid::LEVEL * n + i] = f;
                t.data[grid::FILLED * n + i] = f;
            }
        }
        Stitched { basins: Arc::new(Given(t)) }
    }

    /// The joined network of tiles (0, 0) and (0, 1), as one tile.
    fn joined(s: &Stitched) -> Tile {
        let (a, b) = (s.tile(Rect::new(0, 0, TILE, TILE)), s.tile(Rect::new(0, TILE, TILE, TILE)));
        let rect = Rect::new(0, 0, TILE, 2 * TILE);
        let mut t = Tile::zeros(grid::COUNT, rect);
        let n = rect.area();
        for part in [a, b] {
            for y in part.rect.y0..part.rect.y1() {
                for x in part.rect.x0..part.rect.x1() {
                    for c in 0..grid::COUNT {
                        t.data[c * n + (y * rect.w + x) as usize] = part.get(c, y, x);
                    }
                }
            }
        }
        t
    }

    #[test]
    fn a_pit_where_tiles_meet_spills_across_and_its_path_is_cut_under_it() {
        let t = joined(&eastward(0.2));
        for y in 1..TILE - 1 {
            let mut c = (y, TILE - 1);
            assert_eq!(Kind::from_code(t.get(grid::KIND, c.0, c.1)), Kind::Land, "({y}, {}) is still a pit", c.1);
            // Downstream the filled surface strictly falls and the water level never rises.
            while c.1 < TILE + 2 * SPILL_STEPS && t.rect.contains_rect(&Rect::new(c.0, c.1, 1, 1)) {
                let Some(d) = down(&t, c.0, c.1) else { panic!("path from row {y} ends at {c:?}") };
                if !t.rect.contains_rect(&Rect::new(d.0, d.1, 1, 1)) {
                    break;
                }
                assert!(t.get(grid::FILLED, d.0, d.1) < t.get(grid::FILLED, c.0, c.1), "{c:?} → {d:?}");
                assert!(t.get(grid::LEVEL, d.0, d.1) <= t.get(grid::LEVEL, c.0, c.1), "{c:?} → {d:?}");
                c = d;
            }
        }
        // The cut reaches only as far as the path needs: 1.1 m at 0.2 m a cell.
        assert!(t.get(grid::LEVEL, 5, TILE + 3) < 47.0);
        assert_eq!(t.get(grid::LEVEL, 5, TILE + 12), 48.0 - 0.2 * 12.0);
    }

    #[test]
    fn a_pit_whose_path_does_not_fall_under_it_soon_stays_a_lake() {
        let t = joined(&eastward(0.02));
        for y in 0..TILE {
            assert_eq!(Kind::from_code(t.get(grid::KIND, y, TILE - 1)), Kind::Lake);
            assert_eq!(down(&t, y, TILE - 1), None);
        }
    }

    /// A per-tile network whose tiles disagree: a tilted surface with small bumps, raised by
    /// up to 3 m per tile, each cell linked to its lowest neighbour as its own tile sees it.
    /// Where a tile sits higher than the next, its border cells are pits that spill across,
    /// some within a few cells and some not at all.
    fn seamy() -> Stitched {
        let mix = |mut z: u64| {
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58476d1ce4e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d049bb133111eb);
            (z ^ (z >> 31)) as f32 / u64::MAX as f32
        };
        let key = |a: i64, b: i64, c: u64| ((a as u64) << 40) ^ ((b as u64) << 16) ^ c;
        let field = |(ty, tx): (i64, i64), y: i64, x: i64| {
            50.0 - 0.05 * x as f32 - 0.03 * y as f32 + 3.0 * mix(key(ty, tx, 1)) + 0.2 * mix(key(y, x, 2))
        };
        let rect = Rect::new(-64, -64, 192, 192);
        let mut t = Tile::zeros(grid::COUNT, rect);
        let n = rect.area();
        for y in rect.y0..rect.y1() {
            for x in rect.x0..rect.x1() {
                let own = (y.div_euclid(TILE), x.div_euclid(TILE));
                let f = field(own, y, x);
                let lowest = D8
                    .iter()
                    .enumerate()
                    .map(|(k, &(dy, dx))| (k, field(own, y + dy, x + dx)))
                    .filter(|&(_, g)| g < f)
                    .min_by(|a, b| a.1.total_cmp(&b.1));
                let i = ((y - rect.y0) * rect.w + (x - rect.x0)) as usize;
                t.data[grid::DOWN * n + i] = lowest.map_or(f32::from(NO_DOWN), |(k, _)| k as f32);
                t.data[grid::DISCHARGE * n + i] = 1.0;
                t.data[grid::LEVEL * n + i] = f;
                t.data[grid::FILLED * n + i] = f;
            }
        }
        Stitched { basins: Arc::new(Given(t)) }
    }

    #[test]
    fn a_cell_is_joined_the_same_whatever_window_holds_it() {
        let s = seamy();
        let area = Rect::new(-16, -16, 64, 64);
        let whole = s.tile(area);
        // The case is one that spills: cells cut under pits, and pits left as lakes.
        let given = s.basins.query(area);
        let cut = whole.channel(grid::FILLED).iter().zip(given.channel(grid::FILLED)).filter(|(a, b)| a < b).count();
        let lakes = whole.channel(grid::KIND).iter().filter(|&&k| Kind::from_code(k) == Kind::Lake).count();
        assert!(cut >= 10 && lakes > 0, "{cut} cells cut, {lakes} lakes");
        for side in [1, 3, STITCH_TILE, 13, TILE] {
            for y0 in (area.y0..area.y1() - side).step_by(side as usize + 2) {
                for x0 in (area.x0..area.x1() - side).step_by(side as usize + 5) {
                    let r = Rect::new(y0, x0, side, side);
                    let part = s.tile(r);
                    let same = part.data.iter().zip(&whole.crop(r).data).all(|(a, b)| a.to_bits() == b.to_bits());
                    assert!(same, "{r:?} differs from the same cells joined in one window");
                }
            }
        }
    }
}
