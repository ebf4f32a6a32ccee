//! A small host-side random stream for weight initialisation and training batches.
//!
//! Everything random in training (initial weights, crops, σ, noise) is drawn here on the
//! host from ChaCha8 and uploaded, never from a backend's own generator: that is what makes
//! a run a pure function of its seed, on every backend and thread count.

use rand_chacha::rand_core::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A seeded ChaCha8 stream with the few distributions training needs.
#[derive(Clone, Debug)]
pub struct HostRng(ChaCha8Rng);

impl HostRng {
    /// A stream keyed by a seed and up to three more words (e.g. a purpose and a step), so
    /// independent uses never share values.
    pub fn keyed(seed: u64, a: u64, b: u64, c: u64) -> HostRng {
        let mut key = [0u8; 32];
        for (i, w) in [seed, a, b, c].iter().enumerate() {
            key[i * 8..i * 8 + 8].copy_from_slice(&w.to_le_bytes());
        }
        HostRng(ChaCha8Rng::from_seed(key))
    }

    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.0.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform integer in `0..n` (`n > 0`).
    pub fn below(&mut self, n: usize) -> usize {
        ((self.uniform() * n as f64) as usize).min(n.saturating_sub(1))
    }

    /// Standard normal (Box–Muller; one value per call keeps the stream simple to reason about).
    pub fn normal(&mut self) -> f64 {
        // 1 − u keeps the argument of ln() in (0, 1].
        let u1 = 1.0 - self.uniform();
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }

    /// `n` standard-normal values as f32.
    pub fn normals(&mut self, n: usize) -> Vec<f32> {
        (0..n).map(|_| self.normal() as f32).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keyed_streams_are_reproducible_and_distinct() {
        let a: Vec<f32> = HostRng::keyed(1, 2, 3, 4).normals(8);
        assert_eq!(a, HostRng::keyed(1, 2, 3, 4).normals(8));
        assert_ne!(a, HostRng::keyed(1, 2, 3, 5).normals(8));
        let v = HostRng::keyed(9, 0, 0, 0).normals(20_000);
        let mean = v.iter().map(|&x| x as f64).sum::<f64>() / v.len() as f64;
        let var = v.iter().map(|&x| (x as f64 - mean).powi(2)).sum::<f64>() / v.len() as f64;
        assert!(mean.abs() < 0.03 && (var - 1.0).abs() < 0.04, "mean {mean} var {var}");
    }
}
