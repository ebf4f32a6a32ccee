//! The cave field: where caves are, as a pure function of (seed, block position) and the
//! block columns. The caves pass carves it; tree and plant placement ask it whether a
//! column's ground is a cave's mouth, so nothing is rooted over the hole — in this chunk or
//! in the neighbour a tree reaches into.
//!
//! The density is sampled on a lattice of 4 × 8 × 4 blocks and interpolated trilinearly
//! between (vanilla samples its noise the same way): caverns ("cheese") where a two-octave
//! noise is high, tunnels ("spaghetti") where two independent noises are both near their
//! middle (the intersection of two surfaces is a line).
//!
//! Caves stay dry: no cave reaches within [`SEA_SEAL`] blocks of the ground under the sea, a
//! river or a lake, or within [`SHORE_REACH`] columns of them (a cave opening under water
//! would flood in vanilla the moment a block next to it is touched). Elsewhere caves keep
//! [`LAND_SEAL`] blocks under the ground, except in entrance patches (a noise over the
//! ground, [`ENTRANCE_AT`]) where they may break through it: cave mouths.

use super::columns::Columns;
use super::hash::{value_noise, value_noise3};

/// Lattice spacing of the cave density across, blocks.
pub const LATTICE: i64 = 4;
/// Lattice spacing of the cave density up and down, blocks (vanilla's noise cells are
/// 4 × 8 × 4 too; caves are flatter than they are wide).
pub const LATTICE_Y: i64 = 8;
/// Blocks of rock kept between a cave and the ground of a wet column, or of any column within
/// [`SHORE_REACH`] blocks of one.
pub const SEA_SEAL: i32 = 8;
/// Blocks of rock kept between a cave and the ground of dry land outside entrance patches.
pub const LAND_SEAL: i32 = 4;
/// How far from water (blocks) the water's seal still applies.
pub const SHORE_REACH: i64 = 3;
/// Cavern threshold on the cavern noise (0..1): higher, rarer caverns.
const CAVERN_AT: f32 = 0.74;
/// Half-width of a tunnel in noise units around each noise's middle.
const TUNNEL_HALF_WIDTH: f32 = 0.045;
/// Width of the entrance noise's features, blocks.
const ENTRANCE_SCALE: i64 = 32;
/// Entrance noise (0..1) above which caves may open through the ground.
pub const ENTRANCE_AT: f32 = 0.72;
/// Salt of the entrance noise.
const ENTRANCE_SALT: u64 = 0xCA7E_0E1E;
/// How much an entrance patch raises the density near the ground, at its heart (the
/// tunnels' half-width is 0.045): tunnels and caverns that pass under it widen as they near
/// the ground and break through — a level plane of the field alone crosses a tunnel too
/// rarely (no mouth in 64 chunks of flat land).
const ENTRANCE_WIDEN: f32 = 0.2;
/// How far under the ground an entrance patch widens the caves, blocks.
pub const MOUTH_DEPTH: i32 = 12;

/// The cave density at a lattice point (> 0: carved).
pub fn density(seed: u64, x: i64, y: i64, z: i64) -> f32 {
    let (fx, fy, fz) = (x as f64, y as f64, z as f64);
    // Caverns: broad, flattened (vanilla's are wider than tall).
    let cavern = 0.7 * value_noise3(seed, 0xCA7E, fx / 48.0, fy / 24.0, fz / 48.0)
        + 0.3 * value_noise3(seed, 0xCA7F, fx / 16.0, fy / 8.0, fz / 16.0);
    // Tunnels: where two noises are both near one half.
    let a = value_noise3(seed, 0x5A6E, fx / 36.0, fy / 18.0, fz / 36.0) - 0.5;
    let b = value_noise3(seed, 0x5A6F, fx / 36.0, fy / 18.0, fz / 36.0) - 0.5;
    let tunnel = TUNNEL_HALF_WIDTH - a.abs().max(b.abs());
    (cavern - CAVERN_AT).max(tunnel)
}

/// [`density`] at the lattice point (`x`, `y`, `z`) (multiples of [`LATTICE`], [`LATTICE_Y`]
/// and [`LATTICE`]), remembered per thread. The caves pass computes a chunk's lattice, and the
/// surface, tree and plant decisions after it ask [`field`] about the same points again
/// (every column of an entrance patch, eight corners each): without the memo that was as
/// much hashing again as the carving's. The same bits as [`density`], whatever the memo holds.
pub fn lattice_density(seed: u64, x: i64, y: i64, z: i64) -> f32 {
    debug_assert!(x % LATTICE == 0 && y % LATTICE_Y == 0 && z % LATTICE == 0, "({x}, {y}, {z}) is off the lattice");
    let key = (i32::try_from(x / LATTICE), i32::try_from(y / LATTICE_Y), i32::try_from(z / LATTICE));
    let (Ok(lx), Ok(ly), Ok(lz)) = key else { return density(seed, x, y, z) };
    // A chunk's lattice (5 × 5 points a row, up to 49 rows) and its neighbours' shared edges
    // fall on distinct slots.
    let slot = ((lx & 7) | (lz & 7) << 3 | (ly & 63) << 6) as usize;
    MEMO.with_borrow_mut(|memo| {
        let entry = &mut memo[slot];
        if entry.seed != seed || (entry.x, entry.y, entry.z) != (lx, ly, lz) {
            *entry = Remembered { seed, x: lx, y: ly, z: lz, density: density(seed, x, y, z) };
        }
        entry.density
    })
}

/// One remembered lattice density (coordinates in lattice units).
#[derive(Clone, Copy)]
struct Remembered {
    seed: u64,
    x: i32,
    y: i32,
    z: i32,
    density: f32,
}

thread_local! {
    /// The lattice densities each thread computed last, by slot ([`lattice_density`]). Empty
    /// slots hold `x = i32::MIN`, which no lattice point within `i32` has.
    static MEMO: std::cell::RefCell<Box<[Remembered; 4096]>> = std::cell::RefCell::new(Box::new(
        [Remembered { seed: 0, x: i32::MIN, y: 0, z: 0, density: 0.0 }; 4096],
    ));
}

/// The density inside a lattice cell from its eight corners (x fastest, then z, then y:
/// `[x0z0y0, x1z0y0, x0z1y0, x1z1y0, x0z0y1, …]`) at fractions `tx`, `ty`, `tz` of the cell.
/// The one formula both the pass and [`field`] use, so they agree bit for bit.
#[inline]
pub fn interpolate(c: &[f32; 8], tx: f32, ty: f32, tz: f32) -> f32 {
    let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
    let low = lerp(lerp(c[0], c[1], tx), lerp(c[2], c[3], tx), tz);
    let high = lerp(lerp(c[4], c[5], tx), lerp(c[6], c[7], tx), tz);
    lerp(low, high, ty)
}

/// The interpolated density at block (`x`, `y`, `z`) (> 0: carved, if the column lets it).
pub fn field(seed: u64, x: i64, y: i64, z: i64) -> f32 {
    let (cx, cy, cz) =
        (x.div_euclid(LATTICE) * LATTICE, y.div_euclid(LATTICE_Y) * LATTICE_Y, z.div_euclid(LATTICE) * LATTICE);
    let d = |i: i64, j: i64, k: i64| lattice_density(seed, cx + i * LATTICE, cy + j * LATTICE_Y, cz + k * LATTICE);
    let corners = [d(0, 0, 0), d(1, 0, 0), d(0, 0, 1), d(1, 0, 1), d(0, 1, 0), d(1, 1, 0), d(0, 1, 1), d(1, 1, 1)];
    let t = |v: i64, l: i64| v.rem_euclid(l) as f32 / l as f32;
    interpolate(&corners, t(x, LATTICE), t(y, LATTICE_Y), t(z, LATTICE))
}

/// True where caves may break through the ground of dry land (an entrance patch).
pub fn entrance(seed: u64, x: i64, z: i64) -> bool {
    widening(seed, x, z) > 0.0
}

/// What column (`x`, `z`)'s entrance patch adds to the density within [`MOUTH_DEPTH`]
/// blocks of the ground: 0 outside patches, up to [`ENTRANCE_WIDEN`] at their hearts.
pub fn widening(seed: u64, x: i64, z: i64) -> f32 {
    let n = value_noise(seed, ENTRANCE_SALT, x, z, ENTRANCE_SCALE);
    ENTRANCE_WIDEN * ((n - ENTRANCE_AT) / (1.0 - ENTRANCE_AT)).max(0.0)
}

/// The highest Y column (`x`, `z`) may be carved to (`columns` must hold its neighbours
/// within [`SHORE_REACH`]).
pub fn ceiling(seed: u64, columns: &Columns, x: i64, z: i64) -> i32 {
    let near_water =
        (-SHORE_REACH..=SHORE_REACH).any(|dz| (-SHORE_REACH..=SHORE_REACH).any(|dx| columns.is_wet(x + dx, z + dz)));
    ceiling_near(seed, columns, x, z, near_water)
}

/// [`ceiling`], told whether any column within [`SHORE_REACH`] is wet (the caves pass finds
/// that for a whole chunk at once).
pub fn ceiling_near(seed: u64, columns: &Columns, x: i64, z: i64, near_water: bool) -> i32 {
    let ground = columns.surface_y(x, z);
    if near_water {
        let lowest = (-SHORE_REACH..=SHORE_REACH)
            .flat_map(|dz| (-SHORE_REACH..=SHORE_REACH).map(move |dx| (dx, dz)))
            .map(|(dx, dz)| columns.surface_y(x + dx, z + dz))
            .min()
            .unwrap_or(ground);
        lowest - SEA_SEAL
    } else if entrance(seed, x, z) {
        ground
    } else {
        ground - LAND_SEAL
    }
}

/// True where the caves pass carves column (`x`, `z`)'s ground block away: a cave's mouth.
/// `columns` must hold the column's neighbours within [`SHORE_REACH`].
pub fn opens(seed: u64, columns: &Columns, x: i64, z: i64) -> bool {
    may_open(seed, columns, x, z) && ceiling(seed, columns, x, z) >= columns.surface_y(x, z)
}

/// True where column (`x`, `z`)'s ground block would be carved away but for water nearby:
/// what [`opens`] says without looking at the neighbours, so it needs only the column
/// itself. Nothing is rooted where this holds (a few trees fewer near water, and the same
/// answer in every chunk that asks).
pub fn may_open(seed: u64, columns: &Columns, x: i64, z: i64) -> bool {
    // Cheap test first: almost all ground lies outside entrance patches.
    let widen = widening(seed, x, z);
    widen > 0.0 && field(seed, x, i64::from(columns.surface_y(x, z)), z) + widen > 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn remembered_densities_are_the_densities() {
        // Points that share slots (8 lattice units apart across, 64 up), two seeds, visited
        // twice in an order that evicts: every answer is the density itself.
        let points: Vec<(i64, i64, i64)> = (0..400)
            .map(|i: i64| {
                ((i % 11 - 5) * 8 * LATTICE, (i % 7 - 3) * 64 * LATTICE_Y + (i % 3) * LATTICE_Y, (i / 11) * LATTICE)
            })
            .collect();
        for _ in 0..2 {
            for &(x, y, z) in &points {
                for seed in [3, 4] {
                    assert_eq!(
                        lattice_density(seed, x, y, z).to_bits(),
                        density(seed, x, y, z).to_bits(),
                        "({x}, {y}, {z})"
                    );
                }
            }
        }
    }
}
