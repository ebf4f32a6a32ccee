//! The world a run plays in: opening it ([`open`]: rules, generator, spawn point, `level.dat`,
//! store — the same for `serve` and `pregen`), and the saved world: Anvil region files, the
//! chunk ⇄ NBT codec, `level.dat`, the store that loads chunks from disk and writes new ones
//! off the main thread, and the chunk source that puts the store in front of the generator.
//!
//! Owns: everything on disk under the world directory. Must not: decide which chunks are
//! wanted (the server's and the pre-generator's) or how terrain looks (the generator's).

mod chunks;
pub mod codec;
pub mod level;
mod open;
pub mod region;
pub mod spawn;
mod store;

use std::path::Path;

pub use chunks::{ChunkSource, Origin, Scratch};
pub use open::{check_biome_names, open, OpenOptions, OpenWorld, Opening, RulesSource, WorldError};
pub use spawn::{find_spawn, SpawnPoint};
pub use store::{Store, StoreError};

/// Makes `dir` ready for chunks of the world with `seed` at `metres_per_block`: a world made
/// with another seed or at another scale is refused (its chunks would not match new ones), a
/// missing `level.dat` is written with `spawn` so Minecraft and other tools open the world.
pub fn prepare(
    dir: &Path,
    (seed, metres_per_block): (u64, f64),
    spawn: [i32; 3],
    game_type: i32,
) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir)
        .map_err(|e| anyhow::anyhow!("cannot create the world folder {}: {e}", dir.display()))?;
    let level = dir.join("level.dat");
    if level.exists() {
        let info = level::read_level_dat(dir).map_err(|e| anyhow::anyhow!("{}: {e}", level.display()))?;
        if info.seed != seed {
            anyhow::bail!(
                "{} belongs to a world with seed {}, not {seed}: its chunks would not match; use that seed \
                 (--seed {}) or another world.directory",
                level.display(),
                info.seed,
                info.seed
            );
        }
        if info.metres_per_block != metres_per_block {
            anyhow::bail!(
                "{} was made at {} m per block, but world.metres_per_block is {metres_per_block}: its saved chunks \
                 would not line up with new ones; set world.metres_per_block = {} or use another world.directory",
                dir.display(),
                info.metres_per_block,
                info.metres_per_block
            );
        }
        return Ok(());
    }
    let name = dir.file_name().map_or_else(|| "world".to_string(), |n| n.to_string_lossy().into_owned());
    level::write_level_dat(dir, &name, (seed, metres_per_block), spawn, game_type)
        .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", level.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_world_made_with_another_seed_or_scale_is_refused_naming_both() {
        let dir = tempfile::tempdir().expect("temporary directory");
        let world = dir.path().join("w");
        prepare(&world, (5, 40.0), [0, 70, 0], 1).expect("a new world is prepared");
        prepare(&world, (5, 40.0), [9, 9, 9], 1).expect("the same world opens again");
        let seed = prepare(&world, (6, 40.0), [0, 70, 0], 1).unwrap_err().to_string();
        assert!(seed.contains("seed 5, not 6"), "{seed}");
        let scale = prepare(&world, (5, 30.0), [0, 70, 0], 1).unwrap_err().to_string();
        assert!(
            scale.contains(&world.display().to_string()) && scale.contains("40 m per block") && scale.contains("is 30"),
            "{scale}"
        );
    }
}
