//! The world as this process computes it, to compare the binary's output with: rule sets,
//! configurations, pipelines and chunk generators.
//!
//! The one place the integration tests name the library's generation types, so moving them
//! in the library is an edit here, not in every test.

use std::path::{Path, PathBuf};
use std::sync::Arc;

// Re-exported for the test files; each test crate uses only some (see `common/mod.rs`).
#[allow(unused_imports)]
pub use infiniterra::{
    biome::BiomeRules,
    chunkgen::{BiomePalette, Generator, Light},
    config::Config,
    terrain::Pipeline,
    world::find_spawn,
};

use super::repo;

/// The shipped biome rules folder (`biomes/`).
pub fn shipped_biomes() -> PathBuf {
    repo().join("biomes")
}

/// The shipped weights folder (`models/`).
pub fn shipped_models() -> PathBuf {
    repo().join("models")
}

/// The rules of `dir`; panics naming the folder if they do not load.
pub fn rules(dir: &Path) -> BiomeRules {
    BiomeRules::load_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
}

/// The shipped biome rules.
pub fn shipped_rules() -> BiomeRules {
    rules(&shipped_biomes())
}

/// The shipped configuration (`config/server.toml`).
pub fn shipped_config() -> Config {
    Config::load(&repo().join("config/server.toml")).expect("shipped config loads")
}

/// The built-in defaults with world `seed`.
pub fn seeded_config(seed: u64) -> Config {
    let mut config = Config::default();
    config.world.seed = seed;
    config
}

/// The procedural pipeline of `config` (no learned stage, whatever `[engine]` says).
pub fn procedural_pipeline(config: &Config) -> Pipeline {
    Pipeline::new(config.world.seed, &config.terrain())
}

/// `config`'s pipeline running the `learned` stages with the shipped weights on `threads`
/// engine threads (the output is the same bits whatever the thread count).
pub fn learned_pipeline(config: &Config, learned: &[&str], threads: u64) -> Pipeline {
    let mut terrain = config.terrain();
    terrain.engine.learned = learned.iter().map(|s| s.parse().expect("a learned stage")).collect();
    terrain.engine.models = shipped_models();
    terrain.engine.threads = threads;
    Pipeline::build(config.world.seed, &terrain).expect("the shipped models build a pipeline")
}

/// The chunk generator of `config` over `pipeline`.
pub fn generator_with(pipeline: Pipeline, config: &Config) -> Generator {
    Generator::new(Arc::new(pipeline), config)
}

/// The chunk generator of `config` over its procedural pipeline.
pub fn generator(config: &Config) -> Generator {
    generator_with(procedural_pipeline(config), config)
}

/// A biome's name without the `minecraft:` namespace, as the protocol clients report it.
pub fn short(biome: &str) -> &str {
    biome.strip_prefix("minecraft:").unwrap_or(biome)
}

/// River water columns within `radius` blocks (either axis) of `centre`: (x, z, block Y of
/// the water's top), from the pipeline's water channels and the vertical mapping.
#[allow(dead_code)]
pub fn river_columns_near(generator: &Generator, centre: (i64, i64), radius: i64) -> Vec<(i64, i64, i32)> {
    use infiniterra::terrain::hydrology::WaterColumns;
    use infiniterra::terrain::pipeline::channel;
    use infiniterra::terrain::Rect;
    let rect = Rect::new(centre.1 - radius, centre.0 - radius, 2 * radius + 1, 2 * radius + 1);
    let tile = generator.pipeline().columns(rect);
    let mut out = Vec::new();
    for z in rect.y0..rect.y1() {
        for x in rect.x0..rect.x1() {
            let level = tile.get(channel::WATER_LEVEL, z, x);
            if tile.get(channel::WATER, z, x) as u8 == WaterColumns::RIVER && !level.is_nan() {
                out.push((x, z, generator.vertical().surface_y(level)));
            }
        }
    }
    out
}
