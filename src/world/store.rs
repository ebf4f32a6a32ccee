//! The region files of one world, shared by every thread: reads under a per-file lock,
//! writes queued to one writer thread so generation never waits on the disk (until the
//! queue is full, which bounds the memory of chunks not yet written).

use std::collections::HashMap;
use std::num::NonZeroUsize;
use std::path::{Path, PathBuf};
use std::sync::mpsc::{self, Receiver, SyncSender};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError, Weak};
use std::thread::JoinHandle;
use std::time::{SystemTime, UNIX_EPOCH};

use lru::LruCache;

use super::region::{self, ChunkError, RegionError, RegionFile, RegionPos};

/// Region files kept open at once (each is one file descriptor).
const OPEN_FILES: usize = 64;
/// Compressed chunks waiting for the writer before producers block (≈ 10 KB each).
const QUEUE: usize = 512;

/// Why a store operation failed.
#[derive(Debug, thiserror::Error)]
pub enum StoreError {
    /// The region file could not be opened or created.
    #[error(transparent)]
    Region(#[from] RegionError),
    /// A chunk's stored bytes are unreadable.
    #[error("chunk {x}, {z} in {file}: {source}")]
    Chunk {
        /// Chunk x.
        x: i32,
        /// Chunk z.
        z: i32,
        /// The region file.
        file: PathBuf,
        /// What is wrong.
        source: ChunkError,
    },
    /// Writing failed (disk full, permission denied…); the chunk named is not saved.
    #[error("cannot save chunk {x}, {z} to {file}: {message}")]
    Write {
        /// Chunk x.
        x: i32,
        /// Chunk z.
        z: i32,
        /// The region file.
        file: PathBuf,
        /// The operating system's reason.
        message: String,
    },
    /// Flushing a region file to disk failed: chunks written since the last flush may be lost.
    #[error("cannot flush {file} to disk: {message}")]
    Sync {
        /// The region file.
        file: PathBuf,
        /// The operating system's reason.
        message: String,
    },
    /// The writer thread is gone (it could not start, or the store is shutting down).
    #[error("the region writer thread is not running")]
    WriterGone,
}

enum Job {
    Write {
        x: i32,
        z: i32,
        zlib: Vec<u8>,
    },
    /// Write out everything queued before this, fsync the files touched, then answer.
    Flush(SyncSender<Result<(), StoreError>>),
}

struct Files {
    dir: PathBuf,
    open: Mutex<LruCache<RegionPos, Arc<Mutex<RegionFile>>>>,
    /// Every instance still in use, evicted from `open` or not: a file must never have two
    /// instances at once, or their in-memory headers would disagree about free sectors.
    live: Mutex<HashMap<RegionPos, Weak<Mutex<RegionFile>>>>,
}

impl Files {
    fn lock_open(&self) -> MutexGuard<'_, LruCache<RegionPos, Arc<Mutex<RegionFile>>>> {
        self.open.lock().unwrap_or_else(PoisonError::into_inner)
    }

    fn path(&self, pos: RegionPos) -> PathBuf {
        self.dir.join(pos.file_name())
    }

    /// The open file of region `pos`; `None` when it does not exist and `create` is false.
    fn get(&self, pos: RegionPos, create: bool) -> Result<Option<Arc<Mutex<RegionFile>>>, StoreError> {
        if let Some(file) = self.lock_open().get(&pos) {
            return Ok(Some(file.clone()));
        }
        let path = self.path(pos);
        if !create && !path.exists() {
            return Ok(None);
        }
        if create {
            std::fs::create_dir_all(&self.dir).map_err(|source| RegionError::Io { path: self.dir.clone(), source })?;
        }
        // Opening happens under the `live` lock, so two threads cannot open the same file twice,
        // and an instance evicted from the LRU but still held elsewhere is reused.
        let mut live = self.live.lock().unwrap_or_else(PoisonError::into_inner);
        let file = match live.get(&pos).and_then(Weak::upgrade) {
            Some(file) => file,
            None => {
                let file = Arc::new(Mutex::new(RegionFile::open(&path, create)?));
                live.retain(|_, w| w.strong_count() > 0);
                live.insert(pos, Arc::downgrade(&file));
                file
            }
        };
        self.lock_open().put(pos, file.clone());
        Ok(Some(file))
    }
}

fn lock(file: &Mutex<RegionFile>) -> MutexGuard<'_, RegionFile> {
    file.lock().unwrap_or_else(PoisonError::into_inner)
}

/// The saved chunks of one world (`<world>/region/`).
pub struct Store {
    files: Arc<Files>,
    jobs: Mutex<Option<SyncSender<Job>>>,
    writer: Mutex<Option<JoinHandle<()>>>,
    /// The first write error since the last [`Store::flush`], kept so producers can stop.
    failure: Arc<Mutex<Option<String>>>,
}

impl Store {
    /// The store of the world in `world_dir` (region files go in its `region/` folder, made
    /// when the first chunk is written). Starts the writer thread.
    pub fn open(world_dir: &Path) -> std::io::Result<Store> {
        let files = Arc::new(Files {
            dir: world_dir.join("region"),
            open: Mutex::new(LruCache::new(NonZeroUsize::new(OPEN_FILES).expect("non-zero"))),
            live: Mutex::new(HashMap::new()),
        });
        let (jobs, queue) = mpsc::sync_channel(QUEUE);
        let failure = Arc::new(Mutex::new(None));
        let (writer_files, writer_failure) = (files.clone(), failure.clone());
        let writer = std::thread::Builder::new()
            .name("region-writer".into())
            .spawn(move || write_loop(&writer_files, &queue, &writer_failure))?;
        Ok(Store { files, jobs: Mutex::new(Some(jobs)), writer: Mutex::new(Some(writer)), failure })
    }

    /// The folder holding the region files.
    pub fn region_dir(&self) -> &Path {
        &self.files.dir
    }

    /// True when chunk (`x`, `z`) is saved (its bytes may still turn out corrupt).
    pub fn contains(&self, x: i32, z: i32) -> Result<bool, StoreError> {
        let Some(file) = self.files.get(RegionPos::of_chunk(x, z), false)? else { return Ok(false) };
        let (lx, lz) = region::local(x, z);
        let present = lock(&file).contains(lx, lz);
        Ok(present)
    }

    /// The uncompressed NBT of chunk (`x`, `z`), `None` when it is not saved, an error naming
    /// the chunk and the file when its bytes are unreadable.
    pub fn load(&self, x: i32, z: i32) -> Result<Option<Vec<u8>>, StoreError> {
        let pos = RegionPos::of_chunk(x, z);
        let Some(file) = self.files.get(pos, false)? else { return Ok(None) };
        let (lx, lz) = region::local(x, z);
        let read = lock(&file).read(lx, lz);
        read.map_err(|source| StoreError::Chunk { x, z, file: self.files.path(pos), source })
    }

    /// Queues chunk (`x`, `z`) for writing: compresses `nbt` on the calling thread, then hands
    /// it to the writer (waiting only while the queue is full).
    pub fn save(&self, x: i32, z: i32, nbt: &[u8]) -> Result<(), StoreError> {
        let zlib = region::compress(nbt);
        let jobs = self.jobs.lock().unwrap_or_else(PoisonError::into_inner).clone();
        let jobs = jobs.ok_or(StoreError::WriterGone)?;
        jobs.send(Job::Write { x, z, zlib }).map_err(|_| StoreError::WriterGone)
    }

    /// The first write error since the last flush, if any (producers stop on it).
    pub fn failure(&self) -> Option<String> {
        self.failure.lock().unwrap_or_else(PoisonError::into_inner).clone()
    }

    /// Waits until everything saved so far is written and fsynced. An error means some chunk
    /// queued since the previous flush may not be on disk; it clears the recorded failure,
    /// so a later flush reports only newer trouble.
    pub fn flush(&self) -> Result<(), StoreError> {
        let jobs = self.jobs.lock().unwrap_or_else(PoisonError::into_inner).clone();
        flush_through(&jobs.ok_or(StoreError::WriterGone)?)
    }

    /// Flushes, then stops the writer thread. Closing a closed store does nothing and returns
    /// `Ok`: the owner closes explicitly to see the error, and `Drop` closes again.
    pub fn close(&self) -> Result<(), StoreError> {
        // Taking the sender under its lock makes exactly one caller the closer.
        let Some(jobs) = self.jobs.lock().unwrap_or_else(PoisonError::into_inner).take() else {
            return Ok(());
        };
        let flushed = flush_through(&jobs);
        drop(jobs);
        if let Some(writer) = self.writer.lock().unwrap_or_else(PoisonError::into_inner).take() {
            let _ = writer.join();
        }
        flushed
    }
}

impl Drop for Store {
    fn drop(&mut self) {
        if let Err(e) = self.close() {
            tracing::error!("saving the world: {e}");
        }
    }
}

/// Asks the writer behind `jobs` to write and fsync everything queued, and waits for it.
fn flush_through(jobs: &SyncSender<Job>) -> Result<(), StoreError> {
    let (answer, reply) = mpsc::sync_channel(1);
    jobs.send(Job::Flush(answer)).map_err(|_| StoreError::WriterGone)?;
    reply.recv().map_err(|_| StoreError::WriterGone)?
}

fn write_loop(files: &Files, queue: &Receiver<Job>, failure: &Mutex<Option<String>>) {
    let mut dirty: Vec<Arc<Mutex<RegionFile>>> = Vec::new();
    let mut first_error: Option<StoreError> = None;
    for job in queue {
        match job {
            Job::Write { x, z, zlib } => {
                let pos = RegionPos::of_chunk(x, z);
                let written = files.get(pos, true).and_then(|file| {
                    let file = file.expect("created");
                    let (lx, lz) = region::local(x, z);
                    lock(&file).write(lx, lz, &zlib, now_seconds()).map_err(|e| StoreError::Write {
                        x,
                        z,
                        file: files.path(pos),
                        message: e.to_string(),
                    })?;
                    if !dirty.iter().any(|d| Arc::ptr_eq(d, &file)) {
                        dirty.push(file);
                    }
                    Ok(())
                });
                if let Err(e) = written {
                    let mut failed = failure.lock().unwrap_or_else(PoisonError::into_inner);
                    failed.get_or_insert_with(|| e.to_string());
                    first_error.get_or_insert(e);
                }
            }
            Job::Flush(answer) => {
                let mut result = first_error.take().map_or(Ok(()), Err);
                for file in dirty.drain(..) {
                    let file = lock(&file);
                    if let Err(e) = file.sync() {
                        if result.is_ok() {
                            result = Err(StoreError::Sync { file: file.path().to_path_buf(), message: e.to_string() });
                        }
                    }
                }
                *failure.lock().unwrap_or_else(PoisonError::into_inner) = None;
                let _ = answer.send(result);
            }
        }
    }
}

/// Region files record when each chunk was saved (seconds since 1970); not part of the
/// chunk's data, so it does not affect determinism of what is saved.
fn now_seconds() -> u32 {
    SystemTime::now().duration_since(UNIX_EPOCH).map_or(0, |d| d.as_secs() as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn nbt_of(x: i32, z: i32) -> Vec<u8> {
        // Distinct, compressible bytes per chunk (the store does not parse them).
        (0..3000u32).map(|i| (i as i32 ^ x.wrapping_mul(31) ^ z.wrapping_mul(17)) as u8 / 7).collect()
    }

    #[test]
    fn chunks_round_trip_across_more_region_files_than_stay_open() {
        let dir = tempfile::tempdir().expect("temp dir");
        let store = Store::open(dir.path()).expect("store");
        // 100 regions (more than OPEN_FILES), two chunks each, reads interleaved with writes.
        let chunks: Vec<(i32, i32)> =
            (0..100).flat_map(|r: i32| [(r * 32 - 1600, -(r % 7) * 32), (r * 32 - 1599, -(r % 7) * 32 + 5)]).collect();
        for (i, &(x, z)) in chunks.iter().enumerate() {
            store.save(x, z, &nbt_of(x, z)).expect("save");
            if i % 3 == 0 {
                store.flush().expect("flush");
                let (px, pz) = chunks[i / 2];
                assert_eq!(store.load(px, pz).expect("load"), Some(nbt_of(px, pz)), "chunk {px}, {pz}");
            }
        }
        store.close().expect("close");
        let again = Store::open(dir.path()).expect("reopen");
        for &(x, z) in &chunks {
            assert!(again.contains(x, z).expect("contains"));
            assert_eq!(again.load(x, z).expect("load"), Some(nbt_of(x, z)), "chunk {x}, {z}");
        }
        assert_eq!(again.load(5000, 5000).expect("absent"), None);
        assert!(!again.contains(5000, 5000).expect("absent"));
    }

    #[test]
    fn closing_twice_is_a_quiet_no_op() {
        let dir = tempfile::tempdir().expect("temp dir");
        let store = Store::open(dir.path()).expect("store");
        store.save(3, 4, &nbt_of(3, 4)).expect("save");
        store.close().expect("first close");
        // The second close (as `Drop` does after an explicit one) neither fails nor logs.
        store.close().expect("second close is Ok");
        assert!(matches!(store.save(0, 0, &nbt_of(0, 0)), Err(StoreError::WriterGone)));
        drop(store);
        let again = Store::open(dir.path()).expect("reopen");
        assert_eq!(again.load(3, 4).expect("load"), Some(nbt_of(3, 4)));
    }

    #[test]
    fn a_failed_write_is_reported_by_flush_with_the_file_and_then_cleared() {
        let dir = tempfile::tempdir().expect("temp dir");
        // The region folder is a file: nothing can be created in it.
        std::fs::write(dir.path().join("region"), b"not a folder").expect("write");
        let store = Store::open(dir.path()).expect("store");
        store.save(0, 0, &nbt_of(0, 0)).expect("queued");
        let err = store.flush().expect_err("the write failed").to_string();
        assert!(err.contains("region"), "{err}");
        assert_eq!(store.failure(), None, "flush clears the recorded failure");
        assert!(store.flush().is_ok(), "nothing new failed");
    }
}
