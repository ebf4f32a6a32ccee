//! Test configurations: the TOML the binary is started with, written to a test's own folder.

use std::path::{Path, PathBuf};

/// The view distance the test servers cap clients at and the test players ask for.
pub const VIEW: u8 = 4;

/// Writes `text` as `server.toml` in `dir` and returns its path.
pub fn write(dir: &Path, text: &str) -> PathBuf {
    let path = dir.join("server.toml");
    std::fs::write(&path, text).unwrap_or_else(|e| panic!("write {}: {e}", path.display()));
    path
}

/// A configuration that sets only the world seed (everything else at its default).
pub fn seed_only(seed: u64) -> String {
    format!("[world]\nseed = {seed}\n")
}

/// A test server's configuration: loopback `port`, view capped at [`VIEW`], two chunk threads,
/// a small chunk cache, world `seed`, and `world` appended to the `[world]` table (it may open
/// further tables after its own keys).
pub fn server(port: u16, seed: u64, world: &str) -> String {
    server_with(port, seed, "", world)
}

/// [`server`] with `server_keys` (lines) added to its `[server]` table.
pub fn server_with(port: u16, seed: u64, server_keys: &str, world: &str) -> String {
    format!(
        "[server]\nbind = \"127.0.0.1:{port}\"\nview_distance_cap = {VIEW}\nchunk_threads = 2\nchunk_cache = 512\n\
         {server_keys}\n[world]\nseed = {seed}\n{world}"
    )
}

/// A `[world]` key saving to `world` (a folder that can outlive any one server).
pub fn world_directory(world: &Path) -> String {
    format!("directory = {:?}\n", world.display().to_string())
}

/// `[engine]` running the `learned` stages with the shipped weights of `models`.
pub fn learned_engine(learned: &[&str], models: &Path) -> String {
    format!("\n[engine]\nlearned = {learned:?}\nmodels = {:?}\n", models.display().to_string())
}
