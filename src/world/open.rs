//! Opening the world a run plays in or pre-generates into, the same way for `serve` and
//! `pregen`: load the biome rules and check their names against the client's registry, build
//! the terrain pipeline and the chunk generator, find the spawn point, write or check
//! `level.dat`, and open the region store.

use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::biome::{BiomeError, BiomeRules};
use crate::chunkgen::{vanilla_biome_names, Generator};
use crate::config::{shipped, Config};
use crate::terrain::model_files::ModelFiles;
use crate::terrain::pipeline::PipelineError;
use crate::terrain::Pipeline;

use super::spawn::{find_spawn, SpawnPoint};
use super::Store;

/// Where the biome rules are read from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum RulesSource {
    /// Every `*.toml` of a folder (re-read by the console's `reload`).
    Dir(PathBuf),
    /// The shipped biome files (`biomes/default.toml`, `biomes/vegetation.toml`), compiled
    /// into the binary (nothing to re-read).
    BuiltIn,
}

impl RulesSource {
    /// Loads and checks the rules (names included, see [`check_biome_names`]).
    pub fn load(&self) -> Result<BiomeRules, WorldError> {
        let rules = match self {
            RulesSource::Dir(dir) => BiomeRules::load_dir(dir),
            RulesSource::BuiltIn => BiomeRules::from_sources(&shipped::biome_sources()),
        }
        .map_err(WorldError::Rules)?;
        check_biome_names(&rules)?;
        Ok(rules)
    }
}

impl fmt::Display for RulesSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RulesSource::Dir(dir) => write!(f, "{}", dir.display()),
            RulesSource::BuiltIn => f.write_str(shipped::BIOMES_NAME),
        }
    }
}

/// Why the world could not be opened.
#[derive(Debug, thiserror::Error)]
pub enum WorldError {
    /// The biome rules do not load (the message names the file or folder). Not a chained
    /// source: the message already holds the cause, and printing it twice confuses.
    #[error("{0}")]
    Rules(BiomeError),
    /// The rules name biomes the client has no registry entry for.
    #[error(
        "biome rules name biomes that Minecraft 1.20.1 does not have: {} (names look like \"minecraft:plains\")",
        .0.join(", ")
    )]
    UnknownBiomes(Vec<String>),
    /// The terrain pipeline cannot be built (a model file is missing or damaged, a stage is
    /// not built into this binary).
    #[error(transparent)]
    Pipeline(#[from] PipelineError),
    /// The world folder belongs to another seed, or cannot be made ready.
    #[error("{0}")]
    Folder(String),
    /// The region writer could not start.
    #[error("cannot start the region writer: {0}")]
    Store(std::io::Error),
}

impl WorldError {
    /// True when the owner's input (rules, configuration, models, world folder) is at fault;
    /// false for a failure of the machine.
    pub fn is_bad_input(&self) -> bool {
        !matches!(self, WorldError::Store(_))
    }
}

/// Refuses rules that name a biome the client does not know: it would silently become plains.
pub fn check_biome_names(rules: &BiomeRules) -> Result<(), WorldError> {
    let known = vanilla_biome_names();
    let unknown: Vec<String> =
        rules.biome_names().into_iter().filter(|n| !known.iter().any(|k| k == n)).map(str::to_string).collect();
    if unknown.is_empty() {
        Ok(())
    } else {
        Err(WorldError::UnknownBiomes(unknown))
    }
}

/// What [`open`] needs beyond the configuration.
#[derive(Clone, Debug)]
pub struct OpenOptions {
    /// Where the biome rules come from.
    pub rules: RulesSource,
    /// Where the learned stages' models come from.
    pub models: ModelFiles,
    /// The world folder (`None`: `[world] directory`).
    pub directory: Option<PathBuf>,
    /// Open the region store (off: nothing is read from or written to disk).
    pub save: bool,
}

/// Steps of [`open`] worth telling the owner about, in order.
#[derive(Clone, Debug)]
pub enum Opening<'a> {
    /// The pipeline is built, running these learned stages (empty: procedural only).
    Terrain(&'a [&'static str]),
    /// The spawn search starts (it takes a moment on a new seed).
    FindingSpawn,
    /// The spawn point found.
    Spawn(&'a SpawnPoint),
    /// The store is open: chunks are saved to this world folder.
    Saving(&'a Path),
}

/// The opened world.
pub struct OpenWorld {
    /// The biome rules in use.
    pub rules: BiomeRules,
    /// Builds chunks.
    pub generator: Arc<Generator>,
    /// Where players appear.
    pub spawn: SpawnPoint,
    /// The world folder.
    pub directory: PathBuf,
    /// The region store (`None` when saving is off).
    pub store: Option<Arc<Store>>,
}

/// Opens the world of `config`: rules (checked), pipeline and generator, spawn point, then —
/// when saving — `level.dat` (written, or checked against the seed) and the region store.
/// `tell` hears each step as it happens.
pub fn open(config: &Config, options: &OpenOptions, tell: &mut dyn FnMut(Opening)) -> Result<OpenWorld, WorldError> {
    let rules = options.rules.load()?;
    let seed = config.world.seed;
    let pipeline = Pipeline::build_with_models(seed, &config.terrain(), &options.models)?;
    tell(Opening::Terrain(&pipeline.learned_stages()));
    let generator = Arc::new(Generator::new(Arc::new(pipeline), config));
    tell(Opening::FindingSpawn);
    let spawn = find_spawn(&generator, &rules);
    tell(Opening::Spawn(&spawn));
    let directory = options.directory.clone().unwrap_or_else(|| config.world.directory.clone());
    let store = if options.save {
        let at = [spawn.block.x, spawn.block.y, spawn.block.z];
        let identity = (seed, config.world.metres_per_block);
        super::prepare(&directory, identity, at, config.server.gamemode.game_type())
            .map_err(|e| WorldError::Folder(format!("{e:#}")))?;
        let store = Store::open(&directory).map_err(WorldError::Store)?;
        tell(Opening::Saving(&directory));
        Some(Arc::new(store))
    } else {
        None
    };
    Ok(OpenWorld { rules, generator, spawn, directory, store })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_built_in_rules_load_and_name_only_known_biomes() {
        let rules = RulesSource::BuiltIn.load().expect("the shipped rules load");
        assert!(rules.rule_count() > 0);
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("biomes");
        let from_disk = RulesSource::Dir(dir).load().expect("biomes/ loads");
        assert_eq!(from_disk.rule_count(), rules.rule_count());
        // Every shipped file is built in: the tables beside the rules match the folder's.
        assert_eq!(from_disk.veins(), rules.veins());
        assert_eq!(rules.veins().len(), 22);
        for biome in crate::biome::OVERWORLD_BIOMES {
            assert_eq!(from_disk.vegetation(biome), rules.vegetation(biome), "{biome}");
            assert_eq!(from_disk.surface(biome), rules.surface(biome), "{biome}");
        }
        assert!(rules.vegetation("minecraft:forest").is_some_and(|v| v.trees > 0.0));
        assert_ne!(rules.surface("minecraft:desert"), crate::biome::Surface::DEFAULT);
    }

    #[test]
    fn a_missing_rules_folder_is_bad_input_naming_it() {
        let err = RulesSource::Dir(PathBuf::from("no/such/biomes")).load().map(|_| ()).unwrap_err();
        assert!(err.is_bad_input());
        assert!(err.to_string().starts_with("no/such/biomes: "), "{err}");
    }
}
