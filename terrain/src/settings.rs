//! Owner-facing settings of the terrain side, with their allowed ranges.
//!
//! The root crate reads them from `config/server.toml` (sections `[layout]`, `[climate]`,
//! `[engine]`); this module only knows names, defaults and ranges, so the error a server
//! owner sees can name the key and what is allowed.

use std::path::PathBuf;

use serde::Deserialize;

pub use crate::climate::ClimateSettings;
pub use crate::layout::LayoutSettings;

/// A setting outside its allowed range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{key} = {value} is out of range (allowed {allowed})")]
pub struct RangeError {
    /// Dotted key, e.g. `layout.ocean_fraction`.
    pub key: String,
    /// The value given, as written.
    pub value: String,
    /// The allowed range, e.g. `0.05..=0.95`.
    pub allowed: String,
}

/// Checks `min <= value <= max`, naming `key` on failure.
pub fn check_range<T: PartialOrd + std::fmt::Display>(key: &str, value: T, min: T, max: T) -> Result<(), RangeError> {
    if value >= min && value <= max {
        Ok(())
    } else {
        Err(RangeError { key: key.to_string(), value: value.to_string(), allowed: format!("{min}..={max}") })
    }
}

/// The engine's cache and threads, and which learned stages run, as the owner sets them.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EngineSettings {
    /// Window cache budget in MiB, shared by every stage.
    pub cache_mib: u64,
    /// Threads evaluating missing windows of one query.
    pub threads: u64,
    /// Learned stages to run, by name (`"core"`); empty: the procedural layout stands in.
    pub learned: Vec<String>,
    /// Folder of the weights (`<stage>.json` manifest + `<stage>.safetensors`).
    pub models: PathBuf,
    /// Backend of the learned stages: `"cpu"` (burn's pure-Rust backend) or `"wgpu"`.
    pub backend: String,
}

/// Learned stages that exist (have code and can be trained).
pub const LEARNED_STAGES: [&str; 3] = ["coarse", "core", "detail"];

impl Default for EngineSettings {
    fn default() -> Self {
        EngineSettings {
            cache_mib: 256,
            threads: 2,
            learned: Vec::new(),
            models: PathBuf::from("models"),
            backend: "cpu".into(),
        }
    }
}

impl EngineSettings {
    /// Checks every value against its range.
    pub fn validate(&self) -> Result<(), RangeError> {
        check_range("engine.cache_mib", self.cache_mib, 1, 65_536)?;
        check_range("engine.threads", self.threads, 1, 256)?;
        if !["cpu", "wgpu"].contains(&self.backend.as_str()) {
            return Err(RangeError {
                key: "engine.backend".into(),
                value: format!("{:?}", self.backend),
                allowed: "\"cpu\" or \"wgpu\"".into(),
            });
        }
        for stage in &self.learned {
            if !LEARNED_STAGES.contains(&stage.as_str()) {
                return Err(RangeError {
                    key: "engine.learned".into(),
                    value: format!("{stage:?}"),
                    allowed: format!("stages with a model: {:?}", LEARNED_STAGES),
                });
            }
        }
        // The detail model refines the core's output; without the core it has nothing to refine.
        if self.learned.iter().any(|s| s == "detail") && !self.learned.iter().any(|s| s == "core") {
            return Err(RangeError {
                key: "engine.learned".into(),
                value: format!("{:?}", self.learned),
                allowed: "\"detail\" only together with \"core\" (it refines the core's relief)".into(),
            });
        }
        Ok(())
    }
}

/// Everything the terrain pipeline needs besides the seed.
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TerrainSettings {
    /// The procedural continental layout.
    pub layout: LayoutSettings,
    /// The climate model.
    pub climate: ClimateSettings,
    /// The engine's cache and threads.
    pub engine: EngineSettings,
}

impl TerrainSettings {
    /// Checks every value against its range.
    pub fn validate(&self) -> Result<(), RangeError> {
        self.layout.validate()?;
        self.climate.validate()?;
        self.engine.validate()
    }
}
