//! The world's shape as the client sees it: the dimension (height, floor) and the biome
//! registry, and the one chunk layer everyone plays in. (The saved world is `crate::world`.)

use std::sync::Arc;

use valence::prelude::*;

use crate::biome::BiomeRules;
use crate::chunkgen::{BiomePalette, Generator};
use crate::config::Config;
use crate::world::{RulesSource, Store};

/// What start-up hands the app: configuration, generator and the biome rules.
#[derive(Resource)]
pub struct WorldSetup {
    /// The validated configuration.
    pub config: Config,
    /// Builds chunks.
    pub generator: Arc<Generator>,
    /// The biome rules loaded at start-up.
    pub rules: Arc<BiomeRules>,
    /// Where `reload` reads rules from.
    pub rules_source: RulesSource,
    /// The saved world's region files (`None` when `world.save_chunks` is off).
    pub store: Option<Arc<Store>>,
}

/// Biome names → client ids, fixed at start-up (every vanilla biome is registered, so any
/// rule set a `reload` brings in maps too).
#[derive(Resource, Clone)]
pub struct Palette(pub Arc<BiomePalette>);

/// Adds the start-up systems.
pub fn build(app: &mut App) {
    app.add_systems(Startup, (reshape_dimension, apply_deferred, create_layer).chain());
}

/// Players are in vanilla's overworld (clients know its sky and fog), reshaped to the
/// configured height.
fn reshape_dimension(setup: Res<WorldSetup>, mut dimensions: ResMut<DimensionTypeRegistry>) {
    let w = &setup.config.world;
    let Some(dim) = dimensions.get_mut(ident!("overworld")) else {
        tracing::error!("the vanilla dimension minecraft:overworld is missing from valence's registry");
        return;
    };
    // Validated at load: multiples of 16 inside the client's −2032..2031.
    dim.min_y = w.min_y as i32;
    dim.height = w.height as i32;
    dim.logical_height = w.height as i32;
    // valence forces full-bright ambient light because it sends no light; the server sends
    // sky light itself (see `chunkgen::Light`), so the night and the deep sea can be dark.
    dim.ambient_light = 0.0;
}

fn create_layer(
    mut commands: Commands,
    server: Res<Server>,
    dimensions: Res<DimensionTypeRegistry>,
    biomes: Res<BiomeRegistry>,
) {
    let palette = Arc::new(BiomePalette::from_registry(&biomes));
    commands.insert_resource(Palette(palette));
    commands.spawn(LayerBundle::new(ident!("overworld"), &dimensions, &biomes, &server));
}
