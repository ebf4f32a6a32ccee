//! The columns pass: asks the pipeline for the chunk's columns and decides the biome of every
//! 4×4×4 cell, writing the biomes into the chunk.

use valence::prelude::{BiomeId, Chunk};

use crate::chunkgen::Blocks;

use crate::chunkgen::cells::{self, CELL};
use crate::chunkgen::columns::Columns;
use crate::chunkgen::trees;
use crate::chunkgen::{ChunkContext, CHUNK};
use crate::terrain::Rect;

/// Fills `ctx.columns` (the chunk plus a border: trees rooted up to `REACH` outside it, plus
/// one column for slopes and steepness at the edges) and `ctx.biomes`, and sets every biome
/// cell of `chunk`.
pub fn run(ctx: &mut ChunkContext, chunk: &mut Blocks) {
    let pad = trees::REACH + 1;
    let rect = Rect::new(ctx.z0 - pad, ctx.x0 - pad, CHUNK + 2 * pad, CHUNK + 2 * pad);
    let columns = Columns::query(ctx.generator.pipeline(), ctx.vertical(), rect);
    ctx.biomes = biomes(ctx, &columns);
    ctx.columns = Some(columns);
    let cells_y = ctx.cells_y();
    // Cells up a column mostly share a biome: look its id up once per run of them.
    let mut last: Option<(&str, BiomeId)> = None;
    for cz in 0..4 {
        for cx in 0..4 {
            for cy in 0..cells_y {
                let name = ctx.biomes[(cz * 4 + cx) * cells_y + cy];
                let id = match last {
                    Some((n, id)) if std::ptr::eq(n, name) => id,
                    _ => ctx.palette.id(name),
                };
                last = Some((name, id));
                chunk.set_biome(cx as u32, cy as u32, cz as u32, id);
            }
        }
    }
}

/// Biome names of every cell of the chunk, indexed `(cell_z·4 + cell_x)·cells_y + cell_y`.
fn biomes<'r>(ctx: &ChunkContext<'r>, columns: &Columns) -> Vec<&'r str> {
    let (v, lapse) = (ctx.vertical(), ctx.generator.lapse_c_per_km);
    let cells_y = ctx.cells_y();
    let mut names = Vec::with_capacity(16 * cells_y);
    for cz in 0..4 {
        for cx in 0..4 {
            let (sx, sz) = cells::sample_column(ctx.x0 / CELL + cx, ctx.z0 / CELL + cz);
            let ground_top = columns.water_top_y(sx, sz).unwrap_or(columns.surface_y(sx, sz));
            // Every cell at or below the ground shares one set of conditions; the cells above
            // it differ only in height and temperature.
            let conditions = cells::ground_conditions(columns, sx, sz);
            let ground = ctx.rules.biome(&conditions);
            let air = ctx.rules.over(&conditions);
            for cy in 0..cells_y {
                let centre = v.min_y + cy as i32 * CELL as i32 + CELL as i32 / 2;
                names.push(if centre <= ground_top {
                    ground
                } else {
                    air.biome(&cells::at_height(&conditions, ground_top, v, lapse, centre))
                });
            }
        }
    }
    names
}

#[cfg(test)]
mod tests {
    use super::super::testing;
    use super::*;

    #[test]
    fn it_covers_the_chunk_and_its_tree_reach_and_names_every_cell() {
        let (g, palette) = (testing::generator(), testing::palette());
        let rules = testing::single_biome("minecraft:forest");
        let mut ctx = ChunkContext::new(&g, &rules, &palette, 2, -3);
        let mut chunk = Blocks::with_height(g.vertical().height as u32);
        run(&mut ctx, &mut chunk);
        let r = ctx.columns().rect();
        assert_eq!(
            (r.x0, r.y0, r.w, r.h),
            (32 - trees::REACH - 1, -48 - trees::REACH - 1, 16 + 2 * (trees::REACH + 1), 16 + 2 * (trees::REACH + 1))
        );
        assert_eq!(ctx.biomes.len(), 16 * ctx.cells_y());
        assert!(ctx.biomes.iter().all(|&b| b == "minecraft:forest"));
        assert_eq!(chunk.biome(3, 10, 2), palette.id("minecraft:forest"));
    }
}
