//! `infiniterra pregen`: its options, and its errors as exit codes.

use std::path::PathBuf;
use std::time::Duration;

use clap::Args;

use super::{tell_sources, world_sources, Failure, Sources};
use crate::config::Config;
use crate::pregen::batch::{self, Batch, PregenError};
use crate::pregen::{Shape, Shard, Task};

/// Options of `infiniterra pregen`.
#[derive(Clone, Debug, Args)]
pub struct PregenArgs {
    /// Centre block, `X,Z`.
    #[arg(long, value_parser = parse_center, allow_hyphen_values = true)]
    pub center: (i64, i64),
    /// Radius in blocks.
    #[arg(long)]
    pub radius: i64,
    /// Outline: square or circle.
    #[arg(long, default_value = "square")]
    pub shape: Shape,
    /// World folder (default: `[world] directory` of the configuration).
    #[arg(long)]
    pub world: Option<PathBuf>,
    /// Only this shard, `i/N` (0-based): regions are dealt round-robin to N shards.
    #[arg(long, default_value = "0/1")]
    pub shard: Shard,
    /// Generating threads (default: `[server] chunk_threads`).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Seconds between progress lines.
    #[arg(long, default_value_t = 5.0)]
    pub report_every: f64,
    /// Folder of biome rule files (default: `biomes/` here if it exists, else the built-in rules).
    #[arg(long)]
    pub biomes: Option<PathBuf>,
}

fn parse_center(s: &str) -> Result<(i64, i64), String> {
    let bad = || format!("centre {s:?}: expected X,Z in blocks, e.g. 0,0 or -512,1024");
    let (x, z) = s.split_once(',').ok_or_else(bad)?;
    Ok((x.trim().parse().map_err(|_| bad())?, z.trim().parse().map_err(|_| bad())?))
}

/// Runs `pregen`: 0 finished, 2 bad input, 130 interrupted (resumable), 1 anything else.
pub fn run(config: &Config, sources: &Sources, a: &PregenArgs) -> Result<(), Failure> {
    let (rules, models) = world_sources(config, sources, a.biomes.as_deref());
    tell_sources(sources, &rules, &models, config);
    let batch = Batch {
        task: Task { center_x: a.center.0, center_z: a.center.1, radius: a.radius, shape: a.shape },
        world: a.world.clone(),
        shard: a.shard,
        threads: a.threads,
        report_every: Duration::from_secs_f64(a.report_every.max(0.0)),
        rules,
        models,
    };
    batch::run(config, &batch).map_err(|e| match e {
        PregenError::Interrupted => Failure { code: 130, error: e.into() },
        e if e.is_bad_input() => Failure::input(e),
        e => Failure::runtime(e),
    })
}
