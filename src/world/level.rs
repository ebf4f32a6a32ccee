//! `level.dat`: what Minecraft 1.20.1 and world tools (Amulet…) need to open the saved world.
//!
//! The overworld's generator in `level.dat` is a void superflat (one layer of air, plains):
//! every chunk of the world comes from this server, so whatever Minecraft itself generates
//! when someone opens the world in the game and walks past the saved chunks should be
//! empty rather than vanilla terrain that ends in a cliff at our chunks, and a flat
//! generator is the one whose settings 1.20.1 accepts without any data pack. The nether and
//! the end keep vanilla's generators, as a new vanilla world has them. The overworld
//! dimension type is vanilla's (-64..320): a world configured with another height loads in
//! Minecraft with its chunks cut to that range.

use std::fs::{self, File};
use std::io::{self, Read, Write};
use std::path::Path;

use flate2::read::GzDecoder;
use flate2::write::GzEncoder;
use flate2::Compression;
use valence::nbt::{compound, Compound, List, Value};

use super::codec::DATA_VERSION;

/// Anvil's format version, which 1.20.1 writes as `version`.
const ANVIL_VERSION: i32 = 19133;

/// What [`read_level_dat`] reports.
#[derive(Clone, Debug, PartialEq)]
pub struct LevelInfo {
    /// `LevelName`.
    pub name: String,
    /// The world seed (`WorldGenSettings.seed`).
    pub seed: u64,
    /// `SpawnX`, `SpawnY`, `SpawnZ`.
    pub spawn: [i32; 3],
    /// `DataVersion`: the Minecraft version that saved it last.
    pub data_version: i32,
    /// The world's horizontal scale, metres per block (`infiniterra.metres_per_block`; worlds
    /// saved before the scale was configurable were [`LEGACY_METRES_PER_BLOCK`]).
    pub metres_per_block: f64,
}

/// The scale of worlds whose `level.dat` records none: every world saved before
/// `world.metres_per_block` existed was 125 m per block.
pub const LEGACY_METRES_PER_BLOCK: f64 = 125.0;

/// Why `level.dat` could not be read.
#[derive(Debug, thiserror::Error)]
pub enum LevelError {
    /// Reading the file failed.
    #[error("cannot read level.dat: {0}")]
    Io(#[from] io::Error),
    /// Its contents are not gzip-compressed NBT.
    #[error("level.dat is not gzip-compressed NBT: {0}")]
    NotNbt(String),
    /// A field is absent or of another type.
    #[error("level.dat has no {0} (or not of the right type)")]
    Missing(&'static str),
}

/// Writes `<dir>/level.dat` (gzip NBT, root `""` { `Data`: … }) atomically (temporary file,
/// fsync, rename) so that Minecraft 1.20.1 and world tools open the world: version fields,
/// `LevelName` `name`, the spawn point, `WorldGenSettings` with `seed` and the void
/// superflat overworld (see the module documentation), `GameType` `game_type` (0 survival,
/// 1 creative, 2 adventure, 3 spectator), commands allowed, noon; and our own
/// `infiniterra.metres_per_block`, the scale the world's chunks were made at.
pub fn write_level_dat(
    dir: &Path,
    name: &str,
    (seed, metres_per_block): (u64, f64),
    spawn: [i32; 3],
    game_type: i32,
) -> io::Result<()> {
    let mut data = level_data(name, seed, spawn, game_type);
    data.insert("infiniterra", compound! { "metres_per_block" => metres_per_block });
    let root = compound! { "Data" => data };
    let mut gz = GzEncoder::new(Vec::new(), Compression::default());
    root.to_binary(&mut gz, "").map_err(io::Error::other)?;
    let bytes = gz.finish()?;

    let temp = dir.join("level.dat.tmp");
    let mut file = File::create(&temp)?;
    file.write_all(&bytes)?;
    file.sync_all()?;
    drop(file);
    fs::rename(&temp, dir.join("level.dat"))?;
    // The rename itself is durable only once the directory is synced (not possible on
    // every platform: best effort).
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
    Ok(())
}

/// Reads `<dir>/level.dat` back: its name, seed, spawn and data version (to refuse opening a
/// world made with another seed, whose saved chunks would not match new ones).
pub fn read_level_dat(dir: &Path) -> Result<LevelInfo, LevelError> {
    let mut bytes = Vec::new();
    GzDecoder::new(File::open(dir.join("level.dat"))?)
        .read_to_end(&mut bytes)
        .map_err(|e| LevelError::NotNbt(e.to_string()))?;
    let (root, _) = Compound::from_binary(&mut bytes.as_slice()).map_err(|e| LevelError::NotNbt(e.to_string()))?;
    let Some(Value::Compound(data)) = root.get("Data") else { return Err(LevelError::Missing("Data")) };
    let int = |field: &'static str| match data.get(field) {
        Some(Value::Int(v)) => Ok(*v),
        _ => Err(LevelError::Missing(field)),
    };
    let name = match data.get("LevelName") {
        Some(Value::String(name)) => name.clone(),
        _ => return Err(LevelError::Missing("LevelName")),
    };
    let seed = match data.get("WorldGenSettings") {
        Some(Value::Compound(settings)) => match settings.get("seed") {
            Some(Value::Long(seed)) => *seed as u64,
            _ => return Err(LevelError::Missing("WorldGenSettings.seed")),
        },
        _ => return Err(LevelError::Missing("WorldGenSettings")),
    };
    let metres_per_block = match data.get("infiniterra") {
        Some(Value::Compound(ours)) => match ours.get("metres_per_block") {
            Some(Value::Double(m)) => *m,
            _ => return Err(LevelError::Missing("infiniterra.metres_per_block")),
        },
        _ => LEGACY_METRES_PER_BLOCK,
    };
    Ok(LevelInfo {
        name,
        seed,
        spawn: [int("SpawnX")?, int("SpawnY")?, int("SpawnZ")?],
        data_version: int("DataVersion")?,
        metres_per_block,
    })
}

/// The `Data` compound.
fn level_data(name: &str, seed: u64, spawn: [i32; 3], game_type: i32) -> Compound {
    compound! {
        "DataVersion" => DATA_VERSION,
        "version" => ANVIL_VERSION,
        "Version" => compound! {
            "Id" => DATA_VERSION,
            "Name" => "1.20.1",
            "Series" => "main",
            "Snapshot" => 0i8,
        },
        "LevelName" => name,
        "SpawnX" => spawn[0],
        "SpawnY" => spawn[1],
        "SpawnZ" => spawn[2],
        "SpawnAngle" => 0.0f32,
        "GameType" => game_type,
        "Difficulty" => 2i8,
        "DifficultyLocked" => 0i8,
        "hardcore" => 0i8,
        "allowCommands" => 1i8,
        "initialized" => 1i8,
        "LastPlayed" => 0i64,
        "Time" => 0i64,
        // Noon, so the terrain is in daylight when the world is first opened.
        "DayTime" => 6000i64,
        "raining" => 0i8,
        "rainTime" => 0i32,
        "thundering" => 0i8,
        "thunderTime" => 0i32,
        "clearWeatherTime" => 0i32,
        "WasModded" => 0i8,
        "ServerBrands" => List::String(vec!["infiniterra".to_string()]),
        "DataPacks" => compound! {
            "Enabled" => List::String(vec!["vanilla".to_string()]),
            "Disabled" => List::String(Vec::new()),
        },
        "enabled_features" => List::String(vec!["minecraft:vanilla".to_string()]),
        "WorldGenSettings" => compound! {
            // The seed is stored as Java's signed long, bit for bit.
            "seed" => seed as i64,
            "generate_features" => 1i8,
            "bonus_chest" => 0i8,
            "dimensions" => compound! {
                "minecraft:overworld" => compound! {
                    "type" => "minecraft:overworld",
                    "generator" => compound! {
                        "type" => "minecraft:flat",
                        "settings" => compound! {
                            "layers" => List::Compound(vec![compound! {
                                "block" => "minecraft:air",
                                "height" => 1i32,
                            }]),
                            "biome" => "minecraft:plains",
                            "features" => 0i8,
                            "lakes" => 0i8,
                            "structure_overrides" => List::String(Vec::new()),
                        },
                    },
                },
                "minecraft:the_nether" => compound! {
                    "type" => "minecraft:the_nether",
                    "generator" => compound! {
                        "type" => "minecraft:noise",
                        "settings" => "minecraft:nether",
                        "biome_source" => compound! {
                            "type" => "minecraft:multi_noise",
                            "preset" => "minecraft:nether",
                        },
                    },
                },
                "minecraft:the_end" => compound! {
                    "type" => "minecraft:the_end",
                    "generator" => compound! {
                        "type" => "minecraft:noise",
                        "settings" => "minecraft:end",
                        "biome_source" => compound! { "type" => "minecraft:the_end" },
                    },
                },
            },
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn level_dat_round_trips() {
        let dir = match tempfile::tempdir() {
            Ok(dir) => dir,
            Err(e) => panic!("no temporary directory: {e}"),
        };
        let seed = 0xDEAD_BEEF_0123_4567u64; // High bit set: stored as a negative long.
        if let Err(e) = write_level_dat(dir.path(), "Terra ñ", (seed, 37.5), [12, 80, -300], 1) {
            panic!("write failed: {e}");
        }
        assert!(!dir.path().join("level.dat.tmp").exists());
        match read_level_dat(dir.path()) {
            Ok(info) => assert_eq!(
                info,
                LevelInfo {
                    name: "Terra ñ".into(),
                    seed,
                    spawn: [12, 80, -300],
                    data_version: DATA_VERSION,
                    metres_per_block: 37.5
                }
            ),
            Err(e) => panic!("read failed: {e}"),
        }
        // Written again over itself (as after a crash), still one readable file.
        if let Err(e) = write_level_dat(dir.path(), "again", (7, 40.0), [0, 64, 0], 0) {
            panic!("rewrite failed: {e}");
        }
        assert!(matches!(read_level_dat(dir.path()), Ok(LevelInfo { seed: 7, .. })));
    }

    #[test]
    fn a_level_dat_without_a_scale_is_the_old_fixed_scale() {
        let dir = tempfile::tempdir().expect("temporary directory");
        let root = compound! { "Data" => level_data("old", 3, [0, 64, 0], 1) };
        let mut gz = GzEncoder::new(Vec::new(), Compression::default());
        root.to_binary(&mut gz, "").expect("encodes");
        fs::write(dir.path().join("level.dat"), gz.finish().expect("compresses")).expect("writes");
        let info = read_level_dat(dir.path()).expect("reads");
        assert_eq!((info.seed, info.metres_per_block), (3, LEGACY_METRES_PER_BLOCK));
    }

    #[test]
    fn a_damaged_level_dat_is_reported() {
        let dir = match tempfile::tempdir() {
            Ok(dir) => dir,
            Err(e) => panic!("no temporary directory: {e}"),
        };
        assert!(matches!(read_level_dat(dir.path()), Err(LevelError::Io(_))));
        if let Err(e) = fs::write(dir.path().join("level.dat"), b"not gzip") {
            panic!("{e}");
        }
        let e = read_level_dat(dir.path()).map(|_| ()).map_err(|e| e.to_string());
        assert!(matches!(&e, Err(m) if m.contains("not gzip")), "{e:?}");
    }
}
