//! Players' block edits: breaking and placing blocks. An edit changes the chunk every player
//! who sees it is shown (valence sends the block update to the chunk's viewers), its light and
//! its neighbours' are computed again and resent, and the chunk is saved over its generated
//! copy — a saved chunk is always loaded rather than generated, so the edit survives
//! unloading, reconnects and restarts (unless `world.save_chunks` is off, when edits live
//! only while the chunk is in memory).
//!
//! Creative players break a block at the first hit; survival players when their client has
//! finished digging it (the client times the dig by the held tool, as vanilla's does). A held
//! item that is a block is placed against the face clicked — or in place of a replaceable
//! block (grass, water) — in its default state; survival players use one up. No item drops:
//! valence has no item entities to drop them as.

use std::collections::HashSet;
use std::sync::Arc;

use valence::interact_block::InteractBlockEvent;
use valence::inventory::HeldItem;
use valence::prelude::*;

use super::dimension::{Palette, WorldSetup};
use super::drops;
use super::stream::{Relit, Streamer};
use crate::chunkgen::{Light, States};
use crate::world::codec::Encoder;
use crate::world::Store;

/// Chunks edited this tick, saved and relit at the end of it.
#[derive(Resource, Default)]
struct Edited(HashSet<ChunkPos>);

/// What saving an edited chunk needs.
#[derive(Resource)]
struct Saver {
    store: Option<Arc<Store>>,
    encoder: Encoder,
}

/// Adds the editing systems.
pub fn build(app: &mut App) {
    app.init_resource::<Edited>()
        .add_systems(PostStartup, make_saver)
        .add_systems(Update, (dig, place, save_edited).chain());
    drops::build(app);
}

fn make_saver(mut commands: Commands, setup: Res<WorldSetup>, palette: Res<Palette>) {
    let v = setup.generator.vertical();
    commands.insert_resource(Saver {
        store: setup.store.clone(),
        encoder: Encoder::new(v.min_y, palette.0.names().to_vec()),
    });
}

fn dig(
    mut commands: Commands,
    clients: Query<(&GameMode, &Inventory, &HeldItem)>,
    mut layers: Query<(Entity, &mut ChunkLayer)>,
    mut events: EventReader<DiggingEvent>,
    mut edited: ResMut<Edited>,
) {
    let Ok((layer_entity, mut layer)) = layers.get_single_mut() else { return };
    for event in events.iter() {
        let Ok((mode, inventory, held)) = clients.get(event.client) else { continue };
        let done = match *mode {
            GameMode::Creative => event.state == DiggingState::Start,
            GameMode::Survival => event.state == DiggingState::Stop,
            GameMode::Adventure | GameMode::Spectator => false,
        };
        let Some(state) = layer.block(event.position).map(|b| b.state) else { continue };
        if !done || state.is_air() || state == BlockState::BEDROCK && *mode != GameMode::Creative {
            continue;
        }
        layer.set_block(event.position, BlockState::AIR);
        edited.0.insert(ChunkPos::from_block_pos(event.position));
        if *mode == GameMode::Survival {
            if let Some(drop) = drops::drop_of(state, drops::held(inventory, held), event.position) {
                drops::spawn(&mut commands, layer_entity, event.position, drop);
            }
        }
    }
}

fn place(
    mut clients: Query<(&mut Inventory, &GameMode, &HeldItem)>,
    mut layers: Query<&mut ChunkLayer>,
    mut events: EventReader<InteractBlockEvent>,
    mut edited: ResMut<Edited>,
) {
    let Ok(mut layer) = layers.get_single_mut() else { return };
    for event in events.iter() {
        if event.hand != Hand::Main {
            continue;
        }
        let Ok((mut inventory, mode, held)) = clients.get_mut(event.client) else { continue };
        if matches!(*mode, GameMode::Adventure | GameMode::Spectator) {
            continue;
        }
        let slot = held.slot();
        let Some(stack) = inventory.slot(slot).cloned() else { continue };
        let Some(kind) = BlockKind::from_item_kind(stack.item) else { continue };
        let replaceable = |pos: BlockPos| layer.block(pos).is_some_and(|b| b.state.is_replaceable());
        // A click on grass or water puts the block there, as vanilla does; otherwise against
        // the face clicked, where there must be room.
        let at = if replaceable(event.position) { event.position } else { event.position.get_in_direction(event.face) };
        if !replaceable(at) {
            continue;
        }
        if *mode == GameMode::Survival {
            match stack.count().saturating_sub(1) {
                0 => inventory.set_slot(slot, None),
                left => inventory.set_slot_amount(slot, left),
            }
        }
        layer.set_block(at, kind.to_state());
        edited.0.insert(ChunkPos::from_block_pos(at));
    }
}

/// Relights and saves every chunk edited this tick. All of them are relit together, so a
/// chunk beside two edited ones is joined with both edits.
fn save_edited(
    layers: Query<&ChunkLayer>,
    mut edited: ResMut<Edited>,
    saver: Option<ResMut<Saver>>,
    streamer: Option<ResMut<Streamer>>,
    mut sent: Query<&mut super::stream::LightSent>,
) {
    if edited.0.is_empty() {
        return;
    }
    let (Ok(layer), Some(mut saver), Some(mut streamer)) = (layers.get_single(), saver, streamer) else { return };
    let (mut chunks, mut owns) = (Vec::new(), Vec::new());
    for pos in edited.0.drain() {
        if let Some(chunk) = layer.chunk(pos) {
            let states = States::of(chunk);
            owns.push((pos, Light::of_states(&states)));
            chunks.push((pos, chunk, states));
        }
    }
    let lights = match streamer.relight(owns) {
        Ok(Relit { lights, changed }) => {
            for pos in changed {
                for mut s in &mut sent {
                    s.forget(pos);
                }
            }
            lights
        }
        Err(e) => {
            tracing::error!("light of edited chunks: {e:#}");
            vec![None; chunks.len()]
        }
    };
    let Some(store) = saver.store.clone() else { return };
    for ((pos, chunk, states), light) in chunks.iter().zip(lights) {
        let nbt = saver.encoder.encode_states(pos.x, pos.z, *chunk, states, light.as_deref());
        if let Err(e) = store.save(pos.x, pos.z, &nbt) {
            tracing::error!("saving edited chunk {}, {}: {e}", pos.x, pos.z);
            say!("could not save the edit to chunk {}, {}: {e}", pos.x, pos.z);
        }
    }
}
