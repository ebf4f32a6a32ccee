//! Pre-generation: a task (centre, radius, shape) worked through in a cache-friendly order,
//! saved as it goes, resumable after any crash — from the server console (between players'
//! chunks) or as a batch command split into shards by region file.
//!
//! Owns: the order, the progress file and the running job. Must not: decide how a chunk is
//! made or stored (the world's [`ChunkSource`](crate::world::ChunkSource)).

pub mod batch;
mod job;
pub mod plan;
pub mod progress;

use std::panic::{catch_unwind, AssertUnwindSafe};

use crate::biome::BiomeRules;
use crate::world::{ChunkSource, Scratch};

pub use job::{duration, thousands, Hooks, Job, Status, REPORT_EVERY};
pub use plan::{Plan, Shape, Shard, Task};
pub use progress::{Progress, State};

/// Generates and saves chunk number `n` at `pos` of `job` (skipped when already saved), then
/// marks it done; a failure (a full disk, a bug) pauses the job with the reason.
pub fn generate(job: &Job, source: &ChunkSource, scratch: &mut Scratch, rules: &BiomeRules, n: u64, pos: (i32, i32)) {
    let (x, z) = pos;
    let plan = job.plan();
    if plan.region_start(plan.region_index(n)) == n {
        // Entering a region file: its learned-stage windows are evaluated now, all together in
        // full parallel batches, instead of a few at a time as single chunks need them (where
        // the second worker would wait on the first's window). The results are the same bits.
        let (rx, rz) = (x.div_euclid(32), z.div_euclid(32));
        let blocks = crate::terrain::Rect::new(i64::from(rz) * 512, i64::from(rx) * 512, 512, 512);
        source.generator().pipeline().prefetch(blocks);
    }
    match catch_unwind(AssertUnwindSafe(|| source.ensure_saved(scratch, rules, x, z))) {
        Ok(Ok(_)) => job.complete(n),
        Ok(Err(e)) => job.fail(e.to_string()),
        Err(_) => job.fail(format!("generating chunk {x}, {z} panicked (see above)")),
    }
    // Writes fail asynchronously on the writer thread: stop promptly rather than at the next
    // checkpoint.
    if let Some(failure) = source.store().and_then(|s| s.failure()) {
        job.fail(failure);
    }
}

/// Works on `job` with `threads` threads of its own (no server) until nothing is left to
/// hand out, then waits for the final state to be saved and ends the checkpointer. Returns
/// where the job stands: finished, or paused (by an error or [`Job::pause`]).
pub fn run_to_end(job: &Job, source: &ChunkSource, rules: &BiomeRules, threads: usize) -> Status {
    std::thread::scope(|scope| {
        for _ in 0..threads.max(1) {
            scope.spawn(|| {
                let mut scratch = source.scratch();
                while let Some((n, pos)) = job.take() {
                    generate(job, source, &mut scratch, rules, n, pos);
                }
            });
        }
    });
    let status = job.wait();
    // Ends the checkpointer whether the task finished or paused (state saved as it is).
    job.stop();
    status
}
