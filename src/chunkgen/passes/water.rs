//! The water pass: the sea, from above each sea column's ground to the water top, frozen on
//! top where the column is colder than the sea-ice threshold.

use valence::prelude::{BlockState, Chunk, UnloadedChunk};

use crate::chunkgen::surface::SEA_ICE_C;
use crate::chunkgen::ChunkContext;
use crate::terrain::pipeline::channel;

/// Fills every column whose ground is below the water top with water up to it (ice on top
/// where cold).
pub fn run(ctx: &mut ChunkContext, chunk: &mut UnloadedChunk) {
    let v = *ctx.vertical();
    let columns = ctx.columns();
    let water_top = v.water_top_y();
    for (lx, lz, x, z) in ctx.each_column() {
        let surface_y = columns.surface_y(x, z);
        if surface_y >= water_top {
            continue;
        }
        for y in surface_y + 1..=water_top {
            chunk.set_block_state(lx, (y - v.min_y) as u32, lz, BlockState::WATER);
        }
        if columns.get(channel::TEMPERATURE, x, z) < SEA_ICE_C {
            chunk.set_block_state(lx, (water_top - v.min_y) as u32, lz, BlockState::ICE);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::testing;
    use super::*;
    use crate::terrain::Rect;

    #[test]
    fn sea_columns_fill_to_the_water_top_and_freeze_where_cold_and_land_stays_dry() {
        let (g, palette, rules) = (testing::generator(), testing::palette(), testing::single_biome("minecraft:ocean"));
        let v = *g.vertical();
        let mut ctx = ChunkContext::new(&g, &rules, &palette, 0, 0);
        // West half sea 600 m deep (ground Y 52), east half land; the north half is frozen.
        ctx.columns = Some(testing::columns(&g, Rect::new(-4, -4, 24, 24), |x, z| {
            (if x < 8 { -600.0 } else { 100.0 }, if z < 8 { -5.0 } else { 10.0 })
        }));
        let mut chunk = UnloadedChunk::with_height(v.height as u32);
        run(&mut ctx, &mut chunk);
        let at = |x: u32, y: i32, z: u32| chunk.block_state(x, (y - v.min_y) as u32, z);
        assert!(at(2, 52, 2).is_air(), "the ground is not the water pass's");
        for y in 53..v.water_top_y() {
            assert_eq!((at(2, y, 2), at(2, y, 12)), (BlockState::WATER, BlockState::WATER), "y {y}");
        }
        assert_eq!(at(2, v.water_top_y(), 2), BlockState::ICE);
        assert_eq!(at(2, v.water_top_y(), 12), BlockState::WATER);
        assert!(at(2, v.sea_level_y, 12).is_air());
        assert!((v.min_y..v.min_y + v.height).all(|y| at(12, y, 12).is_air()), "water on land");
    }
}
