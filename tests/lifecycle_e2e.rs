//! The binary's life as a new user meets it: started from an empty directory (no config/,
//! models/ or biomes/ there) it serves with its built-in configuration, models and rules,
//! and a console `stop` ends it cleanly (exit 0, no error or warning logged) with the world
//! saved; a `--config` naming a missing file is refused with one message naming it.
//!
//! Self-contained helpers for now (they move to tests/common with the other harnesses).

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpListener;
use std::path::Path;
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Start-up includes the spawn search with the learned core on a debug build.
const START_TIMEOUT: Duration = Duration::from_secs(600);
/// Saving and stopping after `stop`.
const STOP_TIMEOUT: Duration = Duration::from_secs(60);

/// The binary, run in `cwd` with no configuration to find outside it.
fn infiniterra(cwd: &Path) -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_infiniterra"));
    // The platform configuration folder is an empty one of the test's own.
    let home = cwd.join(".home");
    std::fs::create_dir_all(&home).expect("make the home folder");
    command.current_dir(cwd).env("HOME", &home).env("XDG_CONFIG_HOME", home.join(".config")).env("RUST_LOG", "info");
    command
}

fn free_port() -> u16 {
    let listener = TcpListener::bind("127.0.0.1:0").expect("bind a free port");
    listener.local_addr().expect("local address").port()
}

/// A running server: its console, and every line it writes (stdout and stderr) as it comes.
struct Running {
    child: Child,
    stdin: Option<ChildStdin>,
    lines: Receiver<String>,
    readers: Vec<JoinHandle<()>>,
    seen: Vec<String>,
}

impl Running {
    fn start(mut command: Command) -> Running {
        let mut child = command
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("start infiniterra");
        let (tx, lines) = mpsc::channel();
        let stdout: Box<dyn Read + Send> = Box::new(child.stdout.take().expect("stdout"));
        let stderr: Box<dyn Read + Send> = Box::new(child.stderr.take().expect("stderr"));
        let readers = [stdout, stderr]
            .into_iter()
            .map(|stream| {
                let tx = tx.clone();
                std::thread::spawn(move || {
                    for line in BufReader::new(stream).lines().map_while(Result::ok) {
                        if tx.send(line).is_err() {
                            break;
                        }
                    }
                })
            })
            .collect();
        let stdin = child.stdin.take();
        Running { child, stdin, lines, readers, seen: Vec::new() }
    }

    /// Waits for an output line containing `text`.
    fn expect(&mut self, text: &str, timeout: Duration) {
        self.expect_line_where(|l| l.contains(text), timeout);
    }

    /// Waits for an output line matching `want`.
    fn expect_line_where(&mut self, want: impl Fn(&str) -> bool, timeout: Duration) {
        let deadline = Instant::now() + timeout;
        loop {
            match self.lines.recv_timeout(deadline.saturating_duration_since(Instant::now())) {
                Ok(line) => {
                    let found = want(&line);
                    self.seen.push(line);
                    if found {
                        return;
                    }
                }
                Err(RecvTimeoutError::Timeout) => self.fail("the line awaited did not come in time"),
                Err(RecvTimeoutError::Disconnected) => self.fail("exited before the line awaited"),
            }
        }
    }

    fn command(&mut self, line: &str) {
        let stdin = self.stdin.as_mut().expect("console open");
        writeln!(stdin, "{line}").and_then(|()| stdin.flush()).expect("write to the console");
    }

    /// Types `stop` and waits until the process has closed its output and exited; returns its
    /// exit code and every line it wrote.
    fn stop(mut self) -> (Option<i32>, Vec<String>) {
        self.command("stop");
        // Both output streams end when the process exits: the end of the lines is the event.
        let deadline = Instant::now() + STOP_TIMEOUT;
        loop {
            match self.lines.recv_timeout(deadline.saturating_duration_since(Instant::now())) {
                Ok(line) => self.seen.push(line),
                Err(RecvTimeoutError::Disconnected) => break,
                Err(RecvTimeoutError::Timeout) => self.fail("still running after `stop`"),
            }
        }
        for reader in std::mem::take(&mut self.readers) {
            reader.join().expect("output reader");
        }
        let status = self.child.wait().expect("wait for the server");
        (status.code(), std::mem::take(&mut self.seen))
    }

    fn fail(&mut self, why: &str) -> ! {
        let _ = self.child.kill();
        panic!("infiniterra: {why}; output so far:\n{}", self.seen.join("\n"));
    }
}

impl Drop for Running {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

#[test]
fn from_an_empty_directory_it_serves_with_what_is_built_in_and_stops_cleanly() {
    let dir = tempfile::tempdir().expect("temp dir");
    let bind = format!("127.0.0.1:{}", free_port());
    let mut command = infiniterra(dir.path());
    command.arg("serve").arg("--bind").arg(&bind);
    let mut server = Running::start(command);
    server.expect("listening on", START_TIMEOUT);
    // It says which configuration, models and rules it runs with: the built-in ones.
    for (what, built_in) in [("config: ", "built-in"), ("models: ", "built into this binary"), ("biomes: ", "built-in")]
    {
        assert!(
            server.seen.iter().any(|l| l.starts_with(what) && l.contains(built_in)),
            "no {what:?} line naming the built-in copy: {:#?}",
            server.seen
        );
    }
    assert!(server.seen.iter().any(|l| l.contains(&bind)), "not listening on {bind}: {:#?}", server.seen);

    // No player is needed to put chunks on disk: a small console pre-generation does.
    server.command("pregen start 0 0 16");
    server.expect_line_where(|l| l.starts_with("pregen:") && l.contains("finished"), START_TIMEOUT);

    let (code, output) = server.stop();
    assert_eq!(code, Some(0), "{output:#?}");
    // The offline-mode notice is the configuration's documented start-up warning, not a
    // failure; anything else marked as an error or a warning is.
    let bad: Vec<&String> = output
        .iter()
        .filter(|l| l.contains("ERROR") || l.contains("WARN"))
        .filter(|l| !l.starts_with("WARNING: offline mode"))
        .collect();
    assert!(bad.is_empty(), "a clean start and stop logged {bad:#?}\nall output: {output:#?}");

    let world = dir.path().join("world");
    assert!(world.join("level.dat").is_file(), "no level.dat in {}", world.display());
    let regions: Vec<_> = std::fs::read_dir(world.join("region"))
        .expect("a region folder")
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_string_lossy().ends_with(".mca"))
        .collect();
    assert!(!regions.is_empty(), "no region files saved");
    for leftover in ["config", "models", "biomes"] {
        assert!(!dir.path().join(leftover).exists(), "{leftover}/ was created");
    }
}

#[test]
fn a_missing_config_file_is_refused_with_one_message_naming_it() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = infiniterra(dir.path())
        .args(["serve", "--config", "missing.toml"])
        .stdin(Stdio::null())
        .output()
        .expect("run infiniterra");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    let lines: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "{stderr}");
    assert!(lines[0].contains("missing.toml"), "{stderr}");
    assert_eq!(lines[0].matches("No such file").count(), 1, "the reason is given once: {stderr}");
    assert!(!dir.path().join("world").exists(), "nothing is written");
}
