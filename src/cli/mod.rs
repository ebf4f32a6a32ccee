//! The command line (docs/architecture.md, "The command line"): parsing, loading the configuration, dispatching to the
//! subcommands, and turning errors into exit codes (0 ok, 1 runtime failure, 2 bad usage
//! or bad input).

mod args;
mod lab;
mod maps;
mod progress;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::config::{Config, DEFAULT_PATH};

pub use args::Size;

/// infiniterra: a Minecraft world generator with learned, infinite, seed-consistent terrain.
#[derive(Debug, Parser)]
#[command(name = "infiniterra", version, about, propagate_version = true)]
pub struct Cli {
    /// Configuration file.
    #[arg(long, global = true, default_value = DEFAULT_PATH)]
    pub config: PathBuf,
    /// World seed (overrides `[world] seed`).
    #[arg(long, global = true)]
    pub seed: Option<u64>,
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run the Minecraft server (Java Edition 1.20.1).
    Serve {
        /// Folder of biome rule files (`*.toml`); the console's `reload` re-reads it.
        #[arg(long, default_value = "biomes")]
        biomes: PathBuf,
    },
    /// Draw a map of any rectangle of the world as a PNG.
    Render(maps::RenderArgs),
    /// Write raw elevation (float32 metres, .npy) of a rectangle, with a JSON sidecar.
    Export(maps::ExportArgs),
    /// Fetch or prepare the real elevation data the models learn from.
    Data(lab::DataArgs),
    /// Measure how realistic generated terrain is against real terrain.
    Eval(lab::EvalArgs),
    /// Train a stage of the model hierarchy (`--seed` sets the training seed).
    #[cfg(feature = "learned")]
    Train(lab::TrainArgs),
    /// Train a stage of the model hierarchy (needs the default `learned` feature).
    #[cfg(not(feature = "learned"))]
    Train {
        /// Any further arguments.
        #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
        rest: Vec<String>,
    },
    /// Pre-generate a region into Anvil files without a server (resumable; shardable).
    Pregen(crate::pregen::batch::PregenArgs),
    /// Measure the engine and the pipeline on this machine.
    Bench(lab::BenchArgs),
}

/// A failure with the exit code it maps to.
#[derive(Debug)]
pub struct Failure {
    /// 1 runtime failure, 2 bad usage or bad input.
    pub code: u8,
    /// What went wrong.
    pub error: anyhow::Error,
}

impl Failure {
    /// Bad usage or bad input (exit 2).
    pub fn input(error: impl Into<anyhow::Error>) -> Failure {
        Failure { code: 2, error: error.into() }
    }

    /// Anything else (exit 1).
    pub fn runtime(error: impl Into<anyhow::Error>) -> Failure {
        Failure { code: 1, error: error.into() }
    }
}

/// Parses the command line, runs it, prints any error and returns the exit code.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(f) => {
            eprintln!("error: {:#}", f.error);
            ExitCode::from(f.code)
        }
    }
}

/// Loads the configuration named on the command line, applying `--seed`.
pub fn load_config(cli: &Cli) -> Result<Config, Failure> {
    let mut config = Config::load(&cli.config).map_err(Failure::input)?;
    if let Some(seed) = cli.seed {
        config.world.seed = seed;
    }
    Ok(config)
}

/// Runs a parsed command line.
pub fn run(cli: Cli) -> Result<(), Failure> {
    match &cli.command {
        Command::Serve { biomes } => {
            let options = crate::server::ServeOptions { biomes_dir: biomes.clone() };
            crate::server::serve(&load_config(&cli)?, &options).map_err(|e| match e {
                crate::server::ServeError::Input(e) => Failure::input(e),
                crate::server::ServeError::Runtime(e) => Failure::runtime(e),
            })
        }
        Command::Render(a) => maps::render(&load_config(&cli)?, a),
        Command::Export(a) => maps::export(&load_config(&cli)?, a),
        Command::Data(a) => crate::lab::data::run(&a.into()).map_err(Failure::runtime),
        Command::Eval(a) => {
            let mut progress = progress::Progress::new("eval", "tiles");
            let report = crate::lab::eval::run(&a.into(), &mut |d, t| progress.update(d, t));
            progress.finish();
            match report {
                Ok(report) => {
                    println!("{report}\nwrote {}", a.out.display());
                    Ok(())
                }
                Err(e @ crate::lab::eval::EvalError::Input(_)) => Err(Failure::input(e)),
                Err(e) => Err(Failure::runtime(e)),
            }
        }
        #[cfg(feature = "learned")]
        Command::Train(a) => crate::lab::train::run(&a.into(), cli.seed).map_err(|e| match e {
            crate::lab::train::TrainError::Input(e) => Failure::input(e),
            crate::lab::train::TrainError::Runtime(e) => Failure::runtime(e),
        }),
        #[cfg(not(feature = "learned"))]
        Command::Train { .. } => Err(Failure::runtime(anyhow::anyhow!(
            "this binary was built without the learned-model code (--no-default-features): \
             build with the default features (`cargo run --release -- train STAGE`)"
        ))),
        Command::Pregen(a) => crate::pregen::batch::run(&load_config(&cli)?, a),
        Command::Bench(a) => crate::lab::bench::run(&load_config(&cli)?, &a.into()).map_err(Failure::runtime),
    }
}
