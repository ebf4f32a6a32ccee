//! `infiniterra pregen`: pre-generation without a server, for large jobs and batch engines
//! (a Kubernetes Indexed Job or a Slurm array runs one shard per task; shards write
//! disjoint region files). Rerunning the same command resumes where it stopped.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use clap::Args;

use super::plan::{Plan, Shape, Shard, Task};
use super::progress::{self, Progress, State};
use super::{run_to_end, Hooks, Job};
use crate::biome::BiomeRules;
use crate::cli::Failure;
use crate::config::Config;
use crate::chunkgen::{BiomePalette, Generator};
use crate::server::{check_biome_names, find_spawn};
use crate::terrain::Pipeline;
use crate::world::{self, ChunkSource, Store};

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
    /// Folder of biome rule files.
    #[arg(long, default_value = "biomes")]
    pub biomes: PathBuf,
}

fn parse_center(s: &str) -> Result<(i64, i64), String> {
    let bad = || format!("centre {s:?}: expected X,Z in blocks, e.g. 0,0 or -512,1024");
    let (x, z) = s.split_once(',').ok_or_else(bad)?;
    Ok((x.trim().parse().map_err(|_| bad())?, z.trim().parse().map_err(|_| bad())?))
}

/// Runs (or resumes) the task; returns when it is finished, or paused by an error or Ctrl-C.
pub fn run(config: &Config, args: &PregenArgs) -> Result<(), Failure> {
    let task = Task { center_x: args.center.0, center_z: args.center.1, radius: args.radius, shape: args.shape };
    task.validate().map_err(|e| Failure::input(anyhow::anyhow!("{e}")))?;
    let rules = BiomeRules::load_dir(&args.biomes)
        .map_err(|e| Failure::input(anyhow::anyhow!("{}: {e}", args.biomes.display())))?;
    check_biome_names(&rules).map_err(Failure::input)?;
    let world_dir = args.world.clone().unwrap_or_else(|| config.world.directory.clone());
    let seed = config.world.seed;
    let progress_path = progress::path(&world_dir, args.shard);

    let saved = Progress::load(&progress_path).map_err(Failure::input)?;
    let same = |p: &Progress| p.task == task && p.shard == args.shard && p.seed == seed;
    let done = match saved {
        None => 0,
        // A finished task is history: a new task may follow it.
        Some(p) if !same(&p) && p.state == State::Finished => 0,
        Some(p) if !same(&p) => {
            return Err(Failure::input(anyhow::anyhow!(
                "{} belongs to another task ({}, shard {}, seed {}); finish it with that command, or remove \
                 the file to start this one",
                progress_path.display(),
                p.task,
                p.shard,
                p.seed
            )))
        }
        Some(p) if p.state == State::Finished => {
            println!("pregen: {task} (shard {}) is already finished: {} chunks", args.shard, p.total);
            return Ok(());
        }
        Some(p) => {
            println!("pregen: resuming after chunk {} of {}", p.done, p.total);
            p.done
        }
    };

    let pipeline = Arc::new(Pipeline::build(seed, &config.terrain()).map_err(Failure::input)?);
    let generator = Arc::new(Generator::new(pipeline, config));
    let spawn = find_spawn(&generator, &rules);
    world::prepare(&world_dir, seed, [spawn.block.x, spawn.block.y, spawn.block.z], game_type(config))
        .map_err(Failure::input)?;
    let store = Arc::new(Store::open(&world_dir).map_err(Failure::runtime)?);
    let palette = Arc::new(BiomePalette::vanilla());
    let source = Arc::new(ChunkSource::new(generator, palette, Some(store.clone())));

    let plan = Plan::new(task, args.shard);
    println!(
        "pregen: {task}, shard {}: {} chunks in {} region files, into {}",
        args.shard,
        super::thousands(plan.total()),
        plan.regions().len(),
        store.region_dir().display()
    );
    let started = Instant::now();
    let job = Job::start(
        plan,
        seed,
        store.clone(),
        progress_path.clone(),
        done,
        Hooks {
            report_every: Duration::from_secs_f64(args.report_every.max(0.0)),
            report: Box::new(|line| println!("{line}")),
            on_work: Box::new(|| {}),
        },
    )
    .map_err(|e| Failure::runtime(anyhow::anyhow!("cannot write {}: {e}", progress_path.display())))?;

    // Ctrl-C / SIGTERM pause the task; its progress is saved and the same command resumes it.
    let interrupted = Arc::new(AtomicBool::new(false));
    {
        let (job, interrupted) = (job.clone(), interrupted.clone());
        ctrlc::set_handler(move || {
            interrupted.store(true, Ordering::SeqCst);
            job.pause();
        })
        .map_err(Failure::runtime)?;
    }

    let threads = args.threads.unwrap_or(config.server.chunk_threads as usize).max(1);
    let status = run_to_end(&job, &source, &rules, threads);
    store.close().map_err(Failure::runtime)?;
    let elapsed = started.elapsed().as_secs_f64();
    match status.state {
        State::Finished => {
            println!(
                "pregen: finished {} chunks in {} ({:.0} chunks/s this run)",
                super::thousands(status.total),
                super::duration(elapsed),
                (status.total - done) as f64 / elapsed.max(1e-9)
            );
            Ok(())
        }
        _ if interrupted.load(Ordering::SeqCst) => {
            println!("pregen: paused at {}; run the same command again to continue", status.line());
            Err(Failure { code: 130, error: anyhow::anyhow!("interrupted") })
        }
        _ => Err(Failure::runtime(anyhow::anyhow!(
            "pre-generation paused: {}; fix the cause and run the same command again to continue",
            status.error.unwrap_or_else(|| "unknown error".into())
        ))),
    }
}

/// Minecraft's game type number for `[server] gamemode`.
pub fn game_type(config: &Config) -> i32 {
    match config.server.gamemode.as_str() {
        "survival" => 0,
        "adventure" => 2,
        "spectator" => 3,
        _ => 1,
    }
}
