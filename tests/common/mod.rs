//! Support shared by the integration tests in `tests/*_e2e.rs`: where the repository is, the
//! harness that runs the real `infiniterra` binary, the test configurations it reads, the
//! protocol and Anvil clients that check it from outside, and the fixtures (rule sets,
//! generators, pipelines) the tests compute the expected world with.
//!
//! Every test file includes it with `mod common;`.

// `cargo test` compiles each `tests/*.rs` as its own crate, and none of them uses every
// helper: without this each crate would warn about the helpers the others use.
#![allow(dead_code)]

pub mod amulet;
pub mod config;
pub mod fixtures;
pub mod node;
pub mod pregen;
pub mod process;
pub mod server;

use std::net::TcpListener;
use std::path::{Path, PathBuf};

/// The repository root (the `infiniterra` crate's manifest folder).
pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A loopback port that was free a moment ago (the OS picks it; the listener is closed again).
pub fn free_port() -> u16 {
    let listener = TcpListener::bind("127.0.0.1:0").expect("bind a free port");
    listener.local_addr().expect("local address").port()
}

/// Copies the files (not the folders) of `from` into `to`, creating it.
pub fn copy_files(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).expect("create dir");
    for entry in std::fs::read_dir(from).unwrap_or_else(|e| panic!("{}: {e}", from.display())) {
        let path = entry.expect("dir entry").path();
        if path.is_file() {
            std::fs::copy(&path, to.join(path.file_name().expect("file name"))).expect("copy");
        }
    }
}
