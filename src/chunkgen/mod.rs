//! Chunk generation: block columns from the terrain pipeline → Minecraft chunks.
//!
//! Owns: the vertical mapping (metres → block Y), biomes per 4×4×4 cell, the blocks of a
//! chunk (rock, sea, surface materials, trees and plants) and the light (sky and block) of a
//! finished chunk. Must not touch: networking, scheduling, caching or saving (the server's and the
//! world's: they call [`Generator::chunk`] and [`Light::of`]), or how terrain is made (the
//! pipeline's). Everything here is a pure function of (seed, configuration, rules, global
//! coordinates), so chunks can be built on any thread in any order and still meet seamlessly.
//!
//! A chunk is built by an ordered list of passes ([`passes::PASSES`]): columns (the pipeline
//! query and the biome of every cell) → rock → water → surface → vegetation. Each pass is one
//! module of `passes/` with one job; it reads the shared [`ChunkContext`] and writes into the
//! chunk. Light is not a pass: the server and the world saver compute it from the
//! finished blocks ([`Light::of`]).
//!
//! Adding a pass (see docs/architecture.md, "Where to add: A chunk-generation pass"): write
//! `passes/<name>.rs` with `pub fn run(ctx: &mut ChunkContext, chunk: &mut Blocks)` and
//! its own unit tests, then add it to [`passes::PASSES`] at its place in the order (the list
//! marks where carvers and ores go). A pass must stay a pure function of the context and the
//! chunk so far: anything it decides near a chunk border must be decided the same way by the
//! neighbouring chunk. The per-column queries ([`Generator::surface`],
//! [`Generator::plant_blocks`], [`Generator::clear_of_trees`]) share their decisions with the
//! passes (`column.rs`); a pass that changes the surface or vegetation must keep them in step.
//! The pinned hashes of `pinned_tests.rs` say whether a change altered the world.
//!
//! [`UnloadedChunk`]: valence::prelude::UnloadedChunk

mod blocks;
mod cave_field;
mod cells;
mod chunk;
mod column;
mod columns;
mod context;
mod hash;
mod light;
mod palette;
pub mod passes;
mod plants;
mod states;
mod surface;
mod trees;
mod vertical;

use std::sync::Arc;

use crate::config::Config;
use crate::terrain::Pipeline;

#[cfg(test)]
pub(crate) use blocks::assert_same;
pub use blocks::Blocks;
pub use chunk::{PassTiming, CHUNK};
pub use columns::Columns;
pub use context::ChunkContext;
pub use hash::unit3;
pub use light::Light;
pub use palette::{vanilla_biome_names, BiomePalette};
pub use plants::is_plant;
pub use states::States;
pub use surface::{Ground, Site};
pub use vertical::Vertical;

/// Builds chunks for one world: the pipeline plus the vertical and climate settings.
pub struct Generator {
    pipeline: Arc<Pipeline>,
    vertical: Vertical,
    lapse_c_per_km: f32,
    seed: u64,
}

impl Generator {
    /// A generator over `pipeline` with the `[world]` and `[climate]` settings of `config`.
    pub fn new(pipeline: Arc<Pipeline>, config: &Config) -> Generator {
        Generator {
            pipeline,
            vertical: Vertical::from_world(&config.world),
            lapse_c_per_km: config.climate.lapse_rate_c_per_km as f32,
            seed: config.world.seed,
        }
    }

    /// The terrain pipeline.
    pub fn pipeline(&self) -> &Arc<Pipeline> {
        &self.pipeline
    }

    /// The vertical mapping.
    pub fn vertical(&self) -> &Vertical {
        &self.vertical
    }

    /// The world seed (of the configuration it was made with).
    pub fn seed(&self) -> u64 {
        self.seed
    }
}

/// What [`Generator::surface`] reports for one column.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceSample {
    /// Block Y of the topmost ground block.
    pub y: i32,
    /// Biome of the cell holding that block (`"minecraft:plains"`).
    pub biome: String,
    /// Name of the ground block there (`"grass_block"`), before any vegetation or sea ice;
    /// `"air"` where a cave's mouth has carved it away.
    pub top: &'static str,
    /// Block Y of the top of the water over the column (sea, river or lake), if any.
    pub water_y: Option<i32>,
}

#[cfg(test)]
mod tests;

#[cfg(test)]
mod pinned_tests;
#[cfg(test)]
mod water_tests;
