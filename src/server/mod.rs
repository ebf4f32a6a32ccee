//! `infiniterra serve`: the Minecraft server (Java Edition 1.20.1, valence).
//!
//! Owns: the valence app, players joining and their spawn, streaming chunks to their views,
//! the console, start-up and shutdown. Must not touch: how terrain is made (asks
//! [`Pipeline`](crate::terrain::Pipeline) through [`chunkgen`](crate::chunkgen)) or how blocks are
//! chosen (chunk generation's), or how the world is opened ([`world::open`], shared with `pregen`).
//! Data flows one way: server → world → chunkgen → pipeline.

/// Prints a line for the owner. A closed stdout (the console piped into a process that has
/// exited) must not take the server down with a panic, so write errors are ignored.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}

mod console;
mod dimension;
mod drops;
mod edit;
mod lifecycle;
mod players;
mod pregen;
mod stream;

use std::net::{SocketAddr, TcpListener};
use std::sync::Arc;

use valence::prelude::*;

use crate::config::Config;
use crate::terrain::model_files::ModelFiles;
use crate::world::{self, OpenOptions, Opening, RulesSource, SpawnPoint, WorldError};

/// Options of `infiniterra serve` beyond the configuration file.
#[derive(Clone, Debug)]
pub struct ServeOptions {
    /// Where the biome rules come from (a folder is re-read by the console's `reload`).
    pub rules: RulesSource,
    /// Where the learned stages' models come from.
    pub models: ModelFiles,
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

impl From<WorldError> for ServeError {
    fn from(e: WorldError) -> ServeError {
        if e.is_bad_input() {
            ServeError::Input(e.into())
        } else {
            ServeError::Runtime(e.into())
        }
    }
}

/// Where players appear, as the app's resource.
#[derive(Resource, Clone, Copy, Debug)]
pub struct Spawn(pub SpawnPoint);

/// Runs the server until `stop` on the console, Ctrl-C or SIGTERM.
pub fn serve(config: &Config, options: &ServeOptions) -> Result<(), ServeError> {
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

    // `world::open` loads and checks the rules first, before the pipeline is built and
    // before the network starts: bad rules are reported at once.
    let open = OpenOptions {
        rules: options.rules.clone(),
        models: options.models.clone(),
        directory: None,
        save: config.world.save_chunks,
    };
    let opened = world::open(config, &open, &mut |step| match step {
        // Owners should see at once whether the learned stages run (and from where).
        Opening::Terrain([]) => say!("terrain: procedural layout only (engine.learned = [])"),
        Opening::Terrain(learned) => {
            say!("terrain: learned stages {} from {} on {}", learned.join(", "), options.models, config.engine.backend)
        }
        Opening::FindingSpawn => {
            say!("seed {}: finding a spawn point on land near the origin…", config.world.seed)
        }
        Opening::Spawn(spawn) => say!("spawn point: x {} y {} z {}", spawn.block.x, spawn.block.y, spawn.block.z),
        Opening::Saving(dir) => say!("saving the world to {}", dir.display()),
    })?;
    let store = opened.store.clone();
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
    .insert_resource(dimension::WorldSetup {
        config: config.clone(),
        generator: opened.generator,
        rules: Arc::new(opened.rules),
        rules_source: options.rules.clone(),
        store: store.clone(),
    })
    .insert_resource(Spawn(opened.spawn))
    .insert_resource(exit.clone());
    dimension::build(&mut app);
    players::build(&mut app, config);
    stream::build(&mut app);
    edit::build(&mut app);
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
