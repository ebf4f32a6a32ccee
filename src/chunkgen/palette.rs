//! Biome names → the ids a client knows them by, in the order of valence's biome registry.

use std::collections::HashMap;

use valence::prelude::{BiomeId, BiomeRegistry};

use crate::biome::{overworld_index, OVERWORLD_BIOMES};
use valence::registry::{RegistryCodec, RegistryIdx};

/// Every biome name Minecraft 1.20.1 knows (`"minecraft:plains"`, …), from the registry
/// valence sends to clients.
pub fn vanilla_biome_names() -> Vec<String> {
    RegistryCodec::default().registry(BiomeRegistry::KEY).iter().map(|v| v.name.as_str().to_string()).collect()
}

/// Biome names → the ids the client knows them by (its registry order).
#[derive(Clone, Debug)]
pub struct BiomePalette {
    ids: HashMap<String, BiomeId>,
    /// The id of every overworld biome, indexed like [`OVERWORLD_BIOMES`] (a lookup without
    /// hashing a name, for every biome cell of every chunk).
    overworld: Vec<BiomeId>,
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
        BiomePalette::new(ids, names)
    }

    /// The palette of `ids`, whose names by index are `names`.
    fn new(ids: HashMap<String, BiomeId>, names: Vec<String>) -> BiomePalette {
        let fallback = BiomeId::DEFAULT;
        let overworld = OVERWORLD_BIOMES.iter().map(|&n| ids.get(n).copied().unwrap_or(fallback)).collect();
        BiomePalette { ids, overworld, names, fallback }
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
        BiomePalette::new(ids, names)
    }

    /// Biome names indexed by id.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The id of biome `name`, or the fallback when the registry lacks it.
    pub fn id(&self, name: &str) -> BiomeId {
        match overworld_index(name) {
            Some(i) => self.overworld[i],
            None => self.ids.get(name).copied().unwrap_or(self.fallback),
        }
    }

    /// True when the registry holds `name`.
    pub fn contains(&self, name: &str) -> bool {
        self.ids.contains_key(name)
    }
}
