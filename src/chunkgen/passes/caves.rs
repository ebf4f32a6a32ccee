//! The caves pass: carves the cave field ([`crate::chunkgen::cave_field`]: caverns and
//! winding tunnels from density noise, as vanilla 1.18+ does) out of the rock, and floods
//! what it carves at Y −55 and below with lava (vanilla's lava level). Each column is carved
//! up to its ceiling: under the ground, clear of water, or through the ground in entrance
//! patches (cave mouths).

use valence::prelude::{BlockState, Chunk};

use crate::chunkgen::Blocks;

use crate::chunkgen::cave_field::{
    ceiling_near, interpolate, lattice_density, widening, LATTICE, LATTICE_Y, MOUTH_DEPTH, SHORE_REACH,
};
use crate::chunkgen::columns::Columns;
use crate::chunkgen::{ChunkContext, CHUNK};

/// Carved blocks at this Y and below are lava.
pub const LAVA_Y: i32 = -55;
/// Blocks above the floor that are never carved (the bedrock and a layer over it).
const FLOOR_KEEP: i32 = 5;

/// Carves the chunk's caves (air, lava at [`LAVA_Y`] and below).
pub fn run(ctx: &mut ChunkContext, chunk: &mut Blocks) {
    let v = *ctx.vertical();
    let columns = ctx.columns();
    // The highest Y each column may be carved to.
    let seed = ctx.seed();
    let near = near_water(columns, ctx.x0, ctx.z0);
    let ceiling: Vec<i32> = ctx
        .each_column()
        .map(|(lx, lz, x, z)| ceiling_near(seed, columns, x, z, near[(lz * 16 + lx) as usize]))
        .collect();
    // Entrance patches widen the caves near the ground: from this Y up, by this much.
    let mouths: Vec<(i32, f32)> =
        ctx.each_column().map(|(_, _, x, z)| (columns.surface_y(x, z) - MOUTH_DEPTH, widening(seed, x, z))).collect();
    let widest = mouths.iter().map(|m| m.1).fold(0.0, f32::max);
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
    let mut lattice = vec![0f32; n * n * rows];
    for (j, ly) in (ly0..=ly1).enumerate() {
        for k in 0..n {
            for i in 0..n {
                let (x, z) = (ctx.x0 + i as i64 * LATTICE, ctx.z0 + k as i64 * LATTICE);
                lattice[(j * n + k) * n + i] = lattice_density(seed, x, ly * LATTICE_Y, z);
            }
        }
    }
    let at = |i: usize, j: usize, k: usize| lattice[(j * n + k) * n + i];
    let cells = n - 1;
    let columns = Carve { ceiling: &ceiling, mouths: &mouths };
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
                // Trilinear values stay within the corners': a cell with no corner positive
                // even when widened has no cave (most of the rock), so it is skipped whole.
                if corners.iter().all(|&d| d + widest <= 0.0) {
                    continue;
                }
                carve_cell(chunk, &corners, (i, j, k), ly0, &columns, bottom, v.min_y);
            }
        }
    }
}

/// For every column of the chunk at (`x0`, `z0`) (index `z·16 + x`), whether a column within
/// [`SHORE_REACH`] is wet: the wet columns widened along x, then along z — 14 looks a column
/// instead of the 49 of asking each column's square.
fn near_water(columns: &Columns, x0: i64, z0: i64) -> Vec<bool> {
    let (r, n) = (SHORE_REACH, CHUNK as usize);
    let rows = (z0 - r..z0 + CHUNK + r)
        .map(|z| (x0..x0 + CHUNK).map(move |x| (x - r..=x + r).any(|x| columns.is_wet(x, z))).collect::<Vec<_>>());
    let rows: Vec<Vec<bool>> = rows.collect();
    (0..n)
        .flat_map(|lz| (0..n).map(move |lx| (lz, lx)))
        .map(|(lz, lx)| rows[lz..=lz + 2 * r as usize].iter().any(|row| row[lx]))
        .collect()
}

/// What limits and widens the carving of each column of the chunk (index `z·16 + x`).
struct Carve<'a> {
    /// The highest Y carved.
    ceiling: &'a [i32],
    /// From which Y up the density is raised, and by how much (an entrance patch).
    mouths: &'a [(i32, f32)],
}

/// Carves the blocks of one lattice cell whose interpolated density (widened in entrance
/// patches) is positive.
fn carve_cell(
    chunk: &mut Blocks,
    c: &[f32; 8],
    (i, j, k): (usize, usize, usize),
    ly0: i64,
    columns: &Carve,
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
                let (lx, lz) = (i * l + dx, k * l + dz);
                let column = lz * CHUNK as usize + lx;
                let (from, widen) = columns.mouths[column];
                if interpolate(c, tx, ty, tz) + if y >= from { widen } else { 0.0 } <= 0.0 {
                    continue;
                }
                if y > columns.ceiling[column] {
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
    use crate::chunkgen::cave_field::{density, entrance, field, opens, LAND_SEAL};
    use crate::terrain::Rect;

    /// A chunk of rock up to `ground(x)` with the sea pass run, then this pass.
    fn carved(seed_chunk: (i32, i32), ground: impl Fn(i64) -> f32) -> (Blocks, crate::chunkgen::Vertical) {
        let (g, palette, rules) = (testing::generator(), testing::palette(), testing::single_biome("minecraft:plains"));
        let v = *g.vertical();
        let mut ctx = ChunkContext::new(&g, &rules, &palette, seed_chunk.0, seed_chunk.1);
        let (x0, z0) = (ctx.x0, ctx.z0);
        ctx.columns = Some(testing::columns(&g, Rect::new(z0 - 5, x0 - 5, 26, 26), |x, _| (ground(x), 10.0)));
        let mut chunk = Blocks::with_height(v.height as u32);
        super::super::rock::run(&mut ctx, &mut chunk);
        super::super::water::run(&mut ctx, &mut chunk);
        run(&mut ctx, &mut chunk);
        (chunk, v)
    }

    #[test]
    fn the_chunk_s_shore_test_is_each_column_s() {
        let g = testing::generator();
        // A coast across the chunk, diagonal, and a pond: columns near water and far from it.
        let columns = testing::columns(&g, Rect::new(-5, 27, 26, 26), |x, z| {
            let pond = (x - 40).pow(2) + (z - 9).pow(2) < 4;
            (if pond { -30.0 } else { (x + z - 45) as f32 * 4.0 }, 10.0)
        });
        let near = near_water(&columns, 32, 0);
        let (mut wet, mut dry) = (0, 0);
        for lz in 0..16 {
            for lx in 0..16 {
                let (x, z) = (32 + lx, lz);
                let each = (-SHORE_REACH..=SHORE_REACH)
                    .any(|dz| (-SHORE_REACH..=SHORE_REACH).any(|dx| columns.is_wet(x + dx, z + dz)));
                assert_eq!(near[(lz * 16 + lx) as usize], each, "({x}, {z})");
                if each {
                    wet += 1
                } else {
                    dry += 1
                }
            }
        }
        assert!(wet > 20 && dry > 20, "{wet} near water, {dry} not");
    }

    #[test]
    fn land_has_caves_with_lava_only_deep_down_and_a_sealed_ground() {
        let seed = testing::generator().seed;
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
                            let (gx, gz) = (i64::from(cx) * 16 + i64::from(x), 48 + i64::from(z));
                            let sealed = y <= 103 - LAND_SEAL || entrance(seed, gx, gz);
                            assert!(y > LAVA_Y && sealed && y >= v.min_y + FLOOR_KEEP, "air at Y {y}");
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
    fn caves_open_through_the_ground_only_in_entrance_patches_where_the_field_says() {
        // Flat land at 1,000 m (ground Y 103) over 8 × 8 chunks.
        let g = testing::generator();
        let (mut mouths, mut patch_columns) = (0, 0);
        for cz in 0..8 {
            for cx in 0..8 {
                let (chunk, v) = carved((cx, cz), |_| 1000.0);
                let columns =
                    testing::columns(&g, Rect::new(i64::from(cz) * 16 - 5, i64::from(cx) * 16 - 5, 26, 26), |_, _| {
                        (1000.0, 10.0)
                    });
                assert_eq!(columns.surface_y(i64::from(cx) * 16, i64::from(cz) * 16), 103);
                for z in 0..16u32 {
                    for x in 0..16u32 {
                        let (gx, gz) = (i64::from(cx) * 16 + i64::from(x), i64::from(cz) * 16 + i64::from(z));
                        let open = chunk.block_state(x, (103 - v.min_y) as u32, z).is_air();
                        assert_eq!(open, opens(g.seed, &columns, gx, gz), "({gx}, {gz})");
                        assert!(!open || entrance(g.seed, gx, gz));
                        mouths += usize::from(open);
                        patch_columns += usize::from(entrance(g.seed, gx, gz));
                    }
                }
            }
        }
        let all = 64 * 256;
        assert!(patch_columns > all / 50 && patch_columns < all / 4, "entrance patches: {patch_columns} of {all}");
        // Measured: 59 open columns of 2,426 in patches (a mouth every few chunks).
        assert!(mouths > 0 && mouths < patch_columns / 2, "{mouths} open columns in {patch_columns}");
    }

    #[test]
    fn neighbouring_chunks_carve_one_cave_field_without_seams() {
        // Each block is carved exactly where the density, interpolated from the lattice
        // points around it in global coordinates, is positive: the same in whichever chunk.
        let seed = testing::generator().seed;
        let mut carved_blocks = 0;
        for cx in [-1, 0] {
            let (chunk, v) = carved((cx, 0), |_| 1000.0);
            for z in 0..16u32 {
                for x in [0u32, 1, 14, 15] {
                    for y in (-50..90).step_by(3) {
                        let gx = i64::from(cx) * 16 + i64::from(x);
                        let air = chunk.block_state(x, (y - v.min_y) as u32, z).is_air();
                        assert_eq!(air, field(seed, gx, i64::from(y), i64::from(z)) > 0.0, "({gx}, {y}, {z})");
                        carved_blocks += usize::from(air);
                    }
                }
            }
        }
        assert!(carved_blocks > 0, "nothing carved along the border");
        assert_ne!(density(9, 3, 4, 5), density(10, 3, 4, 5), "the seed must matter");
    }
}
