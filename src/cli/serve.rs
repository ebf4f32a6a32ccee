//! `infiniterra serve`: its options, and its errors as exit codes.

use std::net::SocketAddr;
use std::path::PathBuf;

use clap::Args;

use super::{tell_sources, world_sources, Failure, Sources};
use crate::config::Config;
use crate::server::{self, ServeError, ServeOptions};

/// Options of `infiniterra serve`.
#[derive(Clone, Debug, Args)]
pub struct ServeArgs {
    /// Folder of biome rule files (`*.toml`); the console's `reload` re-reads it. Default:
    /// `biomes/` here if it exists, else the rules built into the binary.
    #[arg(long)]
    pub biomes: Option<PathBuf>,
    /// Address and port to listen on (overrides `[server] bind`), e.g. 127.0.0.1:25566.
    #[arg(long)]
    pub bind: Option<SocketAddr>,
}

/// Runs `serve` until `stop`, Ctrl-C or SIGTERM.
pub fn run(config: &Config, sources: &Sources, a: &ServeArgs) -> Result<(), Failure> {
    let mut config = config.clone();
    if let Some(bind) = a.bind {
        config.server.bind = bind.to_string();
    }
    let (rules, models) = world_sources(&config, sources, a.biomes.as_deref());
    tell_sources(sources, &rules, &models, &config);
    server::serve(&config, &ServeOptions { rules, models }).map_err(|e| match e {
        ServeError::Input(e) => Failure::input(e),
        ServeError::Runtime(e) => Failure::runtime(e),
    })
}
