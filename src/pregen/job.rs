//! A running pre-generation task: hands chunk ordinals to whichever threads do the work
//! (the server's chunk workers between players' chunks, or the batch command's threads),
//! tracks which prefix of the order is finished, and saves it every few seconds once the
//! region files holding it are fsynced.

use std::collections::{BTreeSet, VecDeque};
use std::path::PathBuf;
use std::sync::{Arc, Condvar, Mutex, MutexGuard, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use super::plan::Plan;
use super::progress::{Progress, State};
use crate::world::Store;

/// How often progress is made durable.
const CHECKPOINT: Duration = Duration::from_secs(2);
/// How often a progress line is printed while running, unless told otherwise.
pub const REPORT_EVERY: Duration = Duration::from_secs(5);
/// How far back the rate looks.
const RATE_WINDOW: Duration = Duration::from_secs(15);

/// Where a job stands now (for `pregen progress` and the periodic line).
#[derive(Clone, Debug, PartialEq)]
pub struct Status {
    /// Chunks finished (a prefix of the order, plus those finished beyond it).
    pub done: u64,
    /// Chunks in the plan.
    pub total: u64,
    /// Chunks per second over the last seconds.
    pub rate: f64,
    /// Seconds left at that rate.
    pub eta_s: Option<f64>,
    /// The chunk most recently started.
    pub current: Option<(i32, i32)>,
    /// Running, paused or finished.
    pub state: State,
    /// Why it paused, if an error paused it.
    pub error: Option<String>,
    /// True once cancelled.
    pub cancelled: bool,
}

impl Status {
    /// One line for the owner: done/total, percent, rate, ETA, position.
    pub fn line(&self) -> String {
        let percent = if self.total == 0 { 100.0 } else { 100.0 * self.done as f64 / self.total as f64 };
        let mut line = format!(
            "pregen: {}/{} chunks ({percent:.1}%), {:.0} chunks/s",
            thousands(self.done),
            thousands(self.total),
            self.rate
        );
        match self.state {
            State::Finished => line.push_str(", finished"),
            State::Paused => line.push_str(", paused"),
            State::Running => {
                if let Some(eta) = self.eta_s {
                    line.push_str(&format!(", ETA {}", duration(eta)));
                }
            }
        }
        if let Some((x, z)) = self.current {
            line.push_str(&format!(", at chunk {x}, {z} (block {}, {})", x * 16 + 8, z * 16 + 8));
        }
        if let Some(e) = &self.error {
            line.push_str(&format!(": {e}"));
        }
        line
    }
}

struct Inner {
    /// Next ordinal to hand out.
    next: u64,
    /// Every ordinal below this is finished.
    prefix: u64,
    /// Finished ordinals at or above `prefix`.
    above: BTreeSet<u64>,
    /// The prefix that is saved in the progress file (and so on disk).
    durable: u64,
    state: State,
    error: Option<String>,
    cancelled: bool,
    /// The process is stopping: save where it stands (as running) and hand out nothing more.
    stopping: bool,
    current: Option<(i32, i32)>,
    /// The region whose chunks are being handed out, and its chunk list.
    region: Option<(usize, Vec<(i32, i32)>)>,
    samples: VecDeque<(Instant, u64)>,
    /// The state the checkpointer last recorded (or tried to: a failed save is in `error`).
    saved: State,
    /// The checkpointer has exited (final state saved).
    closed: bool,
}

/// How a job talks to whoever runs it.
pub struct Hooks {
    /// Time between progress lines.
    pub report_every: Duration,
    /// Receives the progress lines.
    pub report: Box<dyn Fn(&str) + Send + Sync>,
    /// Called when work becomes available (a start or a resume), to wake idle workers.
    pub on_work: Box<dyn Fn() + Send + Sync>,
}

/// A task being worked on.
pub struct Job {
    plan: Plan,
    seed: u64,
    store: Arc<Store>,
    progress_path: PathBuf,
    inner: Mutex<Inner>,
    changed: Condvar,
    /// Told whenever work becomes available again (resume), so idle workers look.
    on_work: Box<dyn Fn() + Send + Sync>,
    /// Receives the progress lines, every `report_every`.
    report: Box<dyn Fn(&str) + Send + Sync>,
    report_every: Duration,
    checkpointer: Mutex<Option<JoinHandle<()>>>,
}

impl Job {
    /// Starts (or resumes, from `done` chunks) `plan`, saving progress to `progress_path`
    /// and telling `hooks` how it goes.
    pub fn start(
        plan: Plan,
        seed: u64,
        store: Arc<Store>,
        progress_path: PathBuf,
        done: u64,
        hooks: Hooks,
    ) -> std::io::Result<Arc<Job>> {
        let Hooks { report_every, report, on_work } = hooks;
        let total = plan.total();
        let done = done.min(total);
        let job = Arc::new(Job {
            plan,
            seed,
            store,
            progress_path,
            inner: Mutex::new(Inner {
                next: done,
                prefix: done,
                above: BTreeSet::new(),
                durable: done,
                state: if done == total { State::Finished } else { State::Running },
                error: None,
                cancelled: false,
                stopping: false,
                current: None,
                region: None,
                samples: VecDeque::from([(Instant::now(), done)]),
                saved: State::Running,
                closed: false,
            }),
            changed: Condvar::new(),
            on_work,
            report,
            report_every,
            checkpointer: Mutex::new(None),
        });
        job.save(&job.lock())?;
        let worker = job.clone();
        let handle =
            std::thread::Builder::new().name("pregen-checkpoint".into()).spawn(move || worker.checkpoints())?;
        *job.checkpointer.lock().unwrap_or_else(PoisonError::into_inner) = Some(handle);
        (job.on_work)();
        Ok(job)
    }

    fn lock(&self) -> MutexGuard<'_, Inner> {
        self.inner.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// The plan.
    pub fn plan(&self) -> &Plan {
        &self.plan
    }

    /// The next chunk to generate, or `None` when there is nothing to hand out now (paused,
    /// cancelled, failed or everything handed out).
    pub fn take(&self) -> Option<(u64, (i32, i32))> {
        let mut inner = self.lock();
        if inner.state != State::Running || inner.cancelled || inner.stopping || inner.next >= self.plan.total() {
            return None;
        }
        let n = inner.next;
        inner.next += 1;
        let region = self.plan.region_index(n);
        if inner.region.as_ref().is_none_or(|(i, _)| *i != region) {
            inner.region = Some((region, self.plan.region_chunks(region)));
        }
        let (_, chunks) = inner.region.as_ref().expect("set above");
        let pos = chunks[(n - self.plan.region_start(region)) as usize];
        inner.current = Some(pos);
        Some((n, pos))
    }

    /// Chunk `n` is saved (queued to the store's writer).
    pub fn complete(&self, n: u64) {
        let mut inner = self.lock();
        if n < inner.prefix {
            return;
        }
        inner.above.insert(n);
        while inner.above.first() == Some(&inner.prefix) {
            inner.above.pop_first();
            inner.prefix += 1;
        }
        if inner.prefix == self.plan.total() && inner.state == State::Running {
            self.changed.notify_all();
        }
    }

    /// Generating or saving chunk `n` failed: pause with `error` (a full disk, say). The
    /// owner fixes the cause and continues; the chunk is redone then.
    pub fn fail(&self, error: String) {
        let mut inner = self.lock();
        if inner.state == State::Running {
            inner.state = State::Paused;
            inner.error = Some(error);
            self.changed.notify_all();
        }
    }

    /// Pauses handing out chunks (those in hand finish). Returns false if not running.
    pub fn pause(&self) -> bool {
        let mut inner = self.lock();
        if inner.state != State::Running || inner.cancelled {
            return false;
        }
        inner.state = State::Paused;
        self.changed.notify_all();
        true
    }

    /// Resumes a paused job. After an error, it restarts from the last durable point (chunks
    /// after it may not have been written). Returns false if it was not paused.
    pub fn resume(&self) -> bool {
        let mut inner = self.lock();
        if inner.state != State::Paused || inner.cancelled {
            return false;
        }
        if inner.error.take().is_some() {
            inner.next = inner.durable;
            inner.prefix = inner.durable;
            inner.above.clear();
        }
        inner.state = State::Running;
        let done = inner.prefix;
        inner.samples = VecDeque::from([(Instant::now(), done)]);
        self.changed.notify_all();
        drop(inner);
        (self.on_work)();
        true
    }

    /// Stops for good and removes the progress file.
    pub fn cancel(&self) {
        self.lock().cancelled = true;
        self.changed.notify_all();
    }

    /// The process is stopping: hands out nothing more, saves what is on disk with the state
    /// unchanged (a running task resumes when the server starts again) and waits for that.
    /// Call before closing the store.
    pub fn stop(&self) {
        self.lock().stopping = true;
        self.changed.notify_all();
        self.join();
    }

    /// Where it stands.
    pub fn status(&self) -> Status {
        let inner = self.lock();
        let done = inner.prefix + inner.above.len() as u64;
        let rate = rate(&inner.samples);
        let left = self.plan.total().saturating_sub(done);
        Status {
            done,
            total: self.plan.total(),
            rate,
            eta_s: (rate > 0.0).then(|| left as f64 / rate),
            current: inner.current,
            state: inner.state,
            error: inner.error.clone(),
            cancelled: inner.cancelled,
        }
    }

    /// Blocks until the job is finished, cancelled or paused, with that state saved.
    pub fn wait(&self) -> Status {
        {
            let mut inner = self.lock();
            while !(inner.closed || inner.state == State::Paused && inner.saved == State::Paused) {
                inner = self.changed.wait(inner).unwrap_or_else(PoisonError::into_inner);
            }
        }
        self.status()
    }

    /// Waits for the checkpointer to save the final state (after finish or cancel).
    pub fn join(&self) {
        if let Some(handle) = self.checkpointer.lock().unwrap_or_else(PoisonError::into_inner).take() {
            let _ = handle.join();
        }
    }

    fn save(&self, inner: &Inner) -> std::io::Result<()> {
        Progress {
            task: self.plan.task(),
            shard: self.plan.shard(),
            seed: self.seed,
            done: inner.durable,
            total: self.plan.total(),
            state: inner.state,
            error: inner.error.clone(),
        }
        .save(&self.progress_path)
    }

    /// The checkpointer thread: every few seconds, fsync what is written and record it.
    fn checkpoints(&self) {
        let mut last_report = Instant::now();
        loop {
            let (prefix, cancelled, stopping) = {
                let inner = self.lock();
                let (inner, _) = self.changed.wait_timeout(inner, CHECKPOINT).unwrap_or_else(PoisonError::into_inner);
                (inner.prefix, inner.cancelled, inner.stopping)
            };
            if cancelled {
                if let Err(e) = self.store.flush() {
                    (self.report)(&format!("pregen: cancelled; {e}"));
                }
                let _ = std::fs::remove_file(&self.progress_path);
                (self.report)("pregen: cancelled");
                break;
            }
            // Everything up to `prefix` was queued before this flush, so it is on disk after it.
            let flushed = self.store.flush();
            let mut inner = self.lock();
            match flushed {
                Ok(()) => inner.durable = inner.durable.max(prefix),
                Err(e) => {
                    if inner.state == State::Running {
                        inner.state = State::Paused;
                    }
                    inner.error.get_or_insert_with(|| e.to_string());
                }
            }
            let now = Instant::now();
            let done = inner.prefix;
            inner.samples.push_back((now, done));
            while inner.samples.len() > 2 && inner.samples.front().is_some_and(|(t, _)| now - *t > RATE_WINDOW) {
                inner.samples.pop_front();
            }
            let finished = inner.durable == self.plan.total();
            if finished {
                inner.state = State::Finished;
            }
            if let Err(e) = self.save(&inner) {
                if inner.state == State::Running {
                    inner.state = State::Paused;
                }
                inner.error.get_or_insert_with(|| format!("cannot save {}: {e}", self.progress_path.display()));
            }
            inner.saved = inner.state;
            let state = inner.state;
            self.changed.notify_all();
            drop(inner);
            if finished {
                (self.report)(&self.status().line());
                break;
            }
            if stopping {
                break;
            }
            if state == State::Running && last_report.elapsed() >= self.report_every {
                last_report = Instant::now();
                (self.report)(&self.status().line());
            }
        }
        self.lock().closed = true;
        self.changed.notify_all();
    }
}

fn rate(samples: &VecDeque<(Instant, u64)>) -> f64 {
    match (samples.front(), samples.back()) {
        (Some((t0, d0)), Some((t1, d1))) if t1 > t0 => (d1 - d0) as f64 / (*t1 - *t0).as_secs_f64(),
        _ => 0.0,
    }
}

/// 1234567 → "1,234,567".
pub fn thousands(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// Seconds → "1h 02m", "3m 05s", "12s".
pub fn duration(seconds: f64) -> String {
    let s = seconds.max(0.0).round() as u64;
    match s {
        0..=59 => format!("{s}s"),
        60..=3599 => format!("{}m {:02}s", s / 60, s % 60),
        _ => format!("{}h {:02}m", s / 3600, s / 60 % 60),
    }
}
