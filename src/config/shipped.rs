//! What the repository ships, compiled into the binary so an installed `infiniterra` runs
//! from any directory: the configuration file, the default biome rules with their surfaces,
//! veins and vegetation, and the trained
//! models (a few MB). A file on disk always wins over these (the lookup order is in
//! [`find`](super::find)).

use crate::terrain::model_files::ModelFiles;

/// `config/server.toml` as shipped: the built-in configuration, so the defaults a binary
/// runs with and the file owners copy never differ.
pub const CONFIG: &str = include_str!("../../config/server.toml");

/// The name the built-in configuration goes by in messages.
pub const CONFIG_NAME: &str = "built-in config/server.toml";

/// `biomes/default.toml` as shipped: the biome rules.
pub const BIOMES: &str = include_str!("../../biomes/default.toml");

/// `biomes/vegetation.toml` as shipped: what grows in each biome.
pub const VEGETATION: &str = include_str!("../../biomes/vegetation.toml");

/// `biomes/surface.toml` as shipped: the ground of each biome.
pub const SURFACE: &str = include_str!("../../biomes/surface.toml");

/// `biomes/underground.toml` as shipped: vanilla's ore and rock placements.
pub const UNDERGROUND: &str = include_str!("../../biomes/underground.toml");

/// The name the built-in biome files go by in messages (each message adds the file).
pub const BIOMES_NAME: &str = "built-in biomes/";

/// Every shipped biome file as (name for messages, text), in the order they load.
pub fn biome_sources() -> Vec<(std::path::PathBuf, String)> {
    [
        ("default.toml", BIOMES),
        ("surface.toml", SURFACE),
        ("underground.toml", UNDERGROUND),
        ("vegetation.toml", VEGETATION),
    ]
    .into_iter()
    .map(|(name, text)| (std::path::PathBuf::from(format!("{BIOMES_NAME}{name}")), text.to_string()))
    .collect()
}

/// Every file of `models/` the learned stages read: manifests and weights.
static MODELS: [(&str, &[u8]); 6] = [
    ("coarse.json", include_bytes!("../../models/coarse.json")),
    ("coarse.safetensors", include_bytes!("../../models/coarse.safetensors")),
    ("core.json", include_bytes!("../../models/core.json")),
    ("core.safetensors", include_bytes!("../../models/core.safetensors")),
    ("detail.json", include_bytes!("../../models/detail.json")),
    ("detail.safetensors", include_bytes!("../../models/detail.safetensors")),
];

/// The shipped models, as a source the pipeline reads them from.
pub fn models() -> ModelFiles {
    ModelFiles::Embedded(&MODELS)
}
