//! What every pass of one chunk shares: where the chunk is, the world's settings and rules,
//! and what the columns pass learnt (the pipeline's columns, the biome of every cell).

use crate::biome::BiomeRules;

use super::cells::{self, CELL};
use super::columns::Columns;
use super::{BiomePalette, Generator, Vertical, CHUNK};

/// The shared state of one chunk's generation, handed to every pass in order.
pub struct ChunkContext<'a> {
    /// The generator (pipeline, vertical mapping, climate settings, seed).
    pub generator: &'a Generator,
    /// The biome rules.
    pub rules: &'a BiomeRules,
    /// Biome names → the ids written into the chunk.
    pub palette: &'a BiomePalette,
    /// Global block X of the chunk's first column.
    pub x0: i64,
    /// Global block Z of the chunk's first column.
    pub z0: i64,
    /// The pipeline's columns over the chunk and a border around it (set by the columns pass).
    pub columns: Option<Columns>,
    /// Biome name of every cell, indexed `(cell_z·4 + cell_x)·cells_y + cell_y` (set by the
    /// columns pass).
    pub biomes: Vec<&'a str>,
}

impl<'a> ChunkContext<'a> {
    /// The context of the chunk at chunk coordinates (`chunk_x`, `chunk_z`), before any pass.
    pub fn new(
        generator: &'a Generator,
        rules: &'a BiomeRules,
        palette: &'a BiomePalette,
        chunk_x: i32,
        chunk_z: i32,
    ) -> ChunkContext<'a> {
        ChunkContext {
            generator,
            rules,
            palette,
            x0: i64::from(chunk_x) * CHUNK,
            z0: i64::from(chunk_z) * CHUNK,
            columns: None,
            biomes: Vec::new(),
        }
    }

    /// The vertical mapping.
    pub fn vertical(&self) -> &Vertical {
        &self.generator.vertical
    }

    /// The world seed.
    pub fn seed(&self) -> u64 {
        self.generator.seed
    }

    /// The pipeline's columns; panics before the columns pass has run (passes run in the fixed
    /// order of [`PASSES`](super::passes::PASSES), columns first).
    pub fn columns(&self) -> &Columns {
        self.columns.as_ref().expect("the columns pass runs before any pass that reads columns")
    }

    /// Biome cells per column of cells (the world's height / 4).
    pub fn cells_y(&self) -> usize {
        (self.vertical().height / CELL as i32) as usize
    }

    /// The biome of the cell holding column (`x`, `z`)'s ground block, as
    /// [`Generator::surface_biome`] decides it: from the cells the columns pass decided for a
    /// column of this chunk (the vegetation and snow passes ask for every column, and
    /// deciding a cell's biome anew each time was a tenth of a chunk's time), else anew.
    pub fn surface_biome(&self, x: i64, z: i64) -> &'a str {
        let columns = self.columns();
        let (lx, lz) = (x - self.x0, z - self.z0);
        let v = self.vertical();
        let cell_y = (cells::cell_centre_y(columns.surface_y(x, z)) - v.min_y).div_euclid(CELL as i32);
        // (Passes tested alone run without the columns pass's cells.)
        let decided = self.biomes.len() == 16 * self.cells_y();
        if decided
            && (0..CHUNK).contains(&lx)
            && (0..CHUNK).contains(&lz)
            && (0..self.cells_y() as i32).contains(&cell_y)
        {
            let cell = ((lz / CELL) * 4 + lx / CELL) as usize;
            self.biomes[cell * self.cells_y() + cell_y as usize]
        } else {
            self.generator.surface_biome(self.rules, columns, x, z)
        }
    }

    /// Every column of the chunk: (chunk-local x, chunk-local z, global x, global z), rows of
    /// `z`, then `x`.
    pub fn each_column(&self) -> impl Iterator<Item = (u32, u32, i64, i64)> {
        let (x0, z0) = (self.x0, self.z0);
        (0..CHUNK).flat_map(move |lz| (0..CHUNK).map(move |lx| (lx as u32, lz as u32, x0 + lx, z0 + lz)))
    }
}
