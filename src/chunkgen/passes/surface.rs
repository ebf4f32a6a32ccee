//! The surface pass: each column's top block and the filler under it, chosen by the biome of
//! the cell holding its ground, its steepness, temperature and water depth (see
//! `chunkgen/surface.rs` for the choice), laid over the rock.

use valence::prelude::Chunk;

use crate::chunkgen::Blocks;

use crate::chunkgen::cave_field;
use crate::chunkgen::cells::{self, CELL};
use crate::chunkgen::surface::terracotta_band;
use crate::chunkgen::ChunkContext;

/// Replaces the top of every column's rock with its ground: the top block, then the filler
/// (or terracotta bands) below it. The bedrock floor stays.
pub fn run(ctx: &mut ChunkContext, chunk: &mut Blocks) {
    let v = *ctx.vertical();
    let (columns, cells_y) = (ctx.columns(), ctx.cells_y());
    for (lx, lz, x, z) in ctx.each_column() {
        let surface_y = columns.surface_y(x, z);
        let cell_y = ((cells::cell_centre_y(surface_y) - v.min_y) / CELL as i32) as usize;
        let cell = ((lz as i64 / CELL) * 4 + lx as i64 / CELL) as usize;
        let ground = ctx.generator.ground_at(ctx.rules, columns, ctx.biomes[cell * cells_y + cell_y], x, z);
        let mouth = cave_field::may_open(ctx.seed(), columns, x, z);
        for y in (surface_y - ground.filler_depth).max(v.min_y + 1)..=surface_y {
            let block = if y == surface_y {
                ground.top
            } else if ground.banded {
                terracotta_band(y)
            } else {
                ground.filler
            };
            let ly = (y - v.min_y) as u32;
            // A cave's mouth stays open (elsewhere the ground is whole: caves keep under it).
            if !(mouth && chunk.block_state(lx, ly, lz).is_air()) {
                chunk.set_block_state(lx, ly, lz, block);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use valence::prelude::BlockState;

    use super::super::testing;
    use super::*;
    use crate::terrain::Rect;

    fn surface_of(biome: &str, elevation: f32) -> (Blocks, i32) {
        let (g, palette, rules) = (testing::generator(), testing::palette(), testing::single_biome(biome));
        let v = *g.vertical();
        let mut ctx = ChunkContext::new(&g, &rules, &palette, 0, 0);
        let columns = testing::columns(&g, Rect::new(-5, -5, 26, 26), |_, _| (elevation, 15.0));
        let ground_y = columns.surface_y(5, 5);
        ctx.columns = Some(columns);
        ctx.biomes = vec![biome; 16 * ctx.cells_y()];
        let mut chunk = Blocks::with_height(v.height as u32);
        run(&mut ctx, &mut chunk);
        (chunk, ground_y - v.min_y)
    }

    #[test]
    fn the_top_and_filler_follow_the_biome() {
        let (chunk, y) = surface_of("minecraft:desert", 200.0);
        let at = |dy: i32| chunk.block_state(5, (y + dy) as u32, 5);
        assert_eq!((at(0), at(-1), at(-4)), (BlockState::SAND, BlockState::SANDSTONE, BlockState::SANDSTONE));
        assert!(at(-5).is_air() && at(1).is_air(), "only the ground's own blocks");
    }

    #[test]
    fn badlands_are_banded_and_sea_floors_are_sediment() {
        let (chunk, y) = surface_of("minecraft:badlands", 200.0);
        assert_eq!(chunk.block_state(5, y as u32, 5), BlockState::RED_SAND);
        // `y` counts from the floor, Y −64.
        assert_eq!(chunk.block_state(5, (y - 3) as u32, 5), terracotta_band(y - 3 - 64));
        let (chunk, y) = surface_of("minecraft:ocean", -30.0);
        assert_eq!(chunk.block_state(5, y as u32, 5), BlockState::SAND, "the shallowest sea floor");
    }

    #[test]
    fn the_bedrock_floor_stays() {
        // Ground at the lowest surface Y: its filler would reach below the floor.
        let (mut chunk, y) = (Blocks::with_height(384), 1);
        chunk.set_block_state(5, 0, 5, BlockState::BEDROCK);
        let (g, palette, rules) =
            (testing::generator(), testing::palette(), testing::single_biome("minecraft:badlands"));
        let mut ctx = ChunkContext::new(&g, &rules, &palette, 0, 0);
        ctx.columns = Some(testing::columns(&g, Rect::new(-5, -5, 26, 26), |_, _| (-1.0e9, 15.0)));
        ctx.biomes = vec!["minecraft:badlands"; 16 * ctx.cells_y()];
        run(&mut ctx, &mut chunk);
        assert_eq!(chunk.block_state(5, 0, 5), BlockState::BEDROCK);
        assert!(!chunk.block_state(5, y, 5).is_air());
    }
}
