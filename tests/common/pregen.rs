//! `infiniterra pregen`, the batch command, and the region files it leaves.

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

use infiniterra::world::region::{RegionFile, RegionPos};

use super::fixtures::shipped_biomes;
use super::process::{self, Finished};
use super::repo;

/// `infiniterra pregen` with `config` for the square of `radius` blocks around `center` into
/// `world`, on two threads, with the shipped biome rules.
pub fn command(config: &Path, world: &Path, center: (i64, i64), radius: i64) -> Command {
    let mut command = process::infiniterra(&repo(), ["pregen".as_ref(), "--config".as_ref(), config.as_os_str()]);
    command
        .args(["--world".as_ref(), world.as_os_str()])
        .args(["--center", &format!("{},{}", center.0, center.1)])
        .args(["--radius", &radius.to_string(), "--threads", "2"])
        .arg("--biomes")
        .arg(shipped_biomes());
    command
}

/// Runs `command` to its end and returns its stdout; panics with its output unless it
/// succeeded.
pub fn run_to_end(command: Command) -> String {
    let out = Finished::run(command);
    out.assert_success("pregen");
    out.stdout_text()
}

/// Every saved chunk of a world: (chunk x, z) → its uncompressed NBT.
pub fn saved_chunks(world: &Path) -> BTreeMap<(i32, i32), Vec<u8>> {
    let mut chunks = BTreeMap::new();
    for entry in std::fs::read_dir(world.join("region")).expect("region folder") {
        let path = entry.expect("entry").path();
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or_default().to_string();
        let region = RegionPos::parse_file_name(&name).unwrap_or_else(|| panic!("stray file {name}"));
        let mut file = RegionFile::open(&path, false).expect("open region");
        for (lx, lz) in file.chunks() {
            let nbt = file.read(lx, lz).expect("readable").expect("present");
            chunks.insert((region.x * 32 + lx as i32, region.z * 32 + lz as i32), nbt);
        }
    }
    chunks
}

/// The region files' names of a world, sorted (none if it has no region folder yet).
pub fn region_files(world: &Path) -> Vec<String> {
    let Ok(entries) = std::fs::read_dir(world.join("region")) else { return Vec::new() };
    let mut names: Vec<String> =
        entries.map(|e| e.expect("entry").file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    names
}
