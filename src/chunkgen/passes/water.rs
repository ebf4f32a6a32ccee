//! The water pass: the sea, rivers and lakes, from above each wet column's ground to its
//! water top (frozen on top where the column is colder than the ice threshold), and falling
//! water where a river steps down from one column to the next.

use valence::prelude::{BlockState, Chunk};

use crate::chunkgen::Blocks;
use valence::prelude::{PropName, PropValue};

use crate::chunkgen::surface::SEA_ICE_C;
use crate::chunkgen::ChunkContext;
use crate::terrain::pipeline::channel;

/// Water falling from a higher neighbour (vanilla's `water[level=8]`): what a static world
/// shows where a river steps down a block.
pub fn falling_water() -> BlockState {
    BlockState::WATER.set(PropName::Level, PropValue::_8)
}

/// Fills every wet column with water from its ground up to its water top (ice on top where
/// cold), and the side of each step down with falling water.
pub fn run(ctx: &mut ChunkContext, chunk: &mut Blocks) {
    let v = *ctx.vertical();
    let columns = ctx.columns();
    for (lx, lz, x, z) in ctx.each_column() {
        let Some(top) = columns.water_top_y(x, z) else { continue };
        let ground = columns.surface_y(x, z);
        for y in ground + 1..=top {
            chunk.set_block_state(lx, (y - v.min_y) as u32, lz, BlockState::WATER);
        }
        let frozen = columns.get(channel::TEMPERATURE, x, z) < SEA_ICE_C;
        // A neighbour's water standing higher pours over into this column.
        let above = [(1, 0), (-1, 0), (0, 1), (0, -1)]
            .iter()
            .filter_map(|&(dx, dz)| columns.water_top_y(x + dx, z + dz))
            .max()
            .unwrap_or(top);
        for y in top + 1..=above {
            chunk.set_block_state(lx, (y - v.min_y) as u32, lz, falling_water());
        }
        if frozen && above == top {
            chunk.set_block_state(lx, (top - v.min_y) as u32, lz, BlockState::ICE);
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
        ctx.columns = Some(testing::columns(&g, Rect::new(-5, -5, 26, 26), |x, z| {
            (if x < 8 { -600.0 } else { 100.0 }, if z < 8 { -5.0 } else { 10.0 })
        }));
        let mut chunk = Blocks::with_height(v.height as u32);
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
