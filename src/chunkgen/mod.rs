//! Fill: block columns from the terrain pipeline → Minecraft chunks.
//!
//! Owns: the vertical mapping (metres → block Y), surface materials, biomes per 4×4×4 cell
//! and the assembly of a valence [`UnloadedChunk`](valence::prelude::UnloadedChunk). Must not
//! touch: networking, scheduling or caching (the server's), or how terrain is made (the
//! pipeline's). Everything here is a pure function of (seed, configuration, rules, global
//! coordinates), so chunks can be built on any thread in any order and still meet seamlessly.

mod cells;
mod chunk;
mod columns;
mod hash;
mod light;
mod plants;
mod surface;
mod trees;
mod vertical;

use std::collections::HashMap;
use std::sync::Arc;

use valence::prelude::{BiomeId, BiomeRegistry};
use valence::registry::{RegistryCodec, RegistryIdx};

use crate::config::Config;
use crate::terrain::Pipeline;

pub use chunk::CHUNK;
pub use columns::{Columns, BLOCK_METRES};
pub use light::SkyLight;
pub use plants::is_plant;
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
}

/// What [`Generator::surface`] reports for one column.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceSample {
    /// Block Y of the topmost ground block.
    pub y: i32,
    /// Biome of the cell holding that block (`"minecraft:plains"`).
    pub biome: String,
    /// Name of the ground block there (`"grass_block"`), before any vegetation or sea ice.
    pub top: &'static str,
}

/// Every biome name Minecraft 1.20.1 knows (`"minecraft:plains"`, …), from the registry
/// valence sends to clients.
pub fn vanilla_biome_names() -> Vec<String> {
    RegistryCodec::default().registry(BiomeRegistry::KEY).iter().map(|v| v.name.as_str().to_string()).collect()
}

/// Biome names → the ids the client knows them by (its registry order).
#[derive(Clone, Debug)]
pub struct BiomePalette {
    ids: HashMap<String, BiomeId>,
    /// Name of each id, by index.
    names: Vec<String>,
    fallback: BiomeId,
}

impl BiomePalette {
    /// Every biome of `registry`; unknown names map to the registry's first biome (plains).
    pub fn from_registry(registry: &BiomeRegistry) -> BiomePalette {
        let mut names = vec![String::new(); registry.iter().count()];
        let mut ids = HashMap::new();
        for (id, name, _) in registry.iter() {
            names[id.to_index()] = name.as_str().to_string();
            ids.insert(name.as_str().to_string(), id);
        }
        BiomePalette { ids, names, fallback: BiomeId::DEFAULT }
    }

    /// The palette of valence's default biome registry without a running server: vanilla's
    /// biomes in registry order with plains swapped to the front, exactly as valence's biome
    /// plugin builds the registry the server uses.
    pub fn vanilla() -> BiomePalette {
        let mut names = vanilla_biome_names();
        if let Some(i) = names.iter().position(|n| n == "minecraft:plains") {
            names.swap(0, i);
        }
        let ids = names.iter().enumerate().map(|(i, n)| (n.clone(), BiomeId::from_index(i))).collect();
        BiomePalette { ids, names, fallback: BiomeId::DEFAULT }
    }

    /// Biome names indexed by id.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The id of biome `name`, or the fallback when the registry lacks it.
    pub fn id(&self, name: &str) -> BiomeId {
        self.ids.get(name).copied().unwrap_or(self.fallback)
    }

    /// True when the registry holds `name`.
    pub fn contains(&self, name: &str) -> bool {
        self.ids.contains_key(name)
    }
}

#[cfg(test)]
mod tests;

#[cfg(test)]
mod pinned_tests;
