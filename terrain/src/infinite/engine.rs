//! The shared window cache, the in-flight registry and the worker threads.
//!
//! One [`Engine`] serves every windowed tensor of a pipeline, like the paper's single LRU
//! shared by all stages. The cache holds each window's weighted contribution `W ⊙ Φ` and is
//! bounded in bytes; evicting an entry only means that window will be recomputed when asked
//! for again. A window being computed is marked in flight, so two queries never compute the
//! same window at once: the second waits for the first.
//!
//! Why waiting cannot deadlock: a thread only waits for windows of tensor `T` after it has
//! finished every window of `T` it claimed itself, and computing a window of `T` only queries
//! tensors strictly below `T` in the stage DAG. Every wait therefore points strictly down the
//! DAG, so no cycle of waits can form. (This is also why the workers are plain scoped
//! threads and not a work-stealing pool: a stolen task blocking under its own stack frame
//! would break that argument.)

use std::collections::HashSet;
use std::num::NonZeroUsize;
use std::sync::atomic::Ordering;
use std::sync::{Arc, Condvar, Mutex, MutexGuard};

use lru::LruCache;

/// Identifies one window of one tensor in the shared cache.
pub(crate) type WindowKey = (u32, i64, i64);

/// Bookkeeping bytes charged per cache entry on top of its values.
const ENTRY_OVERHEAD: usize = 96;

/// Engine-wide settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EngineConfig {
    /// Upper bound on the bytes of cached window contributions.
    pub cache_bytes: usize,
    /// Worker threads used to evaluate the missing windows of one query.
    pub threads: usize,
}

impl Default for EngineConfig {
    fn default() -> Self {
        EngineConfig { cache_bytes: 256 << 20, threads: 2 }
    }
}

/// Counters that describe what the engine has done so far.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EngineStats {
    /// Windows whose Φ has been evaluated (recomputations after eviction included).
    pub windows_evaluated: u64,
    /// Window lookups answered from the cache.
    pub cache_hits: u64,
    /// Entries evicted to stay under the byte limit.
    pub evictions: u64,
    /// Bytes cached now.
    pub cache_bytes: usize,
    /// The most bytes ever cached at once.
    pub peak_cache_bytes: usize,
    /// Windows cached now.
    pub cached_windows: usize,
}

/// What one window function (one [`WindowFn`](super::WindowFn) by name) has cost so far.
#[derive(Clone, Debug, PartialEq)]
pub struct FunctionStats {
    /// The function's name ([`WindowFn::name`](super::WindowFn::name)).
    pub name: String,
    /// Windows it evaluated (recomputations after eviction included).
    pub windows: u64,
    /// Seconds its evaluations took, summed over threads: inclusive, so a function that
    /// queries another (the drainage reads the learned relief) counts the windows it waited
    /// for too.
    pub seconds: f64,
}

struct State {
    lru: LruCache<WindowKey, Arc<[f32]>>,
    bytes: usize,
    peak_bytes: usize,
    in_flight: HashSet<WindowKey>,
    hits: u64,
    evictions: u64,
}

/// Where a looked-up window stands.
pub(crate) enum Lookup {
    /// Cached: here is its contribution.
    Ready(Arc<[f32]>),
    /// Another query is computing it.
    InFlight,
    /// Nobody has it: the caller now owns computing it.
    Claimed,
}

/// The shared cache and thread settings of a set of windowed tensors.
pub struct Engine {
    state: Mutex<State>,
    settled: Condvar,
    limit: usize,
    threads: usize,
    /// Per registered tensor (index: its id); every count of windows evaluated comes from here.
    functions: Mutex<Vec<FunctionStats>>,
}

impl Engine {
    /// A new engine with an empty cache.
    pub fn new(config: EngineConfig) -> Arc<Engine> {
        Arc::new(Engine {
            state: Mutex::new(State {
                lru: LruCache::unbounded(),
                bytes: 0,
                peak_bytes: 0,
                in_flight: HashSet::new(),
                hits: 0,
                evictions: 0,
            }),
            settled: Condvar::new(),
            limit: config.cache_bytes,
            threads: config.threads.max(1),
            functions: Mutex::new(Vec::new()),
        })
    }

    /// The cache's byte limit.
    pub fn cache_limit(&self) -> usize {
        self.limit
    }

    /// Worker threads per query.
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// A snapshot of the counters.
    pub fn stats(&self) -> EngineStats {
        let s = self.lock();
        EngineStats {
            windows_evaluated: self.functions().iter().map(|f| f.windows).sum(),
            cache_hits: s.hits,
            evictions: s.evictions,
            cache_bytes: s.bytes,
            peak_cache_bytes: s.peak_bytes,
            cached_windows: s.lru.len(),
        }
    }

    /// Drops every cached window (the next queries recompute them, identically).
    pub fn clear(&self) {
        let mut s = self.lock();
        s.lru.clear();
        s.bytes = 0;
    }

    /// What each window function has evaluated so far and how long it took, one entry per
    /// name, in the order they were first registered (where a query's time goes).
    pub fn function_stats(&self) -> Vec<FunctionStats> {
        let functions = self.functions();
        let mut out: Vec<FunctionStats> = Vec::new();
        for f in functions.iter() {
            match out.iter_mut().find(|o| o.name == f.name) {
                Some(o) => {
                    o.windows += f.windows;
                    o.seconds += f.seconds;
                }
                None => out.push(f.clone()),
            }
        }
        out
    }

    /// Windows tensor `id` has evaluated.
    pub(crate) fn evaluations_of(&self, id: u32) -> u64 {
        self.functions().get(id as usize).map_or(0, |f| f.windows)
    }

    fn functions(&self) -> MutexGuard<'_, Vec<FunctionStats>> {
        // Counters only: a panic mid-update leaves them consistent enough to keep.
        self.functions.lock().unwrap_or_else(|e| e.into_inner())
    }

    pub(crate) fn register(&self, name: &str) -> u32 {
        let mut functions = self.functions();
        let id = functions.len() as u32;
        functions.push(FunctionStats { name: name.to_string(), windows: 0, seconds: 0.0 });
        id
    }

    /// Tensor `id` evaluated `n` windows in `seconds`.
    pub(crate) fn count_evaluations(&self, id: u32, n: usize, seconds: f64) {
        if let Some(f) = self.functions().get_mut(id as usize) {
            f.windows += n as u64;
            f.seconds += seconds;
        }
    }

    fn lock(&self) -> MutexGuard<'_, State> {
        // A panic while holding the lock cannot leave the state inconsistent (every update
        // is a single insert/remove), so a poisoned lock is safe to keep using.
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Looks up several windows under one lock, claiming the ones nobody has.
    pub(crate) fn lookup(&self, keys: impl Iterator<Item = WindowKey>) -> Vec<Lookup> {
        let mut s = self.lock();
        keys.map(|k| {
            if let Some(v) = s.lru.get(&k) {
                let v = v.clone();
                s.hits += 1;
                Lookup::Ready(v)
            } else if s.in_flight.contains(&k) {
                Lookup::InFlight
            } else {
                s.in_flight.insert(k);
                Lookup::Claimed
            }
        })
        .collect()
    }

    /// Stores a computed contribution and wakes whoever waits for it.
    pub(crate) fn publish(&self, key: WindowKey, value: Arc<[f32]>) {
        let size = value.len() * 4 + ENTRY_OVERHEAD;
        let mut s = self.lock();
        s.in_flight.remove(&key);
        if size <= self.limit {
            if let Some(old) = s.lru.put(key, value) {
                s.bytes -= old.len() * 4 + ENTRY_OVERHEAD;
            }
            s.bytes += size;
            while s.bytes > self.limit {
                match s.lru.pop_lru() {
                    Some((_, v)) => {
                        s.bytes -= v.len() * 4 + ENTRY_OVERHEAD;
                        s.evictions += 1;
                    }
                    None => break,
                }
            }
            s.peak_bytes = s.peak_bytes.max(s.bytes);
        }
        drop(s);
        self.settled.notify_all();
    }

    /// Gives up claims that will not be published (the computation panicked).
    pub(crate) fn abandon(&self, keys: &[WindowKey]) {
        let mut s = self.lock();
        for k in keys {
            s.in_flight.remove(k);
        }
        drop(s);
        self.settled.notify_all();
    }

    /// Blocks until none of `keys` is in flight any more.
    pub(crate) fn wait_settled(&self, keys: &[WindowKey]) {
        let mut s = self.lock();
        while keys.iter().any(|k| s.in_flight.contains(k)) {
            s = self.settled.wait(s).unwrap_or_else(|e| e.into_inner());
        }
    }

    /// Applies `f` to every item on up to [`Engine::threads`] scoped threads; results keep
    /// the items' order.
    pub fn par_map<T: Sync, R: Send>(&self, items: &[T], f: impl Fn(&T) -> R + Sync) -> Vec<R> {
        let workers = self.threads.min(items.len());
        if workers <= 1 {
            return items.iter().map(f).collect();
        }
        let next = std::sync::atomic::AtomicUsize::new(0);
        let slots: Vec<Mutex<Option<R>>> = items.iter().map(|_| Mutex::new(None)).collect();
        std::thread::scope(|scope| {
            for _ in 0..workers {
                scope.spawn(|| loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    if i >= items.len() {
                        break;
                    }
                    let r = f(&items[i]);
                    *slots[i].lock().unwrap_or_else(|e| e.into_inner()) = Some(r);
                });
            }
        });
        slots
            .into_iter()
            .map(|m| m.into_inner().unwrap_or_else(|e| e.into_inner()).expect("every item was mapped"))
            .collect()
    }
}

/// Keeps an LRU type name out of the public API while letting tests size caches in windows.
pub fn cache_capacity_hint(windows: usize, window_bytes: usize) -> usize {
    NonZeroUsize::new(windows).map_or(0, |n| n.get() * (window_bytes + ENTRY_OVERHEAD))
}
