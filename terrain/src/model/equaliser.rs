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
//! stored as knots in the manifest; the kernel is built from them on load. It is isotropic,
//! sums to one (the mean level is kept) and reads `radius` pixels beyond each output pixel,
//! so over the infinite grid it is one global convolution: seamless and a pure function of
//! the stage's output, like everything else in the engine.

use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::infinite::{Engine, Source, WindowFn, WindowIndex, WindowLayout, Windowed};
use crate::metrics::{fft2, Complex, Spectrum};
use crate::tile::{Rect, Tile};

/// Side of the frequency grid the kernel is designed on (a power of two; its finest ring is
/// 2 pixels, its coarsest `KERNEL_GRID` pixels).
const KERNEL_GRID: usize = 256;
/// Largest kernel radius a manifest may ask for, pixels.
pub const MAX_RADIUS: usize = 64;
/// Range of an amplitude gain: more than this either way is not a calibration but a
/// different terrain.
pub const GAIN_RANGE: (f64, f64) = (0.25, 4.0);
/// Side of the equaliser's output windows (they do not overlap: each output pixel is one
/// convolution, no blending).
const WINDOW: i64 = 64;

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

    /// Checks the manifest entry can be built into a kernel.
    pub fn validate(&self) -> Result<(), String> {
        if !(1..=MAX_RADIUS).contains(&self.radius) {
            return Err(format!("spectral_equaliser.radius = {} (must be 1–{MAX_RADIUS} pixels)", self.radius));
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

/// A source passed through a [`SpectralEqualiser`], as a window function: each
/// [`WINDOW`]² output window is the convolution of the source over the window and `radius`
/// pixels around it.
pub struct Equalised {
    name: String,
    source: Arc<dyn Source>,
    kernel: Vec<f32>,
    radius: i64,
}

impl Equalised {
    /// `source` (one channel) filtered by `equaliser`; `name` labels the engine's counters.
    pub fn new(name: &str, source: Arc<dyn Source>, equaliser: &SpectralEqualiser) -> Equalised {
        Equalised {
            name: format!("{name}.equaliser"),
            source,
            kernel: equaliser.kernel(),
            radius: equaliser.radius as i64,
        }
    }

    fn window(&self, rect: Rect) -> Tile {
        let r = self.radius;
        let padded = Rect::new(rect.y0 - r, rect.x0 - r, rect.h + 2 * r, rect.w + 2 * r);
        let src = self.source.query(padded);
        let (pw, side) = (padded.w as usize, (2 * r + 1) as usize);
        let mut out = Vec::with_capacity(rect.area());
        for y in 0..rect.h as usize {
            for x in 0..rect.w as usize {
                // Row by row in a fixed order: the same sum, bit for bit, wherever it runs.
                let mut acc = 0.0f32;
                for (ky, krow) in self.kernel.chunks_exact(side).enumerate() {
                    let row = &src.data[(y + ky) * pw + x..(y + ky) * pw + x + side];
                    acc += row.iter().zip(krow).map(|(a, b)| a * b).sum::<f32>();
                }
                out.push(acc);
            }
        }
        Tile::from_data(1, rect, out)
    }
}

/// `source`, the output of stage `name`, as the engine serves it: through `equaliser` when
/// there is one (behind the engine's cache), untouched otherwise.
pub fn equalised(
    engine: &Arc<Engine>,
    name: &str,
    source: Arc<dyn Source>,
    equaliser: Option<&SpectralEqualiser>,
) -> Arc<dyn Source> {
    match equaliser {
        Some(eq) => Windowed::new(engine, Equalised::new(name, source, eq)),
        None => source,
    }
}

impl WindowFn for Equalised {
    fn name(&self) -> &str {
        &self.name
    }

    fn channels(&self) -> usize {
        1
    }

    fn layout(&self) -> WindowLayout {
        WindowLayout::square(WINDOW, WINDOW, 0)
    }

    fn eval(&self, windows: &[WindowIndex]) -> Vec<Tile> {
        let layout = self.layout();
        windows.iter().map(|&w| self.window(layout.rect(w))).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::{radial_power_spectrum, Raster};

    fn flat(gains: Vec<[f64; 2]>) -> SpectralEqualiser {
        SpectralEqualiser { radius: 8, gains }
    }

    #[test]
    fn the_gain_is_log_linear_between_knots_and_flat_beyond() {
        let eq = flat(vec![[64.0, 1.0], [16.0, 2.0], [4.0, 0.5]]);
        eq.validate().expect("descending wavelengths, gains in range");
        for (wavelength, want) in
            [(f64::INFINITY, 1.0), (128.0, 1.0), (32.0, 1.5), (16.0, 2.0), (8.0, 1.25), (2.0, 0.5)]
        {
            assert!((eq.gain(wavelength) - want).abs() < 1e-12, "gain({wavelength}) = {}", eq.gain(wavelength));
        }
        assert!(flat(vec![[4.0, 1.0], [16.0, 1.0]]).validate().unwrap_err().contains("spectral_equaliser.gains"));
        assert!(flat(vec![[16.0, 9.0]]).validate().unwrap_err().contains("gains within"));
        assert!(SpectralEqualiser { radius: 0, ..eq }.validate().unwrap_err().contains("spectral_equaliser.radius"));
    }

    #[test]
    fn a_unit_gain_kernel_is_the_identity_and_every_kernel_keeps_the_mean() {
        let k = flat(vec![[64.0, 1.0]]).kernel();
        assert_eq!(k.len(), 17 * 17);
        assert!(
            (k[8 * 17 + 8] - 1.0).abs() < 1e-6 && k.iter().enumerate().all(|(i, v)| i == 8 * 17 + 8 || v.abs() < 1e-6)
        );
        let k = flat(vec![[32.0, 1.0], [8.0, 0.5]]).kernel();
        assert!((k.iter().map(|&v| v as f64).sum::<f64>() - 1.0).abs() < 1e-5);
        // Isotropic and zero-phase: symmetric under flips and transposition.
        for y in 0..17 {
            for x in 0..17 {
                assert!(
                    (k[y * 17 + x] - k[x * 17 + y]).abs() < 1e-7 && (k[y * 17 + x] - k[(16 - y) * 17 + x]).abs() < 1e-7
                );
            }
        }
    }

    /// A field with equal power at 8 and 32 pixels, as a [`Source`].
    struct Waves;

    impl Source for Waves {
        fn channels(&self) -> usize {
            1
        }
        fn query(&self, rect: Rect) -> Tile {
            let wave = |y: i64, x: i64| {
                let (y, x) = (y as f32, x as f32);
                (std::f32::consts::TAU * (x + 0.3 * y) / 32.0).sin()
                    + (std::f32::consts::TAU * (y - 0.2 * x) / 8.0).sin()
            };
            let data = (rect.y0..rect.y1()).flat_map(|y| (rect.x0..rect.x1()).map(move |x| wave(y, x))).collect();
            Tile::from_data(1, rect, data)
        }
    }

    #[test]
    fn calibrated_gains_bring_a_misshapen_spectrum_to_the_real_one() {
        // Real: both waves at amplitude 1. Generated: the 32-pixel wave at half amplitude, the
        // 8-pixel one doubled — a network short at broad scales and rough at fine ones.
        let real = Raster::from_fn(256, 256, 1000.0, |y, x| Waves.query(Rect::new(y as i64, x as i64, 1, 1)).data[0]);
        let (a, b) = (0.5f32, 2.0f32);
        let generated = Raster::from_fn(256, 256, 1000.0, |y, x| {
            let (y, x) = (y as f32, x as f32);
            a * (std::f32::consts::TAU * (x + 0.3 * y) / 32.0).sin()
                + b * (std::f32::consts::TAU * (y - 0.2 * x) / 8.0).sin()
        });
        let (sr, sg) = (radial_power_spectrum(&real), radial_power_spectrum(&generated));
        let eq =
            SpectralEqualiser::from_spectra(&sr, &sg, 1000.0, 24, &[64.0, 32.0, 16.0, 8.0, 4.0]).expect("rings reach");
        eq.validate().expect("calibrated gains are valid");
        assert_eq!(eq.gain(128.0), 1.0, "the longest wavelengths are left alone");
        assert!(eq.gain(32.0) > 1.5 && eq.gain(8.0) < 0.7, "{:?}", eq.gains);
        // Filtered through the engine-facing window function, the fine wave loses amplitude
        // and the broad one gains it.
        let boost = SpectralEqualiser { radius: 32, gains: vec![[64.0, 1.0], [32.0, 2.0], [16.0, 1.0], [8.0, 0.5]] };
        let filtered = Equalised::new("test", Arc::new(Waves), &boost);
        let out = filtered.eval(&[WindowIndex { iy: 0, ix: 0 }, WindowIndex { iy: 1, ix: 0 }]);
        let input = Waves.query(Rect::new(0, 0, 64, 64));
        let amplitude = |t: &[f32], period: f32| {
            // Projection on the wave's own cosine and sine.
            let (mut c, mut s) = (0.0f64, 0.0f64);
            for (i, v) in t.iter().enumerate() {
                let (y, x) = ((i / 64) as f32, (i % 64) as f32);
                let phase = if period > 16.0 { (x + 0.3 * y) / period } else { (y - 0.2 * x) / period };
                c += (*v * (std::f32::consts::TAU * phase).cos()) as f64;
                s += (*v * (std::f32::consts::TAU * phase).sin()) as f64;
            }
            (c.hypot(s) * 2.0 / t.len() as f64) as f32
        };
        let (broad, fine) = (
            amplitude(&out[0].data, 32.0) / amplitude(&input.data, 32.0),
            amplitude(&out[0].data, 8.0) / amplitude(&input.data, 8.0),
        );
        // A 32-pixel radius cannot resolve a one-octave peak fully (the taper smooths the gain
        // by about a quarter octave), so the broad wave gets most of its ×2, not all of it.
        assert!((1.25..2.1).contains(&broad) && (0.4..0.6).contains(&fine), "broad ×{broad}, fine ×{fine}");
        // Windows tile the plane without overlap: the second starts where the first ends.
        assert_eq!(out[1].rect, Rect::new(64, 0, 64, 64));
    }

    #[test]
    fn through_the_engine_it_is_one_global_convolution_whatever_the_threads_and_order() {
        use crate::infinite::EngineConfig;
        let eq = SpectralEqualiser { radius: 6, gains: vec![[32.0, 1.0], [16.0, 1.5], [4.0, 0.7]] };
        let kernel = eq.kernel();
        // A region straddling four 64² output windows, off the window grid.
        let region = Rect::new(-70, 30, 100, 90);
        let direct: Vec<f32> = {
            let src = Waves.query(region.pad(6));
            let pw = (region.w + 12) as usize;
            (0..region.area())
                .map(|i| {
                    let (y, x) = (i / region.w as usize, i % region.w as usize);
                    let mut acc = 0.0f32;
                    for ky in 0..13 {
                        let row = &src.data[(y + ky) * pw + x..(y + ky) * pw + x + 13];
                        acc += row.iter().zip(&kernel[ky * 13..ky * 13 + 13]).map(|(a, b)| a * b).sum::<f32>();
                    }
                    acc
                })
                .collect()
        };
        let source = |threads: usize| {
            let engine = Engine::new(EngineConfig { cache_bytes: 64 << 20, threads });
            equalised(&engine, "test", Arc::new(Waves), Some(&eq))
        };
        let whole = source(1).query(region);
        let max_err = whole.data.iter().zip(&direct).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
        assert!(max_err < 1e-4, "windowed vs direct convolution differ by {max_err}");
        let two = source(2);
        for (qy, qx) in [(1, 1), (0, 0), (1, 0), (0, 1)] {
            let quarter = Rect::new(region.y0 + qy * 50, region.x0 + qx * 45, 50, 45);
            assert!(
                two.query(quarter) == whole.crop(quarter),
                "{quarter:?}: 2 threads, out of order, not bit-identical"
            );
        }
        assert!(
            equalised(&Engine::new(EngineConfig { cache_bytes: 1 << 20, threads: 1 }), "x", Arc::new(Waves), None)
                .query(region)
                .data
                == Waves.query(region).data
        );
    }
}
