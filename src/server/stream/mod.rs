//! Streaming chunks to players: what every view needs, nearest first, built off the main
//! thread, cached when players move on, unloaded when nobody sees them.
//!
//! Unloading is decided from the players' views ([`ChunkView::contains`]), never from
//! valence's viewer counts, which underflow when clients leave (valence issue #716).

mod cache;
mod light;
#[cfg(test)]
mod tests;
mod workers;

pub use workers::Waker;

use std::collections::{HashMap, HashSet, VecDeque};
use std::sync::mpsc;
use std::sync::Arc;
use std::time::{Duration, Instant};

use valence::app::AppExit;
use valence::client::{FlushPacketsSet, UpdateClientsSet};
use valence::prelude::*;
use valence::protocol::{CompressionThreshold, WritePacket};

use self::cache::ChunkCache;
use self::light::Lit;
use self::workers::{Built, Finished, Results, Workers};
use super::dimension::{Palette, WorldSetup};
use super::players::PlayersSet;
use crate::biome::BiomeRules;
use crate::chunkgen::Light;
use crate::pregen::Job;
use crate::world::ChunkSource;

/// How far back "chunks generated per second" looks.
const RATE_WINDOW: Duration = Duration::from_secs(10);

/// The streaming state: workers, finished-chunk cache and counters.
#[derive(Resource)]
pub struct Streamer {
    workers: Workers,
    results: Results,
    cache: ChunkCache,
    /// Chunks whose building panicked: not retried until the rules change.
    failed: HashSet<ChunkPos>,
    /// Every loaded chunk: the rules generation it was built with (only current ones are
    /// cached when unloaded) and its light.
    loaded: HashMap<ChunkPos, Loaded>,
    /// How light packets are compressed (as valence compresses everything else).
    compression: CompressionThreshold,
    last_views: Vec<ChunkView>,
    /// Something changed that may change the wish list.
    dirty: bool,
    stats: Stats,
}

/// What [`Streamer::relight`] gives back.
pub struct Relit {
    /// Per chunk relit, in order: its light when it is right to the last block (joined: all
    /// its neighbours are loaded), else `None`.
    pub lights: Vec<Option<Arc<Light>>>,
    /// The chunks whose light packet clients must get again.
    pub changed: Vec<ChunkPos>,
}

struct Loaded {
    generation: u64,
    lit: Lit,
}

/// Chunks whose light this client has been sent (valence sends chunks without light).
#[derive(Component, Default)]
pub struct LightSent(HashSet<ChunkPos>);

impl LightSent {
    /// Sends the light of `pos` again (it changed).
    pub fn forget(&mut self, pos: ChunkPos) {
        self.0.remove(&pos);
    }
}

/// Counters for the console's `status`.
#[derive(Default)]
struct Stats {
    generated: u64,
    failed: u64,
    build_time: Duration,
    recent: VecDeque<Instant>,
}

/// A snapshot of the streaming counters.
#[derive(Clone, Debug)]
pub struct StreamStatus {
    /// Chunks built since start-up.
    pub generated: u64,
    /// Chunks built per second over the last ten seconds.
    pub per_second: f64,
    /// Mean time to build one chunk on a worker.
    pub mean_build: Duration,
    /// Chunks whose building failed.
    pub failed: u64,
    /// Chunks wanted and not yet started.
    pub queued: usize,
    /// Chunks being built now.
    pub in_flight: usize,
    /// Finished chunks kept for revisits.
    pub cached: usize,
    /// Chunks loaded in the world (in some player's view).
    pub loaded: usize,
}

impl Streamer {
    /// The counters now.
    pub fn status(&mut self) -> StreamStatus {
        self.trim_recent();
        let (queued, in_flight) = self.workers.counts();
        let s = &self.stats;
        StreamStatus {
            generated: s.generated,
            per_second: s.recent.len() as f64 / RATE_WINDOW.as_secs_f64(),
            mean_build: s.build_time.checked_div(s.generated.max(1) as u32).unwrap_or_default(),
            failed: s.failed,
            queued,
            in_flight,
            cached: self.cache.len(),
            loaded: self.loaded.len(),
        }
    }

    /// New chunks are built with `rules`; cached chunks built with the old ones are dropped
    /// so revisited places show the new rules too (chunks on screen stay as they are).
    pub fn set_rules(&mut self, rules: Arc<BiomeRules>) {
        self.workers.set_rules(rules);
        self.cache.clear();
        self.failed.clear();
        self.dirty = true;
    }

    /// Workers take chunks of `job` whenever no player chunk waits (`None`: stop doing so).
    pub fn set_pregen(&self, job: Option<Arc<Job>>) {
        self.workers.set_pregen(job);
    }

    /// Loaded chunks now have these `own` lights (players edited them): their light and
    /// their neighbours' are joined again where they can be.
    pub fn relight(&mut self, owns: Vec<(ChunkPos, Light)>) -> anyhow::Result<Relit> {
        let relit: Vec<ChunkPos> = owns.iter().map(|(pos, _)| *pos).collect();
        let mut around = HashSet::new();
        for (pos, own) in owns {
            if let Some(loaded) = self.loaded.get_mut(&pos) {
                loaded.lit = Lit::alone(pos, own, self.compression)?;
                around.extend(light::area(pos));
            }
        }
        for &p in &around {
            match self.loaded.get_mut(&p) {
                Some(loaded) => loaded.lit.unjoin(),
                // Joined with the blocks before the edit.
                None => self.cache.drop_chunk(p),
            }
        }
        let mut joined = HashMap::new();
        for &p in &around {
            if let Some(light) = self.join(p)? {
                joined.insert(p, Arc::new(light));
            }
        }
        let lights = relit
            .iter()
            .map(|pos| {
                let lit = &self.loaded.get(pos)?.lit;
                lit.is_joined().then(|| joined.get(pos).cloned().unwrap_or_else(|| lit.own.clone()))
            })
            .collect();
        Ok(Relit { lights, changed: around.into_iter().filter(|p| self.loaded.contains_key(p)).collect() })
    }

    /// Joins the light of loaded chunk `pos` with its neighbours' if it is not joined yet
    /// and they are all loaded. Returns the joined light when that let light in (its packet
    /// changed).
    fn join(&mut self, pos: ChunkPos) -> anyhow::Result<Option<Light>> {
        let area = light::area(pos).map(|p| self.loaded.get(&p).map(|l| &*l.lit.own));
        if self.loaded.get(&pos).is_none_or(|l| l.lit.is_joined()) {
            return Ok(None);
        }
        let Some(area) = area.into_iter().collect::<Option<Vec<&Light>>>() else {
            return Ok(None); // A neighbour is not loaded yet.
        };
        let joined = Light::joined(std::array::from_fn(|i| area[i]));
        let compression = self.compression;
        if let Some(loaded) = self.loaded.get_mut(&pos) {
            loaded.lit.set_joined(pos, joined.as_ref(), compression)?;
        }
        Ok(joined)
    }

    /// Joins the light of every chunk around the chunks `inserted` that can be joined now;
    /// returns those whose light packet changed.
    fn join_around(&mut self, inserted: &[ChunkPos]) -> Vec<ChunkPos> {
        let mut around: Vec<ChunkPos> = inserted.iter().flat_map(|&p| light::area(p)).collect();
        around.sort_unstable_by_key(|p| (p.x, p.z));
        around.dedup();
        let mut changed = Vec::new();
        for pos in around {
            match self.join(pos) {
                Ok(Some(_)) => changed.push(pos),
                Ok(None) => {}
                Err(e) => tracing::error!("joined light of chunk {}, {}: {e:#}", pos.x, pos.z),
            }
        }
        changed
    }

    /// Wakes idle workers from any thread (a pre-generation task resumed).
    pub fn waker(&self) -> Waker {
        self.workers.waker()
    }

    fn trim_recent(&mut self) {
        let now = Instant::now();
        while self.stats.recent.front().is_some_and(|t| now.duration_since(*t) > RATE_WINDOW) {
            self.stats.recent.pop_front();
        }
    }
}

/// Adds the streaming systems.
pub fn build(app: &mut App) {
    app.add_systems(PostStartup, start_workers)
        .add_systems(Update, (track_light, stream_chunks.after(PlayersSet)))
        // After valence has written this tick's chunk packets, before they are flushed.
        .add_systems(PostUpdate, send_light.after(UpdateClientsSet).before(FlushPacketsSet));
}

fn start_workers(
    mut commands: Commands,
    setup: Res<WorldSetup>,
    palette: Res<Palette>,
    server: Res<Server>,
    mut exit: EventWriter<AppExit>,
) {
    let (done, results) = mpsc::channel();
    let threads = setup.config.server.chunk_threads as usize;
    let compression = server.compression_threshold();
    let source = Arc::new(ChunkSource::new(setup.generator.clone(), palette.0.clone(), setup.store.clone()));
    match Workers::start(threads, source, setup.rules.clone(), compression, done) {
        Ok(workers) => commands.insert_resource(Streamer {
            workers,
            results: Results::new(results),
            cache: ChunkCache::new(setup.config.server.chunk_cache as usize),
            failed: HashSet::new(),
            loaded: HashMap::new(),
            compression,
            last_views: Vec::new(),
            dirty: true,
            stats: Stats::default(),
        }),
        Err(e) => {
            tracing::error!("cannot start chunk worker threads: {e}");
            exit.send(AppExit);
        }
    }
}

/// Once per tick: take in finished chunks, join the light of those whose neighbours are all
/// loaded now, unload what no view holds, and hand the workers a fresh nearest-first wish
/// list when anything changed. Never waits on a worker.
fn stream_chunks(
    mut layers: Query<&mut ChunkLayer>,
    clients: Query<View, (With<Client>, Without<Despawned>)>,
    mut sent: Query<&mut LightSent>,
    streamer: Option<ResMut<Streamer>>,
) {
    let (Some(mut streamer), Ok(mut layer)) = (streamer, layers.get_single_mut()) else {
        return;
    };
    let s = &mut *streamer;
    let views: Vec<ChunkView> = clients.iter().map(|v| v.get()).collect();
    let wanted = |pos: ChunkPos| views.iter().any(|v| v.contains(pos));
    let generation = s.workers.generation();
    let mut inserted = Vec::new();

    for Finished { pos, built, generation: built_with, elapsed } in s.results.drain() {
        s.workers.finished(pos);
        s.dirty = true;
        let Some(built) = built else {
            s.stats.failed += 1;
            s.failed.insert(pos);
            continue; // The worker logged why; the chunk stays missing until a reload.
        };
        s.stats.generated += 1;
        s.stats.build_time += elapsed;
        s.stats.recent.push_back(Instant::now());
        if wanted(pos) && layer.chunk(pos).is_none() {
            layer.insert_chunk(pos, built.chunk);
            s.loaded.insert(pos, Loaded { generation: built_with, lit: built.lit });
            inserted.push(pos);
        } else if built_with == generation {
            s.cache.put(pos, built);
        }
    }
    s.trim_recent();

    if views != s.last_views {
        s.dirty = true;
        let gone: Vec<ChunkPos> = layer.chunks().map(|(pos, _)| pos).filter(|&pos| !wanted(pos)).collect();
        for pos in gone {
            let loaded = s.loaded.remove(&pos);
            if let (Some(chunk), Some(loaded)) = (layer.remove_chunk(pos), loaded) {
                if loaded.generation == generation {
                    s.cache.put(pos, Built { chunk, lit: loaded.lit });
                }
            }
        }
        s.last_views = views.clone();
    }

    if s.dirty {
        s.dirty = false;
        let mut nearest: HashMap<ChunkPos, u64> = HashMap::new();
        for view in &views {
            for pos in view.iter() {
                if layer.chunk(pos).is_some() || s.failed.contains(&pos) {
                    continue;
                }
                if let Some(built) = s.cache.take(pos) {
                    layer.insert_chunk(pos, built.chunk);
                    s.loaded.insert(pos, Loaded { generation, lit: built.lit });
                    inserted.push(pos);
                    continue;
                }
                let d = view.pos.distance_squared(pos);
                nearest.entry(pos).and_modify(|e| *e = (*e).min(d)).or_insert(d);
            }
        }
        let mut list: Vec<(u64, ChunkPos)> = nearest.into_iter().map(|(pos, d)| (d, pos)).collect();
        list.sort_unstable_by_key(|&(d, pos)| (d, pos.x, pos.z));
        s.workers.set_wanted(list.into_iter().map(|(_, pos)| pos));
    }

    for pos in s.join_around(&inserted) {
        for mut sent in &mut sent {
            sent.forget(pos);
        }
    }
}

fn track_light(mut commands: Commands, joined: Query<Entity, Added<Client>>) {
    for entity in &joined {
        commands.entity(entity).insert(LightSent::default());
    }
}

/// Every loaded chunk in a client's view has been sent to it by now (valence does that in
/// `UpdateClientsSet`); follow each one it has not had light for with its light packet.
fn send_light(mut clients: Query<(&mut Client, View, &mut LightSent)>, streamer: Option<Res<Streamer>>) {
    let Some(streamer) = streamer else {
        return;
    };
    for (mut client, view, mut sent) in &mut clients {
        let view = view.get();
        // Chunks that left the view are forgotten by the client; resend if they come back.
        sent.0.retain(|&pos| view.contains(pos));
        for pos in view.iter() {
            if !sent.0.contains(&pos) {
                if let Some(loaded) = streamer.loaded.get(&pos) {
                    client.write_packet_bytes(loaded.lit.packet());
                    sent.0.insert(pos);
                }
            }
        }
    }
}
