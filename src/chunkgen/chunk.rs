//! One chunk from the pipeline: biomes per cell, then ground, stone, bedrock and sea.

use valence::prelude::{BlockState, Chunk, UnloadedChunk};

use crate::biome::BiomeRules;
use crate::terrain::pipeline::channel;
use crate::terrain::Rect;

use super::cells::{self, CELL};
use super::columns::Columns;
use super::plants::{self, Plant};
use super::surface::{self, Ground, Site};
use super::trees::{self, Tree};
use super::{BiomePalette, Generator, SurfaceSample};

/// Blocks per chunk edge.
pub const CHUNK: i64 = 16;
/// Deepest filler any [`Ground`] asks for, plus the top block: sections entirely below this
/// many blocks under the lowest surface of a chunk are plain rock.
const MAX_GROUND_DEPTH: i32 = 16;

impl Generator {
    /// Builds the chunk at chunk coordinates (`chunk_x`, `chunk_z`) with `rules`, its biomes
    /// numbered by `palette`. Pure: the same inputs give the same chunk, and neighbouring chunks
    /// meet without seams (everything is a function of global coordinates).
    pub fn chunk(&self, rules: &BiomeRules, palette: &BiomePalette, chunk_x: i32, chunk_z: i32) -> UnloadedChunk {
        let (x0, z0) = (i64::from(chunk_x) * CHUNK, i64::from(chunk_z) * CHUNK);
        // Trees rooted up to `REACH` outside the chunk, plus one column of border for slopes
        // and steepness at the edges.
        let pad = trees::REACH + 1;
        let columns = Columns::query(
            &self.pipeline,
            &self.vertical,
            Rect::new(z0 - pad, x0 - pad, CHUNK + 2 * pad, CHUNK + 2 * pad),
        );
        let v = &self.vertical;
        let mut chunk = UnloadedChunk::with_height(v.height as u32);

        let cells_y = (v.height / CELL as i32) as usize;
        let biome_names = self.chunk_biomes(rules, &columns, x0, z0, cells_y);
        for cz in 0..4 {
            for cx in 0..4 {
                for cy in 0..cells_y {
                    let name = biome_names[(cz * 4 + cx) * cells_y + cy];
                    chunk.set_biome(cx as u32, cy as u32, cz as u32, palette.id(name));
                }
            }
        }

        let min_surface = (0..CHUNK)
            .flat_map(|z| (0..CHUNK).map(move |x| (x, z)))
            .map(|(x, z)| columns.surface_y(x0 + x, z0 + z))
            .min()
            .unwrap_or(v.min_y);
        // Whole sections of rock below every column's ground: filled wholesale, which is much
        // faster than block by block.
        let rock_top = min_surface - MAX_GROUND_DEPTH;
        let sections = v.height / 16;
        let mut first_free_y = v.min_y;
        for s in 0..sections {
            let (lo, hi) = (v.min_y + s * 16, v.min_y + s * 16 + 15);
            if hi >= rock_top {
                break;
            }
            chunk.fill_block_state_section(s as u32, rock(lo));
            first_free_y = hi + 1;
        }

        for lz in 0..CHUNK {
            for lx in 0..CHUNK {
                let (x, z) = (x0 + lx, z0 + lz);
                let surface_y = columns.surface_y(x, z);
                let cell_y = ((cells::cell_centre_y(surface_y) - v.min_y) / CELL as i32) as usize;
                let biome = biome_names[((lz / CELL) * 4 + lx / CELL) as usize * cells_y + cell_y];
                let ground = self.ground_at(&columns, biome, x, z);
                self.fill_column(&mut chunk, lx as u32, lz as u32, first_free_y, surface_y, &ground);
                let water_top = v.water_top_y();
                if surface_y < water_top {
                    for y in surface_y + 1..=water_top {
                        chunk.set_block_state(lx as u32, (y - v.min_y) as u32, lz as u32, BlockState::WATER);
                    }
                    if columns.get(channel::TEMPERATURE, x, z) < surface::SEA_ICE_C {
                        chunk.set_block_state(lx as u32, (water_top - v.min_y) as u32, lz as u32, BlockState::ICE);
                    }
                }
            }
        }
        let trees = self.trees(rules, &columns, x0, z0, CHUNK);
        trees::place(&mut chunk, &trees, x0, z0, v.min_y);
        // Plants last, and only where every block they need is still air (tree blocks in a
        // column do not depend on the chunk, so neither does this).
        for lz in 0..CHUNK {
            for lx in 0..CHUNK {
                let Some((base_y, plant)) = self.plant_at(rules, &columns, &trees, x0 + lx, z0 + lz) else { continue };
                let blocks = plant.blocks();
                let ys = (base_y..).take(blocks.len()).map(|y| (y - v.min_y) as u32);
                if ys.clone().all(|ly| chunk.block_state(lx as u32, ly, lz as u32).is_air()) {
                    for (ly, b) in ys.zip(blocks) {
                        chunk.set_block_state(lx as u32, ly, lz as u32, b);
                    }
                }
            }
        }
        chunk
    }

    /// The blocks of the plant on column (`x`, `z`), from the one above the ground upwards
    /// (empty for bare ground), as [`chunk`](Self::chunk) places them where no tree stands.
    pub fn plant_blocks(&self, rules: &BiomeRules, x: i64, z: i64) -> Vec<BlockState> {
        let columns = Columns::query(&self.pipeline, &self.vertical, tree_rect(x, z, 1));
        let trees = self.trees(rules, &columns, x, z, 1);
        self.plant_at(rules, &columns, &trees, x, z).map_or_else(Vec::new, |(_, p)| p.blocks())
    }

    /// The plant of column (`x`, `z`) and the Y of its lowest block, or `None`. `trees` must
    /// hold every tree rooted within `REACH` of the column and `columns` cover
    /// [`tree_rect`] of it. Cacti grow only where their four neighbours stay air at every
    /// height they reach: lower ground, no plant and no tree nearby.
    fn plant_at(&self, rules: &BiomeRules, columns: &Columns, trees: &[Tree], x: i64, z: i64) -> Option<(i32, Plant)> {
        let v = &self.vertical;
        let candidate = |x: i64, z: i64| -> Option<(i32, Plant)> {
            let ground_y = columns.surface_y(x, z);
            if ground_y < v.water_top_y() || columns.drop_blocks(x, z) >= surface::STEEP_DROP_BLOCKS {
                return None;
            }
            let biome = self.surface_biome(rules, columns, x, z);
            let ground = self.ground_at(columns, biome, x, z);
            if ground.top.is_liquid() {
                return None;
            }
            plants::candidate(self.seed, biome, ground.top, x, z).map(|p| (ground_y + 1, p))
        };
        let (base_y, plant) = candidate(x, z)?;
        if base_y + plant.blocks().len() as i32 > v.min_y + v.height {
            return None;
        }
        if let Plant::Cactus(_) = plant {
            let near_tree = trees.iter().any(|t| (t.x - x).abs() <= trees::REACH && (t.z - z).abs() <= trees::REACH);
            let crowded = [(1, 0), (-1, 0), (0, 1), (0, -1)]
                .into_iter()
                .any(|(dx, dz)| columns.surface_y(x + dx, z + dz) >= base_y || candidate(x + dx, z + dz).is_some());
            if near_tree || crowded {
                return None;
            }
        }
        Some((base_y, plant))
    }

    /// True when no tree stands on or over column (`x`, `z`) (a place to put a player).
    pub fn clear_of_trees(&self, rules: &BiomeRules, x: i64, z: i64) -> bool {
        let columns = Columns::query(&self.pipeline, &self.vertical, tree_rect(x, z, 1));
        self.trees(rules, &columns, x, z, 1)
            .iter()
            .all(|t| (t.x - x).abs() >= trees::REACH || (t.z - z).abs() >= trees::REACH)
    }

    /// Every tree rooted within reach of the `size`×`size` square at (`x0`, `z0`), in global
    /// order. `columns` must cover [`tree_rect`] of the square.
    fn trees(&self, rules: &BiomeRules, columns: &Columns, x0: i64, z0: i64, size: i64) -> Vec<Tree> {
        debug_assert!(columns.rect().contains_rect(&tree_rect(x0, z0, size)));
        let v = &self.vertical;
        let mut trees = Vec::new();
        for (x, z, chance) in trees::candidate_roots(self.seed, x0, z0, size) {
            let biome = self.surface_biome(rules, columns, x, z);
            let Some((density, kind)) = trees::woodland(biome) else { continue };
            if chance >= density {
                continue;
            }
            let ground_y = columns.surface_y(x, z);
            let ground = self.ground_at(columns, biome, x, z);
            let dry = ground_y >= v.water_top_y() && !ground.top.is_liquid();
            if dry && columns.drop_blocks(x, z) < surface::STEEP_DROP_BLOCKS && trees::holds_tree(ground.top) {
                let tree = Tree::new(self.seed, x, z, ground_y, kind);
                if tree.top_y() < v.min_y + v.height {
                    trees.push(tree);
                }
            }
        }
        trees
    }

    /// Biome of the cell holding the ground block of column (`x`, `z`).
    fn surface_biome<'r>(&self, rules: &'r BiomeRules, columns: &Columns, x: i64, z: i64) -> &'r str {
        let (sx, sz) = cells::sample_column(x.div_euclid(CELL), z.div_euclid(CELL));
        let centre = cells::cell_centre_y(columns.surface_y(x, z));
        rules.biome(&cells::conditions(columns, &self.vertical, self.lapse_c_per_km, sx, sz, centre))
    }

    /// The topmost ground block of column (`x`, `z`) and the biome of the cell holding it,
    /// computed exactly as [`chunk`](Self::chunk) computes them (tests compare a live server
    /// with this).
    pub fn surface(&self, rules: &BiomeRules, x: i64, z: i64) -> SurfaceSample {
        let (cell_x, cell_z) = (x.div_euclid(CELL), z.div_euclid(CELL));
        let columns = Columns::query(
            &self.pipeline,
            &self.vertical,
            Rect::new(cell_z * CELL - 1, cell_x * CELL - 1, CELL + 2, CELL + 2),
        );
        let y = columns.surface_y(x, z);
        let biome = self.surface_biome(rules, &columns, x, z);
        let top = self.ground_at(&columns, biome, x, z).top;
        SurfaceSample { y, biome: biome.to_string(), top: top.to_kind().to_str() }
    }

    /// Biome names of every cell of a chunk, indexed `(cell_z·4 + cell_x)·cells_y + cell_y`.
    fn chunk_biomes<'r>(
        &self,
        rules: &'r BiomeRules,
        columns: &Columns,
        x0: i64,
        z0: i64,
        cells_y: usize,
    ) -> Vec<&'r str> {
        let v = &self.vertical;
        let mut names = Vec::with_capacity(16 * cells_y);
        for cz in 0..4 {
            for cx in 0..4 {
                let (sx, sz) = cells::sample_column(x0 / CELL + cx, z0 / CELL + cz);
                let ground_top = columns.surface_y(sx, sz).max(v.water_top_y());
                // Every cell at or below the ground shares one set of conditions.
                let ground = rules.biome(&cells::conditions(columns, v, self.lapse_c_per_km, sx, sz, ground_top));
                for cy in 0..cells_y {
                    let centre = v.min_y + cy as i32 * CELL as i32 + CELL as i32 / 2;
                    names.push(if centre <= ground_top {
                        ground
                    } else {
                        rules.biome(&cells::conditions(columns, v, self.lapse_c_per_km, sx, sz, centre))
                    });
                }
            }
        }
        names
    }

    fn ground_at(&self, columns: &Columns, biome: &str, x: i64, z: i64) -> Ground {
        let surface_y = columns.surface_y(x, z);
        surface::ground(&Site {
            biome,
            water_depth: (self.vertical.water_top_y() - surface_y).max(0),
            drop_blocks: columns.drop_blocks(x, z),
            temperature_c: columns.get(channel::TEMPERATURE, x, z),
            seed: self.seed,
            x,
            z,
        })
    }

    /// Bedrock, rock, filler and top of one column, from `from_y` (everything below is already
    /// rock) up to `surface_y`.
    fn fill_column(&self, chunk: &mut UnloadedChunk, lx: u32, lz: u32, from_y: i32, surface_y: i32, ground: &Ground) {
        let min_y = self.vertical.min_y;
        let filler_top = surface_y - 1;
        let filler_bottom = surface_y - ground.filler_depth;
        for y in from_y.max(min_y)..=surface_y {
            let block = if y == min_y {
                BlockState::BEDROCK
            } else if y == surface_y {
                ground.top
            } else if y >= filler_bottom && y <= filler_top {
                if ground.banded {
                    surface::terracotta_band(y)
                } else {
                    ground.filler
                }
            } else {
                rock(y)
            };
            chunk.set_block_state(lx, (y - min_y) as u32, lz, block);
        }
        if from_y > min_y {
            chunk.set_block_state(lx, 0, lz, BlockState::BEDROCK);
        }
    }
}

/// The columns needed to decide the trees around the `size`×`size` square at (`x0`, `z0`)
/// (and so everything else in it): roots up to `REACH` outside it with one neighbour each
/// for steepness, and the sample columns (with neighbours) of the biome cells holding them.
fn tree_rect(x0: i64, z0: i64, size: i64) -> Rect {
    let span = |lo: i64| {
        let (first_root, last_root) = (lo - trees::REACH, lo + size - 1 + trees::REACH);
        let first_sample = cells::sample_column(first_root.div_euclid(CELL), 0).0;
        let last_sample = cells::sample_column(last_root.div_euclid(CELL), 0).0;
        let start = (first_root - 1).min(first_sample - 1);
        (start, (last_root + 1).max(last_sample + 1) - start + 1)
    };
    let ((x, w), (z, h)) = (span(x0), span(z0));
    Rect::new(z, x, h, w)
}

/// Deepslate below Y 0, stone above (as in vanilla).
fn rock(y: i32) -> BlockState {
    if y < 0 {
        BlockState::DEEPSLATE
    } else {
        BlockState::STONE
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_chunk_needs_four_columns_of_border_and_any_square_its_cells() {
        assert_eq!(tree_rect(0, 16, 16), Rect::new(12, -4, 24, 24));
        for x in -9..9 {
            let r = tree_rect(x, x, 1);
            // The cell of the farthest root on each side, with its sample column's neighbours.
            let lo_cell = (x - trees::REACH).div_euclid(CELL) * CELL;
            assert!(r.x0 <= lo_cell + 1 && r.x0 < x - trees::REACH, "{x}: {r:?}");
            assert!(r.x1() > x + trees::REACH + 1, "{x}: {r:?}");
        }
    }
}
