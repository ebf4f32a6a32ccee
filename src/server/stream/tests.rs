//! Streaming in process: a valence app without networking, the real generator and rules,
//! clients on in-memory connections, and the streaming systems of the server.
//!
//! Every wait runs ticks until a condition holds, bounded by a timeout.

use std::collections::{HashMap, HashSet};
use std::net::{IpAddr, Ipv4Addr};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use valence::client::{despawn_disconnected_clients, ClientBundle, ClientBundleArgs, ClientConnection, ReceivedPacket};
use valence::keepalive::KeepaliveSettings;
use valence::network::NetworkPlugin;
use valence::prelude::*;
use valence::protocol::bytes::BytesMut;
use valence::protocol::PacketEncoder;

use super::light::Lit;
use super::Streamer;
use crate::biome::BiomeRules;
use crate::chunkgen::{Generator, Light, States};
use crate::config::Config;
use crate::server::dimension::{self, WorldSetup};
use crate::terrain::Pipeline;

/// A client whose packets go nowhere and who never says anything.
struct Silent;

impl ClientConnection for Silent {
    fn try_send(&mut self, _bytes: BytesMut) -> anyhow::Result<()> {
        Ok(())
    }

    fn try_recv(&mut self) -> anyhow::Result<Option<ReceivedPacket>> {
        Ok(None)
    }

    fn len(&self) -> usize {
        0
    }
}

const VIEW: u8 = 2;
const CACHE: u64 = 40;
const WAIT: Duration = Duration::from_secs(120);

/// The app with the server's world and streaming systems; its layer entity.
fn app() -> (App, Entity) {
    let mut config = Config::default();
    config.world.seed = 11;
    config.server.chunk_threads = 2;
    config.server.chunk_cache = CACHE;
    let generator = Arc::new(Generator::new(Arc::new(Pipeline::new(11, &config.terrain())), &config));
    let rules = BiomeRules::load_dir(&PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("biomes")).expect("rules load");
    let mut app = App::new();
    app.insert_resource(KeepaliveSettings { period: Duration::MAX })
        .add_plugins(DefaultPlugins.build().disable::<NetworkPlugin>().disable::<valence::log::LogPlugin>())
        .insert_resource(WorldSetup {
            config,
            generator,
            rules: Arc::new(rules),
            rules_source: crate::world::RulesSource::BuiltIn,
            store: None,
        })
        .add_systems(Update, despawn_disconnected_clients);
    dimension::build(&mut app);
    super::build(&mut app);
    app.update(); // Start-up: the layer and the workers.
    let layer = app.world.query_filtered::<Entity, With<ChunkLayer>>().single(&app.world);
    (app, layer)
}

/// A client in `layer` at block (x, z), seeing `VIEW` chunks.
fn join(app: &mut App, layer: Entity, name: &str, x: f64, z: f64) -> Entity {
    let mut bundle = ClientBundle::new(ClientBundleArgs {
        username: name.into(),
        uuid: Uuid::from_u128(name.len() as u128 + 1),
        ip: IpAddr::V4(Ipv4Addr::LOCALHOST),
        properties: vec![],
        conn: Box::new(Silent),
        enc: PacketEncoder::new(),
    });
    bundle.player.layer.0 = layer;
    bundle.visible_chunk_layer.0 = layer;
    bundle.visible_entity_layers.0.insert(layer);
    bundle.view_distance = ViewDistance::new(VIEW);
    bundle.player.position = Position::new([x, 100.0, z]);
    app.world.spawn(bundle).id()
}

fn view_of(x: f64, z: f64) -> HashSet<ChunkPos> {
    ChunkView::new(ChunkPos::from_block_pos(BlockPos::new(x as i32, 0, z as i32)), VIEW).iter().collect()
}

fn in_layer(app: &App, layer: Entity) -> HashSet<ChunkPos> {
    app.world.get::<ChunkLayer>(layer).expect("layer").chunks().map(|(pos, _)| pos).collect()
}

/// Ticks until `done` holds; panics after `WAIT`.
fn tick_until(app: &mut App, what: &str, mut done: impl FnMut(&mut App) -> bool) {
    let deadline = Instant::now() + WAIT;
    while !done(app) {
        assert!(Instant::now() < deadline, "timed out waiting for {what}");
        app.update();
        // Between ticks the workers build chunks; let them have the core.
        std::thread::yield_now();
    }
}

fn loaded_in_streamer(app: &mut App) -> usize {
    app.world.resource_mut::<Streamer>().status().loaded
}

#[test]
fn moving_far_away_unloads_the_old_view_and_loads_the_new_one() {
    let (mut app, layer) = app();
    let client = join(&mut app, layer, "mover", 8.0, 8.0);
    let old = view_of(8.0, 8.0);
    tick_until(&mut app, "the first view", |app| in_layer(app, layer) == old);
    assert_eq!(loaded_in_streamer(&mut app), old.len());

    // A teleport 100 chunks east: nothing of the old view overlaps the new one.
    let (x, z) = (8.0 + 1600.0, 8.0);
    let new = view_of(x, z);
    assert!(old.is_disjoint(&new));
    app.world.get_mut::<Position>(client).expect("position").set([x, 100.0, z]);
    app.update();
    let now = in_layer(&app, layer);
    assert!(now.is_disjoint(&old), "old chunks still loaded after the move: {:?}", now.intersection(&old));
    {
        let mut streamer = app.world.resource_mut::<Streamer>();
        let status = streamer.status();
        assert!(status.queued + status.in_flight > 0, "nothing asked for the new view: {status:?}");
        // The old chunks went to the finished-chunk cache, which stays within its bound.
        assert!(status.cached > 0 && status.cached <= CACHE as usize, "{status:?}");
        assert_eq!(status.loaded, now.len(), "{status:?}");
    }
    tick_until(&mut app, "the new view", |app| in_layer(app, layer) == new);
    assert_eq!(loaded_in_streamer(&mut app), new.len());

    // Back again: the cached chunks come back, and the east goes.
    app.world.get_mut::<Position>(client).expect("position").set([8.0, 100.0, 8.0]);
    app.update();
    assert!(in_layer(&app, layer).is_disjoint(&new));
    tick_until(&mut app, "the first view again", |app| in_layer(app, layer) == old);
}

#[test]
fn a_client_disconnecting_unloads_the_chunks_only_it_saw() {
    let (mut app, layer) = app();
    let (a, b) = (join(&mut app, layer, "a", 8.0, 8.0), join(&mut app, layer, "bb", 8.0 + 48.0, 8.0));
    let (view_a, view_b) = (view_of(8.0, 8.0), view_of(8.0 + 48.0, 8.0));
    let both: HashSet<ChunkPos> = view_a.union(&view_b).copied().collect();
    assert!(!view_a.is_disjoint(&view_b) && view_a != view_b);
    tick_until(&mut app, "both views", |app| in_layer(app, layer) == both);

    // The connection of `a` drops (valence removes `Client`): what only `a` saw goes.
    app.world.entity_mut(a).remove::<Client>();
    tick_until(&mut app, "the chunks of `a` to go", |app| !in_layer(app, layer).iter().any(|p| !view_b.contains(p)));
    assert_eq!(in_layer(&app, layer), view_b, "what `b` sees stays");
    assert_eq!(loaded_in_streamer(&mut app), view_b.len());

    // And then `b`: nothing stays loaded.
    app.world.entity_mut(b).remove::<Client>();
    tick_until(&mut app, "every chunk to go", |app| in_layer(app, layer).is_empty());
    let status = app.world.resource_mut::<Streamer>().status();
    assert_eq!(status.loaded, 0, "{status:?}");
    assert_eq!(status.queued, 0, "{status:?}");
    assert!(status.cached <= CACHE as usize, "{status:?}");
}

/// The app with one client at block (8, 8) and every chunk of its view loaded; the layer and
/// the view.
fn one_view_loaded() -> (App, Entity, HashSet<ChunkPos>) {
    let (mut app, layer) = app();
    join(&mut app, layer, "looker", 8.0, 8.0);
    let view = view_of(8.0, 8.0);
    tick_until(&mut app, "the view", |app| in_layer(app, layer) == view);
    (app, layer, view)
}

#[test]
fn chunks_whose_neighbours_are_all_loaded_are_sent_their_joined_light() {
    let (app, _, view) = one_view_loaded();
    let setup = app.world.resource::<WorldSetup>();
    let palette = app.world.resource::<dimension::Palette>().0.clone();
    let own = |p: ChunkPos| Light::of_states(&setup.generator.blocks(&setup.rules, &palette, p.x, p.z).states());
    let streamer = app.world.resource::<Streamer>();
    let (mut inner, mut brighter) = (0, 0);
    for &pos in &view {
        let lit = &streamer.loaded[&pos].lit;
        assert_eq!(*lit.own, own(pos), "chunk {pos:?}'s own light");
        let area = super::light::area(pos);
        if !area.iter().all(|p| view.contains(p)) {
            assert!(!lit.is_joined(), "chunk {pos:?} on the view's edge cannot be joined");
            continue;
        }
        inner += 1;
        assert!(lit.is_joined(), "chunk {pos:?} has every neighbour loaded");
        // What a client gets is the light of the nine chunks built here, joined.
        let lights = area.map(own);
        let want = Light::joined(std::array::from_fn(|i| &lights[i])).unwrap_or_else(|| lights[4].clone());
        brighter += usize::from(want != lights[4]);
        let expected = Lit::alone(pos, want, streamer.compression).expect("encodes");
        assert_eq!(lit.packet(), expected.packet(), "chunk {pos:?}'s light packet");
    }
    assert!(inner > 0, "some chunk of the view has all its neighbours in it");
    assert!(brighter > 0, "here, light crosses some border ({inner} chunks joined)");
}

#[test]
fn an_edit_relights_the_chunks_around_it_as_their_blocks_now_are() {
    let (mut app, layer, view) = one_view_loaded();
    let v = *app.world.resource::<WorldSetup>().generator.vertical();
    // A shaft from the sky down the east edge of chunk 0, 0 (x 15, z 8) to 20 blocks under
    // the ground, and a tunnel from its foot east into chunk 1, 0: a player's digging.
    let mut chunks = app.world.get_mut::<ChunkLayer>(layer).expect("layer");
    let top = v.min_y + v.height - 1;
    let ground =
        (v.min_y..=top).rev().find(|&y| chunks.block([15, y, 8]).is_some_and(|b| !b.state.is_air())).expect("ground");
    let foot = ground - 20;
    for y in foot..=top {
        chunks.set_block([15, y, 8], BlockState::AIR);
    }
    for x in 16..20 {
        chunks.set_block([x, foot, 8], BlockState::AIR);
    }
    let own = |chunks: &ChunkLayer, p: ChunkPos| Light::of_states(&States::of(chunks.chunk(p).expect("loaded")));
    let (a, b) = (ChunkPos::new(0, 0), ChunkPos::new(1, 0));
    let (own_a, own_b) = (own(&chunks, a), own(&chunks, b));
    let mut lights: HashMap<ChunkPos, Light> = HashMap::new();
    for p in view.iter().copied() {
        lights.insert(p, own(&chunks, p));
    }
    let mut streamer = app.world.resource_mut::<Streamer>();
    let relit = streamer.relight(vec![(a, own_a), (b, own_b)]).expect("relit");
    let changed: HashSet<ChunkPos> = relit.changed.iter().copied().collect();
    let around: HashSet<ChunkPos> = super::light::area(a).into_iter().chain(super::light::area(b)).collect();
    assert_eq!(changed, around, "the light of the edited chunks and their neighbours is sent again");
    for &pos in &around {
        let area = super::light::area(pos);
        if !area.iter().all(|p| view.contains(p)) {
            continue;
        }
        let nine = area.map(|p| &lights[&p]);
        let want = Light::joined(nine).unwrap_or_else(|| lights[&pos].clone());
        if pos == b {
            let y = (foot - v.min_y) as u32;
            assert_eq!(
                (want.sky(0, y, 8), lights[&b].sky(0, y, 8)),
                (14, 0),
                "the tunnel is lit from the shaft next door"
            );
            assert_eq!(relit.lights[1].as_deref(), Some(&want), "the light saved with the edit is the joined light");
        }
        let lit = &streamer.loaded[&pos].lit;
        assert_eq!(lit.packet(), Lit::alone(pos, want, streamer.compression).expect("encodes").packet(), "{pos:?}");
    }
}
