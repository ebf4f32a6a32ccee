//! The snow pass: a layer of snow on whatever is highest in every column of a snowy biome —
//! the ground, a tree's crown — as vanilla's freeze step lays it, with grass under it turned
//! to its snowy face. Water keeps its ice (the water pass's) and plants stay bare.

use valence::prelude::{BlockState, Chunk, PropName, PropValue};

use crate::chunkgen::Blocks;

use crate::chunkgen::{is_plant, ChunkContext};

/// How far above the ground anything generated reaches (the tallest tree and its crown).
const ABOVE_GROUND: i32 = 24;

/// True for the biomes vanilla freezes: every `snowy_*`, `frozen_*`, ice spikes, groves and
/// the jagged peaks.
pub fn snowy(biome: &str) -> bool {
    let b = biome.strip_prefix("minecraft:").unwrap_or(biome);
    b.starts_with("snowy_") || b.starts_with("frozen_") || matches!(b, "ice_spikes" | "grove" | "jagged_peaks")
}

/// Lays the snow.
pub fn run(ctx: &mut ChunkContext, chunk: &mut Blocks) {
    // Most chunks have no snowy cell at all: skip their columns' biome lookups.
    if !ctx.biomes.iter().any(|b| snowy(b)) {
        return;
    }
    let (v, columns) = (*ctx.vertical(), ctx.columns());
    let height = chunk.height() as i32;
    for (lx, lz, x, z) in ctx.each_column() {
        if columns.is_wet(x, z) || !snowy(ctx.surface_biome(x, z)) {
            continue;
        }
        let ground = columns.surface_y(x, z) - v.min_y;
        let top = (ground + ABOVE_GROUND).min(height - 2);
        // The highest block that is not air, from above what anything reaches down to the
        // ground (a cave's mouth leaves none).
        let Some(y) = (ground.max(0)..=top).rev().find(|&y| !chunk.block_state(lx, y as u32, lz).is_air()) else {
            continue;
        };
        let below = chunk.block_state(lx, y as u32, lz);
        if below.is_liquid() || is_plant(below) || below == BlockState::SNOW || below == BlockState::ICE {
            continue;
        }
        chunk.set_block_state(lx, y as u32 + 1, lz, BlockState::SNOW);
        if matches!(below, BlockState::GRASS_BLOCK | BlockState::PODZOL | BlockState::MYCELIUM) {
            chunk.set_block_state(lx, y as u32, lz, below.set(PropName::Snowy, PropValue::True));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::testing;
    use super::*;
    use crate::chunkgen::passes::{surface, vegetation};
    use crate::terrain::Rect;

    /// Flat land at Y 67 in `biome` with its ground, trees and plants, then snow.
    fn snowed(biome: &'static str) -> Blocks {
        let (g, palette, rules) = (testing::generator(), testing::palette(), testing::single_biome(biome));
        let v = *g.vertical();
        let mut ctx = ChunkContext::new(&g, &rules, &palette, 0, 0);
        ctx.columns = Some(testing::columns(&g, Rect::new(-5, -5, 26, 26), |_, _| (100.0, 0.0)));
        ctx.biomes = vec![biome; 16 * ctx.cells_y()];
        let mut chunk = Blocks::with_height(v.height as u32);
        surface::run(&mut ctx, &mut chunk);
        vegetation::run(&mut ctx, &mut chunk);
        run(&mut ctx, &mut chunk);
        chunk
    }

    fn top(chunk: &Blocks, x: u32, z: u32) -> (u32, BlockState) {
        let y = (0..chunk.height()).rev().find(|&y| !chunk.block_state(x, y, z).is_air()).expect("a block");
        (y, chunk.block_state(x, y, z))
    }

    #[test]
    fn snowy_woods_are_white_on_the_ground_and_on_the_crowns_and_plains_are_not() {
        let taiga = snowed("minecraft:snowy_taiga");
        let (mut on_leaves, mut on_ground) = (0, 0);
        for z in 0..16 {
            for x in 0..16 {
                let (y, b) = top(&taiga, x, z);
                if is_plant(taiga.block_state(x, y - 1, z)) {
                    continue; // plants stay bare
                }
                assert_eq!(b, BlockState::SNOW, "column {x}, {z}");
                let under = taiga.block_state(x, y - 1, z);
                if under.to_kind().to_str().ends_with("_leaves") {
                    on_leaves += 1;
                } else {
                    on_ground += 1;
                    assert_ne!(under, BlockState::GRASS_BLOCK, "grass under snow shows its snowy face");
                }
            }
        }
        assert!(on_leaves > 10 && on_ground > 10, "{on_leaves} on crowns, {on_ground} on the ground");
        let plains = snowed("minecraft:plains");
        assert!((0..16).all(|z| (0..16).all(|x| top(&plains, x, z).1 != BlockState::SNOW)));
    }

    #[test]
    fn snowy_biomes_are_the_frozen_ones() {
        for b in ["minecraft:snowy_plains", "minecraft:frozen_peaks", "minecraft:grove", "ice_spikes"] {
            assert!(snowy(b), "{b}");
        }
        for b in ["minecraft:plains", "minecraft:taiga", "minecraft:river", "minecraft:stony_peaks"] {
            assert!(!snowy(b), "{b}");
        }
    }
}
