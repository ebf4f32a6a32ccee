//! Decisions about one column that the passes and the per-column queries share: its surface
//! biome, its ground, the trees around it and its plant.
//!
//! [`Generator::surface`], [`Generator::plant_blocks`] and [`Generator::clear_of_trees`] answer
//! for a single column by querying just the rectangle it needs; the passes decide the same
//! things for a whole chunk with these same functions, so both always agree (tests compare a
//! live server with the per-column answers).

use valence::prelude::BlockState;

use crate::biome::BiomeRules;
use crate::terrain::pipeline::channel;
use crate::terrain::Rect;

use super::cave_field;
use super::cells::{self, CELL};
use super::columns::Columns;
use super::plants::{self, Plant};
use super::surface::{self, Ground, Site};
use super::trees::{self, Tree};
use super::{Generator, SurfaceSample};

impl Generator {
    /// The blocks of the land plant on column (`x`, `z`), from the one above the ground
    /// upwards (empty for bare ground), as [`chunk`](Self::chunk) places them where no tree
    /// stands. Plants of the water's edge (sugar cane on a bank, lily pads) are the aquatic
    /// pass's, decided from the chunk's blocks, and not reported here: a column with water
    /// beside it may hold sugar cane.
    pub fn plant_blocks(&self, rules: &BiomeRules, x: i64, z: i64) -> Vec<BlockState> {
        let columns = Columns::query(&self.pipeline, &self.vertical, tree_rect(x, z, 1));
        let biome = |x, z| self.surface_biome(rules, &columns, x, z);
        let trees = self.trees(rules, &columns, &biome, x, z, 1);
        self.plant_at(rules, &columns, &biome, &trees, x, z).map_or_else(Vec::new, |(_, p)| p.blocks())
    }

    /// The plant of column (`x`, `z`) and the Y of its lowest block, or `None`. `trees` must
    /// hold every tree rooted within `REACH` of the column, `columns` cover [`tree_rect`] of
    /// it and `biome` answer as [`surface_biome`](Self::surface_biome) does. Cacti grow only where their four neighbours stay air at every
    /// height they reach: lower ground, no plant and no tree nearby.
    pub(super) fn plant_at<'r>(
        &self,
        rules: &'r BiomeRules,
        columns: &Columns,
        biome: &dyn Fn(i64, i64) -> &'r str,
        trees: &[Tree],
        x: i64,
        z: i64,
    ) -> Option<(i32, Plant)> {
        let v = &self.vertical;
        let candidate = |x: i64, z: i64| -> Option<(i32, Plant)> {
            let ground_y = columns.surface_y(x, z);
            if columns.is_wet(x, z)
                || columns.drop_blocks(x, z) >= surface::STEEP_DROP_BLOCKS
                || cave_field::may_open(self.seed, columns, x, z)
            {
                return None;
            }
            let biome = biome(x, z);
            let ground = self.ground_at(rules, columns, biome, x, z);
            if ground.top.is_liquid() {
                return None;
            }
            plants::candidate(self.seed, rules.vegetation(biome), ground.top, x, z).map(|p| (ground_y + 1, p))
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
            // Sugar cane grows on banks (see passes/aquatic.rs): a cactus keeps away from water.
            let by_water = (-2..=2).any(|dz| (-2..=2).any(|dx| columns.is_wet(x + dx, z + dz)));
            if near_tree || crowded || by_water {
                return None;
            }
        }
        Some((base_y, plant))
    }

    /// True when no tree stands on or over column (`x`, `z`) (a place to put a player).
    pub fn clear_of_trees(&self, rules: &BiomeRules, x: i64, z: i64) -> bool {
        let columns = Columns::query(&self.pipeline, &self.vertical, tree_rect(x, z, 1));
        self.trees(rules, &columns, &|x, z| self.surface_biome(rules, &columns, x, z), x, z, 1)
            .iter()
            .all(|t| (t.x - x).abs() > trees::REACH || (t.z - z).abs() > trees::REACH)
    }

    /// Every tree rooted within reach of the `size`×`size` square at (`x0`, `z0`), in global
    /// order. `columns` must cover [`tree_rect`] of the square, and `biome` answer as
    /// [`surface_biome`](Self::surface_biome) does.
    pub(super) fn trees<'r>(
        &self,
        rules: &'r BiomeRules,
        columns: &Columns,
        biome: &dyn Fn(i64, i64) -> &'r str,
        x0: i64,
        z0: i64,
        size: i64,
    ) -> Vec<Tree> {
        debug_assert!(columns.rect().contains_rect(&tree_rect(x0, z0, size)));
        let v = &self.vertical;
        let mut trees = Vec::new();
        for (x, z, chance, draw) in trees::candidate_roots(self.seed, x0, z0, size) {
            let biome = biome(x, z);
            let Some(vegetation) = rules.vegetation(biome) else { continue };
            if chance >= vegetation.trees {
                continue;
            }
            let Some(species) = vegetation.species(draw) else { continue };
            let ground_y = columns.surface_y(x, z);
            let ground = self.ground_at(rules, columns, biome, x, z);
            let dry = !columns.is_wet(x, z) && !ground.top.is_liquid();
            let rooted = !cave_field::may_open(self.seed, columns, x, z);
            if dry && rooted && columns.drop_blocks(x, z) < surface::STEEP_DROP_BLOCKS && trees::holds_tree(ground.top)
            {
                // A 2×2 trunk needs its other three columns level, dry and whole; where they
                // are not, the species grows in its one-column form.
                let wide = trees::is_wide(species)
                    && trees::WIDE_TRUNK.iter().all(|&(dx, dz)| {
                        let (x, z) = (x + dx, z + dz);
                        columns.surface_y(x, z) == ground_y
                            && !columns.is_wet(x, z)
                            && !cave_field::may_open(self.seed, columns, x, z)
                    });
                let tree = Tree::new(self.seed, x, z, ground_y, species, wide);
                if tree.top_y() < v.min_y + v.height {
                    trees.push(tree);
                }
            }
        }
        trees
    }

    /// Biome of the cell holding the ground block of column (`x`, `z`).
    pub(super) fn surface_biome<'r>(&self, rules: &'r BiomeRules, columns: &Columns, x: i64, z: i64) -> &'r str {
        let (sx, sz) = cells::sample_column(x.div_euclid(CELL), z.div_euclid(CELL));
        let centre = cells::cell_centre_y(columns.surface_y(x, z));
        rules.biome(&cells::conditions(columns, &self.vertical, self.lapse_c_per_km, sx, sz, centre))
    }

    /// The topmost ground block of column (`x`, `z`) and the biome of the cell holding it,
    /// computed exactly as [`chunk`](Self::chunk) computes them (tests compare a live server
    /// with this).
    pub fn surface(&self, rules: &BiomeRules, x: i64, z: i64) -> SurfaceSample {
        let (cell_x, cell_z) = (x.div_euclid(CELL), z.div_euclid(CELL));
        // The cell and the columns a cave mouth's test looks at around it.
        let m = 1 + cave_field::SHORE_REACH;
        let columns = Columns::query(
            &self.pipeline,
            &self.vertical,
            Rect::new(cell_z * CELL - m, cell_x * CELL - m, CELL + 2 * m, CELL + 2 * m),
        );
        let y = columns.surface_y(x, z);
        let biome = self.surface_biome(rules, &columns, x, z);
        let top = if cave_field::opens(self.seed, &columns, x, z) {
            "air"
        } else {
            self.ground_at(rules, &columns, biome, x, z).top.to_kind().to_str()
        };
        SurfaceSample { y, biome: biome.to_string(), top, water_y: columns.water_top_y(x, z) }
    }

    /// The surface of every column of `rect` (row-major: z rows, x within a row), each exactly
    /// as [`surface`](Self::surface) reports it, from one pipeline query: pictures of whole
    /// areas would otherwise pay a query per column.
    pub fn surfaces(&self, rules: &BiomeRules, rect: Rect) -> Vec<SurfaceSample> {
        // Whole biome cells with one column of border: every sample column and every
        // column's neighbours (for its steepness) lie inside.
        let (cx0, cz0) = (rect.x0.div_euclid(CELL), rect.y0.div_euclid(CELL));
        let (cx1, cz1) = ((rect.x1() - 1).div_euclid(CELL) + 1, (rect.y1() - 1).div_euclid(CELL) + 1);
        let padded = Rect::new(cz0 * CELL - 1, cx0 * CELL - 1, (cz1 - cz0) * CELL + 2, (cx1 - cx0) * CELL + 2);
        let columns = Columns::query(&self.pipeline, &self.vertical, padded);
        let mut out = Vec::with_capacity(rect.area());
        for z in rect.y0..rect.y1() {
            for x in rect.x0..rect.x1() {
                let biome = self.surface_biome(rules, &columns, x, z);
                let top = self.ground_at(rules, &columns, biome, x, z).top;
                out.push(SurfaceSample {
                    y: columns.surface_y(x, z),
                    biome: biome.to_string(),
                    top: top.to_kind().to_str(),
                    water_y: columns.water_top_y(x, z),
                });
            }
        }
        out
    }

    /// The ground of column (`x`, `z`) in `biome` (top and filler, by water depth, steepness
    /// and temperature, and the biome's surface table).
    pub(super) fn ground_at(&self, rules: &BiomeRules, columns: &Columns, biome: &str, x: i64, z: i64) -> Ground {
        surface::ground(&Site {
            biome,
            soil: rules.surface(biome),
            water_depth: columns.water_depth(x, z),
            water: columns.water(x, z),
            discharge_m3s: columns.get(channel::DISCHARGE, x, z),
            dry_bed: columns.is_dry_bed(x, z),
            precipitation_mm: columns.get(channel::PRECIPITATION, x, z),
            drop_blocks: columns.drop_blocks(x, z),
            temperature_c: columns.get(channel::TEMPERATURE, x, z),
            seed: self.seed,
            x,
            z,
        })
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
        // Whole biome cells: a cell's water condition looks at all its 4×4 columns.
        let start = (first_root - 1).min(first_sample - CELL / 2);
        (start, (last_root + 1).max(last_sample + 1) - start + 1)
    };
    let ((x, w), (z, h)) = (span(x0), span(z0));
    Rect::new(z, x, h, w)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn surfaces_of_an_area_agree_with_the_column_queries() {
        let config = crate::config::Config::default();
        let pipeline = std::sync::Arc::new(crate::terrain::Pipeline::new(3, &config.terrain()));
        let g = Generator::new(pipeline, &config);
        let rules = BiomeRules::load_dir(&std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("biomes")).unwrap();
        // Not aligned to biome cells on any side.
        let rect = Rect::new(-7, 5, 6, 9);
        let all = g.surfaces(&rules, rect);
        assert_eq!(all.len(), 54);
        for (i, s) in all.iter().enumerate() {
            let (x, z) = (rect.x0 + (i % 9) as i64, rect.y0 + (i / 9) as i64);
            assert_eq!(*s, g.surface(&rules, x, z), "({x}, {z})");
        }
    }

    #[test]
    fn a_chunk_needs_its_tree_reach_and_one_column_of_border_and_any_square_its_cells() {
        let border = trees::REACH + 1;
        assert_eq!(tree_rect(0, 16, 16), Rect::new(16 - border, -border, 16 + 2 * border, 16 + 2 * border));
        for x in -9..9 {
            let r = tree_rect(x, x, 1);
            // The cell of the farthest root on each side, with its sample column's neighbours.
            let lo_cell = (x - trees::REACH).div_euclid(CELL) * CELL;
            assert!(r.x0 <= lo_cell + 1 && r.x0 < x - trees::REACH, "{x}: {r:?}");
            assert!(r.x1() > x + trees::REACH + 1, "{x}: {r:?}");
        }
    }
}
