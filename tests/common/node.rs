//! The Minecraft protocol clients of `tests/e2e/` (mineflayer, pinned in its
//! `package-lock.json`): each script connects to a port, does its part and prints one JSON
//! line.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use serde_json::Value;

use super::repo;

/// The scripts' folder, with its packages installed once per test binary if `scripts/test` has
/// not already.
pub fn clients() -> &'static Path {
    static READY: OnceLock<PathBuf> = OnceLock::new();
    READY.get_or_init(|| {
        let dir = repo().join("tests/e2e");
        if !dir.join("node_modules/mineflayer/package.json").is_file() {
            let status = Command::new("npm")
                .args(["ci", "--no-audit", "--no-fund", "--loglevel=error", "--prefix"])
                .arg(&dir)
                .status()
                .expect("npm is needed for the end-to-end tests");
            assert!(status.success(), "npm ci --prefix tests/e2e failed");
        }
        dir
    })
}

/// Runs `node tests/e2e/SCRIPT PORT ARGS…` and parses the last JSON line it printed; the error
/// says what it printed instead.
pub fn run(script: &str, port: u16, args: &[String]) -> Result<Value, String> {
    let out = Command::new("node").arg(clients().join(script)).arg(port.to_string()).args(args).output();
    let out = out.expect("node is needed for the end-to-end tests");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let line = stdout.lines().rev().find(|l| l.starts_with('{')).unwrap_or("");
    serde_json::from_str::<Value>(line).map_err(|_| {
        format!(
            "{script} printed no JSON (exit {:?})\nstdout: {stdout}\nstderr: {}",
            out.status,
            String::from_utf8_lossy(&out.stderr)
        )
    })
}
