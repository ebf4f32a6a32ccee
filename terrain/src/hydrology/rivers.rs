//! Rivers and lakes at the block grid: courses drawn through the network's cells, channels
//! and valleys cut into the relief, lake and river water levels per block column.

use std::sync::Arc;

use super::drainage::{Kind, D8, NO_DOWN};
use super::{grid, CELL_METRES};
use crate::infinite::Source;
use crate::noise::{gradient, hash3, sin_cos_turns};
use crate::tile::{Rect, Tile};

/// Discharge (m³/s) from which a cell's water is a river a player sees: a stream of a few
/// hundred km² in a temperate climate (HydroRIVERS, the global river map, starts at
/// 0.1 m³/s or 10 km²).
pub const RIVER_DISCHARGE: f32 = 0.5;
/// Rivers are drawn this many times wider than hydraulic geometry says (a 10 m stream would
/// be a quarter of a block): wide enough to see and to swim in, still ordered by size.
const WIDTH_EXAGGERATION: f64 = 3.0;
/// The narrowest river, blocks.
const MIN_WIDTH_BLOCKS: f64 = 2.0;
/// The widest river, metres.
const MAX_WIDTH_M: f64 = 1200.0;
/// How far a node strays from its cell's centre, in cells (either axis): courses are not
/// drawn on a lattice.
const JITTER: f64 = 0.3;
/// Straight pieces each course curve is drawn with.
const SEGMENTS: usize = 8;
/// How far a course bends off its curve between two nodes, as a fraction of the curve's
/// chord (either side, at most 32/27 times this): a curve through nodes 1 km apart alone runs
/// straight for kilometres where several cells drain one way, and real rivers wind below
/// that scale. The bend is zero, and flat, at both ends of a curve, so courses still join
/// smoothly at every node and the network's cells decide where a river goes.
const MEANDER: f64 = 0.18;
/// Slope of a valley's sides above the floodplain (m/m): the valley a river cuts widens as
/// it deepens into higher ground.
const VALLEY_SLOPE: f64 = 0.2;
/// How far beyond its floodplain a river's valley reaches, metres; past it the relief is
/// untouched.
const VALLEY_REACH_M: f64 = 640.0;
/// How far under a dry basin's spill level the ground must lie to be its bed (salt or clay
/// flat), metres: the depth that makes a wet basin a lake
/// ([`super::drainage::LAKE_MIN_DEPTH_M`]).
pub const DRY_BED_DEPTH_M: f64 = super::drainage::LAKE_MIN_DEPTH_M as f64;
/// Interpolated basin indicator from which a basin's water fills all ground under its level.
const SHORE_FULL: f64 = 0.6;
/// Interpolated basin indicator below which there is no basin water.
const SHORE_EDGE: f64 = 0.15;
/// How far under a basin's level the ground must lie at [`SHORE_EDGE`], metres (linear from
/// 0 at [`SHORE_FULL`]).
const SHORE_RISE_M: f64 = 40.0;
/// How far a shore point is displaced by noise, cells.
const SHORE_WARP: f64 = 0.3;
/// Frequency of the shore-warping noise, per cell.
const SHORE_WARP_FREQ: f64 = 1.7;
/// How many times wider than upstream a river is where it meets the sea: over its last cell
/// it widens to twice its width, over its mouth to this (an estuary, as tides and the sea's
/// salt water widen real ones), never past [`MAX_WIDTH_M`].
pub const ESTUARY_FLARE: f64 = 4.0;
/// How far from a river's bank [`WaterColumns::river_distance`] counts, metres (the reach of
/// its valley); farther columns read this.
pub const RIVER_DISTANCE_MAX_M: f64 = VALLEY_REACH_M;
/// Channel depth at a river's centre, blocks, for the smallest river; one more per ×10
/// discharge, at most [`MAX_DEPTH_BLOCKS`].
const MAX_DEPTH_BLOCKS: f64 = 4.0;

/// Width (metres) of a river of discharge `q` (m³/s) on blocks of `block_m` metres: the
/// hydraulic-geometry width 4·√Q, exaggerated ([`WIDTH_EXAGGERATION`]), never narrower than
/// [`MIN_WIDTH_BLOCKS`] blocks.
pub fn water_width_m(q: f64, block_m: f64) -> f64 {
    (WIDTH_EXAGGERATION * 4.0 * q.max(0.0).sqrt()).min(MAX_WIDTH_M).max(MIN_WIDTH_BLOCKS * block_m)
}

/// [`water_width_m`] widened `flare` times (an estuary, [`ESTUARY_FLARE`]), at most
/// [`MAX_WIDTH_M`] unless the river is already wider.
pub fn flared_width_m(q: f64, flare: f64, block_m: f64) -> f64 {
    let w = water_width_m(q, block_m);
    (w * flare).min(MAX_WIDTH_M).max(w)
}

/// What [`Rivers::columns`] says of each block column, row-major over the rectangle.
pub struct WaterColumns {
    /// Water surface, metres (river or lake); NaN where neither (the sea is the caller's:
    /// everything below 0 m).
    pub level: Vec<f32>,
    /// [`Kind`] code of the water: [`Kind::Land`] for none, [`Kind::Sea`] is never given here,
    /// river water is [`WaterColumns::RIVER`].
    pub kind: Vec<u8>,
    /// Discharge of the river or lake, m³/s (0 elsewhere).
    pub discharge: Vec<f32>,
    /// Distance from the column to the nearest river's bank, metres: 0 in a river, at most
    /// [`RIVER_DISTANCE_MAX_M`] (what every column farther away reads).
    pub river_distance: Vec<f32>,
}

impl WaterColumns {
    /// Code of river water in [`WaterColumns::kind`] (beside [`Kind`]'s codes).
    pub const RIVER: u8 = 4;
}

/// A stretch of a river's course as a map draws it.
pub struct Course {
    /// Points along it, metres (x east, z south).
    pub points: Vec<(f64, f64)>,
    /// Its discharge, m³/s (the largest along it).
    pub discharge: f64,
}

/// One curve of a river's course: points (x, z metres), discharge, water level and width
/// factor ([`ESTUARY_FLARE`]) along it.
struct Piece {
    points: Vec<[f64; 5]>,
    lo: (f64, f64),
    hi: (f64, f64),
    reach: f64,
}

impl Piece {
    /// A quadratic Bézier from `a` via `b` to `c` (each x, z, discharge, level, width
    /// factor), bent sideways by `bend` (two numbers in [−1, 1], see [`meander`]):
    /// discharge and width factor linear along it, the level a Bézier too (so it never rises
    /// where the three levels fall).
    fn new(a: [f64; 5], b: [f64; 5], c: [f64; 5], bend: (f64, f64), block_m: f64) -> Piece {
        let length = |p: [f64; 5], q: [f64; 5]| ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2)).sqrt();
        let (chord, path) = (length(a, c), length(a, b) + length(b, c));
        // Sharp turns bend less: a bend as deep as the turn's radius would fold the course.
        let straightness = if path > 0.0 { chord / path } else { 1.0 };
        let amplitude = MEANDER * chord * straightness * straightness;
        let points: Vec<[f64; 5]> = (0..=SEGMENTS)
            .map(|k| {
                let t = k as f64 / SEGMENTS as f64;
                let (u, v, w) = ((1.0 - t) * (1.0 - t), 2.0 * t * (1.0 - t), t * t);
                let (x, z) = (u * a[0] + v * b[0] + w * c[0], u * a[1] + v * b[1] + w * c[1]);
                // Sideways: the unit normal of the curve's direction there.
                let (dx, dz) = (
                    2.0 * (1.0 - t) * (b[0] - a[0]) + 2.0 * t * (c[0] - b[0]),
                    2.0 * (1.0 - t) * (b[1] - a[1]) + 2.0 * t * (c[1] - b[1]),
                );
                let norm = (dx * dx + dz * dz).sqrt();
                let off = if norm > 0.0 { amplitude * meander(t, bend) / norm } else { 0.0 };
                [
                    x - off * dz,
                    z + off * dx,
                    a[2] + t * (c[2] - a[2]),
                    u * a[3] + v * b[3] + w * c[3],
                    a[4] + t * (c[4] - a[4]),
                ]
            })
            .collect();
        let reach = flared_width_m(a[2].max(c[2]), a[4].max(c[4]), block_m) + VALLEY_REACH_M;
        let lo = points.iter().fold((f64::INFINITY, f64::INFINITY), |m, p| (m.0.min(p[0]), m.1.min(p[1])));
        let hi = points.iter().fold((f64::NEG_INFINITY, f64::NEG_INFINITY), |m, p| (m.0.max(p[0]), m.1.max(p[1])));
        Piece { points, lo, hi, reach }
    }

    /// Distance (metres) from (`x`, `z`) to the curve, and the discharge, level and width
    /// factor there.
    fn nearest(&self, x: f64, z: f64) -> (f64, f64, f64, f64) {
        // The offset from (x, z) to segment `s`'s nearest point, and where along it that is.
        let offset = |s: &[[f64; 5]]| {
            let (p, q) = (s[0], s[1]);
            let (dx, dz) = (q[0] - p[0], q[1] - p[1]);
            let len2 = dx * dx + dz * dz;
            let t = if len2 > 0.0 { (((x - p[0]) * dx + (z - p[1]) * dz) / len2).clamp(0.0, 1.0) } else { 0.0 };
            ((x - p[0] - t * dx, z - p[1] - t * dz), t)
        };
        // Two passes, so `hypot` (a libm call, and this loop's largest cost) runs about once per
        // curve: the squares find the nearest, then only segments within their rounding of it
        // are measured exactly. The first segment of least `hypot` wins, as a single pass
        // keeping every strictly nearer segment would choose.
        let near2 = self.points.windows(2).fold(f64::INFINITY, |m, s| {
            let ((ex, ez), _) = offset(s);
            m.min(ex * ex + ez * ez)
        });
        let mut best = (f64::INFINITY, 0.0, 0.0, 1.0);
        for s in self.points.windows(2) {
            let ((ex, ez), t) = offset(s);
            if ex * ex + ez * ez > near2 * (1.0 + 1e-9) {
                continue;
            }
            let d = ex.hypot(ez);
            if d < best.0 {
                let (p, q) = (s[0], s[1]);
                best = (d, p[2] + t * (q[2] - p[2]), p[3] + t * (q[3] - p[3]), p[4] + t * (q[4] - p[4]));
            }
        }
        best
    }

    /// False only where the curve's valley surely does not reach (`x`, `z`): outside its box
    /// grown by the reach and a millimetre — far above the rounding of [`Piece::nearest`]
    /// even at the world border at 250 m per block (7.5·10⁹ m, where a metre's last bit is
    /// 10⁻⁶) — so a column it turns away would have been measured at least the reach away.
    /// A region's columns each skip most of the region's curves on this test alone.
    fn may_reach(&self, x: f64, z: f64) -> bool {
        const MARGIN_M: f64 = 1e-3;
        self.touches((x - MARGIN_M, z - MARGIN_M), (x + MARGIN_M, z + MARGIN_M))
    }

    /// True when the curve's valley may reach the box [`lo`, `hi`] (metres).
    fn touches(&self, lo: (f64, f64), hi: (f64, f64)) -> bool {
        self.lo.0 - self.reach <= hi.0
            && self.hi.0 + self.reach >= lo.0
            && self.lo.1 - self.reach <= hi.1
            && self.hi.1 + self.reach >= lo.1
    }
}

/// The sideways bend of a course curve at `t` ∈ [0, 1], in units of its amplitude:
/// `sin²(πt) · (p + q · cos(πt))` for `bend = (p, q)`, zero with a zero slope at both ends (so
/// neighbouring curves join without a kink), one bow (`q` = 0) or an S (`p` = 0) between.
/// Sine and cosine by [`sin_cos_turns`], the same bits on every platform.
fn meander(t: f64, (p, q): (f64, f64)) -> f64 {
    let (sin, cos) = sin_cos_turns(0.5 * t);
    sin * sin * (p + q * cos)
}

/// Rivers and lakes of one world at the block grid.
pub struct Rivers {
    network: Arc<dyn Source>,
    seed: u64,
}

/// The network's cells around a rectangle, with the questions the block grid asks of them.
struct Cells {
    tile: Tile,
}

impl Cells {
    fn kind(&self, cy: i64, cx: i64) -> Kind {
        Kind::from_code(self.tile.get(grid::KIND, cy, cx))
    }

    fn discharge(&self, cy: i64, cx: i64) -> f64 {
        f64::from(self.tile.get(grid::DISCHARGE, cy, cx))
    }

    fn level(&self, cy: i64, cx: i64) -> f64 {
        f64::from(self.tile.get(grid::LEVEL, cy, cx))
    }

    /// The downstream neighbour, if any.
    fn down(&self, cy: i64, cx: i64) -> Option<(i64, i64)> {
        let code = self.tile.get(grid::DOWN, cy, cx).round() as i8;
        (code != NO_DOWN).then(|| {
            let (dy, dx) = D8[code as usize];
            (cy + dy, cx + dx)
        })
    }

    /// True for a river cell: land whose discharge reaches [`RIVER_DISCHARGE`] and that
    /// drains somewhere.
    fn is_river(&self, cy: i64, cx: i64) -> bool {
        self.kind(cy, cx) == Kind::Land
            && self.tile.get(grid::DISCHARGE, cy, cx) >= RIVER_DISCHARGE
            && self.down(cy, cx).is_some()
    }
}

impl Rivers {
    /// The rivers of world seed `seed` over `network` (a [`super::Basins`] tensor).
    pub fn new(network: Arc<dyn Source>, seed: u64) -> Rivers {
        Rivers { network, seed: seed ^ 0x0052_1BE5_0000_0001 }
    }

    /// Where the course of cell (`cy`, `cx`) passes, metres (x, z): its centre, jittered.
    fn node(&self, cy: i64, cx: i64) -> (f64, f64) {
        let h = hash3(self.seed, cy, cx);
        let u = |bits: u64| ((bits & 0xFFFF) as f64 / 65535.0 - 0.5) * 2.0 * JITTER;
        ((cx as f64 + 0.5 + u(h)) * CELL_METRES, (cy as f64 + 0.5 + u(h >> 16)) * CELL_METRES)
    }

    /// How the course from cell `from` into cell `to` bends ([`meander`]): two numbers in
    /// [−1, 1] of the world seed and the two cells alone, so every query draws it alike.
    fn bend(&self, from: (i64, i64), to: (i64, i64)) -> (f64, f64) {
        let h = hash3(hash3(self.seed ^ 0x4D45_414E, from.0, from.1), to.0, to.1);
        let u = |bits: u64| (bits & 0xFFFF) as f64 / 65535.0 * 2.0 - 1.0;
        (u(h), u(h >> 16))
    }

    /// The network's cells (kind, discharge, level, downstream) over `cells`.
    pub fn network(&self, cells: Rect) -> Tile {
        self.network.query(cells)
    }

    /// The course curves of every river cell of `nodes` (which, grown by one cell, `cells`
    /// must cover).
    fn pieces(&self, cells: &Cells, nodes: Rect, block_m: f64) -> Vec<Piece> {
        let mut out = Vec::new();
        for cy in nodes.y0..nodes.y1() {
            for cx in nodes.x0..nodes.x1() {
                if !cells.is_river(cy, cx) {
                    continue;
                }
                let Some((dy, dx)) = cells.down(cy, cx) else { continue };
                let here = cells.level(cy, cx);
                let there = cells.level(dy, dx).min(here);
                let (pc, pd) = (self.node(cy, cx), self.node(dy, dx));
                let q = cells.discharge(cy, cx);
                let mid = |a: (f64, f64), b: (f64, f64)| ((a.0 + b.0) / 2.0, (a.1 + b.1) / 2.0);
                let m = mid(pc, pd);
                // A river that meets the sea widens over its last cell and its mouth (an
                // estuary): width factors 1 → √flare → flare.
                let estuary = cells.kind(dy, dx) == Kind::Sea;
                let (f_end, f_last) = if estuary { (ESTUARY_FLARE.sqrt(), ESTUARY_FLARE) } else { (1.0, 1.0) };
                let end = [m.0, m.1, q, (here + there) / 2.0, f_end];
                let centre = [pc.0, pc.1, q, here, 1.0];
                let mut upstream = 0;
                for &(oy, ox) in &D8 {
                    let (uy, ux) = (cy + oy, cx + ox);
                    let feeds = (cells.is_river(uy, ux) || cells.kind(uy, ux) == Kind::Lake)
                        && cells.down(uy, ux) == Some((cy, cx));
                    if !feeds {
                        continue;
                    }
                    upstream += 1;
                    let pu = self.node(uy, ux);
                    let s = mid(pu, pc);
                    let level = (cells.level(uy, ux).max(here) + here) / 2.0;
                    let bend = self.bend((uy, ux), (cy, cx));
                    out.push(Piece::new([s.0, s.1, cells.discharge(uy, ux), level, 1.0], centre, end, bend, block_m));
                }
                if upstream == 0 {
                    // A source: the course starts at the node.
                    out.push(Piece::new(
                        centre,
                        [(pc.0 + m.0) / 2.0, (pc.1 + m.1) / 2.0, q, (here + end[3]) / 2.0, 1.0],
                        end,
                        self.bend((cy, cx), (cy, cx)),
                        block_m,
                    ));
                }
                if matches!(cells.kind(dy, dx), Kind::Sea | Kind::Lake | Kind::Dry) {
                    // The mouth: on into the sea, the lake or the dry basin's bed.
                    let last = [pd.0, pd.1, q, there, f_last];
                    out.push(Piece::new(
                        end,
                        [(m.0 + pd.0) / 2.0, (m.1 + pd.1) / 2.0, q, (end[3] + there) / 2.0, 1.0],
                        last,
                        self.bend((cy, cx), (dy, dx)),
                        block_m,
                    ));
                }
            }
        }
        out
    }

    /// The course of every river near `blocks` (blocks of `block_m` metres): its curves as
    /// polylines in metres (x, z), each with its discharge (m³/s) — what a map draws.
    pub fn courses(&self, blocks: Rect, block_m: f64) -> Vec<Course> {
        let (lo, hi, nodes) = self.around(blocks, block_m);
        let cells = Cells { tile: self.network(nodes.pad(1)) };
        self.pieces(&cells, nodes, block_m)
            .into_iter()
            .filter(|p| p.touches(lo, hi))
            .map(|p| Course {
                discharge: p.points.iter().map(|q| q[2]).fold(0.0, f64::max),
                points: p.points.iter().map(|q| (q[0], q[1])).collect(),
            })
            .collect()
    }

    /// The box (metres) `blocks` covers and the network nodes whose courses may reach it.
    fn around(&self, blocks: Rect, block_m: f64) -> ((f64, f64), (f64, f64), Rect) {
        let lo = (blocks.x0 as f64 * block_m, blocks.y0 as f64 * block_m);
        let hi = (blocks.x1() as f64 * block_m, blocks.y1() as f64 * block_m);
        // A curve's chord is under 2 (1 + JITTER) cells, and it bends off by at most 32/27
        // MEANDER chords (`meander`'s largest value).
        let bend = 1.2 * MEANDER * 2.0 * (1.0 + JITTER);
        let reach = MAX_WIDTH_M + VALLEY_REACH_M + CELL_METRES * (1.0 + JITTER + bend);
        let cell = |m: f64| (m / CELL_METRES).floor() as i64;
        let (y0, x0) = (cell(lo.1 - reach), cell(lo.0 - reach));
        (lo, hi, Rect::new(y0, x0, cell(hi.1 + reach) - y0 + 1, cell(hi.0 + reach) - x0 + 1))
    }

    /// Evaluates the network cells [`Rivers::columns`] over `blocks` will read, so that a
    /// later query inside finds them cached.
    pub fn prefetch(&self, blocks: Rect, block_m: f64) {
        let (_, _, nodes) = self.around(blocks, block_m);
        self.network(nodes.pad(1));
    }

    /// The water of every block column of `blocks` (blocks of `block_m` metres, `vertical_m`
    /// metres of height per block), cutting river channels and valleys into `elevation`
    /// (metres, row-major over `blocks`).
    pub fn columns(&self, blocks: Rect, block_m: f64, vertical_m: f64, elevation: &mut [f32]) -> WaterColumns {
        let n = blocks.area();
        let (lo, hi, nodes) = self.around(blocks, block_m);
        let cells = Cells { tile: self.network(nodes.pad(1)) };
        let pieces: Vec<Piece> =
            self.pieces(&cells, nodes, block_m).into_iter().filter(|p| p.touches(lo, hi)).collect();

        let mut out = WaterColumns {
            level: vec![f32::NAN; n],
            kind: vec![Kind::Land as u8; n],
            discharge: vec![0.0; n],
            river_distance: vec![RIVER_DISTANCE_MAX_M as f32; n],
        };
        let mut i = 0;
        for z in blocks.y0..blocks.y1() {
            for x in blocks.x0..blocks.x1() {
                let (xm, zm) = ((x as f64 + 0.5) * block_m, (z as f64 + 0.5) * block_m);
                let mut e = f64::from(elevation[i]);
                let mut river: Option<(f64, f64, f64)> = None;
                let mut bank = RIVER_DISTANCE_MAX_M;
                for p in &pieces {
                    if !p.may_reach(xm, zm) {
                        continue;
                    }
                    let (d, q, level, flare) = p.nearest(xm, zm);
                    if d >= p.reach {
                        continue;
                    }
                    let half = flared_width_m(q, flare, block_m) / 2.0;
                    bank = bank.min((d - half).max(0.0));
                    let plain = 2.0 * half;
                    let floor = level + VALLEY_SLOPE * (d - plain).max(0.0);
                    let weight = if d <= plain { 1.0 } else { smoothstep(1.0 - (d - plain) / (p.reach - plain)) };
                    e = e.min(f64::from(elevation[i]) - weight * (f64::from(elevation[i]) - floor).max(0.0));
                    if d <= half && river.is_none_or(|r| d / half < r.0) {
                        river = Some((d / half, q, level));
                    }
                }
                if let Some((across, q, level)) = river {
                    let full = (1.0 + (q / f64::from(RIVER_DISCHARGE)).log10()).clamp(1.0, MAX_DEPTH_BLOCKS).floor();
                    let depth = (full * (1.0 - across * across).sqrt()).round().max(1.0);
                    e = e.min(level - depth * vertical_m - 0.01);
                    out.level[i] = level as f32;
                    out.kind[i] = WaterColumns::RIVER;
                    out.discharge[i] = q as f32;
                }
                // Lakes and dry beds: ground under a basin's level where the basin's cells
                // (smoothly interpolated, warped) reach; see `basin_at`.
                if let Some((kind, level, q)) = self.basin_at(&cells, xm, zm, e) {
                    if kind == Kind::Lake || river.is_none() {
                        out.level[i] = level as f32;
                        out.kind[i] = kind as u8;
                        out.discharge[i] = if kind == Kind::Lake { q as f32 } else { 0.0 };
                    }
                }
                out.river_distance[i] = bank as f32;
                elevation[i] = e as f32;
                i += 1;
            }
        }
        out
    }
}

impl Rivers {
    /// The lake or dry basin (kind, level, discharge) whose water covers ground at `e`
    /// metres at `(xm, zm)`, if any. A basin's cells (1 km) are spread into an indicator
    /// interpolated between cell centres at a point warped by noise, so shores do not trace
    /// the lattice: where the indicator is high the water fills all ground under the level;
    /// towards its edge it needs ground ever further under it ([`SHORE_RISE_M`]), so on flat
    /// ground the shore is the warped contour and on slopes it is the level's own contour.
    fn basin_at(&self, cells: &Cells, xm: f64, zm: f64, e: f64) -> Option<(Kind, f64, f64)> {
        let (cy, cx) = ((zm / CELL_METRES).floor() as i64, (xm / CELL_METRES).floor() as i64);
        let basin = |y: i64, x: i64| matches!(cells.kind(y, x), Kind::Lake | Kind::Dry);
        if !(-1..=1).any(|a| (-1..=1).any(|b| basin(cy + a, cx + b))) {
            return None;
        }
        let (u, v) = (xm / CELL_METRES * SHORE_WARP_FREQ, zm / CELL_METRES * SHORE_WARP_FREQ);
        let warp = SHORE_WARP * CELL_METRES;
        let wx = xm + warp * gradient(self.seed ^ 0x5A0E, v, u);
        let wz = zm + warp * gradient(self.seed ^ 0x5A0F, v + 17.0, u + 31.0);
        // Interpolate between the four cell centres around the warped point.
        let (fy, fx) = (wz / CELL_METRES - 0.5, wx / CELL_METRES - 0.5);
        let (y0, x0) = (fy.floor() as i64, fx.floor() as i64);
        let (ty, tx) = (smoothstep(fy - y0 as f64), smoothstep(fx - x0 as f64));
        let mut best: Option<(f64, i64, i64)> = None;
        let mut indicator = 0.0;
        for (a, b, w) in
            [(0, 0, (1.0 - ty) * (1.0 - tx)), (0, 1, (1.0 - ty) * tx), (1, 0, ty * (1.0 - tx)), (1, 1, ty * tx)]
        {
            let (y, x) = (y0 + a, x0 + b);
            if basin(y, x) {
                indicator += w;
                if best.is_none_or(|(bw, _, _)| w > bw) {
                    best = Some((w, y, x));
                }
            }
        }
        let (_, y, x) = best?;
        let level = cells.level(y, x);
        let rise = SHORE_RISE_M * ((SHORE_FULL - indicator) / (SHORE_FULL - SHORE_EDGE)).max(0.0);
        let kind = cells.kind(y, x);
        // A dry basin's bed is its floor, where runoff would pool: the ground at least
        // DRY_BED_DEPTH_M under the basin's spill level; its shallower slopes stay land.
        let floor = if kind == Kind::Dry { DRY_BED_DEPTH_M } else { 0.0 };
        (indicator > SHORE_EDGE && e + rise + floor < level).then(|| (kind, level, cells.discharge(y, x)))
    }
}

/// 0 at 0, 1 at 1, flat at both ends.
fn smoothstep(t: f64) -> f64 {
    let t = t.clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

#[cfg(test)]
mod tests {
    use super::super::grid;
    use super::*;

    /// A network with one river along cell row 0, west to east, from cell x 0 to 9, into a
    /// sea from cell x 10 on; every other cell is land without a river.
    struct OneRiver;

    impl Source for OneRiver {
        fn channels(&self) -> usize {
            grid::COUNT
        }

        fn query(&self, rect: Rect) -> Tile {
            let mut t = Tile::zeros(grid::COUNT, rect);
            let n = rect.area();
            let mut i = 0;
            for y in rect.y0..rect.y1() {
                for x in rect.x0..rect.x1() {
                    let (kind, down, q, level) = if x >= 10 {
                        (Kind::Sea, NO_DOWN, 0.0, 0.0)
                    } else if y == 0 && x >= 0 {
                        (Kind::Land, 4, 100.0, 50.0 - 5.0 * x as f32)
                    } else {
                        (Kind::Land, NO_DOWN, 0.0, 100.0)
                    };
                    t.data[grid::KIND * n + i] = kind as u8 as f32;
                    t.data[grid::DOWN * n + i] = f32::from(down);
                    t.data[grid::DISCHARGE * n + i] = q;
                    t.data[grid::LEVEL * n + i] = level;
                    t.data[grid::FILLED * n + i] = level;
                    i += 1;
                }
            }
            t
        }
    }

    const BLOCK_M: f64 = 40.0;

    /// The water of a line of block columns across the river (north to south) at `x_m`
    /// metres east: 3 km long, land at 100 m west of the sea, sea floor at −10 m.
    fn across(x_m: f64) -> WaterColumns {
        let x = (x_m / BLOCK_M).floor() as i64;
        let blocks = Rect::new(-40, x, 80, 1);
        let mut elevation = vec![if x_m < 10_000.0 { 100.0 } else { -10.0 }; blocks.area()];
        Rivers::new(Arc::new(OneRiver), 3).columns(blocks, BLOCK_M, 25.0, &mut elevation)
    }

    fn river_columns(w: &WaterColumns) -> usize {
        w.kind.iter().filter(|&&k| k == WaterColumns::RIVER).count()
    }

    #[test]
    fn a_river_widens_into_an_estuary_where_it_meets_the_sea() {
        let upstream = river_columns(&across(3_500.0));
        let width = |q: f64, f: f64| flared_width_m(q, f, BLOCK_M) / BLOCK_M;
        // 3·4·√100 m = 120 m: three blocks (a column's centre may fall either side of a bank).
        assert!((width(100.0, 1.0) - 1.0..=width(100.0, 1.0) + 1.0).contains(&(upstream as f64)), "{upstream}");
        // Over the last cell the river widens, over its mouth to ESTUARY_FLARE times.
        let widths: Vec<usize> =
            [8_500.0, 9_200.0, 9_800.0, 10_300.0].iter().map(|&x| river_columns(&across(x))).collect();
        assert!(widths.windows(2).all(|w| w[1] >= w[0]), "an estuary widens towards the sea: {widths:?}");
        assert!(widths[3] as f64 >= 0.75 * ESTUARY_FLARE * upstream as f64, "{widths:?} from {upstream}");
        // Never past the widest river, however large the flare.
        assert_eq!(flared_width_m(1e6, ESTUARY_FLARE, BLOCK_M), MAX_WIDTH_M);
        assert_eq!(flared_width_m(4.0, 1.0, BLOCK_M), water_width_m(4.0, BLOCK_M));
    }

    #[test]
    fn a_course_bends_between_its_ends_and_joins_its_neighbours_without_a_kink() {
        let at = |x: f64| [x, 0.0, 1.0, 10.0, 1.0];
        let piece = |bend| Piece::new(at(0.0), at(500.0), at(1000.0), bend, BLOCK_M);
        assert!(piece((0.0, 0.0)).points.iter().all(|q| q[1] == 0.0), "no bend: the Bézier itself");
        let bow = piece((1.0, 0.0));
        // A bow: the middle off by the full amplitude, the ends where they were.
        let middle = bow.points[SEGMENTS / 2];
        assert!((middle[1].abs() - MEANDER * 1000.0).abs() < 1e-6, "{middle:?}");
        let (first, last) = (bow.points[0], bow.points[SEGMENTS]);
        assert!(first[1].abs() < 1e-9 && last[1].abs() < 1e-9 && first[0] == 0.0 && (last[0] - 1000.0).abs() < 1e-9);
        // An S: the two halves on opposite sides.
        let s = piece((0.0, 1.0));
        assert!(s.points[2][1] * s.points[SEGMENTS - 2][1] < 0.0, "{:?}", s.points);
        // The bend's shape: zero and flat at both ends, never past 32/27.
        for bend in [(1.0, 1.0), (-1.0, 1.0), (0.3, -0.8)] {
            let slope = |t: f64| (meander(t + 1e-6, bend) - meander(t, bend)) / 1e-6;
            assert!(meander(0.0, bend).abs() < 1e-12 && meander(1.0, bend).abs() < 1e-12);
            assert!(slope(0.0).abs() < 1e-4 && slope(1.0 - 1e-6).abs() < 1e-4, "{bend:?}");
            assert!((0..=1000).all(|k| meander(k as f64 / 1000.0, bend).abs() <= 32.0 / 27.0 + 1e-9));
        }
        // Level, discharge and width factor do not move with the bend.
        assert!(bow.points.iter().zip(&piece((0.0, 0.0)).points).all(|(a, b)| a[2..] == b[2..]));
    }

    #[test]
    fn the_nearest_point_and_the_reach_test_agree_with_measuring_every_segment() {
        // A winding curve; points on a grid around and beyond it, some on its nodes.
        let piece = Piece::new(
            [0.0, 0.0, 1.0, 10.0, 1.0],
            [700.0, 400.0, 2.0, 9.0, 1.5],
            [1000.0, 1000.0, 3.0, 8.0, 2.0],
            (0.7, -0.4),
            BLOCK_M,
        );
        for (i, j) in (-20..=60).flat_map(|i| (-20..=60).map(move |j| (i, j))) {
            let (x, z) = (i as f64 * 25.0, j as f64 * 25.0);
            // Every segment measured by `hypot`; the first of least distance wins.
            let mut brute = (f64::INFINITY, 0.0, 0.0, 1.0);
            for s in piece.points.windows(2) {
                let (p, q) = (s[0], s[1]);
                let (dx, dz) = (q[0] - p[0], q[1] - p[1]);
                let t = (((x - p[0]) * dx + (z - p[1]) * dz) / (dx * dx + dz * dz)).clamp(0.0, 1.0);
                let d = (x - p[0] - t * dx).hypot(z - p[1] - t * dz);
                if d < brute.0 {
                    brute = (d, p[2] + t * (q[2] - p[2]), p[3] + t * (q[3] - p[3]), p[4] + t * (q[4] - p[4]));
                }
            }
            let near = piece.nearest(x, z);
            assert_eq!(near, brute, "at ({x}, {z})");
            assert!(piece.may_reach(x, z) || near.0 >= piece.reach, "({x}, {z}) is {} m away", near.0);
        }
        // The test turns columns away: far ones are not measured at all.
        assert!(!piece.may_reach(-piece.reach - 1.0, 0.0) && piece.may_reach(-piece.reach + 1.0, 0.0));
    }

    #[test]
    fn a_winding_river_has_water_all_along_it() {
        // Every 100 m from its second cell to its mouth, a cut across holds river water.
        for x in (15..100).map(|i| i as f64 * 100.0) {
            assert!(river_columns(&across(x)) > 0, "no river at x {x} m");
        }
    }

    #[test]
    fn the_distance_to_a_river_is_zero_in_it_and_grows_like_a_distance_away_from_it() {
        let w = across(3_500.0);
        for (i, (&k, &d)) in w.kind.iter().zip(&w.river_distance).enumerate() {
            assert_eq!(k == WaterColumns::RIVER, d == 0.0, "column {i}: kind {k}, distance {d}");
        }
        // One block further from the river is at most one block further from its bank.
        assert!(
            w.river_distance.windows(2).all(|p| (p[1] - p[0]).abs() <= BLOCK_M as f32 + 1e-3),
            "{:?}",
            w.river_distance
        );
        // Far off (1.6 km) the distance reads its ceiling; half-way it is a few hundred metres.
        assert_eq!(
            (w.river_distance[0], w.river_distance[79]),
            (RIVER_DISTANCE_MAX_M as f32, RIVER_DISTANCE_MAX_M as f32)
        );
        assert!(w.river_distance.iter().any(|&d| (200.0..500.0).contains(&d)), "{:?}", w.river_distance);
    }
}
