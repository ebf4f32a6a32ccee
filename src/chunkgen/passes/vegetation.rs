//! The vegetation pass: trees rooted in or near the chunk, then one plant at most per column
//! where every block it needs is still air.

use valence::prelude::Chunk;

use crate::chunkgen::Blocks;

use crate::chunkgen::trees;
use crate::chunkgen::{ChunkContext, CHUNK};

/// Places every tree reaching into the chunk, then the plants.
pub fn run(ctx: &mut ChunkContext, chunk: &mut Blocks) {
    let (g, v, columns) = (ctx.generator, *ctx.vertical(), ctx.columns());
    let biome = |x, z| ctx.surface_biome(x, z);
    let trees = g.trees(ctx.rules, columns, &biome, ctx.x0, ctx.z0, CHUNK);
    trees::place(chunk, &trees, ctx.x0, ctx.z0, v.min_y);
    // Plants last, and only where every block they need is still air (tree blocks in a
    // column do not depend on the chunk, so neither does this).
    for (lx, lz, x, z) in ctx.each_column() {
        let Some((base_y, plant)) = g.plant_at(ctx.rules, columns, &biome, &trees, x, z) else { continue };
        let blocks = plant.blocks();
        let ys = (base_y..).take(blocks.len()).map(|y| (y - v.min_y) as u32);
        if ys.clone().all(|ly| chunk.block_state(lx, ly, lz).is_air()) {
            for (ly, b) in ys.zip(blocks) {
                chunk.set_block_state(lx, ly, lz, b);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use valence::prelude::BlockState;

    use super::super::testing;
    use super::*;
    use crate::chunkgen::is_plant;
    use crate::terrain::Rect;

    /// Flat land at Y 67 in `biome`, with only the ground blocks the vegetation looks at.
    fn vegetate(biome: &str) -> Blocks {
        let (g, palette, rules) = (testing::generator(), testing::palette(), testing::single_biome(biome));
        let v = *g.vertical();
        let mut ctx = ChunkContext::new(&g, &rules, &palette, 0, 0);
        ctx.columns = Some(testing::columns(&g, Rect::new(-5, -5, 26, 26), |_, _| (100.0, 15.0)));
        let mut chunk = Blocks::with_height(v.height as u32);
        run(&mut ctx, &mut chunk);
        chunk
    }

    #[test]
    fn forests_grow_trees_and_plains_grow_plants_on_the_ground() {
        let ground = (67 + 64) as u32;
        let forest = vegetate("minecraft:forest");
        let trunks = (0..16).flat_map(|z| (0..16).map(move |x| (x, z)));
        let trunks = trunks.filter(|&(x, z)| forest.block_state(x, ground + 1, z) == BlockState::OAK_LOG).count();
        assert!(trunks >= 3, "{trunks} trunks in a forest chunk");
        let plains = vegetate("minecraft:plains");
        let plants = (0..16).flat_map(|z| (0..16).map(move |x| (x, z)));
        let plants = plants.filter(|&(x, z)| is_plant(plains.block_state(x, ground + 1, z))).count();
        assert!(plants > 20, "{plants} plants in a plains chunk");
        assert!((0..16).all(|x| (0..=ground).all(|y| plains.block_state(x, y, 3).is_air())), "not the ground's");
    }
}
