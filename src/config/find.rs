//! Which configuration file a run uses, so the binary works from any directory: the one
//! named by `--config`, else `config/server.toml` under the current directory, else
//! `infiniterra/server.toml` in the platform's configuration folder, else the built-in copy
//! of the shipped file.

use std::fmt;
use std::path::{Path, PathBuf};

use super::{shipped, Config, ConfigError, DEFAULT_PATH};

/// Where the configuration in use came from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ConfigOrigin {
    /// A file on disk.
    File(PathBuf),
    /// The shipped file compiled into the binary.
    BuiltIn,
}

impl fmt::Display for ConfigOrigin {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ConfigOrigin::File(path) => write!(f, "{}", path.display()),
            ConfigOrigin::BuiltIn => f.write_str(shipped::CONFIG_NAME),
        }
    }
}

/// The platform's configuration file: `$XDG_CONFIG_HOME/infiniterra/server.toml`, else
/// `~/.config/infiniterra/server.toml` (`None` when neither variable is set).
pub fn platform_path() -> Option<PathBuf> {
    let non_empty = |name: &str| std::env::var_os(name).filter(|v| !v.is_empty()).map(PathBuf::from);
    let base = non_empty("XDG_CONFIG_HOME").or_else(|| non_empty("HOME").map(|home| home.join(".config")))?;
    Some(base.join("infiniterra").join("server.toml"))
}

impl Config {
    /// Loads the configuration a run uses: `explicit` when given (an error when it cannot be
    /// read), else the first file of `config/server.toml` (under the current directory) and
    /// [`platform_path`] that exists, else the built-in copy of the shipped file.
    pub fn find(explicit: Option<&Path>) -> Result<(Config, ConfigOrigin), ConfigError> {
        if let Some(path) = explicit {
            return Ok((Config::load(path)?, ConfigOrigin::File(path.to_path_buf())));
        }
        let candidates = std::iter::once(PathBuf::from(DEFAULT_PATH)).chain(platform_path());
        for path in candidates {
            if path.is_file() {
                return Ok((Config::load(&path)?, ConfigOrigin::File(path)));
            }
        }
        Ok((Config::built_in(), ConfigOrigin::BuiltIn))
    }

    /// The shipped `config/server.toml`, as compiled into the binary.
    pub fn built_in() -> Config {
        Config::parse(shipped::CONFIG, Path::new(shipped::CONFIG_NAME))
            .unwrap_or_else(|e| panic!("the built-in configuration is invalid: {e}"))
    }
}
