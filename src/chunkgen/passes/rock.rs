//! The rock pass: bedrock at the floor, deepslate below Y 0 and stone above it, up to every
//! column's ground (the surface pass then lays the ground's own blocks on top).

use valence::prelude::{BlockState, Chunk, UnloadedChunk};

use crate::chunkgen::ChunkContext;

/// Deepest filler any ground asks for, plus the top block: sections entirely below this many
/// blocks under the lowest surface of a chunk are plain rock.
pub const MAX_GROUND_DEPTH: i32 = 16;

/// Fills every column with rock from the floor to its surface block.
pub fn run(ctx: &mut ChunkContext, chunk: &mut UnloadedChunk) {
    let v = *ctx.vertical();
    let columns = ctx.columns();
    let min_surface = ctx.each_column().map(|(_, _, x, z)| columns.surface_y(x, z)).min().unwrap_or(v.min_y);
    // Whole sections of rock below every column's ground: filled wholesale, which is much
    // faster than block by block.
    let rock_top = min_surface - MAX_GROUND_DEPTH;
    let mut first_free_y = v.min_y;
    for s in 0..v.height / 16 {
        let (lo, hi) = (v.min_y + s * 16, v.min_y + s * 16 + 15);
        if hi >= rock_top {
            break;
        }
        chunk.fill_block_state_section(s as u32, rock(lo));
        first_free_y = hi + 1;
    }
    for (lx, lz, x, z) in ctx.each_column() {
        for y in first_free_y..=columns.surface_y(x, z) {
            chunk.set_block_state(
                lx,
                (y - v.min_y) as u32,
                lz,
                if y == v.min_y { BlockState::BEDROCK } else { rock(y) },
            );
        }
        chunk.set_block_state(lx, 0, lz, BlockState::BEDROCK);
    }
}

/// Deepslate below Y 0, stone above (as in vanilla).
pub fn rock(y: i32) -> BlockState {
    if y < 0 {
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
    fn columns_are_bedrock_then_deepslate_then_stone_up_to_the_ground() {
        let (g, palette, rules) = (testing::generator(), testing::palette(), testing::single_biome("minecraft:plains"));
        let v = *g.vertical();
        let mut ctx = ChunkContext::new(&g, &rules, &palette, 0, 0);
        // Ground rising 25 m (one block) per column eastwards from Y 63.
        ctx.columns = Some(testing::columns(&g, Rect::new(-4, -4, 24, 24), |x, _| (x.max(0) as f32 * 25.0, 10.0)));
        let mut chunk = UnloadedChunk::with_height(v.height as u32);
        run(&mut ctx, &mut chunk);
        for lx in [0u32, 7, 15] {
            let at = |y: i32| chunk.block_state(lx, (y - v.min_y) as u32, 5);
            let ground = 63 + lx as i32;
            assert_eq!(at(v.min_y), BlockState::BEDROCK);
            assert_eq!(at(v.min_y + 1), BlockState::DEEPSLATE);
            assert_eq!(at(-1), BlockState::DEEPSLATE);
            assert_eq!((at(0), at(ground)), (BlockState::STONE, BlockState::STONE));
            assert!(at(ground + 1).is_air(), "column {lx}");
        }
    }
}
