//! The spectral equaliser: a fixed zero-phase filter that gives a stage's output the power
//! spectrum of real terrain.
//!
//! A small, briefly trained network draws too little of the stochastic relief that its
//! context only hints at (11–32 km for the core: ridges and valleys a few context cells long)
//! and, asked through the relief hint for the real amount of relief, puts the rest into
//! 4–11 km texture — even bumps where real ranges run in long ridges. Per wavelength the
//! shortfall and the excess are steady (the same on training and held-out tiles, for every
//! blending stride and sampler tried), so a linear filter whose amplitude gain is
//! √(real power / generated power) per wavelength corrects them. Its gains are measured by
//! `infiniterra train STAGE --calibrate-spectrum` on counterparts of **training** tiles and
//! stored as knots in the manifest; the kernel is built from them on load. It is isotropic
//! and sums to one (the mean level is kept).
//!
//! It filters each window's output, mirrored at the window's edges, before the engine blends
//! the windows — not the blended field: a filter over the field would read `radius` pixels
//! around every query, and for a cold 512-block region that is half as many network windows
//! again. Near a window's edges the mirrored filter is not the global one, but there the
//! tent weights are small, and the calibration measures (and its second pass corrects) the
//! result as the engine blends it.

use serde::{Deserialize, Serialize};

use crate::metrics::{fft2, Complex, Spectrum};

/// Side of the frequency grid the kernel is designed on (a power of two; its finest ring is
/// 2 pixels, its coarsest `KERNEL_GRID` pixels).
const KERNEL_GRID: usize = 256;
/// Largest kernel radius a manifest may ask for, pixels.
pub const MAX_RADIUS: usize = 64;
/// Range of an amplitude gain: more than this either way is not a calibration but a
/// different terrain.
pub const GAIN_RANGE: (f64, f64) = (0.25, 4.0);

/// A stage's spectral correction, as its manifest stores it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpectralEqualiser {
    /// Kernel radius, pixels: how far beyond each output pixel the filter reads.
    pub radius: usize,
    /// Knots `[wavelength_px, amplitude_gain]`, wavelengths strictly descending; the gain is
    /// linear in ln(wavelength) between knots and flat beyond the end knots.
    pub gains: Vec<[f64; 2]>,
}

impl SpectralEqualiser {
    /// The amplitude gain at `wavelength` pixels (∞ for the mean).
    pub fn gain(&self, wavelength: f64) -> f64 {
        let knots = &self.gains;
        match knots.iter().position(|k| k[0] < wavelength) {
            None => knots.last().map_or(1.0, |k| k[1]),
            Some(0) => knots[0][1],
            Some(i) => {
                let ([l0, g0], [l1, g1]) = (knots[i - 1], knots[i]);
                g0 + (g1 - g0) * (wavelength.ln() - l0.ln()) / (l1.ln() - l0.ln())
            }
        }
    }

    /// Checks the manifest entry can be built into a kernel for windows of side `window`
    /// (the mirror at a window's edge needs a radius under the window's side).
    pub fn validate(&self, window: usize) -> Result<(), String> {
        let max = MAX_RADIUS.min(window.saturating_sub(1));
        if !(1..=max).contains(&self.radius) {
            return Err(format!("spectral_equaliser.radius = {} (must be 1–{max} pixels)", self.radius));
        }
        let bad_knot = |&[l, g]: &[f64; 2]| !(l.is_finite() && l > 0.0 && (GAIN_RANGE.0..=GAIN_RANGE.1).contains(&g));
        if self.gains.is_empty() || self.gains.iter().any(bad_knot) || self.gains.windows(2).any(|w| w[1][0] >= w[0][0])
        {
            return Err(format!(
                "spectral_equaliser.gains = {:?}: need [wavelength_px, gain] knots, wavelengths positive and strictly \
                 descending, gains within {}–{}",
                self.gains, GAIN_RANGE.0, GAIN_RANGE.1
            ));
        }
        Ok(())
    }

    /// The gains that turn `generated`'s mean spectrum into `real`'s (same rings, from tiles
    /// of `metres` per pixel): [`band_gain`] at each knot wavelength, except gain 1 at and
    /// beyond the first (longest), where the context decides the terrain and a tile's window
    /// blurs the rings. `None` when the spectra do not reach the knots.
    pub fn from_spectra(
        real: &Spectrum,
        generated: &Spectrum,
        metres: f64,
        radius: usize,
        knots: &[f64],
    ) -> Option<SpectralEqualiser> {
        let longest = *knots.first()?;
        let mut gains = vec![[longest * 2.0, 1.0]];
        for &wavelength in knots {
            let gain = band_gain(real, generated, metres, wavelength)?;
            let gain = if wavelength >= longest { 1.0 } else { gain.clamp(GAIN_RANGE.0, GAIN_RANGE.1) };
            gains.push([wavelength, gain]);
        }
        Some(SpectralEqualiser { radius, gains })
    }

    /// These gains (as [`SpectralEqualiser::from_spectra`] made them) corrected by what is
    /// left after applying them: each knot's gain times [`band_gain`] of `real` over
    /// `equalised` (this equaliser's output) there, clamped; the first two knots, gain 1 at
    /// and beyond the longest wavelength, stay.
    pub fn refined(&self, real: &Spectrum, equalised: &Spectrum, metres: f64) -> SpectralEqualiser {
        let gains = self
            .gains
            .iter()
            .enumerate()
            .map(|(i, &[l, g])| match band_gain(real, equalised, metres, l) {
                Some(more) if i >= 2 => [l, (g * more).clamp(GAIN_RANGE.0, GAIN_RANGE.1)],
                _ => [l, g],
            })
            .collect();
        SpectralEqualiser { radius: self.radius, gains }
    }

    /// The convolution kernel, row-major `(2·radius + 1)²`, summing to one: the inverse DFT
    /// of the radial gain on a [`KERNEL_GRID`]² frequency grid, cut to the radius with a Hann
    /// taper (which smooths the gain curve by about a quarter octave at the radius's scale).
    pub fn kernel(&self) -> Vec<f32> {
        let n = KERNEL_GRID;
        let signed = |i: usize| if i < n / 2 { i as f64 } else { i as f64 - n as f64 };
        let mut field: Vec<Complex> = (0..n * n)
            .map(|i| {
                let k = signed(i / n).hypot(signed(i % n));
                let wavelength = if k == 0.0 { f64::INFINITY } else { n as f64 / k };
                (self.gain(wavelength), 0.0)
            })
            .collect();
        fft2(&mut field, n, n, true);
        let r = self.radius as i64;
        let side = 2 * r + 1;
        let taper = |d: i64| 0.5 + 0.5 * (std::f64::consts::PI * d as f64 / (r + 1) as f64).cos();
        let at = |d: i64| d.rem_euclid(n as i64) as usize;
        let raw: Vec<f64> = (0..side * side)
            .map(|i| {
                let (dy, dx) = (i / side - r, i % side - r);
                field[at(dy) * n + at(dx)].0 * taper(dy) * taper(dx)
            })
            .collect();
        let sum: f64 = raw.iter().sum();
        raw.iter().map(|v| (v / sum) as f32).collect()
    }
}

/// √(real / generated) power over the rings within a quarter octave of `wavelength` pixels
/// (geometric mean): the amplitude gain that brings `generated` to `real` there (spectra of
/// the same rings, from tiles of `metres` per pixel). `None` when no ring lies there.
pub fn band_gain(real: &Spectrum, generated: &Spectrum, metres: f64, wavelength: f64) -> Option<f64> {
    let band: Vec<f64> = real
        .frequency
        .iter()
        .zip(real.power.iter().zip(&generated.power))
        .filter(|(f, (r, g))| **r > 0.0 && **g > 0.0 && (1.0 / (*f * metres * wavelength)).log2().abs() <= 0.25)
        .map(|(_, (r, g))| (r / g).ln())
        .collect();
    (!band.is_empty()).then(|| (0.5 * band.iter().sum::<f64>() / band.len() as f64).exp())
}

/// A [`SpectralEqualiser`] ready to run: its kernel, built once.
#[derive(Clone, Debug, PartialEq)]
pub struct EqualiserKernel {
    radius: usize,
    weights: Vec<f32>,
}

impl EqualiserKernel {
    /// The kernel of `equaliser`.
    pub fn new(equaliser: &SpectralEqualiser) -> EqualiserKernel {
        EqualiserKernel { radius: equaliser.radius, weights: equaliser.kernel() }
    }

    /// One `side`² window (row-major) filtered, mirrored at its edges (edge pixels not
    /// repeated). Panics unless the radius is under `side`.
    pub fn apply(&self, values: &[f32], side: usize) -> Vec<f32> {
        assert!(self.radius < side && values.len() == side * side, "a {side}² window and radius {}", self.radius);
        let (r, k) = (self.radius as i64, 2 * self.radius + 1);
        let last = side as i64 - 1;
        let mirror = |i: i64| {
            (if i < 0 {
                -i
            } else if i > last {
                2 * last - i
            } else {
                i
            }) as usize
        };
        let padded_side = side + 2 * self.radius;
        let mut padded = Vec::with_capacity(padded_side * padded_side);
        for y in -r..side as i64 + r {
            let row = &values[mirror(y) * side..(mirror(y) + 1) * side];
            padded.extend((-r..side as i64 + r).map(|x| row[mirror(x)]));
        }
        let mut out = Vec::with_capacity(side * side);
        for y in 0..side {
            for x in 0..side {
                // Row by row in a fixed order: the same sum, bit for bit, wherever it runs.
                let mut acc = 0.0f32;
                for (ky, krow) in self.weights.chunks_exact(k).enumerate() {
                    let start = (y + ky) * padded_side + x;
                    acc += padded[start..start + k].iter().zip(krow).map(|(a, b)| a * b).sum::<f32>();
                }
                out.push(acc);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::{radial_power_spectrum, Raster};
    use std::f32::consts::TAU;

    fn flat(gains: Vec<[f64; 2]>) -> SpectralEqualiser {
        SpectralEqualiser { radius: 8, gains }
    }

    #[test]
    fn the_gain_is_log_linear_between_knots_and_flat_beyond() {
        let eq = flat(vec![[64.0, 1.0], [16.0, 2.0], [4.0, 0.5]]);
        eq.validate(64).expect("descending wavelengths, gains in range");
        for (wavelength, want) in
            [(f64::INFINITY, 1.0), (128.0, 1.0), (32.0, 1.5), (16.0, 2.0), (8.0, 1.25), (2.0, 0.5)]
        {
            assert!((eq.gain(wavelength) - want).abs() < 1e-12, "gain({wavelength}) = {}", eq.gain(wavelength));
        }
        assert!(flat(vec![[4.0, 1.0], [16.0, 1.0]]).validate(64).unwrap_err().contains("spectral_equaliser.gains"));
        assert!(flat(vec![[16.0, 9.0]]).validate(64).unwrap_err().contains("gains within"));
        assert!(SpectralEqualiser { radius: 0, ..eq.clone() }
            .validate(64)
            .unwrap_err()
            .contains("spectral_equaliser.radius"));
        assert!(eq.validate(8).unwrap_err().contains("must be 1–7"), "the mirror needs a radius under the window");
    }

    #[test]
    fn a_unit_gain_kernel_is_the_identity_and_every_kernel_keeps_the_mean() {
        let k = flat(vec![[64.0, 1.0]]).kernel();
        assert_eq!(k.len(), 17 * 17);
        assert!(
            (k[8 * 17 + 8] - 1.0).abs() < 1e-6 && k.iter().enumerate().all(|(i, v)| i == 8 * 17 + 8 || v.abs() < 1e-6)
        );
        let eq = flat(vec![[32.0, 1.0], [8.0, 0.5]]);
        let k = eq.kernel();
        assert!((k.iter().map(|&v| v as f64).sum::<f64>() - 1.0).abs() < 1e-5);
        // Isotropic and zero-phase: symmetric under flips and transposition.
        for y in 0..17 {
            for x in 0..17 {
                assert!(
                    (k[y * 17 + x] - k[x * 17 + y]).abs() < 1e-7 && (k[y * 17 + x] - k[(16 - y) * 17 + x]).abs() < 1e-7
                );
            }
        }
        // A level window stays level, edges included (the mirror adds nothing).
        let out = EqualiserKernel::new(&eq).apply(&[250.0; 32 * 32], 32);
        assert!(out.iter().all(|v| (v - 250.0).abs() < 1e-2), "{:?}", &out[..4]);
    }

    /// Two plane waves: `broad`× one of 32 pixels and `fine`× one of 8.
    fn waves(side: usize, broad: f32, fine: f32) -> Vec<f32> {
        (0..side * side)
            .map(|i| {
                let (y, x) = ((i / side) as f32, (i % side) as f32);
                broad * (TAU * (x + 0.3 * y) / 32.0).sin() + fine * (TAU * (y - 0.2 * x) / 8.0).sin()
            })
            .collect()
    }

    /// Amplitude of the 32-pixel (`broad`) or the 8-pixel wave in the centre 64² of a
    /// `side`² window: projection on the wave's own cosine and sine.
    fn amplitude(v: &[f32], side: usize, broad: bool) -> f32 {
        let (mut c, mut s, mut n) = (0.0f64, 0.0f64, 0.0f64);
        let m = (side - 64) / 2;
        for y in m..m + 64 {
            for x in m..m + 64 {
                let (yf, xf) = (y as f32, x as f32);
                let phase = if broad { (xf + 0.3 * yf) / 32.0 } else { (yf - 0.2 * xf) / 8.0 };
                c += (v[y * side + x] * (TAU * phase).cos()) as f64;
                s += (v[y * side + x] * (TAU * phase).sin()) as f64;
                n += 1.0;
            }
        }
        (c.hypot(s) * 2.0 / n) as f32
    }

    #[test]
    fn calibrated_gains_bring_a_misshapen_spectrum_to_the_real_one() {
        // Real: both waves at amplitude 1. Generated: the 32-pixel wave at half amplitude, the
        // 8-pixel one doubled — a network short at broad scales and rough at fine ones.
        let raster = |v: Vec<f32>| Raster::new(256, 256, 1000.0, v);
        let (sr, sg) = (
            radial_power_spectrum(&raster(waves(256, 1.0, 1.0))),
            radial_power_spectrum(&raster(waves(256, 0.5, 2.0))),
        );
        let eq =
            SpectralEqualiser::from_spectra(&sr, &sg, 1000.0, 24, &[64.0, 32.0, 16.0, 8.0, 4.0]).expect("rings reach");
        eq.validate(64).expect("calibrated gains are valid");
        assert_eq!(eq.gain(128.0), 1.0, "the longest wavelengths are left alone");
        assert!(eq.gain(32.0) > 1.5 && eq.gain(8.0) < 0.7, "{:?}", eq.gains);
        // Applied to a window, the fine wave loses amplitude and the broad one gains it. A
        // 32-pixel radius cannot resolve a one-octave peak fully (the taper smooths the gain by
        // about a quarter octave), so the broad wave gets most of its ×2, not all of it.
        let boost = SpectralEqualiser { radius: 32, gains: vec![[64.0, 1.0], [32.0, 2.0], [16.0, 1.0], [8.0, 0.5]] };
        let input = waves(128, 1.0, 1.0);
        let out = EqualiserKernel::new(&boost).apply(&input, 128);
        let broad = amplitude(&out, 128, true) / amplitude(&input, 128, true);
        let fine = amplitude(&out, 128, false) / amplitude(&input, 128, false);
        assert!((1.25..2.1).contains(&broad) && (0.4..0.6).contains(&fine), "broad ×{broad}, fine ×{fine}");
    }
}
