//! The Laplacian split: `low = blur(downsample₈(x))`, `residual = x − upsample(low)`.

/// Downsampling factor of the low-frequency channel.
pub const LAPLACIAN_FACTOR: usize = 8;

/// 5-tap binomial blur weights (σ ≈ 1 low-res cell): removes the block pattern of the
/// box downsample without smearing the low band across continents.
const BLUR: [f32; 5] = [1.0 / 16.0, 4.0 / 16.0, 6.0 / 16.0, 4.0 / 16.0, 1.0 / 16.0];

/// Box-downsamples an `h × w` image by `f` (h and w must be multiples of f).
fn downsample(x: &[f32], h: usize, w: usize, f: usize) -> Vec<f32> {
    let (lh, lw) = (h / f, w / f);
    let mut out = vec![0.0; lh * lw];
    for y in 0..h {
        for xx in 0..w {
            out[(y / f) * lw + xx / f] += x[y * w + xx];
        }
    }
    let n = (f * f) as f32;
    out.iter_mut().for_each(|v| *v /= n);
    out
}

/// The `h × w` image box-downsampled by `f` (cell means); with [`LAPLACIAN_FACTOR`] it is
/// the grid [`lowpass`] blurs — what a learned stage's context source provides.
pub fn box_downsample(x: &[f32], h: usize, w: usize, f: usize) -> Vec<f32> {
    assert!(f > 0 && h % f == 0 && w % f == 0, "{h}×{w} is not a multiple of {f}");
    downsample(x, h, w, f)
}

/// Half-width of [`blur`] in cells: a context needs this many extra cells on every side.
pub const BLUR_RADIUS: usize = 2;

/// Separable 5-tap binomial blur of an `h × w` low-band grid with clamped edges (the second
/// half of [`lowpass`]).
pub fn blur(x: &[f32], h: usize, w: usize) -> Vec<f32> {
    let clamp = |i: isize, n: usize| i.clamp(0, n as isize - 1) as usize;
    let mut tmp = vec![0.0; h * w];
    for y in 0..h {
        for xx in 0..w {
            tmp[y * w + xx] = (0..5).map(|k| BLUR[k] * x[y * w + clamp(xx as isize + k as isize - 2, w)]).sum();
        }
    }
    let mut out = vec![0.0; h * w];
    for y in 0..h {
        for xx in 0..w {
            out[y * w + xx] = (0..5).map(|k| BLUR[k] * tmp[clamp(y as isize + k as isize - 2, h) * w + xx]).sum();
        }
    }
    out
}

/// The low-frequency channel of an `h × w` image: `(h/8) × (w/8)` values.
pub fn lowpass(x: &[f32], h: usize, w: usize) -> Vec<f32> {
    ContextSpec::default().lowpass(x, h, w)
}

/// Bilinear upsampling of the low channel back to `h × w` (cell centres aligned, edges clamped).
pub fn upsample_low(low: &[f32], h: usize, w: usize) -> Vec<f32> {
    ContextSpec::default().upsample(low, h, w)
}

/// How a learned stage's context (its low band) is made from the full-resolution signal:
/// box means over `factor`² pixels, optionally blurred by [`blur`], and bilinearly upsampled
/// back. The core uses the default (8×, blurred: the paper's Laplacian split); a stage that
/// refines a grid only 2× coarser than its own (detail over core) keeps the coarse grid's
/// values unblurred, so the relief above it is not thrown away and regenerated.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContextSpec {
    /// Output pixels per context cell, per axis.
    pub factor: usize,
    /// Whether the box means are blurred ([`BLUR_RADIUS`] extra cells read on each side).
    pub blur: bool,
}

impl Default for ContextSpec {
    fn default() -> ContextSpec {
        ContextSpec { factor: LAPLACIAN_FACTOR, blur: true }
    }
}

impl ContextSpec {
    /// Refuses a factor the encodings cannot use (names the value).
    pub fn validate(&self) -> Result<(), String> {
        if !(1..=16).contains(&self.factor) {
            return Err(format!("context.factor = {} (must be 1 to 16)", self.factor));
        }
        Ok(())
    }

    /// Extra context cells a window needs on each side (the blur's reach).
    pub fn margin(&self) -> usize {
        if self.blur {
            BLUR_RADIUS
        } else {
            0
        }
    }

    /// The low channel of an `h × w` image: `(h/f) × (w/f)` values.
    pub fn lowpass(&self, x: &[f32], h: usize, w: usize) -> Vec<f32> {
        let f = self.factor;
        assert!(h % f == 0 && w % f == 0, "{h}×{w} is not a multiple of {f}");
        let means = downsample(x, h, w, f);
        if self.blur {
            blur(&means, h / f, w / f)
        } else {
            means
        }
    }

    /// Bilinear upsampling of a low channel back to `h × w` (cell centres aligned, edges
    /// clamped).
    pub fn upsample(&self, low: &[f32], h: usize, w: usize) -> Vec<f32> {
        let f = self.factor as f32;
        let (lh, lw) = (h / self.factor, w / self.factor);
        let tap = |d: usize, n: usize| {
            let c = ((d as f32 + 0.5) / f - 0.5).clamp(0.0, (n - 1) as f32);
            let i = (c.floor() as usize).min(n.saturating_sub(2));
            (i, (c - i as f32).min(1.0), (i + 1).min(n - 1))
        };
        let mut out = vec![0.0; h * w];
        for y in 0..h {
            let (y0, ty, y1) = tap(y, lh);
            for x in 0..w {
                let (x0, tx, x1) = tap(x, lw);
                let top = low[y0 * lw + x0] + tx * (low[y0 * lw + x1] - low[y0 * lw + x0]);
                let bottom = low[y1 * lw + x0] + tx * (low[y1 * lw + x1] - low[y1 * lw + x0]);
                out[y * w + x] = top + ty * (bottom - top);
            }
        }
        out
    }

    /// `upsample(lowpass(x))`: the smooth context of an image, at its own size.
    pub fn smooth(&self, x: &[f32], h: usize, w: usize) -> Vec<f32> {
        self.upsample(&self.lowpass(x, h, w), h, w)
    }
}

/// Splits an image into its low-frequency channel and the residual.
pub fn laplacian_split(x: &[f32], h: usize, w: usize) -> (Vec<f32>, Vec<f32>) {
    let low = lowpass(x, h, w);
    let up = upsample_low(&low, h, w);
    let residual = x.iter().zip(&up).map(|(a, b)| a - b).collect();
    (low, residual)
}

/// Recombines a low channel and a residual.
pub fn laplacian_merge(low: &[f32], residual: &[f32], h: usize, w: usize) -> Vec<f32> {
    upsample_low(low, h, w).iter().zip(residual).map(|(a, b)| a + b).collect()
}

/// Laplacian denoising: decode `low + residual`, re-extract a clean low channel from the
/// result and recombine it with the residual. A generated low channel with out-of-band
/// noise (which the upsampling would turn into blocky artefacts) is replaced by the low band
/// of what was actually generated; a consistent pair (`low == lowpass(decoded)`) comes back
/// unchanged.
pub fn laplacian_denoise(low: &[f32], residual: &[f32], h: usize, w: usize) -> Vec<f32> {
    let decoded = laplacian_merge(low, residual, h, w);
    laplacian_merge(&lowpass(&decoded, h, w), residual, h, w)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn terrain_like(h: usize, w: usize) -> Vec<f32> {
        (0..h * w)
            .map(|i| {
                let (y, x) = ((i / w) as f32, (i % w) as f32);
                800.0 * (x * 0.05).sin() * (y * 0.04).cos() + 120.0 * (x * 0.9 + y * 0.7).sin() + 3.0 * x
            })
            .collect()
    }

    #[test]
    fn split_then_merge_round_trips() {
        let (h, w) = (64, 48);
        let x = terrain_like(h, w);
        let (low, res) = laplacian_split(&x, h, w);
        assert_eq!(low.len(), (h / 8) * (w / 8));
        let back = laplacian_merge(&low, &res, h, w);
        let worst = x.iter().zip(&back).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
        assert!(worst < 1e-3, "round trip error {worst} m");
    }

    #[test]
    fn the_low_channel_holds_the_large_scale_and_the_residual_the_rest() {
        let (h, w) = (64, 64);
        let x = terrain_like(h, w);
        let (low, res) = laplacian_split(&x, h, w);
        let mean = |v: &[f32]| v.iter().map(|a| a.abs()).sum::<f32>() / v.len() as f32;
        assert!(mean(&low) > 3.0 * mean(&res), "low {} residual {}", mean(&low), mean(&res));
    }

    #[test]
    fn a_context_spec_generalises_the_laplacian_split() {
        let (h, w) = (64, 48);
        let x = terrain_like(h, w);
        assert_eq!(ContextSpec::default().smooth(&x, h, w), upsample_low(&lowpass(&x, h, w), h, w));
        // 2×, unblurred: the low channel is the plain 2×2 means, and a field constant over
        // each cell pair comes back exactly where bilinear weights stay inside one cell row.
        let two = ContextSpec { factor: 2, blur: false };
        let low = two.lowpass(&x, h, w);
        assert_eq!(low.len(), (h / 2) * (w / 2));
        let mean = (x[0] + x[1] + x[w] + x[w + 1]) / 4.0;
        assert!((low[0] - mean).abs() < 1e-3);
        let smooth = two.smooth(&x, h, w);
        let err = x.iter().zip(&smooth).map(|(a, b)| (a - b).abs()).sum::<f32>() / x.len() as f32;
        let err8 = x.iter().zip(ContextSpec::default().smooth(&x, h, w)).map(|(a, b)| (a - b).abs()).sum::<f32>()
            / x.len() as f32;
        assert!(err < err8 / 2.0, "a 2× unblurred context keeps more: {err} vs {err8}");
        assert!(ContextSpec { factor: 0, blur: true }.validate().unwrap_err().contains("context.factor = 0"));
    }

    #[test]
    fn denoising_removes_out_of_band_noise_in_the_low_channel() {
        let (h, w) = (64, 64);
        let x = terrain_like(h, w);
        let (low, res) = laplacian_split(&x, h, w);
        let noisy: Vec<f32> =
            low.iter().enumerate().map(|(i, v)| v + if i % 2 == 0 { 300.0 } else { -300.0 }).collect();
        let err = |v: &[f32]| v.iter().zip(&x).map(|(a, b)| (a - b).powi(2)).sum::<f32>().sqrt();
        let plain = laplacian_merge(&noisy, &res, h, w);
        let cleaned = laplacian_denoise(&noisy, &res, h, w);
        assert!(err(&cleaned) < 0.6 * err(&plain), "denoised {} vs plain {}", err(&cleaned), err(&plain));
        // A consistent pair comes back unchanged.
        let kept = laplacian_denoise(&low, &res, h, w);
        assert!(err(&kept) < 0.1, "a clean pair moved by {}", err(&kept));
    }
}
