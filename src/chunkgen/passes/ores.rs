//! The ores pass: veins of ore and blobs of other rock in the stone and deepslate the caves
//! left, as the rule folder's `[[vein]]`s list them (`biomes/underground.toml` ships vanilla
//! 1.20.1's placements — attempts per chunk, vein size, height range and shape — from its
//! data-driven world generation, `worldgen/placed_feature/ore_*.json`, as listed on the
//! Minecraft Wiki's "Ore" page: coal, iron, copper, gold, redstone, lapis, diamond, emerald in
//! the mountains; granite, diorite, andesite, tuff, gravel and dirt blobs).
//!
//! A vein belongs to the chunk it starts in; chunks draw the veins of their eight neighbours
//! too and keep the blocks that fall inside themselves, so veins cross chunk borders whole
//! whatever order chunks are built in. A vein replaces only stone or deepslate (its deepslate
//! variant in deepslate), never air, water, lava or the ground's own blocks.

use valence::prelude::{BlockState, Chunk};

use crate::chunkgen::Blocks;

use crate::biome::{Vein, VeinHeight};
use crate::chunkgen::hash::hash3;
use crate::chunkgen::{ChunkContext, CHUNK};

/// Blocks a vanilla vein of each `size` places in solid stone, on average: a Monte Carlo of
/// vanilla's `OreFeature` (`scripts/vanilla-ore-veins`, 20,000 veins a size). A vein's
/// `size` is not its block count: small ones place fewer (size 3, an emerald vein, 0.47), the
/// long blobs far more (size 64, granite, 685).
const VANILLA_BLOCKS: [(u32, f32); 10] = [
    (3, 0.47),
    (4, 1.98),
    (7, 4.95),
    (8, 5.77),
    (9, 6.81),
    (10, 8.42),
    (12, 11.64),
    (17, 22.10),
    (33, 111.84),
    (64, 684.63),
];

/// Up to this much (blocks²) is added to a block's squared distance from a vein's start, so
/// veins are lumpy rather than balls.
const JITTER: f32 = 1.5;

/// How many blocks a ball of squared radius `r2` places on average: each block within the
/// jittered reach counts with the chance its jitter lets it in.
fn expected_blocks(r2: f32) -> f32 {
    let r = (r2 + JITTER).sqrt().ceil() as i32;
    let mut n = 0.0;
    for dy in -r..=r {
        for dz in -r..=r {
            for dx in -r..=r {
                let d2 = (dx * dx + dy * dy + dz * dz) as f32;
                n += ((r2 + JITTER * 0.5 - d2) / JITTER).clamp(0.0, 1.0);
            }
        }
    }
    n
}

/// Blocks a vein of any `size` from 1 to 64 places on average: vanilla's measured means
/// ([`VANILLA_BLOCKS`]), interpolated between the sizes measured (log-log, as the means grow
/// like a power of the size) and in proportion below the smallest.
fn mean_blocks(size: u32) -> f32 {
    let size = size.clamp(1, crate::biome::MAX_VEIN_SIZE);
    if let Some(&(_, measured)) = VANILLA_BLOCKS.iter().find(|&&(s, _)| s == size) {
        return measured;
    }
    let (first, _) = VANILLA_BLOCKS[0];
    if size <= first {
        return VANILLA_BLOCKS[0].1 * size as f32 / first as f32;
    }
    let i = VANILLA_BLOCKS.iter().position(|&(s, _)| s >= size).unwrap_or(VANILLA_BLOCKS.len() - 1);
    let ((s0, m0), (s1, m1)) = (VANILLA_BLOCKS[i - 1], VANILLA_BLOCKS[i]);
    let t = ((size as f32).ln() - (s0 as f32).ln()) / ((s1 as f32).ln() - (s0 as f32).ln());
    (m0.ln() + t * (m1.ln() - m0.ln())).exp()
}

/// Squared radius (blocks²) of the ball a vein of `size` fills: the one that places
/// [`mean_blocks`], by bisection, computed once for every size.
fn radius2(size: u32) -> f32 {
    static RADII: std::sync::LazyLock<Vec<f32>> = std::sync::LazyLock::new(|| {
        (0..=crate::biome::MAX_VEIN_SIZE)
            .map(|size| {
                let want = mean_blocks(size);
                let (mut lo, mut hi) = (-JITTER, 400.0f32);
                for _ in 0..40 {
                    let mid = 0.5 * (lo + hi);
                    if expected_blocks(mid) < want {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                0.5 * (lo + hi)
            })
            .collect()
    });
    RADII[size.min(crate::biome::MAX_VEIN_SIZE) as usize]
}

/// Whether the block at offset `d` from a vein's start is in the vein of squared radius `r2`
/// and lumps `salt`.
fn in_vein(salt: u64, r2: f32, (dx, dy, dz): (i64, i64, i64)) -> bool {
    // One multiply per block (not a full hash): plenty for lumpiness.
    let cell = ((dx + 16) | (dy + 16) << 5 | (dz + 16) << 10) as u64;
    let h = (salt ^ cell).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    let jitter = (h >> 40) as f32 / (1u64 << 24) as f32 * JITTER;
    (dx * dx + dy * dy + dz * dz) as f32 + jitter <= r2 + JITTER * 0.5
}

/// How far (blocks) a vein of `size` reaches from its start, jitter included.
fn reach(size: u32) -> i64 {
    (radius2(size) + JITTER).max(0.0).sqrt().ceil() as i64
}

/// Writes every vein that starts in this chunk or a neighbour into this chunk.
pub fn run(ctx: &mut ChunkContext, chunk: &mut Blocks) {
    let v = *ctx.vertical();
    let (seed, columns) = (ctx.seed(), ctx.columns());
    let (cx, cz) = (ctx.x0.div_euclid(CHUNK), ctx.z0.div_euclid(CHUNK));
    // No stone lies above the chunk's highest ground (the terrain is a height field), so a
    // vein that starts more than its reach above it places nothing: most of the upper iron,
    // coal and emerald attempts.
    let highest = ctx.each_column().map(|(_, _, x, z)| columns.surface_y(x, z)).max().unwrap_or(i32::MAX);
    for (k, ore) in ctx.rules.veins().iter().enumerate() {
        let r = reach(ore.size);
        for nz in cz - 1..=cz + 1 {
            for nx in cx - 1..=cx + 1 {
                for (x, y, z) in starts(seed, k as u64, (nx, nz), ore) {
                    // Veins too far from this chunk to touch it are skipped whole.
                    let (lx, lz) = (x - ctx.x0, z - ctx.z0);
                    if lx < -r || lx >= CHUNK + r || lz < -r || lz >= CHUNK + r {
                        continue;
                    }
                    if y < v.min_y + 1 || y >= v.min_y + v.height || i64::from(y) - r > i64::from(highest) {
                        continue;
                    }
                    if ore.min_elevation_m > f32::NEG_INFINITY && columns.elevation(x, z) < ore.min_elevation_m {
                        continue;
                    }
                    place_vein(
                        chunk,
                        ctx.x0,
                        ctx.z0,
                        v.min_y,
                        ore,
                        hash3(seed, 0x0E1A ^ k as u64, x, i64::from(y), z),
                        (x, y, z),
                    );
                }
            }
        }
    }
}

/// Where the veins of `ore` that start in chunk (`cx`, `cz`) start (global block coordinates).
pub fn starts(seed: u64, kind: u64, (cx, cz): (i64, i64), ore: &Vein) -> Vec<(i64, i32, i64)> {
    let h = |i: u64, what: u64| hash3(seed, 0x0DE5 ^ (kind << 16) ^ (what << 8), cx, i as i64, cz);
    let unit = |x: u64| (x >> 40) as f32 / (1u64 << 24) as f32;
    let whole = ore.per_chunk.floor() as u64;
    let extra = unit(h(u64::MAX, 0)) < ore.per_chunk.fract();
    (0..whole + u64::from(extra))
        .map(|i| {
            let r = h(i, 1);
            let x = cx * CHUNK + (r & 15) as i64;
            let z = cz * CHUNK + ((r >> 4) & 15) as i64;
            let y = match ore.height {
                VeinHeight::Uniform(lo, hi) => lo + ((r >> 8) % (hi - lo + 1) as u64) as i32,
                VeinHeight::Triangle(lo, hi) => {
                    // The sum of two uniforms is triangular.
                    let half = (hi - lo) as u64 / 2 + 1;
                    lo + ((r >> 8) % half) as i32 + ((r >> 24) % half) as i32
                }
            };
            (x, y, z)
        })
        .collect()
}

/// One vein of vanilla's `ore.size`, as many blocks as vanilla's place on average: the blocks
/// within the vein's ball around its start, each block's distance jittered so veins are
/// lumpy, written where they fall inside the chunk.
fn place_vein(chunk: &mut Blocks, x0: i64, z0: i64, min_y: i32, ore: &Vein, salt: u64, (sx, sy, sz): (i64, i32, i64)) {
    let (r, r2) = (reach(ore.size), radius2(ore.size));
    // Only the offsets that land inside the chunk (above its floor): most of a neighbour's
    // vein lies outside, and visiting its blocks only to skip them cost more than the rest.
    let (sy, min_y) = (i64::from(sy), i64::from(min_y));
    let dys = (1 - sy + min_y).max(-r)..=(i64::from(chunk.height()) - 1 - sy + min_y).min(r);
    let dzs = (z0 - sz).max(-r)..=(z0 + CHUNK - 1 - sz).min(r);
    let dxs = (x0 - sx).max(-r)..=(x0 + CHUNK - 1 - sx).min(r);
    // No jitter lets in a block farther than this (blocks², with a block to spare for
    // rounding): each row is visited only across the ball, about half its bounding box.
    let limit = r2 + JITTER * 0.5 + 1.0;
    for dy in dys {
        let ly = sy + dy - min_y;
        for dz in dzs.clone() {
            let lz = sz + dz - z0;
            let left = limit - (dy * dy + dz * dz) as f32;
            if left < 0.0 {
                continue;
            }
            let half = left.sqrt() as i64;
            for dx in (*dxs.start()).max(-half)..=(*dxs.end()).min(half) {
                let lx = sx + dx - x0;
                if !in_vein(salt, r2, (dx, dy, dz)) {
                    continue;
                }
                let (lx, ly, lz) = (lx as u32, ly as u32, lz as u32);
                let block = match chunk.block_state(lx, ly, lz) {
                    BlockState::STONE => ore.block,
                    BlockState::DEEPSLATE => ore.deepslate,
                    _ => continue,
                };
                chunk.set_block_state(lx, ly, lz, block);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::rock::DEEPSLATE_TOP;
    use super::super::testing;
    use super::*;
    use crate::terrain::Rect;

    /// Chunk (`cx`, `cz`) of solid rock up to 2,000 m (Y 143), with this pass run.
    fn ores_in(cx: i32, cz: i32) -> Blocks {
        let (g, palette, rules) = (testing::generator(), testing::palette(), testing::single_biome("minecraft:plains"));
        let v = *g.vertical();
        let mut ctx = ChunkContext::new(&g, &rules, &palette, cx, cz);
        let (x0, z0) = (ctx.x0, ctx.z0);
        ctx.columns = Some(testing::columns(&g, Rect::new(z0 - 5, x0 - 5, 26, 26), |_, _| (2000.0, 10.0)));
        let mut chunk = Blocks::with_height(v.height as u32);
        super::super::rock::run(&mut ctx, &mut chunk);
        run(&mut ctx, &mut chunk);
        chunk
    }

    #[test]
    fn veins_place_as_many_blocks_as_vanillas_on_average() {
        for &(size, want) in &VANILLA_BLOCKS {
            let r = reach(size);
            let r2 = radius2(size);
            let (mut total, veins) = (0usize, 2000u64);
            for salt in 0..veins {
                let salt = hash3(11, 0x0E1A, salt as i64, 0, 0);
                for dy in -r..=r {
                    for dz in -r..=r {
                        total += (-r..=r).filter(|&dx| in_vein(salt, r2, (dx, dy, dz))).count();
                    }
                }
            }
            let mean = total as f32 / veins as f32;
            assert!((mean - want).abs() <= 0.08 * want + 0.05, "size {size}: {mean} blocks a vein, vanilla {want}");
        }
    }

    #[test]
    fn sizes_between_vanillas_place_blocks_between_theirs() {
        for &(size, want) in &VANILLA_BLOCKS {
            assert!((mean_blocks(size) - want).abs() < 1e-3 * want, "size {size}");
        }
        let means: Vec<f32> = (1..=64).map(mean_blocks).collect();
        assert!(means.windows(2).all(|w| w[0] < w[1]), "{means:?}");
        assert!(radius2(20) > radius2(17) && radius2(20) < radius2(33));
    }

    #[test]
    fn veins_start_where_vanilla_places_them() {
        let rules = testing::single_biome("minecraft:plains");
        assert_eq!(rules.veins().len(), 22, "vanilla's 22 placements");
        for (k, ore) in rules.veins().iter().enumerate() {
            let (lo, hi) = match ore.height {
                VeinHeight::Uniform(lo, hi) | VeinHeight::Triangle(lo, hi) => (lo, hi),
            };
            let mut n = 0;
            for c in 0..200 {
                for (x, y, z) in starts(5, k as u64, (c, -c), ore) {
                    n += 1;
                    assert!((lo..=hi).contains(&y), "ore {k} at Y {y}");
                    assert!((c * 16..c * 16 + 16).contains(&x) && (-c * 16..-c * 16 + 16).contains(&z));
                }
            }
            let want = 200.0 * ore.per_chunk;
            assert!((n as f32 - want).abs() <= 3.0 * want.sqrt() + 1.0, "ore {k}: {n} starts for {want}");
        }
    }

    #[test]
    fn ores_sit_at_their_depths_in_their_host_rock_and_veins_cross_chunk_borders() {
        let v = *testing::generator().vertical();
        let chunks: Vec<Blocks> = (0..4).map(|cx| ores_in(cx, 2)).collect();
        let at = |x: i64, y: i32, z: u32| {
            let c = &chunks[x.div_euclid(16) as usize];
            c.block_state(x.rem_euclid(16) as u32, (y - v.min_y) as u32, z)
        };
        let (mut diamonds, mut coal, mut crossing) = (0, 0, 0);
        for x in 0..64i64 {
            for z in 0..16u32 {
                for y in v.min_y..144 {
                    let b = at(x, y, z);
                    if b == BlockState::DIAMOND_ORE || b == BlockState::DEEPSLATE_DIAMOND_ORE {
                        diamonds += 1;
                        assert!(y <= 16 + 3, "diamond at Y {y}");
                    }
                    if b == BlockState::COAL_ORE || b == BlockState::DEEPSLATE_COAL_ORE {
                        coal += 1;
                    }
                    // Deepslate variants only in deepslate (at and below Y 0, ragged up to
                    // Y 8), plain ones above.
                    let name = b.to_kind().to_str();
                    if name.ends_with("_ore") {
                        if y <= 0 || y >= DEEPSLATE_TOP {
                            assert_eq!(name.starts_with("deepslate_"), y <= 0, "{name} at Y {y}");
                        }
                        // The same ore on both sides of a chunk border: a vein drawn whole.
                        if x % 16 == 15 && x < 63 && at(x + 1, y, z) == b {
                            crossing += 1;
                        }
                    }
                }
            }
        }
        assert!(diamonds > 0 && coal > 100, "{diamonds} diamond and {coal} coal blocks in four chunks");
        assert!(crossing > 0, "no vein crosses a chunk border");
    }
}
