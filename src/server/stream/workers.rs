//! Chunk workers: threads that take the nearest wanted chunk, build it (or load it from the
//! saved world), and hand it back. With no player chunk waiting, they work on the console's
//! pre-generation task, so players' chunks always come first.
//!
//! The main thread owns the wish list and rewrites it whenever views change, so a chunk that
//! is no longer wanted is simply gone from the list before any worker starts it (cancelled
//! for free). Only the `threads` chunks being built are ever in flight. The main thread only
//! ever holds the lock for a swap or a counter read: it never waits on terrain.

use std::collections::HashSet;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::mpsc::{Receiver, Sender};
use std::sync::{Arc, Condvar, Mutex, MutexGuard, PoisonError};
use std::thread::{self, JoinHandle};
use std::time::{Duration, Instant};

use valence::prelude::{ChunkPos, UnloadedChunk};
use valence::protocol::CompressionThreshold;

use super::light::Lit;
use crate::biome::BiomeRules;
use crate::pregen::{self, Job};
use crate::world::{ChunkSource, Origin, Scratch};

/// A chunk ready to insert, with its light.
pub struct Built {
    /// The blocks and biomes.
    pub chunk: UnloadedChunk,
    /// Its light, with the packet for it ready to send.
    pub lit: Lit,
}

/// A chunk a worker finished (or failed to build).
pub struct Finished {
    /// Where it goes.
    pub pos: ChunkPos,
    /// The chunk; `None` when building it failed (a bug, logged by the server).
    pub built: Option<Built>,
    /// The rules generation it was built with (see [`Workers::set_rules`]).
    pub generation: u64,
    /// How long it took.
    pub elapsed: Duration,
}

struct Queue {
    /// Wanted chunks, farthest first: workers pop the nearest from the end.
    pending: Vec<ChunkPos>,
    in_flight: HashSet<ChunkPos>,
    rules: Arc<BiomeRules>,
    generation: u64,
    /// The pre-generation task worked on when no player chunk waits.
    pregen: Option<Arc<Job>>,
    shutdown: bool,
}

struct Shared {
    queue: Mutex<Queue>,
    wake: Condvar,
}

impl Shared {
    /// A poisoned lock only means a worker panicked while holding it; the queue is plain data
    /// that is valid after any completed statement, so keep going.
    fn lock(&self) -> MutexGuard<'_, Queue> {
        self.queue.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

/// The worker pool and its queue.
pub struct Workers {
    shared: Arc<Shared>,
    _threads: Vec<JoinHandle<()>>,
}

impl Workers {
    /// Starts `threads` workers getting chunks from `source` with `rules`, sending results to
    /// `done`.
    pub fn start(
        threads: usize,
        source: Arc<ChunkSource>,
        rules: Arc<BiomeRules>,
        compression: CompressionThreshold,
        done: Sender<Finished>,
    ) -> std::io::Result<Workers> {
        let shared = Arc::new(Shared {
            queue: Mutex::new(Queue {
                pending: Vec::new(),
                in_flight: HashSet::new(),
                rules,
                generation: 0,
                pregen: None,
                shutdown: false,
            }),
            wake: Condvar::new(),
        });
        let mut handles = Vec::with_capacity(threads);
        for i in 0..threads.max(1) {
            let (shared, source, done) = (shared.clone(), source.clone(), done.clone());
            let handle = thread::Builder::new()
                .name(format!("chunk-worker-{i}"))
                .spawn(move || work(&shared, &source, compression, &done))?;
            handles.push(handle);
        }
        Ok(Workers { shared, _threads: handles })
    }

    /// Replaces the wish list (`nearest_first`: most urgent first). Chunks being built are
    /// skipped; everything not listed is dropped.
    pub fn set_wanted(&self, nearest_first: impl DoubleEndedIterator<Item = ChunkPos>) {
        let mut q = self.shared.lock();
        let in_flight = std::mem::take(&mut q.in_flight);
        q.pending.clear();
        q.pending.extend(nearest_first.rev().filter(|p| !in_flight.contains(p)));
        q.in_flight = in_flight;
        drop(q);
        self.shared.wake.notify_all();
    }

    /// Marks a chunk as no longer being built (its result arrived).
    pub fn finished(&self, pos: ChunkPos) {
        self.shared.lock().in_flight.remove(&pos);
    }

    /// Chunks built from now on use `rules`; returns the new generation number.
    pub fn set_rules(&self, rules: Arc<BiomeRules>) -> u64 {
        let mut q = self.shared.lock();
        q.rules = rules;
        q.generation += 1;
        q.generation
    }

    /// Works on `job` whenever no player chunk waits (`None`: no task).
    pub fn set_pregen(&self, job: Option<Arc<Job>>) {
        self.shared.lock().pregen = job;
        self.shared.wake.notify_all();
    }

    /// A handle that wakes idle workers from any thread.
    pub fn waker(&self) -> Waker {
        Waker(self.shared.clone())
    }

    /// The current rules generation.
    pub fn generation(&self) -> u64 {
        self.shared.lock().generation
    }

    /// (waiting, in flight) job counts.
    pub fn counts(&self) -> (usize, usize) {
        let q = self.shared.lock();
        (q.pending.len(), q.in_flight.len())
    }
}

impl Drop for Workers {
    /// Workers finish the chunk in hand and exit; nobody waits for them (the process is
    /// ending or the pool is being replaced).
    fn drop(&mut self) {
        self.shared.lock().shutdown = true;
        self.shared.wake.notify_all();
    }
}

/// Wakes idle workers (used by a pre-generation task when it resumes).
#[derive(Clone)]
pub struct Waker(Arc<Shared>);

impl Waker {
    /// Wakes every idle worker. Taking the lock first means a worker between "nothing to do"
    /// and waiting cannot miss it.
    pub fn wake(&self) {
        drop(self.0.lock());
        self.0.wake.notify_all();
    }
}

/// What a worker does next.
enum Task {
    Player(ChunkPos, Arc<BiomeRules>, u64),
    Pregen(Arc<Job>, u64, (i32, i32), Arc<BiomeRules>),
}

fn work(shared: &Shared, source: &ChunkSource, compression: CompressionThreshold, done: &Sender<Finished>) {
    let mut scratch = source.scratch();
    loop {
        let task = {
            let mut q = shared.lock();
            loop {
                if q.shutdown {
                    return;
                }
                if let Some(pos) = q.pending.pop() {
                    q.in_flight.insert(pos);
                    break Task::Player(pos, q.rules.clone(), q.generation);
                }
                if let Some(job) = q.pregen.clone() {
                    if let Some((n, pos)) = job.take() {
                        break Task::Pregen(job, n, pos, q.rules.clone());
                    }
                }
                q = shared.wake.wait(q).unwrap_or_else(PoisonError::into_inner);
            }
        };
        let (pos, rules, generation) = match task {
            Task::Player(pos, rules, generation) => (pos, rules, generation),
            Task::Pregen(job, n, pos, rules) => {
                pregen::generate(&job, source, &mut scratch, &rules, n, pos);
                continue;
            }
        };
        let start = Instant::now();
        // A panic in one chunk must not take the worker (and all later chunks) with it.
        let built = catch_unwind(AssertUnwindSafe(|| build(source, &mut scratch, &rules, compression, pos)))
            .unwrap_or_else(|_| Err(anyhow::anyhow!("building it panicked (see above)")));
        let built = built.map_err(|e| tracing::error!("chunk {} {}: {e:#}", pos.x, pos.z)).ok();
        let finished = Finished { pos, built, generation, elapsed: start.elapsed() };
        if done.send(finished).is_err() {
            return; // The server is gone.
        }
    }
}

/// Loads or builds one chunk and encodes its light packet. An unreadable saved chunk is
/// reported on the console and regenerated.
fn build(
    source: &ChunkSource,
    scratch: &mut Scratch,
    rules: &BiomeRules,
    compression: CompressionThreshold,
    pos: ChunkPos,
) -> anyhow::Result<Built> {
    let (chunk, light, origin) = source.get(scratch, rules, pos.x, pos.z);
    if let Origin::Regenerated(reason) = origin {
        say!("corrupt chunk {}, {}: {reason}; regenerated it", pos.x, pos.z);
    }
    Ok(Built { chunk, lit: Lit::alone(pos, light, compression)? })
}

/// The receiving end, wrapped so a Bevy resource (which must be `Sync`) can own it.
pub struct Results(Mutex<Receiver<Finished>>);

impl Results {
    /// Wraps a receiver.
    pub fn new(receiver: Receiver<Finished>) -> Results {
        Results(Mutex::new(receiver))
    }

    /// Every result available now, without waiting.
    pub fn drain(&self) -> Vec<Finished> {
        let receiver = self.0.lock().unwrap_or_else(PoisonError::into_inner);
        receiver.try_iter().collect()
    }
}
