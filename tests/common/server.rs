//! A test server: `infiniterra serve` on a free loopback port with a configuration written to
//! its own temporary folder, its console, and the protocol clients that join it.

use std::path::Path;
use std::time::Duration;

use infiniterra::config::Config;
use serde_json::Value;

use super::config::{self, VIEW};
use super::process::{self, Finished, Process};
use super::{free_port, node, repo};

/// Start-up includes building the pipeline and searching a spawn point in a debug build.
pub const START_TIMEOUT: Duration = Duration::from_secs(180);
/// The longest wait for one answer on the console, or for the exit after `stop`.
pub const LINE_TIMEOUT: Duration = Duration::from_secs(30);

/// A running server and its console.
pub struct Server {
    pub process: Process,
    pub port: u16,
    /// The configuration it was started with.
    pub config: Config,
    /// Holds the configuration file (and the world, unless the test put it elsewhere).
    pub dir: tempfile::TempDir,
}

impl Server {
    /// Starts the server with rules from `biomes` and world `seed`, saving to a fresh world
    /// folder, and waits for "listening on".
    pub fn start(biomes: &Path, seed: u64) -> Server {
        let dir = tempfile::tempdir().expect("temp dir");
        let world = config::world_directory(&dir.path().join("world"));
        Server::start_in(biomes, seed, dir, &world)
    }

    /// Starts the server with `world` appended to the `[world]` table of its configuration (see
    /// [`config::server`]), and waits for "listening on".
    pub fn start_with(biomes: &Path, seed: u64, world: &str) -> Server {
        Server::start_in(biomes, seed, tempfile::tempdir().expect("temp dir"), world)
    }

    /// [`Server::start_with`], with `server_keys` (lines) added to the `[server]` table.
    pub fn start_with_server_keys(biomes: &Path, seed: u64, server_keys: &str, world: &str) -> Server {
        Server::start_configured(biomes, seed, tempfile::tempdir().expect("temp dir"), server_keys, world)
    }

    fn start_in(biomes: &Path, seed: u64, dir: tempfile::TempDir, world: &str) -> Server {
        Server::start_configured(biomes, seed, dir, "", world)
    }

    fn start_configured(biomes: &Path, seed: u64, dir: tempfile::TempDir, server_keys: &str, world: &str) -> Server {
        let port = free_port();
        let config_path = config::write(dir.path(), &config::server_with(port, seed, server_keys, world));
        let config = Config::load(&config_path).expect("test config loads");
        let args =
            ["serve".as_ref(), "--config".as_ref(), config_path.as_os_str(), "--biomes".as_ref(), biomes.as_os_str()];
        let process = Process::start(process::infiniterra(&repo(), args));
        let mut server = Server { process, port, config, dir };
        server.expect_line(|l| l.contains("listening on"), START_TIMEOUT);
        server
    }

    /// Waits for a stdout line matching `want`; panics with the server's output on timeout.
    pub fn expect_line(&mut self, want: impl Fn(&str) -> bool, timeout: Duration) -> String {
        self.process.expect_line(want, timeout)
    }

    /// Whether a stdout line read so far matches `want`.
    pub fn stdout_seen(&self, want: impl Fn(&str) -> bool) -> bool {
        self.process.seen(want)
    }

    /// Types a console command.
    pub fn command(&mut self, command: &str) {
        self.process.send(command);
    }

    /// `stop`, then waits for the process to exit and returns its status and output.
    pub fn stop(mut self) -> Finished {
        self.command("stop");
        self.process.finish(LINE_TIMEOUT)
    }

    /// Kills the server and panics with `why` and its output.
    pub fn fail(&mut self, why: &str) -> ! {
        self.process.fail(&format!("server: {why}"))
    }

    /// Runs `node tests/e2e/SCRIPT PORT ARGS…` against the server and parses its JSON line.
    pub fn node(&mut self, script: &str, args: &[String]) -> Value {
        match node::run(script, self.port, args) {
            Ok(report) => report,
            Err(why) => self.fail(&why),
        }
    }

    /// A player joins and reports (`tests/e2e/probe.js`); panics unless it spawned.
    pub fn probe(&mut self, name: &str, extra: &[String]) -> Value {
        let mut args = vec!["--name".into(), name.into(), "--view".into(), VIEW.to_string()];
        args.extend_from_slice(extra);
        let report = self.node("probe.js", &args);
        if report["ok"] != Value::Bool(true) {
            self.fail(&format!("player {name} failed: {report}"));
        }
        report
    }

    /// `status`, answered with the numbers of its `queue:` line.
    pub fn queue(&mut self) -> (u64, u64, u64, u64) {
        self.command("status");
        let line = self.expect_line(|l| l.starts_with("queue:"), LINE_TIMEOUT);
        queue_numbers(&line)
    }
}

/// The numbers of the console's `queue:` line: (waiting, in flight, loaded, cached).
pub fn queue_numbers(line: &str) -> (u64, u64, u64, u64) {
    let numbers: Vec<u64> = line
        .split(|c: char| !c.is_ascii_digit())
        .filter(|s| !s.is_empty())
        .map(|s| s.parse().expect("number"))
        .collect();
    assert_eq!(numbers.len(), 4, "{line}");
    (numbers[0], numbers[1], numbers[2], numbers[3])
}
