//! Players joining and leaving: where they appear, in which game mode, how far they see.

use valence::client::{FlushPacketsSet, UpdateClientsSet};
use valence::protocol::packets::play::HealthUpdateS2c;
use valence::protocol::{VarInt, WritePacket};
use valence::spawn::RespawnPosition;

use valence::prelude::*;

use crate::config::Config;

use super::Spawn;

/// Systems that place players and set their view: streaming runs after them, so it never
/// loads chunks for where a player was before being placed.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PlayersSet;

/// Server-side settings of players.
#[derive(Resource, Clone, Copy)]
struct PlayerSettings {
    game_mode: GameMode,
    view_distance_cap: u8,
}

/// Adds the player systems.
pub fn build(app: &mut App, config: &Config) {
    app.insert_resource(PlayerSettings {
        game_mode: config.server.gamemode.client(),
        view_distance_cap: config.server.view_distance_cap.clamp(2, 32) as u8,
    })
    .add_systems(Update, (init_clients, cap_view_distance).in_set(PlayersSet))
    .add_systems(Update, (despawn_disconnected_clients, announce_leaving))
    // After valence has sent the join packet, before this tick's packets leave.
    .add_systems(PostUpdate, send_health.after(UpdateClientsSet).before(FlushPacketsSet));
}

#[allow(clippy::type_complexity)]
fn init_clients(
    mut clients: Query<
        (
            &Username,
            &mut EntityLayerId,
            &mut VisibleChunkLayer,
            &mut VisibleEntityLayers,
            &mut Position,
            &mut RespawnPosition,
            &mut GameMode,
        ),
        Added<Client>,
    >,
    layers: Query<Entity, (With<ChunkLayer>, With<EntityLayer>)>,
    spawn: Res<Spawn>,
    settings: Res<PlayerSettings>,
) {
    let Ok(layer) = layers.get_single() else {
        return;
    };
    for (name, mut layer_id, mut visible_chunks, mut visible_entities, mut pos, mut respawn, mut mode) in &mut clients {
        layer_id.0 = layer;
        visible_chunks.0 = layer;
        visible_entities.0.insert(layer);
        pos.set(spawn.0.feet);
        *respawn = RespawnPosition { pos: spawn.0.block, yaw: 0.0 };
        *mode = settings.game_mode;
        say!("{} joined", name.0);
    }
}

fn announce_leaving(mut left: RemovedComponents<Client>, names: Query<&Username>) {
    for entity in left.iter() {
        if let Ok(name) = names.get(entity) {
            say!("{} left", name.0);
        }
    }
}

/// valence has no health: without this packet clients never finish spawning.
fn send_health(mut clients: Query<&mut Client, Added<Client>>) {
    for mut client in &mut clients {
        client.write_packet(&HealthUpdateS2c { health: 20.0, food: VarInt(20), food_saturation: 5.0 });
    }
}

fn cap_view_distance(mut clients: Query<&mut ViewDistance, Changed<ViewDistance>>, settings: Res<PlayerSettings>) {
    for mut dist in &mut clients {
        if dist.get() > settings.view_distance_cap {
            dist.set(settings.view_distance_cap);
        }
    }
}
