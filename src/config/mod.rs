//! The owner's configuration file (`config/server.toml`): parsing, defaults, validation.
//!
//! Owns: the file format and the error an owner sees. Every bad value stops start-up with
//! a message naming the file, the line, the key and what is allowed; unknown keys are errors
//! too (a typo must not silently fall back to a default).

mod find;
mod gamemode;
mod locate;
pub mod shipped;

use std::net::SocketAddr;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::terrain::settings::{check_range, EngineSettings, RangeError, TerrainSettings};
use crate::terrain::{climate::ClimateSettings, layout::LayoutSettings};

pub use find::{platform_path, ConfigOrigin};
pub use gamemode::GameMode;

/// Where the configuration is looked for first (under the current directory) unless
/// `--config` names a file.
pub const DEFAULT_PATH: &str = "config/server.toml";

/// A configuration that cannot be used, with where and why.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// The file could not be read.
    #[error("{file}: cannot read the configuration file: {reason}")]
    Read {
        /// The file.
        file: PathBuf,
        /// The operating system's reason (text, not a chained source, so it is printed once).
        reason: String,
    },
    /// Syntax error, wrong type or unknown key.
    #[error("{file}:{line}: {message}")]
    Parse {
        /// The file.
        file: PathBuf,
        /// 1-based line (0 when unknown).
        line: usize,
        /// What the parser said.
        message: String,
    },
    /// A value outside its range.
    #[error("{file}:{line}: {range}")]
    Range {
        /// The file.
        file: PathBuf,
        /// 1-based line of the key (0 when the value is a default).
        line: usize,
        /// Which key, the value and the allowed range.
        range: RangeError,
    },
}

/// The Minecraft server (`[server]`).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ServerSettings {
    /// Address and port to listen on.
    pub bind: String,
    /// Check players against Mojang's session servers (needs internet access).
    pub online_mode: bool,
    /// Most players at once.
    pub max_players: u64,
    /// Upper bound on the view distance clients may ask for, in chunks.
    pub view_distance_cap: u64,
    /// Worker threads that generate chunks.
    pub chunk_threads: u64,
    /// Finished chunks kept in memory.
    pub chunk_cache: u64,
    /// Game mode of joining players: "creative", "survival", "adventure" or "spectator".
    pub gamemode: GameMode,
}

impl Default for ServerSettings {
    fn default() -> Self {
        ServerSettings {
            bind: "0.0.0.0:25565".into(),
            online_mode: false,
            max_players: 20,
            view_distance_cap: 12,
            chunk_threads: 2,
            chunk_cache: 4096,
            gamemode: GameMode::Creative,
        }
    }
}

/// How metres become blocks (`[world]`).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WorldSettings {
    /// The world seed (overridden by `--seed`).
    pub seed: u64,
    /// Block Y of the sea surface.
    pub sea_level_y: i64,
    /// Lowest block Y (multiple of 16).
    pub min_y: i64,
    /// Height of the world in blocks (multiple of 16).
    pub height: i64,
    /// Horizontal size of one block column, metres: the world's scale (15 … 250). A saved
    /// world keeps the scale it was made with.
    pub metres_per_block: f64,
    /// Metres of real elevation per block above the sea (the vertical scale, chosen for looks).
    pub vertical_metres_per_block: f64,
    /// Metres of depth per block under the sea (the sea floor is compressed).
    pub sea_vertical_metres_per_block: f64,
    /// Folder of the saved world (`level.dat`, `region/r.X.Z.mca`), relative to the current
    /// directory unless absolute.
    pub directory: PathBuf,
    /// Save every generated chunk and load saved chunks instead of generating them again.
    pub save_chunks: bool,
}

impl Default for WorldSettings {
    fn default() -> Self {
        WorldSettings {
            seed: 1,
            sea_level_y: 63,
            min_y: -64,
            height: 384,
            metres_per_block: crate::terrain::settings::DEFAULT_METRES_PER_BLOCK,
            vertical_metres_per_block: 25.0,
            sea_vertical_metres_per_block: 60.0,
            directory: PathBuf::from("world"),
            save_chunks: true,
        }
    }
}

/// The whole file.
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Config {
    /// `[server]`
    pub server: ServerSettings,
    /// `[world]`
    pub world: WorldSettings,
    /// `[layout]`
    pub layout: LayoutSettings,
    /// `[climate]`
    pub climate: ClimateSettings,
    /// `[engine]`
    pub engine: EngineSettings,
}

impl Config {
    /// Reads and validates `path`.
    pub fn load(path: &Path) -> Result<Config, ConfigError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| ConfigError::Read { file: path.to_path_buf(), reason: e.to_string() })?;
        Config::parse(&text, path)
    }

    /// Parses and validates `text` (named `path` in errors).
    pub fn parse(text: &str, path: &Path) -> Result<Config, ConfigError> {
        let config: Config = toml::from_str(text).map_err(|e| ConfigError::Parse {
            file: path.to_path_buf(),
            line: e.span().map_or(0, |s| locate::line_of_offset(text, s.start)),
            message: e.message().trim().to_string(),
        })?;
        config.validate().map_err(|range| ConfigError::Range {
            file: path.to_path_buf(),
            line: locate::line_of_key(text, &range.key).unwrap_or(0),
            range,
        })?;
        Ok(config)
    }

    /// The terrain side's settings.
    pub fn terrain(&self) -> TerrainSettings {
        TerrainSettings {
            metres_per_block: self.world.metres_per_block,
            vertical_metres_per_block: self.world.vertical_metres_per_block,
            layout: self.layout.clone(),
            climate: self.climate.clone(),
            engine: self.engine.clone(),
        }
    }

    /// The address to listen on (validated at load).
    pub fn bind_address(&self) -> SocketAddr {
        self.server.bind.parse().unwrap_or_else(|_| SocketAddr::from(([0, 0, 0, 0], 25565)))
    }

    fn validate(&self) -> Result<(), RangeError> {
        let s = &self.server;
        if s.bind.parse::<SocketAddr>().is_err() {
            return Err(RangeError {
                key: "server.bind".into(),
                value: format!("{:?}", s.bind),
                allowed: "an IP address and port such as \"0.0.0.0:25565\"".into(),
            });
        }
        check_range("server.max_players", s.max_players, 1, 10_000)?;
        check_range("server.view_distance_cap", s.view_distance_cap, 2, 32)?;
        check_range("server.chunk_threads", s.chunk_threads, 1, 256)?;
        check_range("server.chunk_cache", s.chunk_cache, 0, 1_000_000)?;
        let w = &self.world;
        check_range("world.min_y", w.min_y, -2032, 2016)?;
        check_range("world.height", w.height, 16, 4064)?;
        check_range("world.sea_level_y", w.sea_level_y, w.min_y + 1, w.min_y + w.height - 2)?;
        check_range("world.vertical_metres_per_block", w.vertical_metres_per_block, 1.0, 1000.0)?;
        check_range("world.sea_vertical_metres_per_block", w.sea_vertical_metres_per_block, 1.0, 5000.0)?;
        for (key, v) in [("world.min_y", w.min_y), ("world.height", w.height)] {
            if v.rem_euclid(16) != 0 {
                return Err(RangeError { key: key.into(), value: v.to_string(), allowed: "a multiple of 16".into() });
            }
        }
        check_range("world.min_y + world.height", w.min_y + w.height, -2016, 2032)?;
        if w.directory.as_os_str().is_empty() {
            return Err(RangeError {
                key: "world.directory".into(),
                value: "\"\"".into(),
                allowed: "a folder path such as \"world\"".into(),
            });
        }
        self.terrain().validate()
    }
}

#[cfg(test)]
mod tests;
