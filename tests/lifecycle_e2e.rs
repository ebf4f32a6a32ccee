//! The binary's life as a new user meets it: started from an empty directory (no config/,
//! models/ or biomes/ there) it serves with its built-in configuration, models and rules,
//! and a console `stop` ends it cleanly (exit 0, no error or warning logged) with the world
//! saved; a `--config` naming a missing file is refused with one message naming it.

mod common;

use std::path::Path;
use std::process::Command;
use std::time::Duration;

use common::free_port;
use common::process::{self, Finished, Process};

/// Start-up includes the spawn search with the learned core on a debug build.
const START_TIMEOUT: Duration = Duration::from_secs(600);
/// Saving and stopping after `stop`.
const STOP_TIMEOUT: Duration = Duration::from_secs(60);

/// `infiniterra ARGS…` run in `cwd`, with an empty platform configuration folder of the
/// test's own, so nothing outside `cwd` can be found.
fn infiniterra(cwd: &Path, args: &[&str]) -> Command {
    let mut command = process::infiniterra(cwd, args);
    let home = cwd.join(".home");
    std::fs::create_dir_all(&home).expect("make the home folder");
    command.env("HOME", &home).env("XDG_CONFIG_HOME", home.join(".config"));
    command
}

#[test]
fn from_an_empty_directory_it_serves_with_what_is_built_in_and_stops_cleanly() {
    let dir = tempfile::tempdir().expect("temp dir");
    let bind = format!("127.0.0.1:{}", free_port());
    let mut server = Process::start(infiniterra(dir.path(), &["serve", "--bind", &bind]));
    server.expect_line(|l| l.contains("listening on"), START_TIMEOUT);
    // It says which configuration, models and rules it runs with: the built-in ones.
    for (what, built_in) in [("config: ", "built-in"), ("models: ", "built into this binary"), ("biomes: ", "built-in")]
    {
        assert!(
            server.seen(|l| l.starts_with(what) && l.contains(built_in)),
            "no {what:?} line naming the built-in copy"
        );
    }
    assert!(server.seen(|l| l.contains(&bind)), "not listening on {bind}");

    // No player is needed to put chunks on disk: a small console pre-generation does.
    server.send("pregen start 0 0 16");
    server.expect_line(|l| l.starts_with("pregen:") && l.contains("finished"), START_TIMEOUT);

    server.send("stop");
    let done: Finished = server.finish(STOP_TIMEOUT);
    assert_eq!(done.code(), Some(0), "{}", done.both());
    let output: Vec<String> = done.both().lines().map(process::strip_ansi).collect();
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
    let out = Finished::run(infiniterra(dir.path(), &["serve", "--config", "missing.toml"]));
    let stderr = out.stderr_text();
    assert_eq!(out.code(), Some(2), "{stderr}");
    let lines: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "{stderr}");
    assert!(lines[0].contains("missing.toml"), "{stderr}");
    assert_eq!(lines[0].matches("No such file").count(), 1, "the reason is given once: {stderr}");
    assert!(!dir.path().join("world").exists(), "nothing is written");
}
