//! Training data for the learned stages: prepared real tiles, encoded once at load, and the
//! deterministic random crops every step draws from them.
//!
//! Encoding follows docs/learned-terrain.md (encoding): elevations go through the signed square root, then the
//! Laplacian split (8× downsample + blur) gives the low band the stage is conditioned on; the
//! network generates the residual. The low band is computed on whole tiles, not on crops, so
//! a crop sees the same smooth context the pipeline's globally aligned coarse grid gives.

use std::path::{Path, PathBuf};

use infiniterra_terrain::encoding::{signed_sqrt, ContextSpec};
use infiniterra_terrain::model::hint::{features, FEATURES};
use infiniterra_terrain::model::{sha256_file, DataChecksum, HostRng, NoiseDistribution, Normalisation, ReliefHint};

use crate::npy::read_npy_f32;

/// Side of every prepared tile (`data prepare` writes stacks of them).
pub const PREPARED_TILE: usize = 256;
/// Probability that a sample's conditioning vector is dropped (all zeros), so the network
/// also works when the pipeline has no relief hint to give.
const VECTOR_DROPOUT: f64 = 0.2;
/// Stream numbers of the host RNG (see [`HostRng::keyed`]).
const STREAM_BATCH: u64 = 0x6261_7463;
const STREAM_STATS: u64 = 0x7374_6174;
const STREAM_PREVIEW: u64 = 0x7072_6576;
const STREAM_HINT: u64 = 0x6869_6e74;
/// Crops the relief hint is fitted on.
const HINT_CROPS: usize = 4000;

/// One tile, encoded: signed-sqrt elevation and its upsampled low band, both `size²`.
#[derive(Clone, Debug)]
pub struct EncodedTile {
    /// Side in pixels (a multiple of 8).
    pub size: usize,
    /// `signed_sqrt(elevation)`.
    pub h: Vec<f32>,
    /// `spec.smooth(h)`: the smooth context.
    pub low: Vec<f32>,
}

impl EncodedTile {
    /// Encodes a square tile of elevations in metres, with the context `spec` makes.
    pub fn from_metres(size: usize, metres: &[f32], spec: ContextSpec) -> EncodedTile {
        assert_eq!(metres.len(), size * size);
        let h: Vec<f32> = metres.iter().map(|&e| signed_sqrt(e)).collect();
        let low = spec.smooth(&h, size, size);
        EncodedTile { size, h, low }
    }
}

/// A set of encoded tiles and the files they came from.
#[derive(Clone, Debug, Default)]
pub struct TileSet {
    /// The tiles.
    pub tiles: Vec<EncodedTile>,
    /// Checksums of the files read.
    pub checksums: Vec<DataChecksum>,
}

/// A training or preview batch, host-side, channel-major `[batch, 1, crop, crop]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Batch {
    /// Samples.
    pub size: usize,
    /// Crop side.
    pub crop: usize,
    /// Targets: residual / target_scale.
    pub clean: Vec<f32>,
    /// Conditioning: (low − cond_mean) / cond_scale.
    pub cond: Vec<f32>,
    /// Conditioning vectors `[relief_z, present]`, zeros when dropped.
    pub vector: Vec<f32>,
    /// Noise levels, one per sample.
    pub sigma: Vec<f32>,
    /// Unit Gaussian noise, like `clean`.
    pub noise: Vec<f32>,
    /// The crops' signed-sqrt low bands (for decoding samples back to metres).
    pub low: Vec<f32>,
}

/// Reads `<dir>/<split>.npy` (tiles stacked along rows), box-downsamples each tile by
/// `downsample` (2 turns the 500 m detail set into 1 km tiles) and encodes it with `spec`.
pub fn read_split(dir: &Path, split: &str, downsample: usize, spec: ContextSpec) -> Result<TileSet, String> {
    let path: PathBuf = dir.join(format!("{split}.npy"));
    let ((rows, cols), data) = read_npy_f32(&path)
        .map_err(|e| format!("{e} (prepare the data with `infiniterra data fetch` and `infiniterra data prepare`)"))?;
    if cols != PREPARED_TILE || rows % PREPARED_TILE != 0 {
        return Err(format!("{}: shape ({rows}, {cols}) is not a stack of {PREPARED_TILE}² tiles", path.display()));
    }
    if data.iter().any(|v| !v.is_finite()) {
        return Err(format!("{}: holds non-finite values", path.display()));
    }
    let f = downsample.max(1);
    let size = PREPARED_TILE / f;
    let tiles = data
        .chunks(PREPARED_TILE * PREPARED_TILE)
        .map(|t| {
            let mut small = vec![0.0f32; size * size];
            for y in 0..PREPARED_TILE {
                for x in 0..PREPARED_TILE {
                    small[(y / f) * size + x / f] += t[y * PREPARED_TILE + x] / (f * f) as f32;
                }
            }
            EncodedTile::from_metres(size, &small, spec)
        })
        .collect();
    let sha256 = sha256_file(&path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    Ok(TileSet { tiles, checksums: vec![DataChecksum { file: path.display().to_string(), sha256 }] })
}

impl TileSet {
    /// Appends another set.
    pub fn extend(&mut self, other: TileSet) {
        self.tiles.extend(other.tiles);
        self.checksums.extend(other.checksums);
    }

    /// Normalisation constants measured on this set: residual and context statistics, and
    /// the distribution of log crop relief. Deterministic (fixed crops).
    pub fn normalisation(&self, crop: usize, sigma_data: f32) -> Normalisation {
        let (mut n, mut sum_r2, mut sum_c, mut sum_c2) = (0f64, 0f64, 0f64, 0f64);
        for t in &self.tiles {
            for (&h, &l) in t.h.iter().zip(&t.low) {
                let r = (h - l) as f64;
                sum_r2 += r * r;
                sum_c += l as f64;
                sum_c2 += (l as f64).powi(2);
                n += 1.0;
            }
        }
        let residual_std = (sum_r2 / n.max(1.0)).sqrt().max(1e-3);
        let cond_mean = sum_c / n.max(1.0);
        let cond_std = (sum_c2 / n.max(1.0) - cond_mean * cond_mean).max(1e-6).sqrt();
        let mut rng = HostRng::keyed(0, STREAM_STATS, 0, 0);
        let logs: Vec<f64> = (0..2000)
            .map(|_| {
                let (t, y0, x0, _) = self.pick(&mut rng, crop);
                let r: Vec<f32> = crop_of(t, y0, x0, crop, 0, |t, i| t.h[i] - t.low[i]);
                log_std(&r)
            })
            .collect();
        let lm = logs.iter().sum::<f64>() / logs.len() as f64;
        let ls = (logs.iter().map(|v| (v - lm).powi(2)).sum::<f64>() / logs.len() as f64).sqrt().max(1e-3);
        Normalisation {
            target_scale: (residual_std / sigma_data as f64) as f32,
            cond_mean: cond_mean as f32,
            cond_scale: cond_std as f32,
            relief_mean: lm as f32,
            relief_std: ls as f32,
        }
    }

    /// The relief hint of this set: `relief_z` (as the conditioning vector holds it) regressed
    /// on the context statistics of [`HINT_CROPS`] fixed crops. Deterministic.
    pub fn relief_hint(&self, crop: usize, norm: &Normalisation, features: usize) -> Option<ReliefHint> {
        let (x, z) = self.relief_samples(crop, norm);
        ReliefHint::fit(&x, &z, features)
    }

    /// Context features and true `relief_z` of [`HINT_CROPS`] fixed crops: what the hint is
    /// fitted on, and what it is checked against on other tiles.
    pub fn relief_samples(&self, crop: usize, norm: &Normalisation) -> (Vec<[f64; FEATURES]>, Vec<f64>) {
        let mut rng = HostRng::keyed(0, STREAM_HINT, 0, 0);
        let (mut x, mut z): (Vec<[f64; FEATURES]>, Vec<f64>) = (Vec::new(), Vec::new());
        for _ in 0..HINT_CROPS {
            let (t, y0, x0, _) = self.pick(&mut rng, crop);
            let residual = crop_of(t, y0, x0, crop, 0, |t, k| t.h[k] - t.low[k]);
            let low = crop_of(t, y0, x0, crop, 0, |t, k| t.low[k]);
            x.push(features(&low, crop));
            z.push((log_std(&residual) - norm.relief_mean as f64) / norm.relief_std as f64);
        }
        (x, z)
    }

    /// The smallest tile side (crops must fit every tile).
    pub fn min_tile(&self) -> usize {
        self.tiles.iter().map(|t| t.size).min().unwrap_or(0)
    }

    /// A random tile and crop origin and a random dihedral transform (0..8).
    fn pick<'a>(&'a self, rng: &mut HostRng, crop: usize) -> (&'a EncodedTile, usize, usize, usize) {
        let t = &self.tiles[rng.below(self.tiles.len())];
        let y0 = rng.below(t.size - crop + 1);
        let x0 = rng.below(t.size - crop + 1);
        (t, y0, x0, rng.below(8))
    }

    /// The batch of training step `step`: a pure function of (seed, step), so a resumed run
    /// sees exactly the batches an uninterrupted one would.
    pub fn batch(
        &self,
        seed: u64,
        step: u64,
        size: usize,
        crop: usize,
        norm: &Normalisation,
        noise: &NoiseDistribution,
    ) -> Batch {
        self.draw(seed, STREAM_BATCH, step, size, crop, norm, noise, true)
    }

    /// A fixed batch for previews and validation (no vector dropout, σ from `noise`).
    pub fn fixed_batch(&self, size: usize, crop: usize, norm: &Normalisation, noise: &NoiseDistribution) -> Batch {
        self.draw(0, STREAM_PREVIEW, 0, size, crop, norm, noise, false)
    }

    #[allow(clippy::too_many_arguments)]
    fn draw(
        &self,
        seed: u64,
        stream: u64,
        step: u64,
        size: usize,
        crop: usize,
        norm: &Normalisation,
        noise: &NoiseDistribution,
        dropout: bool,
    ) -> Batch {
        assert!(!self.tiles.is_empty() && crop % 8 == 0 && crop <= self.min_tile());
        let n = crop * crop;
        let mut b = Batch {
            size,
            crop,
            clean: Vec::with_capacity(size * n),
            cond: Vec::with_capacity(size * n),
            vector: Vec::with_capacity(size * 2),
            sigma: Vec::with_capacity(size),
            noise: Vec::with_capacity(size * n),
            low: Vec::with_capacity(size * n),
        };
        for i in 0..size {
            let mut rng = HostRng::keyed(seed, stream, step, i as u64);
            let (t, y0, x0, d) = self.pick(&mut rng, crop);
            let residual = crop_of(t, y0, x0, crop, d, |t, k| t.h[k] - t.low[k]);
            let low = crop_of(t, y0, x0, crop, d, |t, k| t.low[k]);
            let relief = ((log_std(&residual) as f32) - norm.relief_mean) / norm.relief_std;
            let keep = !dropout || rng.uniform() >= VECTOR_DROPOUT;
            b.vector.extend_from_slice(&if keep { [relief, 1.0] } else { [0.0, 0.0] });
            b.clean.extend(residual.iter().map(|r| r / norm.target_scale));
            b.cond.extend(low.iter().map(|l| (l - norm.cond_mean) / norm.cond_scale));
            b.low.extend_from_slice(&low);
            b.sigma.extend(noise.sample(&mut rng, 1));
            b.noise.extend(rng.normals(n));
        }
        b
    }
}

/// ln of the standard deviation of a crop (floored so flat sea floor stays finite).
pub(super) fn log_std(v: &[f32]) -> f64 {
    let m = v.iter().map(|&x| x as f64).sum::<f64>() / v.len() as f64;
    let var = v.iter().map(|&x| (x as f64 - m).powi(2)).sum::<f64>() / v.len() as f64;
    (var.sqrt() + 1e-2).ln()
}

/// A `crop × crop` window of a per-pixel value of `t` at (y0, x0), under dihedral transform
/// `d` (bit 0: transpose, bit 1: flip rows, bit 2: flip columns).
pub(super) fn crop_of(
    t: &EncodedTile,
    y0: usize,
    x0: usize,
    crop: usize,
    d: usize,
    value: impl Fn(&EncodedTile, usize) -> f32,
) -> Vec<f32> {
    let mut out = Vec::with_capacity(crop * crop);
    for y in 0..crop {
        for x in 0..crop {
            let (mut sy, mut sx) = if d & 1 == 1 { (x, y) } else { (y, x) };
            if d & 2 == 2 {
                sy = crop - 1 - sy;
            }
            if d & 4 == 4 {
                sx = crop - 1 - sx;
            }
            out.push(value(t, (y0 + sy) * t.size + x0 + sx));
        }
    }
    out
}

/// Synthetic terrain-like tiles (no data files needed): for tests and `--smoke` runs.
pub fn synthetic(count: usize, size: usize) -> TileSet {
    synthetic_with(count, size, ContextSpec::default())
}

/// [`synthetic`] tiles encoded with the context `spec`.
pub fn synthetic_with(count: usize, size: usize, spec: ContextSpec) -> TileSet {
    let tiles = (0..count)
        .map(|k| {
            let metres: Vec<f32> = (0..size * size)
                .map(|i| {
                    let (y, x) = ((i / size) as f32, (i % size) as f32);
                    let p = k as f32;
                    900.0 * (x * 0.05 + p).sin() * (y * 0.04).cos() + 150.0 * (x * 0.7 + y * 0.3 + p).sin() + 100.0
                })
                .collect();
            EncodedTile::from_metres(size, &metres, spec)
        })
        .collect();
    TileSet { tiles, checksums: Vec::new() }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_relief_hint_learns_that_rough_context_means_rough_detail() {
        // Tiles whose small-scale roughness grows with their large-scale relief, as on Earth.
        let size = 128;
        let tiles: Vec<EncodedTile> = (1..=6)
            .map(|k| {
                let a = 60.0 * k as f32;
                let metres: Vec<f32> = (0..size * size)
                    .map(|i| {
                        let (y, x) = ((i / size) as f32, (i % size) as f32);
                        a * 4.0 * (x * 0.04 + k as f32).sin() * (y * 0.03).cos() + a * (x * 0.9 + y * 0.4).sin() + 500.0
                    })
                    .collect();
                EncodedTile::from_metres(size, &metres, ContextSpec::default())
            })
            .collect();
        let set = TileSet { tiles, checksums: Vec::new() };
        let norm = set.normalisation(32, 0.5);
        let hint = set.relief_hint(32, &norm, FEATURES).expect("well-posed");
        assert_eq!(set.relief_hint(32, &norm, FEATURES), Some(hint.clone()), "the fit is deterministic");
        assert!(hint.r2 > 0.8, "R² {}", hint.r2);
        let low = |t: &EncodedTile| crop_of(t, 10, 20, 32, 0, |t, k| t.low[k]);
        let (gentle, rough) = (hint.predict(&low(&set.tiles[0]), 32), hint.predict(&low(&set.tiles[5]), 32));
        assert!(rough > gentle + 1.0, "rough context → {rough}, gentle → {gentle}");
    }

    #[test]
    fn batches_are_a_function_of_seed_and_step() {
        let set = synthetic(3, 64);
        let norm = set.normalisation(32, 0.5);
        let noise = NoiseDistribution::default();
        let a = set.batch(7, 12, 4, 32, &norm, &noise);
        assert_eq!(a, set.batch(7, 12, 4, 32, &norm, &noise));
        assert_ne!(a, set.batch(7, 13, 4, 32, &norm, &noise));
        assert_eq!(a.clean.len(), 4 * 32 * 32);
        // The normalised targets have roughly σ_data spread.
        let big = set.batch(1, 0, 64, 32, &norm, &noise);
        let std = (big.clean.iter().map(|v| v * v).sum::<f32>() / big.clean.len() as f32).sqrt();
        assert!((0.25..1.0).contains(&std), "target std {std}");
    }

    #[test]
    fn dihedral_crops_are_permutations_of_the_same_pixels() {
        let set = synthetic(1, 32);
        let t = &set.tiles[0];
        let base = {
            let mut v = crop_of(t, 4, 8, 16, 0, |t, i| t.h[i]);
            v.sort_by(f32::total_cmp);
            v
        };
        for d in 1..8 {
            let mut v = crop_of(t, 4, 8, 16, d, |t, i| t.h[i]);
            v.sort_by(f32::total_cmp);
            assert_eq!(v, base, "transform {d}");
        }
    }
}
