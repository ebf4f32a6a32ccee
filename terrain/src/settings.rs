//! Owner-facing settings of the terrain side, with their allowed ranges.
//!
//! The root crate reads them from `config/server.toml` (sections `[layout]`, `[climate]`,
//! `[engine]`); this module only knows names, defaults and ranges, so the error a server
//! owner sees can name the key and what is allowed.

use std::path::PathBuf;

use serde::Deserialize;

pub use crate::climate::ClimateSettings;
pub use crate::layout::LayoutSettings;
pub use crate::range::{check_range, RangeError};
use crate::stages::{self, LearnedStageSpec};

/// A learned stage named in `engine.learned`: always an entry of the stage table
/// ([`stages::LEARNED`]), so code holding one never meets an unknown name.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct StageName(&'static str);

impl StageName {
    /// The stage's name.
    pub fn as_str(self) -> &'static str {
        self.0
    }

    /// The stage's entry in the table.
    pub fn spec(self) -> &'static LearnedStageSpec {
        stages::learned(self.0).expect("a StageName is always in the table")
    }
}

impl std::str::FromStr for StageName {
    type Err = RangeError;

    /// The stage called `s`; an error naming `engine.learned` and the stages that exist.
    fn from_str(s: &str) -> Result<StageName, RangeError> {
        stages::learned(s).map(|spec| StageName(spec.name)).ok_or_else(|| RangeError {
            key: "engine.learned".into(),
            value: format!("{s:?}"),
            allowed: format!("stages with a model: {:?}", stages::learned_names()),
        })
    }
}

impl<'de> Deserialize<'de> for StageName {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<StageName, D::Error> {
        String::deserialize(d)?.parse().map_err(serde::de::Error::custom)
    }
}

impl std::fmt::Display for StageName {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.0)
    }
}

/// Written as the quoted name (`"core"`), as it appears in the configuration.
impl std::fmt::Debug for StageName {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:?}", self.0)
    }
}

impl PartialEq<str> for StageName {
    fn eq(&self, other: &str) -> bool {
        self.0 == other
    }
}

impl PartialEq<&str> for StageName {
    fn eq(&self, other: &&str) -> bool {
        self.0 == *other
    }
}

impl PartialEq<String> for StageName {
    fn eq(&self, other: &String) -> bool {
        self.0 == other
    }
}

/// Where the learned stages run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Backend {
    /// burn's pure-Rust CPU backend.
    #[default]
    Cpu,
    /// burn's wgpu backend (needs the `wgpu` build feature).
    Wgpu,
}

impl Backend {
    /// The name in the configuration (`"cpu"`, `"wgpu"`).
    pub fn as_str(self) -> &'static str {
        match self {
            Backend::Cpu => "cpu",
            Backend::Wgpu => "wgpu",
        }
    }
}

impl std::str::FromStr for Backend {
    type Err = RangeError;

    /// The backend called `s`; an error naming `engine.backend` and the backends that exist.
    fn from_str(s: &str) -> Result<Backend, RangeError> {
        match s {
            "cpu" => Ok(Backend::Cpu),
            "wgpu" => Ok(Backend::Wgpu),
            _ => Err(RangeError {
                key: "engine.backend".into(),
                value: format!("{s:?}"),
                allowed: "\"cpu\" or \"wgpu\"".into(),
            }),
        }
    }
}

impl<'de> Deserialize<'de> for Backend {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Backend, D::Error> {
        String::deserialize(d)?.parse().map_err(serde::de::Error::custom)
    }
}

impl std::fmt::Display for Backend {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// The engine's cache and threads, and which learned stages run, as the owner sets them.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EngineSettings {
    /// Window cache budget in MiB, shared by every stage; at least [`MIN_CACHE_MIB`].
    pub cache_mib: u64,
    /// Threads evaluating missing windows of one query.
    pub threads: u64,
    /// Learned stages to run (`["core"]`); empty: the procedural layout stands in.
    pub learned: Vec<StageName>,
    /// Folder of the weights (`<stage>.json` manifest + `<stage>.safetensors`).
    pub models: PathBuf,
    /// Backend of the learned stages.
    pub backend: Backend,
}

/// The smallest window cache an owner may set, MiB. One chunk's query touches about 6 MiB of
/// windows (most of them the continent's drainage and the climate it is drained with, a
/// thousand kilometres around); a cache smaller than that evicts windows the same query still
/// needs and recomputes them over and over (measured: a walk of 300 chunks went from seconds
/// to over an hour with 1 MiB).
pub const MIN_CACHE_MIB: u64 = 32;

impl Default for EngineSettings {
    fn default() -> Self {
        EngineSettings {
            cache_mib: 256,
            threads: 2,
            learned: Vec::new(),
            models: PathBuf::from("models"),
            backend: Backend::Cpu,
        }
    }
}

impl EngineSettings {
    /// Checks every value against its range, and that every learned stage's required stages
    /// run too (names and backends are checked when they are parsed).
    pub fn validate(&self) -> Result<(), RangeError> {
        check_range("engine.cache_mib", self.cache_mib, MIN_CACHE_MIB, 65_536)?;
        check_range("engine.threads", self.threads, 1, 256)?;
        for stage in &self.learned {
            let spec = stage.spec();
            if let Some(&required) = spec.requires.iter().find(|r| !self.runs(r)) {
                let why = if required == spec.context_stage {
                    format!("it refines the {required}'s relief")
                } else {
                    format!("it needs the {required} stage")
                };
                return Err(RangeError {
                    key: "engine.learned".into(),
                    value: format!("{:?}", self.learned),
                    allowed: format!("{stage:?} only together with {required:?} ({why})"),
                });
            }
        }
        Ok(())
    }

    /// Whether the learned stage `name` runs.
    pub fn runs(&self, name: &str) -> bool {
        self.learned.iter().any(|s| s == name)
    }
}

/// Blocks per model pixel (horizontally), whatever the world's scale: the model grid is
/// always 4 blocks (the pipeline re-exports it).
pub const BLOCKS_PER_MODEL_PIXEL: i64 = 4;
/// Horizontal size of a block column by default, metres (`world.metres_per_block`).
pub const DEFAULT_METRES_PER_BLOCK: f64 = 40.0;
/// The horizontal scales a world may have, metres per block.
pub const METRES_PER_BLOCK_RANGE: (f64, f64) = (15.0, 250.0);

/// Everything the terrain pipeline needs besides the seed.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TerrainSettings {
    /// Horizontal size of one block column, metres: the world's scale. The pipeline's finest
    /// grid is always 4 blocks, whatever the scale.
    pub metres_per_block: f64,
    /// Metres of elevation per block above the sea (`world.vertical_metres_per_block`): a
    /// river's channel is cut whole blocks deep.
    pub vertical_metres_per_block: f64,
    /// The procedural continental layout.
    pub layout: LayoutSettings,
    /// The climate model.
    pub climate: ClimateSettings,
    /// The engine's cache and threads.
    pub engine: EngineSettings,
}

impl Default for TerrainSettings {
    fn default() -> Self {
        TerrainSettings {
            metres_per_block: DEFAULT_METRES_PER_BLOCK,
            vertical_metres_per_block: 25.0,
            layout: LayoutSettings::default(),
            climate: ClimateSettings::default(),
            engine: EngineSettings::default(),
        }
    }
}

impl TerrainSettings {
    /// Size of a model pixel (always [`BLOCKS_PER_MODEL_PIXEL`] blocks), metres.
    pub fn model_pixel_metres(&self) -> f64 {
        self.metres_per_block * BLOCKS_PER_MODEL_PIXEL as f64
    }

    /// Checks every value against its range.
    pub fn validate(&self) -> Result<(), RangeError> {
        let (lo, hi) = METRES_PER_BLOCK_RANGE;
        check_range("world.metres_per_block", self.metres_per_block, lo, hi)?;
        self.layout.validate()?;
        self.climate.validate()?;
        self.engine.validate()
    }
}
