//! How much water a region holds and where its rivers go, for `infiniterra water`:
//! the numbers issue 25 compares with real Earth (see docs/water.md for the sources).
//!
//! Columns are counted at the block grid (what a player sees: river and lake water per
//! land column); river length and where rivers end are measured on the drainage network
//! (1 km cells), where a river is a cell whose discharge passes a threshold, as in the
//! global river maps it is compared with.

use crate::terrain::hydrology::drainage::{D8, NO_DOWN};
use crate::terrain::hydrology::{continental, grid, Kind, WaterColumns, CELL_METRES, RIVER_DISCHARGE};
use crate::terrain::pipeline::{channel, COARSE_METRES};
use crate::terrain::{Pipeline, Rect};

/// Blocks per side of the tiles the columns are asked for in.
const TILE_BLOCKS: i64 = 512;
/// How far (cells) past the region a river is followed to its end.
const FOLLOW_CELLS: i64 = 400;

/// What [`measure`] found.
#[derive(Clone, Debug, Default)]
pub struct WaterStats {
    /// Land columns: not sea (ground at or above sea level, or river or lake water).
    pub land_columns: u64,
    /// Columns of river water.
    pub river_columns: u64,
    /// Columns of lake water.
    pub lake_columns: u64,
    /// Columns of dry lake bed.
    pub dry_bed_columns: u64,
    /// Land area of the region, km² (from the network's cells).
    pub land_km2: f64,
    /// River length (km) of cells with at least 0.1 m³/s (HydroRIVERS' threshold).
    pub river_km_01: f64,
    /// River length (km) of cells with at least [`RIVER_DISCHARGE`] (the rivers drawn in
    /// the world).
    pub river_km_drawn: f64,
    /// Of the drawn river length: km ending in the sea, in a lake, in a dry basin, leaving
    /// the followed window ([`FOLLOW_CELLS`] past the region) and finding no end down the
    /// continent's drainage either, and ending nowhere (a dead end on land or a loop: a
    /// defect). Past the window a path goes on down the continent's trunk rivers.
    pub ends_km: [f64; 5],
    /// Area of land cells draining to the sea (km²) and to an inland sink (lake without
    /// outlet or dry basin).
    pub drains_to_sea_km2: f64,
}

/// Measures the blocks of `area` (y = z, x = x), calling `progress(done, total)` as block
/// tiles finish.
pub fn measure(pipeline: &Pipeline, area: Rect, mut progress: impl FnMut(u64, u64)) -> WaterStats {
    let mut s = WaterStats::default();
    let (tiles_x, tiles_z) = ((area.w + TILE_BLOCKS - 1) / TILE_BLOCKS, (area.h + TILE_BLOCKS - 1) / TILE_BLOCKS);
    let total = (tiles_x * tiles_z + 1) as u64;
    for ty in 0..tiles_z {
        for tx in 0..tiles_x {
            let (bx, bz) = (area.x0 + tx * TILE_BLOCKS, area.y0 + ty * TILE_BLOCKS);
            let (w, h) = ((area.x1() - bx).min(TILE_BLOCKS), (area.y1() - bz).min(TILE_BLOCKS));
            let t = pipeline.columns(Rect::new(bz, bx, h, w));
            for ((&e, &kind), &level) in
                t.channel(channel::ELEVATION).iter().zip(t.channel(channel::WATER)).zip(t.channel(channel::WATER_LEVEL))
            {
                let kind = kind as u8;
                let inland = !level.is_nan() && (kind == WaterColumns::RIVER || kind == Kind::Lake as u8);
                if e < 0.0 && !inland {
                    continue;
                }
                s.land_columns += 1;
                match kind {
                    WaterColumns::RIVER if inland => s.river_columns += 1,
                    k if k == Kind::Lake as u8 && inland => s.lake_columns += 1,
                    k if k == Kind::Dry as u8 => s.dry_bed_columns += 1,
                    _ => {}
                }
            }
            progress((ty * tiles_x + tx + 1) as u64, total);
        }
    }
    network_stats(pipeline, area, &mut s);
    progress(total, total);
    s
}

/// River length and ends, on the network's cells.
fn network_stats(pipeline: &Pipeline, area: Rect, s: &mut WaterStats) {
    let m = pipeline.block_metres();
    let cell = |b: i64| ((b as f64 * m) / CELL_METRES).floor() as i64;
    let region =
        Rect::new(cell(area.y0), cell(area.x0), cell(area.y1()) - cell(area.y0), cell(area.x1()) - cell(area.x0));
    let window = region.pad(FOLLOW_CELLS);
    let net = pipeline.network(window);
    let km = CELL_METRES / 1000.0;
    let kind = |y: i64, x: i64| Kind::from_code(net.get(grid::KIND, y, x));
    let down = |y: i64, x: i64| -> Option<(i64, i64)> {
        let d = net.get(grid::DOWN, y, x) as i8;
        (d != NO_DOWN).then(|| (y + D8[d as usize].0, x + D8[d as usize].1))
    };
    let inside = |y: i64, x: i64| y >= window.y0 && y < window.y1() && x >= window.x0 && x < window.x1();
    // Past the followed window a path is followed on, down the continent's own drainage
    // (the trunk rivers the network's windows have burned in): 0 sea, 2 dry basin, 3 no end.
    let ends_beyond = std::cell::RefCell::new(std::collections::HashMap::new());
    let beyond = |y: i64, x: i64| -> usize {
        let f = (COARSE_METRES / CELL_METRES).round() as i64;
        let mut c = (y.div_euclid(f), x.div_euclid(f));
        if let Some(&end) = ends_beyond.borrow().get(&c) {
            return end;
        }
        let start = c;
        let mut end = 3;
        for _ in 0..4 * FOLLOW_CELLS {
            let t = pipeline.continent(Rect::new(c.0, c.1, 1, 1));
            let code = t.get(continental::channel::DOWN, c.0, c.1) as i8;
            if code == NO_DOWN {
                if t.get(continental::channel::CARVED, c.0, c.1) < 0.0 {
                    end = 0;
                } else if t.get(continental::channel::RISE, c.0, c.1) > 0.0 {
                    end = 2;
                }
                break;
            }
            c = (c.0 + D8[code as usize].0, c.1 + D8[code as usize].1);
        }
        ends_beyond.borrow_mut().insert(start, end);
        end
    };
    // Where each cell's water ends: 0 sea, 1 lake, 2 dry basin, 3 beyond the window, 4 nowhere
    // (a dead end on land, or a loop).
    let end_of = |mut y: i64, mut x: i64| -> usize {
        for _ in 0..(4 * FOLLOW_CELLS) {
            match kind(y, x) {
                Kind::Sea => return 0,
                Kind::Lake => return 1,
                Kind::Dry => return 2,
                Kind::Land => {}
            }
            match down(y, x) {
                Some((ny, nx)) if inside(ny, nx) => (y, x) = (ny, nx),
                Some((ny, nx)) => return beyond(ny, nx),
                None => return 4,
            }
        }
        4
    };
    // Where a lake's water finally goes (through its outlet, if it has one).
    let final_end = |y: i64, x: i64| -> usize {
        let (mut y, mut x) = (y, x);
        for _ in 0..(4 * FOLLOW_CELLS) {
            match kind(y, x) {
                Kind::Sea => return 0,
                Kind::Dry => return 2,
                Kind::Land | Kind::Lake => {}
            }
            match down(y, x) {
                Some((ny, nx)) if inside(ny, nx) => (y, x) = (ny, nx),
                Some((ny, nx)) => return beyond(ny, nx),
                _ if kind(y, x) == Kind::Lake => return 1,
                _ => return 3,
            }
        }
        3
    };
    for y in region.y0..region.y1() {
        for x in region.x0..region.x1() {
            let k = kind(y, x);
            if k == Kind::Sea {
                continue;
            }
            s.land_km2 += km * km;
            if final_end(y, x) == 0 {
                s.drains_to_sea_km2 += km * km;
            }
            if k != Kind::Land {
                continue;
            }
            let q = net.get(grid::DISCHARGE, y, x);
            let Some((ny, nx)) = down(y, x) else { continue };
            let step = if ny != y && nx != x { km * std::f64::consts::SQRT_2 } else { km };
            if q >= 0.1 {
                s.river_km_01 += step;
            }
            if q >= RIVER_DISCHARGE {
                s.river_km_drawn += step;
                s.ends_km[end_of(y, x)] += step;
            }
        }
    }
}

impl WaterStats {
    /// Share of land columns that are river water, %.
    pub fn river_pct(&self) -> f64 {
        100.0 * self.river_columns as f64 / self.land_columns.max(1) as f64
    }

    /// Share of land columns that are lake water, %.
    pub fn lake_pct(&self) -> f64 {
        100.0 * self.lake_columns as f64 / self.land_columns.max(1) as f64
    }

    /// Share of land columns that are dry lake bed, %.
    pub fn dry_bed_pct(&self) -> f64 {
        100.0 * self.dry_bed_columns as f64 / self.land_columns.max(1) as f64
    }

    /// River length per 1,000 km² of land at discharge ≥ 0.1 m³/s and at the drawn threshold.
    pub fn density(&self) -> (f64, f64) {
        let per = 1000.0 / self.land_km2.max(1e-9);
        (self.river_km_01 * per, self.river_km_drawn * per)
    }

    /// Shares (%) of drawn river length ending in the sea, a lake, a dry basin, beyond the
    /// window, nowhere.
    pub fn ends_pct(&self) -> [f64; 5] {
        self.ends_km.map(|k| 100.0 * k / self.river_km_drawn.max(1e-9))
    }

    /// Share of land draining to the sea (exorheic), %.
    pub fn exorheic_pct(&self) -> f64 {
        100.0 * self.drains_to_sea_km2 / self.land_km2.max(1e-9)
    }
}
