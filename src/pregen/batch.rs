//! `infiniterra pregen`: pre-generation without a server, for large jobs and batch engines
//! (a Kubernetes Indexed Job or a Slurm array runs one shard per task; shards write
//! disjoint region files). Rerunning the same command resumes where it stopped.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use super::plan::{Plan, Shard, Task};
use super::progress::{self, Progress, State};
use super::{run_to_end, Hooks, Job};
use crate::chunkgen::BiomePalette;
use crate::config::Config;
use crate::terrain::model_files::ModelFiles;
use crate::world::{self, ChunkSource, OpenOptions, RulesSource, WorldError};

/// What one batch run does (the command line's options, parsed).
#[derive(Clone, Debug)]
pub struct Batch {
    /// The area.
    pub task: Task,
    /// World folder (`None`: `[world] directory` of the configuration).
    pub world: Option<PathBuf>,
    /// Only this shard of the task's region files.
    pub shard: Shard,
    /// Generating threads (`None`: `[server] chunk_threads`).
    pub threads: Option<usize>,
    /// Time between progress lines.
    pub report_every: Duration,
    /// Where the biome rules come from.
    pub rules: RulesSource,
    /// Where the learned stages' models come from.
    pub models: ModelFiles,
}

/// Why a batch run did not finish.
#[derive(Debug, thiserror::Error)]
pub enum PregenError {
    /// The task or the progress file given is unusable (exit code 2).
    #[error("{0}")]
    Input(String),
    /// The world cannot be opened (rules, models, world folder…).
    #[error(transparent)]
    World(#[from] WorldError),
    /// Ctrl-C or SIGTERM paused the task; its progress is saved.
    #[error("interrupted")]
    Interrupted,
    /// Anything else: a write failed, a thread could not start (exit code 1).
    #[error("{0}")]
    Runtime(String),
}

impl PregenError {
    /// True when the owner's input is at fault (exit code 2), not the machine.
    pub fn is_bad_input(&self) -> bool {
        match self {
            PregenError::Input(_) => true,
            PregenError::World(e) => e.is_bad_input(),
            PregenError::Interrupted | PregenError::Runtime(_) => false,
        }
    }
}

/// Runs (or resumes) the task; returns when it is finished, or paused by an error or Ctrl-C.
pub fn run(config: &Config, batch: &Batch) -> Result<(), PregenError> {
    let task = batch.task;
    task.validate().map_err(PregenError::Input)?;
    let world_dir = batch.world.clone().unwrap_or_else(|| config.world.directory.clone());
    let seed = config.world.seed;
    let progress_path = progress::path(&world_dir, batch.shard);

    let saved = Progress::load(&progress_path).map_err(|e| PregenError::Input(format!("{e:#}")))?;
    let same = |p: &Progress| p.task == task && p.shard == batch.shard && p.seed == seed;
    let done = match saved {
        None => 0,
        // A finished task is history: a new task may follow it.
        Some(p) if !same(&p) && p.state == State::Finished => 0,
        Some(p) if !same(&p) => {
            return Err(PregenError::Input(format!(
                "{} belongs to another task ({}, shard {}, seed {}); finish it with that command, or remove \
                 the file to start this one",
                progress_path.display(),
                p.task,
                p.shard,
                p.seed
            )))
        }
        Some(p) if p.state == State::Finished => {
            println!("pregen: {task} (shard {}) is already finished: {} chunks", batch.shard, p.total);
            return Ok(());
        }
        Some(p) => {
            println!("pregen: resuming after chunk {} of {}", p.done, p.total);
            p.done
        }
    };

    let options = OpenOptions {
        rules: batch.rules.clone(),
        models: batch.models.clone(),
        directory: Some(world_dir.clone()),
        save: true,
    };
    let opened = world::open(config, &options, &mut |_| {})?;
    let store = opened.store.clone().ok_or_else(|| PregenError::Runtime("the region store is not open".into()))?;
    let rules = opened.rules;
    let palette = Arc::new(BiomePalette::vanilla());
    let source = Arc::new(ChunkSource::new(opened.generator, palette, Some(store.clone())));

    let plan = Plan::new(task, batch.shard);
    println!(
        "pregen: {task}, shard {}: {} chunks in {} region files, into {}",
        batch.shard,
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
            report_every: batch.report_every,
            report: Box::new(|line| println!("{line}")),
            on_work: Box::new(|| {}),
        },
    )
    .map_err(|e| PregenError::Runtime(format!("cannot write {}: {e}", progress_path.display())))?;

    // Ctrl-C / SIGTERM pause the task; its progress is saved and the same command resumes it.
    let interrupted = Arc::new(AtomicBool::new(false));
    {
        let (job, interrupted) = (job.clone(), interrupted.clone());
        ctrlc::set_handler(move || {
            interrupted.store(true, Ordering::SeqCst);
            job.pause();
        })
        .map_err(|e| PregenError::Runtime(format!("cannot handle Ctrl-C: {e}")))?;
    }

    let threads = batch.threads.unwrap_or(config.server.chunk_threads as usize).max(1);
    let status = run_to_end(&job, &source, &rules, threads);
    store.close().map_err(|e| PregenError::Runtime(format!("saving the world: {e}")))?;
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
            Err(PregenError::Interrupted)
        }
        _ => Err(PregenError::Runtime(format!(
            "pre-generation paused: {}; fix the cause and run the same command again to continue",
            status.error.unwrap_or_else(|| "unknown error".into())
        ))),
    }
}
