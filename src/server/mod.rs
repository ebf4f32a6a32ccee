//! `infiniterra serve`: the Minecraft server (Java Edition 1.20.1, valence).
//!
//! Owns: the valence app, players joining and their spawn, streaming chunks to their views,
//! the console, start-up and shutdown. Must not touch: how terrain is made (asks
//! [`Pipeline`](crate::terrain::Pipeline) through [`chunkgen`](crate::chunkgen)) or how blocks are
//! chosen (chunk generation's). Data flows one way: server → chunkgen → pipeline.

/// Prints a line for the owner. A closed stdout (the console piped into a process that has
/// exited) must not take the server down with a panic, so write errors are ignored.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}

mod console;
mod lifecycle;
mod players;
mod pregen;
mod spawn;
mod stream;
mod world;

use std::net::{SocketAddr, TcpListener};
use std::path::PathBuf;
use std::sync::Arc;

use valence::prelude::*;

use crate::biome::BiomeRules;
use crate::config::Config;
use crate::chunkgen::Generator;
use crate::terrain::Pipeline;

pub use spawn::{find_spawn, SpawnPoint};
pub use world::check_biome_names;

/// Options of `infiniterra serve` beyond the configuration file.
#[derive(Clone, Debug)]
pub struct ServeOptions {
    /// Folder of biome rule files (`*.toml`), re-read by the console's `reload`.
    pub biomes_dir: PathBuf,
}

/// Why the server could not start or stopped with an error.
#[derive(Debug, thiserror::Error)]
pub enum ServeError {
    /// Bad input from the owner (biome rules, configuration): exit code 2.
    #[error("{0:#}")]
    Input(anyhow::Error),
    /// Anything else (the address is taken, a thread could not start): exit code 1.
    #[error("{0:#}")]
    Runtime(anyhow::Error),
}

/// Runs the server until `stop` on the console, Ctrl-C or SIGTERM.
pub fn serve(config: &Config, options: &ServeOptions) -> Result<(), ServeError> {
    let rules = BiomeRules::load_dir(&options.biomes_dir)
        .map_err(|e| ServeError::Input(anyhow::anyhow!("{}: {e}", options.biomes_dir.display())))?;
    world::check_biome_names(&rules).map_err(ServeError::Input)?;

    let address = config.bind_address();
    if address.port() == 0 {
        return Err(ServeError::Input(anyhow::anyhow!(
            "server.bind = \"{address}\": port 0 would pick a random port players cannot know; set one, e.g. 25565"
        )));
    }
    check_address_free(address).map_err(ServeError::Runtime)?;
    if !config.server.online_mode {
        eprintln!(
            "WARNING: offline mode (server.online_mode = false): anyone who can reach {address} can join under \
             any name, without Mojang's account check. Only expose this server to people you trust."
        );
    }

    let pipeline =
        Pipeline::build(config.world.seed, &config.terrain()).map_err(|e| ServeError::Input(anyhow::anyhow!("{e}")))?;
    // Owners should see at once whether the learned stages run (and from which folder).
    let learned = pipeline.learned_stages();
    if learned.is_empty() {
        say!("terrain: procedural layout only (engine.learned = [])");
    } else {
        say!(
            "terrain: learned stages {} from {} on {}",
            learned.join(", "),
            config.engine.models.display(),
            config.engine.backend
        );
    }
    let pipeline = Arc::new(pipeline);
    let generator = Arc::new(Generator::new(pipeline, config));
    say!("seed {}: finding a spawn point on land near the origin…", config.world.seed);
    let spawn = find_spawn(&generator, &rules);
    say!("spawn point: x {} y {} z {}", spawn.block.x, spawn.block.y, spawn.block.z);
    let store = if config.world.save_chunks {
        let dir = &config.world.directory;
        let at = [spawn.block.x, spawn.block.y, spawn.block.z];
        crate::world::prepare(dir, config.world.seed, at, crate::pregen::batch::game_type(config))
            .map_err(ServeError::Input)?;
        let store = crate::world::Store::open(dir)
            .map_err(|e| ServeError::Runtime(anyhow::anyhow!("cannot start the region writer: {e}")))?;
        say!("saving the world to {}", dir.display());
        Some(Arc::new(store))
    } else {
        None
    };
    let pregen = pregen::PregenControl::default();

    let exit = lifecycle::ExitCode::default();
    let mut app = App::new();
    app.insert_resource(NetworkSettings {
        connection_mode: if config.server.online_mode {
            ConnectionMode::Online { prevent_proxy_connections: false }
        } else {
            ConnectionMode::Offline
        },
        address,
        max_players: config.server.max_players as usize,
        ..Default::default()
    })
    .add_plugins(DefaultPlugins)
    .insert_resource(world::WorldSetup {
        config: config.clone(),
        generator,
        rules: Arc::new(rules),
        biomes_dir: options.biomes_dir.clone(),
        store: store.clone(),
    })
    .insert_resource(spawn)
    .insert_resource(exit.clone());
    world::build(&mut app);
    players::build(&mut app, config);
    stream::build(&mut app);
    console::build(&mut app);
    pregen::build(&mut app, pregen.clone());
    lifecycle::build(&mut app, address).map_err(ServeError::Runtime)?;
    app.run();
    // Save before exiting: the task records where it is (a running one resumes at the next
    // start), then every queued chunk is written and fsynced.
    if let Some(job) = pregen.job() {
        job.stop();
    }
    if let Some(store) = store {
        if let Err(e) = store.close() {
            tracing::error!("saving the world: {e}");
            return Err(ServeError::Runtime(anyhow::anyhow!("saving the world: {e}")));
        }
    }
    exit.result()
}

/// Fails early, with a clear message, when the address cannot be listened on (valence would
/// only log it and run without listening).
fn check_address_free(address: SocketAddr) -> anyhow::Result<()> {
    TcpListener::bind(address).map(drop).map_err(|e| anyhow::anyhow!("cannot listen on {address}: {e}"))
}
