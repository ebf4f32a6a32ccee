//! The caves pass: carves caverns ("cheese") and winding tunnels ("spaghetti") out of the
//! rock, as vanilla 1.18+ does with density noise, and floods what it carves at Y −55 and
//! below with lava (vanilla's lava level).
//!
//! The cave field is a density sampled on a lattice of 4 × 8 × 4 blocks and interpolated
//! trilinearly between (vanilla samples its noise the same way): caverns where a two-octave
//! noise is high, tunnels where two independent noises are both near their middle (the
//! intersection of two surfaces is a line). A pure function of (seed, x, y, z), so caves run
//! on across chunk borders.
//!
//! Caves stay dry: no cave reaches within [`SEA_SEAL`] blocks of the ground under the sea or
//! near it (a cave opening under water would flood in vanilla the moment a block next to it
//! is touched), and nothing is carved within [`LAND_SEAL`] blocks of the ground elsewhere, so
//! the surface pass's ground stays whole.

use valence::prelude::{BlockState, Chunk, UnloadedChunk};

use crate::chunkgen::hash::value_noise3;
use crate::chunkgen::{ChunkContext, CHUNK};

/// Lattice spacing of the cave density across, blocks.
const LATTICE: i64 = 4;
/// Lattice spacing of the cave density up and down, blocks (vanilla's noise cells are
/// 4 × 8 × 4 too; caves are flatter than they are wide).
const LATTICE_Y: i64 = 8;
/// Blocks of rock kept between a cave and the ground of a sea column, or of any column within
/// [`SHORE_REACH`] blocks of one.
pub const SEA_SEAL: i32 = 8;
/// Blocks of rock kept between a cave and the ground of dry land.
pub const LAND_SEAL: i32 = 4;
/// How far from the sea (blocks) the sea's seal still applies.
const SHORE_REACH: i64 = 3;
/// Carved blocks at this Y and below are lava.
pub const LAVA_Y: i32 = -55;
/// Blocks above the floor that are never carved (the bedrock and a layer over it).
const FLOOR_KEEP: i32 = 5;
/// Cavern threshold on the cavern noise (0..1): higher, rarer caverns.
const CAVERN_AT: f32 = 0.74;
/// Half-width of a tunnel in noise units around each noise's middle.
const TUNNEL_HALF_WIDTH: f32 = 0.045;

/// The cave density at a block (> 0: carved).
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

/// Carves the chunk's caves (air, lava at [`LAVA_Y`] and below).
pub fn run(ctx: &mut ChunkContext, chunk: &mut UnloadedChunk) {
    let v = *ctx.vertical();
    let columns = ctx.columns();
    // The highest Y each column may be carved to.
    let ceiling: Vec<i32> = ctx
        .each_column()
        .map(|(_, _, x, z)| {
            let near_sea = (-SHORE_REACH..=SHORE_REACH)
                .any(|dz| (-SHORE_REACH..=SHORE_REACH).any(|dx| columns.is_wet(x + dx, z + dz)));
            let ground = columns.surface_y(x, z);
            if near_sea {
                let lowest = (-SHORE_REACH..=SHORE_REACH)
                    .flat_map(|dz| (-SHORE_REACH..=SHORE_REACH).map(move |dx| (dx, dz)))
                    .map(|(dx, dz)| columns.surface_y(x + dx, z + dz))
                    .min()
                    .unwrap_or(ground);
                lowest - SEA_SEAL
            } else {
                ground - LAND_SEAL
            }
        })
        .collect();
    let top = ceiling.iter().copied().max().unwrap_or(v.min_y);
    let bottom = v.min_y + FLOOR_KEEP;
    if top < bottom {
        return;
    }
    // The lattice over the chunk, from the lattice row at or below `bottom` to the one at or
    // above `top`.
    let (ly0, ly1) = ((bottom as i64).div_euclid(LATTICE_Y), (top as i64).div_euclid(LATTICE_Y) + 1);
    let n = (CHUNK / LATTICE + 1) as usize;
    let rows = (ly1 - ly0 + 1) as usize;
    let seed = ctx.seed();
    let mut lattice = vec![0f32; n * n * rows];
    for (j, ly) in (ly0..=ly1).enumerate() {
        for k in 0..n {
            for i in 0..n {
                let (x, z) = (ctx.x0 + i as i64 * LATTICE, ctx.z0 + k as i64 * LATTICE);
                lattice[(j * n + k) * n + i] = density(seed, x, ly * LATTICE_Y, z);
            }
        }
    }
    let at = |i: usize, j: usize, k: usize| lattice[(j * n + k) * n + i];
    let cells = n - 1;
    for j in 0..rows - 1 {
        for k in 0..cells {
            for i in 0..cells {
                let corners = [
                    at(i, j, k),
                    at(i + 1, j, k),
                    at(i, j, k + 1),
                    at(i + 1, j, k + 1),
                    at(i, j + 1, k),
                    at(i + 1, j + 1, k),
                    at(i, j + 1, k + 1),
                    at(i + 1, j + 1, k + 1),
                ];
                // Trilinear values stay within the corners': a cell with no positive corner
                // has no cave (most of the rock), so it is skipped whole.
                if corners.iter().all(|&d| d <= 0.0) {
                    continue;
                }
                carve_cell(chunk, &corners, (i, j, k), ly0, &ceiling, bottom, v.min_y);
            }
        }
    }
}

/// Carves the blocks of one lattice cell whose interpolated density is positive.
fn carve_cell(
    chunk: &mut UnloadedChunk,
    c: &[f32; 8],
    (i, j, k): (usize, usize, usize),
    ly0: i64,
    ceiling: &[i32],
    bottom: i32,
    min_y: i32,
) {
    let l = LATTICE as usize;
    let y0 = ((ly0 + j as i64) * LATTICE_Y) as i32;
    for dy in 0..LATTICE_Y as usize {
        let y = y0 + dy as i32;
        if y < bottom {
            continue;
        }
        let ty = dy as f32 / LATTICE_Y as f32;
        for dz in 0..l {
            let tz = dz as f32 / LATTICE as f32;
            for dx in 0..l {
                let tx = dx as f32 / LATTICE as f32;
                let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
                let low = lerp(lerp(c[0], c[1], tx), lerp(c[2], c[3], tx), tz);
                let high = lerp(lerp(c[4], c[5], tx), lerp(c[6], c[7], tx), tz);
                if lerp(low, high, ty) <= 0.0 {
                    continue;
                }
                let (lx, lz) = (i * l + dx, k * l + dz);
                if y > ceiling[lz * CHUNK as usize + lx] {
                    continue;
                }
                let block = if y <= LAVA_Y { BlockState::LAVA } else { BlockState::AIR };
                let ly = (y - min_y) as u32;
                if !chunk.block_state(lx as u32, ly, lz as u32).is_liquid() {
                    chunk.set_block_state(lx as u32, ly, lz as u32, block);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::testing;
    use super::*;
    use crate::terrain::Rect;

    /// A chunk of rock up to `ground(x)` with the sea pass run, then this pass.
    fn carved(seed_chunk: (i32, i32), ground: impl Fn(i64) -> f32) -> (UnloadedChunk, crate::chunkgen::Vertical) {
        let (g, palette, rules) = (testing::generator(), testing::palette(), testing::single_biome("minecraft:plains"));
        let v = *g.vertical();
        let mut ctx = ChunkContext::new(&g, &rules, &palette, seed_chunk.0, seed_chunk.1);
        let (x0, z0) = (ctx.x0, ctx.z0);
        ctx.columns = Some(testing::columns(&g, Rect::new(z0 - 4, x0 - 4, 24, 24), |x, _| (ground(x), 10.0)));
        let mut chunk = UnloadedChunk::with_height(v.height as u32);
        super::super::rock::run(&mut ctx, &mut chunk);
        super::super::water::run(&mut ctx, &mut chunk);
        run(&mut ctx, &mut chunk);
        (chunk, v)
    }

    #[test]
    fn land_has_caves_with_lava_only_deep_down_and_a_sealed_ground() {
        let (mut air, mut lava) = (0, 0);
        for cx in 0..6 {
            // Ground at 1,000 m: Y 103.
            let (chunk, v) = carved((cx, 3), |_| 1000.0);
            for y in v.min_y..v.min_y + v.height {
                for z in 0..16 {
                    for x in 0..16 {
                        let b = chunk.block_state(x, (y - v.min_y) as u32, z);
                        if y <= 103 && b.is_air() {
                            air += 1;
                            assert!(y > LAVA_Y && y <= 103 - LAND_SEAL && y >= v.min_y + FLOOR_KEEP, "air at Y {y}");
                        }
                        if b == BlockState::LAVA {
                            lava += 1;
                            assert!(y <= LAVA_Y, "lava at Y {y}");
                        }
                    }
                }
            }
        }
        let rock = 6 * 256 * (103 + 64);
        assert!(air > rock / 100 && air < rock / 5, "{air} of {rock} blocks carved");
        assert!(lava > 0, "no lava in six chunks");
    }

    #[test]
    fn caves_stay_dry_under_and_beside_the_sea() {
        // West half sea 600 m deep (ground Y 52), east half land at 100 m.
        for cx in 0..6 {
            let (chunk, v) = carved((cx, -2), |x| if x.rem_euclid(16) < 8 { -600.0 } else { 100.0 });
            let at = |x: i32, y: i32, z: i32| chunk.block_state(x as u32, (y - v.min_y) as u32, z as u32);
            let mut air = 0;
            for z in 0..16 {
                for x in 0..16 {
                    for y in v.min_y + 1..v.water_top_y() {
                        if !at(x, y, z).is_air() {
                            continue;
                        }
                        air += 1;
                        // Three blocks of rock at least between any cave and the water.
                        for (dx, dy, dz) in
                            (-3..=3).flat_map(|a| (-3..=3).flat_map(move |b| (-3..=3).map(move |c| (a, b, c))))
                        {
                            let (nx, ny, nz) = (x + dx, y + dy, z + dz);
                            if (0..16).contains(&nx) && (0..16).contains(&nz) {
                                assert!(!at(nx, ny, nz).is_liquid() || ny <= LAVA_Y, "cave ({x}, {y}, {z}) by water");
                            }
                        }
                    }
                }
            }
            assert!(air > 0, "no caves under the land half");
        }
    }

    #[test]
    fn neighbouring_chunks_carve_one_cave_field_without_seams() {
        // Each block is carved exactly where the density, interpolated from the lattice
        // points around it in global coordinates, is positive: the same in whichever chunk.
        let g = testing::generator();
        let seed = g.seed;
        let interpolated = |x: i64, y: i64, z: i64| {
            let (cx, cy, cz) = (x.div_euclid(LATTICE), y.div_euclid(LATTICE_Y), z.div_euclid(LATTICE));
            let t = |v: i64| v.rem_euclid(LATTICE) as f32 / LATTICE as f32;
            let ty = y.rem_euclid(LATTICE_Y) as f32 / LATTICE_Y as f32;
            let d =
                |i: i64, j: i64, k: i64| density(seed, (cx + i) * LATTICE, (cy + j) * LATTICE_Y, (cz + k) * LATTICE);
            let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
            let plane = |j: i64| lerp(lerp(d(0, j, 0), d(1, j, 0), t(x)), lerp(d(0, j, 1), d(1, j, 1), t(x)), t(z));
            lerp(plane(0), plane(1), ty)
        };
        let mut carved_blocks = 0;
        for cx in [-1, 0] {
            let (chunk, v) = carved((cx, 0), |_| 1000.0);
            for z in 0..16u32 {
                for x in [0u32, 1, 14, 15] {
                    for y in (-50..90).step_by(3) {
                        let gx = i64::from(cx) * 16 + i64::from(x);
                        let air = chunk.block_state(x, (y - v.min_y) as u32, z).is_air();
                        assert_eq!(air, interpolated(gx, i64::from(y), i64::from(z)) > 0.0, "({gx}, {y}, {z})");
                        carved_blocks += usize::from(air);
                    }
                }
            }
        }
        assert!(carved_blocks > 0, "nothing carved along the border");
        assert_ne!(density(9, 3, 4, 5), density(10, 3, 4, 5), "the seed must matter");
    }
}
