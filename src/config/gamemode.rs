//! `[server] gamemode`: the game mode joining players get, parsed once when the file loads.

use std::fmt;

use serde::Deserialize;

use crate::terrain::settings::RangeError;

/// Game mode of joining players (and of the saved world's `level.dat`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(try_from = "String")]
pub enum GameMode {
    /// Build freely, fly, no damage.
    #[default]
    Creative,
    /// Gather, craft, take damage.
    Survival,
    /// Survival without breaking or placing blocks.
    Adventure,
    /// Fly through everything, invisible.
    Spectator,
}

impl GameMode {
    /// Every mode, in the order the file documents them.
    pub const ALL: [GameMode; 4] = [GameMode::Creative, GameMode::Survival, GameMode::Adventure, GameMode::Spectator];

    /// The name written in the configuration file.
    pub fn name(self) -> &'static str {
        match self {
            GameMode::Creative => "creative",
            GameMode::Survival => "survival",
            GameMode::Adventure => "adventure",
            GameMode::Spectator => "spectator",
        }
    }

    /// The client's game mode (what valence sends players).
    pub fn client(self) -> valence::prelude::GameMode {
        match self {
            GameMode::Creative => valence::prelude::GameMode::Creative,
            GameMode::Survival => valence::prelude::GameMode::Survival,
            GameMode::Adventure => valence::prelude::GameMode::Adventure,
            GameMode::Spectator => valence::prelude::GameMode::Spectator,
        }
    }

    /// Minecraft's `GameType` number in `level.dat` (0 survival, 1 creative, 2 adventure,
    /// 3 spectator).
    pub fn game_type(self) -> i32 {
        match self {
            GameMode::Survival => 0,
            GameMode::Creative => 1,
            GameMode::Adventure => 2,
            GameMode::Spectator => 3,
        }
    }
}

impl fmt::Display for GameMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl TryFrom<String> for GameMode {
    type Error = RangeError;

    /// The error names the key and the allowed values, as every range error of the file does
    /// (the parser adds the file and line).
    fn try_from(name: String) -> Result<GameMode, RangeError> {
        GameMode::ALL.into_iter().find(|m| m.name() == name).ok_or_else(|| RangeError {
            key: "server.gamemode".into(),
            value: format!("{name:?}"),
            allowed: "\"creative\", \"survival\", \"adventure\" or \"spectator\"".into(),
        })
    }
}
