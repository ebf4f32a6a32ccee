//! Generated counterparts of held-out tiles, for `infiniterra eval`: the shipped model runs
//! through the real engine (windows, noise tiles, tent blending) on each held-out tile's
//! grid, conditioned on that tile's own low band, and the results are written as a stack of
//! tiles with a sidecar — what `infiniterra eval --generated FILE --reference DIR` reads.

use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use anyhow::Context;
use infiniterra_terrain::encoding::{lowpass, signed_square, LAPLACIAN_FACTOR};
use infiniterra_terrain::infinite::{Engine, EngineConfig, Source, Windowed};
use infiniterra_terrain::model::stage::CoreStage;
use infiniterra_terrain::model::{load_model, ComputeBackend};
use infiniterra_terrain::tile::{Rect, Tile};

use super::data::read_split;
use crate::export::write_npy_f32;

/// A finite coarse grid extended by clamping, as a [`Source`].
struct ClampedGrid {
    size: i64,
    metres: Vec<f32>,
}

impl Source for ClampedGrid {
    fn channels(&self) -> usize {
        1
    }

    fn query(&self, rect: Rect) -> Tile {
        let mut data = Vec::with_capacity(rect.area());
        for y in rect.y0..rect.y1() {
            for x in rect.x0..rect.x1() {
                let (cy, cx) = (y.clamp(0, self.size - 1), x.clamp(0, self.size - 1));
                data.push(self.metres[(cy * self.size + cx) as usize]);
            }
        }
        Tile::from_data(1, rect, data)
    }
}

/// Writes `count` generated tiles (seeds `seed`, `seed + 1`, …) to `out` (+ `out.json`).
pub fn generate(
    models: &Path,
    data: &Path,
    out: &Path,
    count: usize,
    seed: u64,
    backend: ComputeBackend,
) -> anyhow::Result<()> {
    let device = backend.device()?;
    let model = load_model(models, "core", &device)?;
    let heldout = read_split(&data.join("core"), "heldout", 1).map_err(anyhow::Error::msg)?;
    let count = count.min(heldout.tiles.len());
    let mut stack = Vec::new();
    let started = Instant::now();
    let mut windows = 0;
    for (i, tile) in heldout.tiles.iter().take(count).enumerate() {
        let n = tile.size;
        let low = lowpass(&tile.h, n, n);
        let coarse = ClampedGrid {
            size: (n / LAPLACIAN_FACTOR) as i64,
            metres: low.iter().map(|&v| signed_square(v)).collect(),
        };
        let engine = Engine::new(EngineConfig { cache_bytes: 256 << 20, threads: 2 });
        let stage =
            Windowed::new(&engine, CoreStage::new(model.clone(), device.clone(), Arc::new(coarse), seed + i as u64, 8));
        let t = stage.query(Rect::new(0, 0, n as i64, n as i64));
        windows += stage.evaluations();
        stack.extend_from_slice(&t.data);
        eprintln!("generated held-out tile {}/{count} ({:.1} s so far)", i + 1, started.elapsed().as_secs_f64());
    }
    let secs = started.elapsed().as_secs_f64();
    let size = heldout.tiles.first().map_or(0, |t| t.size);
    write_npy_f32(out, (count * size, size), &stack).with_context(|| format!("writing {}", out.display()))?;
    let side = serde_json::json!({
        "metres_per_pixel": model.manifest.metres_per_pixel,
        "tile": size,
        "count": count,
        "stage": "core",
        "generator": "infiniterra train core --generate-heldout (conditioned on each held-out tile's low band)",
        "seed": seed,
    });
    let json = out.with_extension("json");
    std::fs::write(&json, serde_json::to_string_pretty(&side)?)
        .with_context(|| format!("writing {}", json.display()))?;
    println!(
        "wrote {} ({count} tiles of {size}², {windows} windows in {secs:.1} s = {:.1} windows/s) and {}",
        out.display(),
        windows as f64 / secs,
        json.display()
    );
    Ok(())
}
