//! Engine overhead: a Φ that does nothing, so all the time is the engine's (κ(R), cache,
//! claims, weighting, blending, normalisation).

use std::sync::Arc;
use std::time::Instant;

use super::Measurement;
use crate::terrain::infinite::{Engine, EngineConfig, Source, WindowFn, WindowIndex, WindowLayout, Windowed};
use crate::terrain::{Rect, Tile};

/// A constant Φ over 64×64 windows with 50% overlap (the core stage's shape).
struct Trivial;

impl WindowFn for Trivial {
    fn name(&self) -> &str {
        "bench.trivial"
    }
    fn channels(&self) -> usize {
        1
    }
    fn layout(&self) -> WindowLayout {
        WindowLayout::square(64, 32, 0)
    }
    fn batch_size(&self) -> usize {
        16
    }
    fn eval(&self, windows: &[WindowIndex]) -> Vec<Tile> {
        windows.iter().map(|&w| Tile::from_data(1, self.layout().rect(w), vec![1.0; 64 * 64])).collect()
    }
}

/// Overhead per window evaluated (cold), and per window answered from the cache (warm).
pub fn measure(runs: usize) -> Vec<Measurement> {
    let (mut cold, mut warm, mut chunks) = (Vec::new(), Vec::new(), Vec::new());
    for run in 0..runs {
        let engine = Engine::new(EngineConfig { cache_bytes: 512 << 20, threads: 1 });
        let t = Windowed::new(&engine, Trivial);
        let region = Rect::new(run as i64 * 100_000, -(run as i64) * 77_777, 1024, 1024);
        let start = Instant::now();
        t.query(region);
        let evaluated = t.evaluations() as f64;
        cold.push(start.elapsed().as_secs_f64() * 1e6 / evaluated);
        let start = Instant::now();
        t.query(region);
        warm.push(start.elapsed().as_secs_f64() * 1e6 / evaluated);
        // Small queries, as chunk workers make them: 6×6 model pixels, all windows cached.
        let start = Instant::now();
        let mut n = 0u64;
        for y in (region.y0..region.y1() - 6).step_by(4) {
            for x in (region.x0..region.x1() - 6).step_by(64) {
                t.query(Rect::new(y, x, 6, 6));
                n += 1;
            }
        }
        chunks.push(start.elapsed().as_secs_f64() * 1e6 / n as f64);
        let _ = Arc::strong_count(&t);
    }
    vec![
        Measurement::new("engine: overhead per window evaluated, trivial Φ 64² (cold)", "µs", cold),
        Measurement::new("engine: per window answered from cache (warm re-query)", "µs", warm),
        Measurement::new("engine: 6×6-pixel query, all windows cached", "µs", chunks),
    ]
}
