//! Amulet (PyPI `amulet-core`, pinned in `tests/anvil/requirements.txt`): an Anvil reader
//! that shares no code with ours, run through `tests/anvil/read_world.py`.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use serde_json::Value;
use valence::prelude::BlockState;

use super::repo;

/// The Python with Amulet that `scripts/test` installs (`INFINITERRA_PYTHON`), or the same
/// install, done here when a test runs alone.
pub fn python() -> PathBuf {
    if let Some(python) = std::env::var_os("INFINITERRA_PYTHON") {
        return PathBuf::from(python);
    }
    let out = Command::new("bash").arg(repo().join("scripts/pyenv")).output().expect("run scripts/pyenv");
    assert!(out.status.success(), "scripts/pyenv failed: {}", String::from_utf8_lossy(&out.stderr));
    PathBuf::from(String::from_utf8_lossy(&out.stdout).trim())
}

/// Asks Amulet for the block and biome at each `[x, y, z]` of `positions` in the world saved in
/// `world`; returns the reader's JSON report (`{"positions": [...]}`, one entry per position).
pub fn read_world(world: &Path, positions: Vec<Value>) -> Value {
    let mut child = Command::new(python())
        .arg(repo().join("tests/anvil/read_world.py"))
        .arg(world)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run the Amulet reader");
    child
        .stdin
        .take()
        .expect("stdin")
        .write_all(Value::Array(positions).to_string().as_bytes())
        .expect("send positions");
    let out = child.wait_with_output().expect("Amulet reader");
    assert!(out.status.success(), "Amulet reader failed: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).expect("JSON from the Amulet reader")
}

/// "minecraft:name[key=value,…]" with properties sorted, as the Amulet script prints blocks.
pub fn block_name(state: BlockState) -> String {
    let kind = state.to_kind();
    let mut props: Vec<(String, String)> = kind
        .props()
        .iter()
        .filter_map(|&p| state.get(p).map(|v| (p.to_str().to_string(), v.to_str().to_string())))
        .collect();
    props.sort();
    let mut name = format!("minecraft:{}", kind.to_str());
    if !props.is_empty() {
        let list: Vec<String> = props.into_iter().map(|(k, v)| format!("{k}={v}")).collect();
        name.push_str(&format!("[{}]", list.join(",")));
    }
    name
}

/// Amulet's census of chunks `from..=to` (chunk x, z) of the world saved in `world`
/// (`tests/anvil/census.py`): ore blocks by kind with their heights, cave air, lava and water
/// under the ground.
pub fn census(world: &Path, from: (i32, i32), to: (i32, i32)) -> Value {
    let out = Command::new(python())
        .arg(repo().join("tests/anvil/census.py"))
        .arg(world)
        .args([from.0, from.1, to.0, to.1].map(|v| v.to_string()))
        .output()
        .expect("run the Amulet census");
    assert!(out.status.success(), "Amulet census failed: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).expect("JSON from the Amulet census")
}
