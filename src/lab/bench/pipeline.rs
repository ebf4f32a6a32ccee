//! Pipeline throughput for the stages that exist: block columns per second.

use std::time::Instant;

use super::needed::Needed;
use super::pregen::{busy_percent, cpu_seconds};
use super::Measurement;
use crate::config::Config;
use crate::terrain::{Pipeline, Rect};

/// Cold 512×512-block region, and chunk-by-chunk steady exploration.
pub fn measure(config: &Config, runs: usize) -> anyhow::Result<Vec<Measurement>> {
    let (mut first_region, mut steady, mut warm) = (Vec::new(), Vec::new(), Vec::new());
    // Per window function, summed over the runs: what the cold region needed.
    let mut needed = Needed::default();
    let mut busy = Vec::new();
    for run in 0..runs as i64 {
        // A different far place per run, so each starts cold.
        let origin = (run * 1_000_003 - 3_000_000, -run * 700_001 + 2_000_000);
        let pipeline = Pipeline::build(config.world.seed, &config.terrain())?;
        let (start, cpu) = (Instant::now(), cpu_seconds());
        pipeline.columns(Rect::new(origin.1, origin.0, 512, 512));
        first_region.push(start.elapsed().as_secs_f64());
        busy.extend(busy_percent(start, cpu));
        needed.add(&[], &pipeline.engine().function_stats());

        // Steady exploration: a player's new chunks, one 16×16 query each, walking east
        // across fresh ground in a band 32 chunks wide.
        let pipeline = Pipeline::build(config.world.seed, &config.terrain())?;
        let (cx0, cz0) = (origin.0 / 16 + 50_000, origin.1 / 16);
        let start = Instant::now();
        let mut columns = 0u64;
        for cx in cx0..cx0 + 96 {
            for cz in cz0..cz0 + 32 {
                pipeline.columns(Rect::new(cz * 16, cx * 16, 16, 16));
                columns += 256;
            }
        }
        steady.push(columns as f64 / start.elapsed().as_secs_f64());

        // The same chunks again: windows cached, only the per-query work remains.
        let start = Instant::now();
        for cx in cx0..cx0 + 96 {
            for cz in cz0..cz0 + 32 {
                pipeline.columns(Rect::new(cz * 16, cx * 16, 16, 16));
            }
        }
        warm.push(columns as f64 / start.elapsed().as_secs_f64());
    }
    let mut out = vec![
        Measurement::new("pipeline: first 512×512-block region, cold start", "s", first_region),
        Measurement::new("  how busy the hardware threads were meanwhile", "%", busy),
    ];
    // Where the cold region's time goes.
    out.extend(needed.measurements());
    out.push(Measurement::new("pipeline: steady exploration, chunk-sized queries", "columns/s", steady));
    out.push(Measurement::new("pipeline: revisiting generated chunks (cache warm)", "columns/s", warm));
    Ok(out)
}
