//! Gradient-noise building blocks in metre coordinates: independent, rotated octaves and
//! their fBm and ridged sums.

use crate::noise::{gradient, hash3};

/// One octave of gradient noise with its own seed, wavelength and rotation. Each octave is
/// rotated by a different angle so the lattice's axis-aligned artefacts do not line up.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Octave {
    seed: u64,
    inv_wavelength: f64,
    cos: f64,
    sin: f64,
}

impl Octave {
    /// Octave `index` of noise `component` (a tag that keeps components independent).
    pub(crate) fn new(seed: u64, component: u64, index: i64, wavelength_m: f64) -> Octave {
        let seed = hash3(seed ^ component.wrapping_mul(0x9e37_79b9_7f4a_7c15), component as i64, index);
        let angle = (hash3(seed, -1, -1) >> 11) as f64 / (1u64 << 53) as f64 * std::f64::consts::TAU;
        Octave { seed, inv_wavelength: 1.0 / wavelength_m, cos: angle.cos(), sin: angle.sin() }
    }

    /// The noise at a point in metres, ≈ [-1, 1].
    #[inline]
    pub(crate) fn at(&self, y: f64, x: f64) -> f64 {
        let (y, x) = (y * self.inv_wavelength, x * self.inv_wavelength);
        gradient(self.seed, self.cos * y - self.sin * x, self.sin * y + self.cos * x)
    }
}

/// A weighted sum of octaves with halving wavelengths (fractional Brownian motion).
#[derive(Clone, Debug)]
pub(crate) struct Fbm {
    octaves: Vec<(Octave, f64)>,
}

impl Fbm {
    /// Octaves from `longest_m` down to no shorter than `shortest_m`, the first with
    /// amplitude `amplitude` and each next one `gain` times the previous.
    pub(crate) fn new(seed: u64, component: u64, longest_m: f64, shortest_m: f64, amplitude: f64, gain: f64) -> Fbm {
        let mut octaves = Vec::new();
        let (mut wavelength, mut a) = (longest_m, amplitude);
        while wavelength >= shortest_m {
            octaves.push((Octave::new(seed, component, octaves.len() as i64, wavelength), a));
            wavelength *= 0.5;
            a *= gain;
        }
        Fbm { octaves }
    }

    /// The plain sum.
    #[inline]
    pub(crate) fn at(&self, y: f64, x: f64) -> f64 {
        self.octaves.iter().map(|(o, a)| a * o.at(y, x)).sum()
    }

    /// Ridged multifractal in [0, 1]: each octave is `(1 − |n|)²` (sharp crests along the
    /// noise's zero lines) weighted by the previous octave, so small ridges sit on big ones.
    pub(crate) fn ridged(&self, y: f64, x: f64) -> f64 {
        let (mut sum, mut norm, mut weight) = (0.0, 0.0, 1.0);
        for (o, a) in &self.octaves {
            let v = (1.0 - o.at(y, x).abs()).max(0.0).powi(2) * weight;
            sum += a * v;
            norm += a;
            weight = v.clamp(0.0, 1.0);
        }
        if norm > 0.0 {
            sum / norm
        } else {
            0.0
        }
    }
}

/// Hermite step: 0 below `e0`, 1 above `e1`, smooth in between.
#[inline]
pub(crate) fn smoothstep(e0: f64, e1: f64, x: f64) -> f64 {
    if e1 <= e0 {
        return if x >= e0 { 1.0 } else { 0.0 };
    }
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}
