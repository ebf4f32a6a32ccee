//! The rock pass: bedrock at the floor, deepslate at and below Y 0 and stone above it, up to
//! every column's ground (the surface pass then lays the ground's own blocks on top). As in
//! vanilla 1.20.1 both boundaries are ragged: bedrock thins out over the floor's five lowest
//! blocks and deepslate over Y 0 … 8, each block drawn by a hash of its position (so chunks
//! agree on their borders and a world is the same in any order).

use valence::prelude::{BlockState, Chunk};

use crate::chunkgen::Blocks;

use crate::chunkgen::hash::unit3;
use crate::chunkgen::ChunkContext;

/// Blocks over the floor bedrock reaches: the floor itself always, each block above it less
/// often, none this high (vanilla's `bedrock_floor` gradient).
pub const BEDROCK_LAYERS: i32 = 5;
/// Deepslate at and below Y 0 always, above it less often up to this Y, never from it on
/// (vanilla's `deepslate` gradient).
pub const DEEPSLATE_TOP: i32 = 8;

const SALT_BEDROCK: u64 = 0x6265_6472;
const SALT_DEEPSLATE: u64 = 0x6465_6570;

/// Fills every column with rock from the floor to its surface block.
pub fn run(ctx: &mut ChunkContext, chunk: &mut Blocks) {
    let (v, seed) = (*ctx.vertical(), ctx.seed());
    let columns = ctx.columns();
    let surface: Vec<i32> = ctx.each_column().map(|(_, _, x, z)| columns.surface_y(x, z)).collect();
    let lowest = surface.iter().copied().min().unwrap_or(v.min_y);
    let top = surface.iter().copied().max().unwrap_or(v.min_y);
    // Layer by layer, written along the layer (up a column strides through memory). Layers
    // clear of both ragged boundaries are one block: whole below the lowest ground, else in
    // the columns whose ground reaches them; the others are drawn block by block.
    for y in v.min_y..=top {
        let ly = (y - v.min_y) as u32;
        let clear_of_bedrock = y - v.min_y >= BEDROCK_LAYERS;
        let one = if clear_of_bedrock && y <= 0 {
            Some(BlockState::DEEPSLATE)
        } else if clear_of_bedrock && y >= DEEPSLATE_TOP {
            Some(BlockState::STONE)
        } else {
            None
        };
        match one {
            Some(block) if y <= lowest => chunk.layer_mut(ly).fill(block),
            Some(block) => {
                for (b, &ground) in chunk.layer_mut(ly).iter_mut().zip(&surface) {
                    if y <= ground {
                        *b = block;
                    }
                }
            }
            None => {
                for ((lx, lz, x, z), &ground) in ctx.each_column().zip(&surface) {
                    if y <= ground {
                        chunk.set_block_state(lx, ly, lz, rock_at(seed, v.min_y, x, y, z));
                    }
                }
            }
        }
    }
}

/// The rock at block (`x`, `y`, `z`) of a world whose floor is `min_y`.
pub fn rock_at(seed: u64, min_y: i32, x: i64, y: i32, z: i64) -> BlockState {
    let over_floor = y - min_y;
    if over_floor < BEDROCK_LAYERS
        && (over_floor == 0
            || unit3(seed, SALT_BEDROCK, x, y.into(), z) < 1.0 - over_floor as f32 / BEDROCK_LAYERS as f32)
    {
        BlockState::BEDROCK
    } else if y <= 0
        || (y < DEEPSLATE_TOP
            && unit3(seed, SALT_DEEPSLATE, x, y.into(), z) < (DEEPSLATE_TOP - y) as f32 / DEEPSLATE_TOP as f32)
    {
        BlockState::DEEPSLATE
    } else {
        BlockState::STONE
    }
}

#[cfg(test)]
mod tests {
    use super::super::testing;
    use super::*;
    use crate::terrain::Rect;

    #[test]
    fn columns_are_bedrock_then_deepslate_then_stone_up_to_the_ground_with_ragged_boundaries() {
        let (g, palette, rules) = (testing::generator(), testing::palette(), testing::single_biome("minecraft:plains"));
        let v = *g.vertical();
        let mut ctx = ChunkContext::new(&g, &rules, &palette, 0, 0);
        // Ground rising 25 m (one block) per column eastwards from Y 63.
        ctx.columns = Some(testing::columns(&g, Rect::new(-5, -5, 26, 26), |x, _| (x.max(0) as f32 * 25.0, 10.0)));
        let mut chunk = Blocks::with_height(v.height as u32);
        run(&mut ctx, &mut chunk);
        let count = |y: i32, block: BlockState| {
            (0..16u32)
                .flat_map(|x| (0..16u32).map(move |z| (x, z)))
                .filter(|&(x, z)| chunk.block_state(x, (y - v.min_y) as u32, z) == block)
                .count()
        };
        assert_eq!(count(v.min_y, BlockState::BEDROCK), 256, "the floor is whole");
        // Bedrock thins out upwards over the floor's layers (vanilla: 80, 60, 40, 20 %).
        let bedrock: Vec<usize> = (1..BEDROCK_LAYERS).map(|k| count(v.min_y + k, BlockState::BEDROCK)).collect();
        for (k, &n) in bedrock.iter().enumerate() {
            let expect = 256.0 * (1.0 - (k + 1) as f32 / BEDROCK_LAYERS as f32);
            assert!((n as f32 - expect).abs() < 40.0, "layer {}: {n} bedrock, about {expect} expected", k + 1);
        }
        assert_eq!(count(v.min_y + BEDROCK_LAYERS, BlockState::BEDROCK), 0);
        assert_eq!(count(0, BlockState::DEEPSLATE), 256, "deepslate at and below Y 0");
        let deepslate: Vec<usize> = (1..DEEPSLATE_TOP).map(|y| count(y, BlockState::DEEPSLATE)).collect();
        assert!(
            deepslate.windows(2).all(|w| w[0] + 24 >= w[1]) && deepslate[0] > 180 && deepslate[6] < 80,
            "{deepslate:?}"
        );
        assert_eq!(count(DEEPSLATE_TOP, BlockState::STONE), 256);
        for lx in [0u32, 7, 15] {
            let at = |y: i32| chunk.block_state(lx, (y - v.min_y) as u32, 5);
            let ground = 63 + lx as i32;
            assert_eq!(at(-1), BlockState::DEEPSLATE);
            assert_eq!(at(ground), BlockState::STONE);
            assert!(at(ground + 1).is_air(), "column {lx}");
        }
        // The same block wherever the chunk is generated from: a function of the position.
        assert_eq!(rock_at(g.seed(), v.min_y, 5, 3, 9), rock_at(g.seed(), v.min_y, 5, 3, 9));
        let (a, b) = ((0..64).map(|x| rock_at(1, v.min_y, x, 3, 0)), (0..64).map(|x| rock_at(2, v.min_y, x, 3, 0)));
        assert!(a.zip(b).any(|(a, b)| a != b), "the boundary does not depend on the seed");
    }
}
