//! The server console: commands typed on standard input, answered on standard output.
//!
//! A thread reads lines into a channel that an Update system drains, so the tick never waits
//! on the terminal. End of input (a service or CI without a terminal) just ends the reader:
//! the server keeps running.

use std::io::BufRead;
use std::sync::mpsc::{self, Receiver};
use std::sync::{Arc, Mutex, PoisonError};

use valence::prelude::*;

use super::dimension::WorldSetup;
use super::lifecycle::StopRequest;
use super::stream::Streamer;
use crate::world::RulesSource;

const HELP: &str = "commands:
  help     this list
  status   players, chunk generation, queue, cache and memory
  reload   re-read the biome rules (on error the current rules stay)
  seed     the world seed
  stop     disconnect everyone, save and stop the server
";

#[derive(Resource)]
struct ConsoleInput(Mutex<Receiver<String>>);

/// Starts the reader thread and adds the command system.
pub fn build(app: &mut App) {
    let (lines, input) = mpsc::channel();
    let reader = std::thread::Builder::new().name("console".into()).spawn(move || {
        for line in std::io::stdin().lock().lines() {
            let Ok(line) = line else { break };
            if lines.send(line).is_err() {
                break;
            }
        }
    });
    if let Err(e) = reader {
        tracing::warn!("console disabled: cannot start its thread: {e}");
    }
    app.insert_resource(ConsoleInput(Mutex::new(input))).add_systems(Update, run_commands);
}

fn run_commands(
    input: Res<ConsoleInput>,
    mut setup: ResMut<WorldSetup>,
    streamer: Option<ResMut<Streamer>>,
    stop: Res<StopRequest>,
    clients: Query<&Username, With<Client>>,
    mut pregen: ResMut<super::pregen::PregenControl>,
) {
    let lines: Vec<String> = input.0.lock().unwrap_or_else(PoisonError::into_inner).try_iter().collect();
    let mut streamer = streamer;
    for line in lines {
        let command = line.trim();
        let is_pregen = command.split_whitespace().next() == Some("pregen");
        if !is_pregen && !command.is_empty() {
            pregen.forget_confirmation();
        }
        match command {
            "" => {}
            "help" => say!("{HELP}{}", super::pregen::HELP),
            "seed" => say!("seed {}", setup.config.world.seed),
            "stop" => stop.request(),
            "status" => {
                print_status(streamer.as_deref_mut(), &clients);
                if let Some(job) = pregen.job() {
                    say!("{}", job.status().line());
                }
            }
            "reload" => reload(&mut setup, streamer.as_deref_mut()),
            other if is_pregen => {
                let words: Vec<&str> = other.split_whitespace().skip(1).collect();
                super::pregen::command(&words, &setup, &mut pregen, streamer.as_deref());
            }
            other => say!("unknown command {other:?}: type `help` for the list"),
        }
    }
}

fn print_status(streamer: Option<&mut Streamer>, clients: &Query<&Username, With<Client>>) {
    let names: Vec<&str> = clients.iter().map(|u| u.0.as_str()).collect();
    match names.len() {
        0 => say!("players: 0"),
        n => say!("players: {n} ({})", names.join(", ")),
    }
    if let Some(s) = streamer {
        let st = s.status();
        say!(
            "chunks: {:.1} generated/s (last 10 s), {} generated, {} failed, mean {:.1} ms each",
            st.per_second,
            st.generated,
            st.failed,
            st.mean_build.as_secs_f64() * 1000.0
        );
        say!("queue: {} waiting, {} in flight; {} loaded, {} cached", st.queued, st.in_flight, st.loaded, st.cached);
    }
    match resident_bytes() {
        Some(bytes) => say!("memory: {:.1} MiB resident", bytes as f64 / (1024.0 * 1024.0)),
        None => say!("memory: unknown (no /proc/self/statm)"),
    }
}

/// Re-reads the rules; bad rules are reported and the current ones stay.
fn reload(setup: &mut WorldSetup, streamer: Option<&mut Streamer>) {
    if setup.rules_source == RulesSource::BuiltIn {
        say!(
            "reload: the biome rules are the ones built into the binary, so there is nothing to re-read; \
             start with `serve --biomes DIR` (or a biomes/ folder here) to edit them"
        );
        return;
    }
    match setup.rules_source.load() {
        Ok(rules) => {
            let rules = Arc::new(rules);
            say!("reloaded {} biome rules from {}; new chunks use them", rules.rule_count(), setup.rules_source);
            setup.rules = rules.clone();
            if let Some(s) = streamer {
                s.set_rules(rules);
            }
        }
        Err(e) => say!("reload failed, keeping the current rules: {e:#}"),
    }
}

/// Resident memory of this process, bytes (Linux).
fn resident_bytes() -> Option<u64> {
    let statm = std::fs::read_to_string("/proc/self/statm").ok()?;
    let pages: u64 = statm.split_whitespace().nth(1)?.parse().ok()?;
    // The page size is 4 KiB on every Linux this runs on (x86-64, aarch64 default).
    Some(pages * 4096)
}
