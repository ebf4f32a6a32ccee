//! One chunk: the passes of [`PASSES`](super::passes::PASSES) run in order over a fresh chunk.

use std::time::Instant;

use valence::prelude::UnloadedChunk;

use crate::biome::BiomeRules;

use super::passes::{Pass, PASSES};
use super::{BiomePalette, Blocks, ChunkContext, Generator};

/// Blocks per chunk edge.
pub const CHUNK: i64 = 16;

/// How long one pass took on one chunk.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PassTiming {
    /// The pass's name (`"rock"`).
    pub name: &'static str,
    /// Wall-clock time, nanoseconds.
    pub nanos: u64,
}

impl Generator {
    /// Builds the chunk at chunk coordinates (`chunk_x`, `chunk_z`) with `rules`, its biomes
    /// numbered by `palette`. Pure: the same inputs give the same chunk, and neighbouring chunks
    /// meet without seams (everything is a function of global coordinates).
    pub fn chunk(&self, rules: &BiomeRules, palette: &BiomePalette, chunk_x: i32, chunk_z: i32) -> UnloadedChunk {
        self.blocks(rules, palette, chunk_x, chunk_z).to_chunk()
    }

    /// [`chunk`](Self::chunk) as plain arrays, before valence's paletted form: what
    /// pre-generation encodes and light is computed from.
    pub fn blocks(&self, rules: &BiomeRules, palette: &BiomePalette, chunk_x: i32, chunk_z: i32) -> Blocks {
        self.run_passes(rules, palette, chunk_x, chunk_z, |_, _| {})
    }

    /// [`blocks`](Self::blocks), also reporting the time each pass took, in pass order (for
    /// benchmarks: the cost per pass).
    pub fn chunk_timed(
        &self,
        rules: &BiomeRules,
        palette: &BiomePalette,
        chunk_x: i32,
        chunk_z: i32,
    ) -> (Blocks, Vec<PassTiming>) {
        let mut timings = Vec::with_capacity(PASSES.len());
        let chunk = self.run_passes(rules, palette, chunk_x, chunk_z, |pass, nanos| {
            timings.push(PassTiming { name: pass.name, nanos });
        });
        (chunk, timings)
    }

    /// Runs every pass in order, calling `timed` after each with its wall-clock nanoseconds.
    fn run_passes(
        &self,
        rules: &BiomeRules,
        palette: &BiomePalette,
        chunk_x: i32,
        chunk_z: i32,
        mut timed: impl FnMut(&Pass, u64),
    ) -> Blocks {
        let mut ctx = ChunkContext::new(self, rules, palette, chunk_x, chunk_z);
        let mut chunk = Blocks::with_height(self.vertical.height as u32);
        for pass in &PASSES {
            let start = Instant::now();
            (pass.run)(&mut ctx, &mut chunk);
            timed(pass, u64::try_from(start.elapsed().as_nanos()).unwrap_or(u64::MAX));
        }
        chunk
    }
}
