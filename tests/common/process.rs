//! The harness around a real `infiniterra` process: start it with any arguments in any
//! folder, read its stdout and stderr line by line as they come, wait for a line (always with
//! a deadline), type on its stdin, and collect its exit status and every line it printed.
//!
//! Tests synchronise on what the process prints or on its exit, never on sleeps. For example,
//! serving from an empty folder and stopping cleanly:
//!
//! ```text
//! let empty = tempfile::tempdir()?;
//! let bind = format!("127.0.0.1:{}", free_port());
//! let mut server = Process::start(infiniterra(empty.path(), ["serve", "--bind", &bind]));
//! server.expect_line(|l| l.contains("listening on"), START_TIMEOUT);
//! server.send("stop");
//! let done = server.finish(LINE_TIMEOUT);
//! assert!(done.success() && done.error_lines().is_empty(), "{}", done.both());
//! ```

use std::io::{BufRead, BufReader, Read, Write};
use std::path::Path;
use std::process::{Child, ChildStdin, Command, ExitStatus, Output, Stdio};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::time::{Duration, Instant};

/// Which of the process's output streams a line came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stream {
    Stdout,
    Stderr,
}

/// `infiniterra ARGS…` run in `dir`, logging at `info` (the level the tests read).
pub fn infiniterra<S: AsRef<std::ffi::OsStr>>(dir: &Path, args: impl IntoIterator<Item = S>) -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_infiniterra"));
    command.args(args).current_dir(dir).env("RUST_LOG", "info");
    command
}

/// A running process, its stdin, and every output line read from it so far.
pub struct Process {
    child: Child,
    stdin: Option<ChildStdin>,
    lines: Receiver<(Stream, String)>,
    /// Every line read so far, in the order read (the two streams interleaved as they came).
    log: Vec<(Stream, String)>,
}

impl Process {
    /// Starts `command` with all three standard streams piped.
    pub fn start(mut command: Command) -> Process {
        let mut child = command
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap_or_else(|e| panic!("start {command:?}: {e}"));
        let (tx, lines) = mpsc::channel();
        read_lines(child.stdout.take().expect("stdout"), Stream::Stdout, tx.clone());
        read_lines(child.stderr.take().expect("stderr"), Stream::Stderr, tx);
        let stdin = child.stdin.take();
        Process { child, stdin, lines, log: Vec::new() }
    }

    /// Waits for a stdout line matching `want` and returns it; panics with the output so far if
    /// none comes within `timeout` or the process ends first.
    pub fn expect_line(&mut self, want: impl Fn(&str) -> bool, timeout: Duration) -> String {
        self.expect(Stream::Stdout, want, timeout)
    }

    /// Waits for a line of `stream` matching `want` (lines of either stream are logged).
    pub fn expect(&mut self, stream: Stream, want: impl Fn(&str) -> bool, timeout: Duration) -> String {
        let deadline = Instant::now() + timeout;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.lines.recv_timeout(left) {
                Ok((from, line)) => {
                    self.log.push((from, line.clone()));
                    if from == stream && want(&line) {
                        return line;
                    }
                }
                Err(RecvTimeoutError::Timeout) => self.fail(&format!("no matching {stream:?} line within {timeout:?}")),
                Err(RecvTimeoutError::Disconnected) => self.fail(&format!("exited before a matching {stream:?} line")),
            }
        }
    }

    /// Whether a stdout line read so far matches `want`.
    pub fn seen(&self, want: impl Fn(&str) -> bool) -> bool {
        self.log.iter().any(|(from, line)| *from == Stream::Stdout && want(line))
    }

    /// Types `line` on the process's stdin.
    pub fn send(&mut self, line: &str) {
        let stdin = self.stdin.as_mut().expect("stdin open");
        writeln!(stdin, "{line}").expect("write to stdin");
        stdin.flush().expect("flush stdin");
    }

    /// Closes stdin (the process reads end of input).
    pub fn close_stdin(&mut self) {
        self.stdin = None;
    }

    /// Whether the process is still running.
    pub fn running(&mut self) -> bool {
        self.child.try_wait().expect("process state").is_none()
    }

    /// Waits until the process has closed its output and exited; panics (killing it) if that
    /// takes longer than `timeout`.
    pub fn finish(mut self, timeout: Duration) -> Finished {
        let deadline = Instant::now() + timeout;
        // Both reader threads end at end of output, which the process's exit brings: the
        // channel disconnecting is the event to wait on.
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.lines.recv_timeout(left) {
                Ok(line) => self.log.push(line),
                Err(RecvTimeoutError::Disconnected) => break,
                Err(RecvTimeoutError::Timeout) => self.fail(&format!("did not exit within {timeout:?}")),
            }
        }
        let status = self.child.wait().expect("wait for the process");
        Finished::new(status, std::mem::take(&mut self.log))
    }

    /// Kills the process (SIGKILL) and collects what it printed.
    pub fn kill(mut self) -> Finished {
        self.child.kill().expect("SIGKILL");
        self.finish(Duration::from_secs(30))
    }

    /// Kills the process and panics with `why` and every line it printed.
    pub fn fail(&mut self, why: &str) -> ! {
        let _ = self.child.kill();
        // Killed, it closes its output at once: collect the rest (bounded all the same).
        let deadline = Instant::now() + Duration::from_secs(5);
        while let Ok(line) = self.lines.recv_timeout(deadline.saturating_duration_since(Instant::now())) {
            self.log.push(line);
        }
        panic!("{why}\n{}", format_log(&self.log));
    }
}

impl Drop for Process {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Sends each line of `from` to `to`, tagged with `stream`, until end of output.
fn read_lines(from: impl Read + Send + 'static, stream: Stream, to: Sender<(Stream, String)>) {
    std::thread::spawn(move || {
        for line in BufReader::new(from).lines().map_while(Result::ok) {
            if to.send((stream, line)).is_err() {
                break;
            }
        }
    });
}

/// Both streams of a log, one after the other, for a failure message.
fn format_log(log: &[(Stream, String)]) -> String {
    let of = |stream: Stream| log.iter().filter(|(s, _)| *s == stream).map(|(_, l)| l.as_str()).collect::<Vec<_>>();
    format!("--- stdout ---\n{}\n--- stderr ---\n{}", of(Stream::Stdout).join("\n"), of(Stream::Stderr).join("\n"))
}

/// A process that has exited: its status and every line it printed.
pub struct Finished {
    pub status: ExitStatus,
    pub stdout: Vec<String>,
    pub stderr: Vec<String>,
}

impl Finished {
    fn new(status: ExitStatus, log: Vec<(Stream, String)>) -> Finished {
        let of = |stream: Stream| log.iter().filter(|(s, _)| *s == stream).map(|(_, l)| l.clone()).collect();
        Finished { status, stdout: of(Stream::Stdout), stderr: of(Stream::Stderr) }
    }

    /// Runs `command` to its end (stdin empty) and collects its output.
    pub fn run(mut command: Command) -> Finished {
        let out = command.stdin(Stdio::null()).output().unwrap_or_else(|e| panic!("run {command:?}: {e}"));
        Finished::from(out)
    }

    /// Whether it exited with status 0.
    pub fn success(&self) -> bool {
        self.status.success()
    }

    /// Its exit code (`None` when a signal ended it).
    pub fn code(&self) -> Option<i32> {
        self.status.code()
    }

    /// Its stdout, lines joined by newlines.
    pub fn stdout_text(&self) -> String {
        self.stdout.join("\n")
    }

    /// Its stderr, lines joined by newlines.
    pub fn stderr_text(&self) -> String {
        self.stderr.join("\n")
    }

    /// Lines of either stream logged at level ERROR (colour codes ignored), or saying "error:"
    /// as the CLI does when it exits on one.
    pub fn error_lines(&self) -> Vec<String> {
        self.stdout
            .iter()
            .chain(&self.stderr)
            .map(|l| strip_ansi(l))
            .filter(|l| l.split_whitespace().take(3).any(|w| w == "ERROR") || l.starts_with("error:"))
            .collect()
    }

    /// Panics with the whole output unless it exited with status 0.
    pub fn assert_success(&self, what: &str) {
        assert!(self.success(), "{what} failed: {:?}\n{}", self.status, self.both());
    }

    /// Both streams, for a failure message.
    pub fn both(&self) -> String {
        format!("--- stdout ---\n{}\n--- stderr ---\n{}", self.stdout_text(), self.stderr_text())
    }
}

impl From<Output> for Finished {
    fn from(out: Output) -> Finished {
        let lines = |bytes: &[u8]| String::from_utf8_lossy(bytes).lines().map(str::to_string).collect();
        Finished { status: out.status, stdout: lines(&out.stdout), stderr: lines(&out.stderr) }
    }
}

/// `line` without ANSI escape sequences (log levels are coloured even when piped).
pub fn strip_ansi(line: &str) -> String {
    let mut out = String::with_capacity(line.len());
    let mut chars = line.chars();
    while let Some(c) = chars.next() {
        if c == '\u{1b}' {
            // CSI: ESC [ parameters… final byte in @..~.
            if chars.next() == Some('[') {
                for c in chars.by_ref() {
                    if ('@'..='~').contains(&c) {
                        break;
                    }
                }
            }
        } else {
            out.push(c);
        }
    }
    out
}
