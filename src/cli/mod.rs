//! The command line (docs/architecture.md, "The command line"): parsing, loading the configuration, dispatching to the
//! subcommands, and turning errors into exit codes (0 ok, 1 runtime failure, 2 bad usage
//! or bad input).

mod args;
mod lab;
mod maps;
mod pregen;
mod progress;
mod serve;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::config::{shipped, Config, ConfigOrigin};
use crate::terrain::model_files::ModelFiles;
use crate::world::RulesSource;

pub use args::Size;
pub use pregen::PregenArgs;
pub use serve::ServeArgs;

/// infiniterra: a Minecraft world generator with learned, infinite, seed-consistent terrain.
#[derive(Debug, Parser)]
#[command(name = "infiniterra", version, about, propagate_version = true)]
pub struct Cli {
    /// Configuration file (default: `config/server.toml` here, else
    /// `~/.config/infiniterra/server.toml`, else the built-in configuration).
    #[arg(long, global = true)]
    pub config: Option<PathBuf>,
    /// Folder of the learned stages' models (default: `[engine] models` if it holds them, else
    /// the models built into the binary).
    #[arg(long, global = true)]
    pub models: Option<PathBuf>,
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
    Serve(serve::ServeArgs),
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
    Pregen(pregen::PregenArgs),
    /// Measure the engine and the pipeline on this machine.
    Bench(lab::BenchArgs),
    /// Measure a region's rivers and lakes against real Earth's (docs/water.md).
    Water(maps::WaterArgs),
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

/// Where this run's configuration came from (the models and rules are settled per command).
#[derive(Clone, Debug)]
pub struct Sources {
    /// The configuration file, or the built-in one.
    pub config: ConfigOrigin,
    /// `--models`, if given.
    pub models: Option<PathBuf>,
}

/// Loads the configuration the command line names (or finds it), applying `--seed` and
/// `--models`.
pub fn load_config(cli: &Cli) -> Result<(Config, Sources), Failure> {
    let (mut config, origin) = Config::find(cli.config.as_deref()).map_err(Failure::input)?;
    if let Some(seed) = cli.seed {
        config.world.seed = seed;
    }
    if let Some(models) = &cli.models {
        // Tools that read `engine.models` themselves (bench, eval) see `--models` too.
        config.engine.models = models.clone();
    }
    Ok((config, Sources { config: origin, models: cli.models.clone() }))
}

/// The models and biome rules a product command uses: `--models` / `--biomes` when given;
/// else the configured models folder, or `biomes/` here, when they exist; else the copies
/// built into the binary. An owner who points `[engine] models` elsewhere gets that folder
/// or an error naming it, never a silent substitute.
fn world_sources(config: &Config, sources: &Sources, biomes: Option<&Path>) -> (RulesSource, ModelFiles) {
    let rules = match biomes {
        Some(dir) => RulesSource::Dir(dir.to_path_buf()),
        None if Path::new("biomes").is_dir() => RulesSource::Dir(PathBuf::from("biomes")),
        None => RulesSource::BuiltIn,
    };
    let dir = ModelFiles::Dir(config.engine.models.clone());
    let default_dir = config.engine.models == crate::terrain::settings::EngineSettings::default().models;
    let holds_manifests = config.engine.learned.iter().all(|stage| dir.has(Path::new(&format!("{stage}.json"))));
    let models = if sources.models.is_some() || !default_dir || holds_manifests { dir } else { shipped::models() };
    (rules, models)
}

/// Tells the owner which configuration, models and biome rules this run uses.
fn tell_sources(sources: &Sources, rules: &RulesSource, models: &ModelFiles, config: &Config) {
    println!("config: {}", sources.config);
    if config.engine.learned.is_empty() {
        println!("models: none needed (engine.learned = [])");
    } else {
        println!("models: {models}");
    }
    println!("biomes: {rules}");
}

/// Runs a parsed command line.
pub fn run(cli: Cli) -> Result<(), Failure> {
    match &cli.command {
        Command::Serve(a) => {
            let (config, sources) = load_config(&cli)?;
            serve::run(&config, &sources, a)
        }
        Command::Render(a) => {
            let (config, sources) = load_config(&cli)?;
            maps::render(&config, &sources, a)
        }
        Command::Export(a) => {
            let (config, sources) = load_config(&cli)?;
            maps::export(&config, &sources, a)
        }
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
        Command::Pregen(a) => {
            let (config, sources) = load_config(&cli)?;
            pregen::run(&config, &sources, a)
        }
        Command::Bench(a) => crate::lab::bench::run(&load_config(&cli)?.0, &a.into()).map_err(Failure::runtime),
        Command::Water(a) => {
            let (config, sources) = load_config(&cli)?;
            maps::water(&config, &sources, a)
        }
    }
}
