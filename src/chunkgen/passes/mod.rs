//! The passes of chunk generation, in the one order they run (see docs/architecture.md,
//! "Where to add: A chunk-generation pass").
//!
//! Each pass has one job, reads the shared [`ChunkContext`] and writes into the chunk; later
//! passes may overwrite what earlier ones wrote (the surface pass replaces the top of the
//! rock). Each must be a pure function of global coordinates so that chunks meet without
//! seams whatever order they are built in.

mod aquatic;
mod caves;
mod columns;
mod icebergs;
mod ores;
mod rock;
mod snow;
mod surface;
mod vegetation;
mod water;

use crate::chunkgen::Blocks;

use super::ChunkContext;

pub use aquatic::is_sea_growth;

/// One pass: a name (for timings) and the function that runs it on a chunk.
pub struct Pass {
    /// Short name (`"rock"`), as benchmarks report it.
    pub name: &'static str,
    /// Runs the pass: reads and extends the context, writes blocks or biomes into the chunk.
    pub run: fn(&mut ChunkContext, &mut Blocks),
}

/// Every pass, in order.
pub const PASSES: [Pass; 10] = [
    // The pipeline's columns around the chunk and the biome of every 4×4×4 cell.
    Pass { name: "columns", run: columns::run },
    // Bedrock, then deepslate and stone up to every column's ground.
    Pass { name: "rock", run: rock::run },
    // The sea, rivers and lakes: water from the ground to the water top, ice on top where
    // cold, falling water where a river steps down.
    Pass { name: "water", run: water::run },
    // Caverns and tunnels (lava deep down), kept dry under and beside the sea: after the
    // rock and sea exist, before the surface is laid on what is left.
    Pass { name: "caves", run: caves::run },
    // Ore veins and rock blobs, vanilla's placements, into the stone and deepslate left.
    Pass { name: "ores", run: ores::run },
    // The ground's top and filler blocks, by biome, steepness and water depth.
    Pass { name: "surface", run: surface::run },
    // Trees, then plants where every block they need is still air.
    Pass { name: "vegetation", run: vegetation::run },
    // Seagrass and kelp in the sea, lily pads on lakes, sugar cane on banks.
    Pass { name: "aquatic", run: aquatic::run },
    // Mounds of packed ice in frozen seas.
    Pass { name: "icebergs", run: icebergs::run },
    // A layer of snow on the highest block of every column of a snowy biome.
    Pass { name: "snow", run: snow::run },
];

/// Test support: contexts over synthetic columns, for the passes' unit tests.
#[cfg(test)]
pub(crate) mod testing {
    use std::path::PathBuf;
    use std::sync::Arc;

    use crate::biome::BiomeRules;
    use crate::chunkgen::{BiomePalette, Columns, Generator};
    use crate::config::Config;
    use crate::terrain::hydrology::WaterColumns;
    use crate::terrain::pipeline::channel;
    use crate::terrain::{Pipeline, Rect, Tile};

    /// A generator of the default configuration (its pipeline is not queried by the passes
    /// that get synthetic columns).
    pub fn generator() -> Generator {
        let config = Config::default();
        Generator::new(Arc::new(Pipeline::new(config.world.seed, &config.terrain())), &config)
    }

    /// The rule set of the generator's tests: sea, cold, dry and steep rules over a fallback.
    pub fn rules() -> BiomeRules {
        let [surface, underground, vegetation] = tables();
        let test = (PathBuf::from("test.toml"), RULES.to_string());
        BiomeRules::from_sources(&[test, surface, underground, vegetation]).expect("test rules load")
    }

    /// The text of [`rules`].
    const RULES: &str = r#"
fallback = "minecraft:plains"

[[rule]]
name = "sea"
biome = "minecraft:ocean"
elevation_m = [-inf, 0]
override = true

[[rule]]
name = "high cold air"
biome = "minecraft:snowy_plains"
temperature_c = [-inf, -10]
override = true

[[rule]]
name = "steep"
biome = "minecraft:windswept_hills"
slope_deg = [8, 90]
"#;

    /// Rules that give every cell `biome`, with the shipped surfaces, veins and vegetation.
    pub fn single_biome(biome: &str) -> BiomeRules {
        let source = format!("fallback = \"{biome}\"\n");
        let [surface, underground, vegetation] = tables();
        BiomeRules::from_sources(&[(PathBuf::from("one.toml"), source), surface, underground, vegetation])
            .expect("single-biome rules")
    }

    /// The shipped surface, underground and vegetation files, to load beside test rules.
    pub fn tables() -> [(PathBuf, String); 3] {
        use crate::config::shipped::{SURFACE, UNDERGROUND, VEGETATION};
        [
            (PathBuf::from("surface.toml"), SURFACE.to_string()),
            (PathBuf::from("underground.toml"), UNDERGROUND.to_string()),
            (PathBuf::from("vegetation.toml"), VEGETATION.to_string()),
        ]
    }

    /// Columns over `rect` with elevation (m) and temperature (°C) given per column.
    pub fn columns(g: &Generator, rect: Rect, f: impl Fn(i64, i64) -> (f32, f32)) -> Columns {
        let mut tile = Tile::zeros(channel::COUNT, rect);
        let w = rect.w as usize;
        for i in 0..rect.area() {
            let (x, z) = (rect.x0 + (i % w) as i64, rect.y0 + (i / w) as i64);
            let (elevation, temperature) = f(x, z);
            tile.channel_mut(channel::ELEVATION)[i] = elevation;
            tile.channel_mut(channel::TEMPERATURE)[i] = temperature;
            tile.channel_mut(channel::PRECIPITATION)[i] = 800.0;
        }
        Columns::from_tile(tile, g.vertical())
    }

    /// Columns over `rect` with elevation (m), temperature (°C) and a river's water level
    /// (m, or `None`) given per column.
    pub fn river_columns(g: &Generator, rect: Rect, f: impl Fn(i64, i64) -> (f32, f32, Option<f32>)) -> Columns {
        let mut tile = Tile::zeros(channel::COUNT, rect);
        let w = rect.w as usize;
        for i in 0..rect.area() {
            let (x, z) = (rect.x0 + (i % w) as i64, rect.y0 + (i / w) as i64);
            let (elevation, temperature, level) = f(x, z);
            tile.channel_mut(channel::ELEVATION)[i] = elevation;
            tile.channel_mut(channel::TEMPERATURE)[i] = temperature;
            tile.channel_mut(channel::PRECIPITATION)[i] = 800.0;
            tile.channel_mut(channel::WATER_LEVEL)[i] = level.unwrap_or(f32::NAN);
            tile.channel_mut(channel::WATER)[i] = if level.is_some() { f32::from(WaterColumns::RIVER) } else { 0.0 };
            tile.channel_mut(channel::DISCHARGE)[i] = if level.is_some() { 5.0 } else { 0.0 };
        }
        Columns::from_tile(tile, g.vertical())
    }

    /// The vanilla palette.
    pub fn palette() -> BiomePalette {
        BiomePalette::vanilla()
    }
}
