//! The procedural baseline: fractional Brownian motion by spectral synthesis, with a fixed
//! seed so every report compares against the same noise.

use super::fft::{fft2, Complex};
use super::Raster;

/// Spectral slope of the baseline: β = −3 (Hurst exponent 0.5), the middle of real DEMs'
/// −2.8…−3.1 and the slope of classic fBm with gain ½ per octave.
pub const FBM_BETA: f64 = -3.0;

/// A small deterministic standard-normal generator (SplitMix64 + Box–Muller): the baseline
/// must be identical on every machine and version, which a seeded library RNG whose stream
/// may change between releases does not promise.
pub(crate) struct Gaussian {
    state: u64,
    spare: Option<f64>,
}

impl Gaussian {
    pub(crate) fn new(seed: u64) -> Gaussian {
        Gaussian { state: seed, spare: None }
    }

    fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub(crate) fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Standard normal.
    pub(crate) fn next(&mut self) -> f64 {
        if let Some(v) = self.spare.take() {
            return v;
        }
        let u1 = 1.0 - self.uniform();
        let (s, c) = (std::f64::consts::TAU * self.uniform()).sin_cos();
        let r = (-2.0 * u1.ln()).sqrt();
        self.spare = Some(r * s);
        r * c
    }
}

/// A `rows × cols` fBm field with power ∝ k^`beta`, zero mean and unit standard deviation,
/// on pixels of `metres`. Synthesised on the next power-of-two square (complex white noise
/// shaped by |k|^(β/2), inverse FFT, real part) and cropped, so it is not periodic.
pub fn fbm(rows: usize, cols: usize, metres: f64, beta: f64, seed: u64) -> Raster {
    let n = rows.max(cols).max(2).next_power_of_two() * 2;
    let mut g = Gaussian::new(seed);
    let signed = |i: usize| if i < n / 2 { i as f64 } else { i as f64 - n as f64 };
    let mut field: Vec<Complex> = (0..n * n)
        .map(|i| {
            let k = signed(i / n).hypot(signed(i % n));
            let a = if k == 0.0 { 0.0 } else { k.powf(beta / 2.0) };
            (a * g.next(), a * g.next())
        })
        .collect();
    fft2(&mut field, n, n, true);
    let mut r = Raster::from_fn(rows, cols, metres, |y, x| field[y * n + x].0 as f32);
    let (mean, std) = r.mean_std();
    let scale = if std > 0.0 { 1.0 / std } else { 0.0 };
    r.data.iter_mut().for_each(|v| *v = ((*v as f64 - mean) * scale) as f32);
    r
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::{fit_beta, radial_power_spectrum};

    #[test]
    fn fbm_is_normalised_reproducible_and_has_the_slope_asked_for() {
        let a = fbm(100, 130, 1000.0, FBM_BETA, 42);
        assert_eq!((a.rows, a.cols), (100, 130));
        let (mean, std) = a.mean_std();
        assert!(mean.abs() < 1e-5 && (std - 1.0).abs() < 1e-5, "{mean} {std}");
        assert_eq!(a, fbm(100, 130, 1000.0, FBM_BETA, 42), "same seed, same field");
        assert_ne!(a, fbm(100, 130, 1000.0, FBM_BETA, 43));
        for beta in [-2.0, -3.0] {
            let beta_fit = fit_beta(&radial_power_spectrum(&fbm(256, 256, 1000.0, beta, 5)));
            assert!((beta_fit - beta).abs() < 0.25, "asked β = {beta}, measured {beta_fit}");
        }
    }
}
