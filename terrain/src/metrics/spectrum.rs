//! Radially averaged power spectra and their log-log slope β.
//!
//! Convention: power ∝ k^β, with k the spatial frequency. White noise has β = 0; a field
//! whose Fourier amplitudes fall as k⁻¹ (2-D "brown" noise) has β = −2; real 1 km DEMs sit
//! near β ≈ −2.8…−3.1 (fBm with Hurst exponent H has β = −2 − 2H).

use rand_chacha::rand_core::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::fft::{fft2, Complex};
use super::Raster;

/// A radially averaged power spectrum: ring ρ = 1…N/2 of an N×N periodogram.
#[derive(Clone, Debug, PartialEq)]
pub struct Spectrum {
    /// Ring frequencies, cycles per metre (ρ / (N·pixel)).
    pub frequency: Vec<f64>,
    /// Mean power spectral density of the ring, m²·m² (windowed periodogram).
    pub power: Vec<f64>,
}

impl Spectrum {
    /// The mean of spectra over the same rings (tiles of one size and resolution); `None`
    /// when there are none or their rings differ.
    pub fn mean<'a>(spectra: impl IntoIterator<Item = &'a Spectrum>) -> Option<Spectrum> {
        let mut spectra = spectra.into_iter();
        let first = spectra.next()?;
        let (mut power, mut count) = (first.power.clone(), 1);
        for s in spectra {
            if s.frequency != first.frequency {
                return None;
            }
            // Ring by ring in the spectra's order: the same sums whoever asks.
            power.iter_mut().zip(&s.power).for_each(|(p, q)| *p += q);
            count += 1;
        }
        power.iter_mut().for_each(|p| *p /= count as f64);
        Some(Spectrum { frequency: first.frequency.clone(), power })
    }
}

/// Plane `a + b·x + c·y` fitted by least squares on a regular grid (x and y are centred, so
/// the normal equations are diagonal).
fn detrended(values: &[f64], n: usize) -> Vec<f64> {
    let centre = (n as f64 - 1.0) / 2.0;
    let (mut sum, mut sx, mut sy, mut sxx) = (0.0, 0.0, 0.0, 0.0);
    for (i, &v) in values.iter().enumerate() {
        let (y, x) = ((i / n) as f64 - centre, (i % n) as f64 - centre);
        sum += v;
        sx += v * x;
        sy += v * y;
        sxx += x * x;
    }
    let (a, b, c) = (sum / values.len() as f64, sx / sxx, sy / sxx);
    values
        .iter()
        .enumerate()
        .map(|(i, &v)| v - a - b * ((i % n) as f64 - centre) - c * ((i / n) as f64 - centre))
        .collect()
}

/// The radially averaged power spectrum of the largest centred power-of-two square of `r`:
/// a best-fit plane is removed and a 2-D Hann window applied (so the tile's edges do not
/// leak a k⁻² artefact into every ring), then |FFT|²·pixel²/Σw² is averaged over integer
/// rings ρ = round(|k|). Empty for rasters under 8×8.
pub fn radial_power_spectrum(r: &Raster) -> Spectrum {
    let side = r.rows.min(r.cols);
    if side < 8 {
        return Spectrum { frequency: Vec::new(), power: Vec::new() };
    }
    let n = 1usize << side.ilog2();
    let crop = r.crop((r.rows - n) / 2, (r.cols - n) / 2, n, n);
    let values: Vec<f64> = crop.data.iter().map(|&v| v as f64).collect();
    let hann: Vec<f64> =
        (0..n).map(|i| 0.5 - 0.5 * (std::f64::consts::TAU * i as f64 / (n - 1) as f64).cos()).collect();
    let mut field: Vec<Complex> =
        detrended(&values, n).iter().enumerate().map(|(i, &v)| (v * hann[i / n] * hann[i % n], 0.0)).collect();
    let weight: f64 = hann.iter().map(|w| w * w).sum::<f64>().powi(2);
    fft2(&mut field, n, n, false);
    let rings = n / 2;
    let (mut sum, mut count) = (vec![0.0; rings + 1], vec![0usize; rings + 1]);
    let signed = |i: usize| if i < n / 2 { i as f64 } else { i as f64 - n as f64 };
    for (i, v) in field.iter().enumerate() {
        let rho = signed(i / n).hypot(signed(i % n)).round() as usize;
        if (1..=rings).contains(&rho) {
            sum[rho] += (v.0 * v.0 + v.1 * v.1) * r.metres * r.metres / weight;
            count[rho] += 1;
        }
    }
    let frequency = (1..=rings).map(|rho| rho as f64 / (n as f64 * r.metres)).collect();
    let power = (1..=rings).map(|rho| sum[rho] / count[rho].max(1) as f64).collect();
    Spectrum { frequency, power }
}

/// The fitted slope β of log power against log frequency over rings 4…N/4 (wavelengths from
/// a quarter of the tile down to 4 pixels: the lowest rings are blurred by the window, the
/// highest by resampling and gridding). Rings are weighted 1/ρ so each octave counts the same.
/// NaN when fewer than 3 usable rings.
pub fn fit_beta(s: &Spectrum) -> f64 {
    let rings = s.power.len();
    let points: Vec<(f64, f64, f64)> = (4..=rings / 2)
        .filter(|&rho| s.power[rho - 1] > 0.0)
        .map(|rho| (s.frequency[rho - 1].ln(), s.power[rho - 1].ln(), 1.0 / rho as f64))
        .collect();
    if points.len() < 3 {
        return f64::NAN;
    }
    let wsum: f64 = points.iter().map(|p| p.2).sum();
    let mx = points.iter().map(|p| p.2 * p.0).sum::<f64>() / wsum;
    let my = points.iter().map(|p| p.2 * p.1).sum::<f64>() / wsum;
    let sxy: f64 = points.iter().map(|p| p.2 * (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = points.iter().map(|p| p.2 * (p.0 - mx).powi(2)).sum();
    sxy / sxx
}

/// [`fit_beta`] of the mean of `spectra` (NaN when there are none or their rings differ).
fn beta_of_mean<'a>(spectra: impl IntoIterator<Item = &'a Spectrum>) -> f64 {
    Spectrum::mean(spectra).map_or(f64::NAN, |m| fit_beta(&m))
}

/// Resamples [`beta_sampling_sd`] draws: enough that the estimate's own scatter is a few per cent.
pub const BOOTSTRAP_RESAMPLES: usize = 400;

/// How far the β of the mean of `spectra` moves with the choice of tiles: the standard
/// deviation of [`fit_beta`] over [`BOOTSTRAP_RESAMPLES`] bootstrap resamples of the tiles
/// (drawn with replacement from a fixed ChaCha stream, so a report is reproducible). A set's
/// mean spectrum is dominated by its few most rugged tiles, so this is large next to most
/// distances the report prints; it is the β-estimate's standard error, not a tolerance. NaN
/// for fewer than two spectra or spectra of different rings.
pub fn beta_sampling_sd(spectra: &[Spectrum]) -> f64 {
    let n = spectra.len();
    if n < 2 || spectra.iter().any(|s| s.frequency != spectra[0].frequency) {
        return f64::NAN;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(0x5eed_b00f);
    let betas: Vec<f64> = (0..BOOTSTRAP_RESAMPLES)
        .map(|_| beta_of_mean((0..n).map(|_| &spectra[(rng.next_u64() % n as u64) as usize])))
        .filter(|b| b.is_finite())
        .collect();
    let m = betas.len().max(1) as f64;
    let mean = betas.iter().sum::<f64>() / m;
    (betas.iter().map(|b| (b - mean).powi(2)).sum::<f64>() / m).sqrt()
}

/// Random partitions [`real_split_distances`] draws.
pub const REAL_SPLITS: usize = 1000;

/// What distance in β two sets of **real** tiles lie apart by the choice of tiles alone: the
/// tiles of `a` and `b` are pooled and, [`REAL_SPLITS`] times, dealt at random (fixed ChaCha
/// stream) into a set of about `a.len()` tiles and one of the rest; each partition gives
/// |β(mean of one) − β(mean of the other)|. Returned sorted ascending. A distance line that
/// most of these miss is one that real land itself misses.
///
/// `regions` (one key per pooled tile, `a`'s first) deals whole regions — neighbouring tiles
/// alike, as a held-out split by squares is made — until the first set holds `a.len()` tiles
/// or more; `None` deals tiles one by one, which ignores neighbours' likeness and so scatters
/// less than a split by regions. Empty when either set is empty, the keys do not match the
/// tiles, or the spectra's rings differ.
pub fn real_split_distances(a: &[Spectrum], b: &[Spectrum], regions: Option<&[u64]>) -> Vec<f64> {
    let pool: Vec<&Spectrum> = a.iter().chain(b).collect();
    let bad_keys = regions.is_some_and(|k| k.len() != pool.len());
    if a.is_empty() || b.is_empty() || bad_keys || pool.iter().any(|s| s.frequency != pool[0].frequency) {
        return Vec::new();
    }
    // Tiles grouped by region, in order of first appearance (so the deal is reproducible).
    let mut groups: Vec<Vec<&Spectrum>> = Vec::new();
    match regions {
        None => groups.extend(pool.iter().map(|s| vec![*s])),
        Some(keys) => {
            let mut index = std::collections::HashMap::new();
            for (s, k) in pool.iter().zip(keys) {
                let g = *index.entry(*k).or_insert_with(|| {
                    groups.push(Vec::new());
                    groups.len() - 1
                });
                groups[g].push(*s);
            }
        }
    }
    let mean_beta = |set: &[&Vec<&Spectrum>]| beta_of_mean(set.iter().flat_map(|g| g.iter().copied()));
    let mut rng = ChaCha8Rng::seed_from_u64(0x5711_7000);
    let mut order: Vec<&Vec<&Spectrum>> = groups.iter().collect();
    let mut out: Vec<f64> = (0..REAL_SPLITS)
        .map(|_| {
            for i in (1..order.len()).rev() {
                order.swap(i, (rng.next_u64() % (i as u64 + 1)) as usize);
            }
            // Whole groups into the first set until it holds a.len() tiles; never all of them.
            let (mut tiles, mut cut) = (0, 0);
            while tiles < a.len() && cut < order.len() - 1 {
                tiles += order[cut].len();
                cut += 1;
            }
            let (one, other) = order.split_at(cut);
            (mean_beta(one) - mean_beta(other)).abs()
        })
        .filter(|d| d.is_finite())
        .collect();
    out.sort_unstable_by(f64::total_cmp);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::fbm::Gaussian;
    use std::f64::consts::TAU;

    #[test]
    fn white_noise_has_a_flat_spectrum() {
        let mut g = Gaussian::new(7);
        let r = Raster::from_fn(128, 128, 1000.0, |_, _| (g.next() * 100.0) as f32);
        let beta = fit_beta(&radial_power_spectrum(&r));
        assert!(beta.abs() < 0.1, "white noise β = {beta}");
    }

    #[test]
    fn amplitudes_falling_as_one_over_k_give_beta_minus_two() {
        // Built by a naive inverse DFT (no FFT involved): every lattice frequency k ≠ 0 of the
        // half plane with amplitude |k|⁻¹ and a random phase. Power ∝ |k|⁻², so β = −2.
        let n = 64;
        let mut g = Gaussian::new(11);
        let mut waves = Vec::new();
        for ky in 0..=n as i64 / 2 {
            for kx in -(n as i64) / 2 + 1..=n as i64 / 2 {
                if ky == 0 && kx <= 0 {
                    continue;
                }
                let k = ((kx * kx + ky * ky) as f64).sqrt();
                waves.push((kx as f64, ky as f64, g.next().hypot(g.next()) / k, TAU * g.uniform()));
            }
        }
        let r = Raster::from_fn(n, n, 500.0, |y, x| {
            waves
                .iter()
                .map(|&(kx, ky, a, p)| a * (TAU * (kx * x as f64 + ky * y as f64) / n as f64 + p).cos())
                .sum::<f64>() as f32
        });
        let beta = fit_beta(&radial_power_spectrum(&r));
        assert!((beta + 2.0).abs() < 0.2, "brown noise β = {beta}");
    }

    #[test]
    fn rings_are_in_cycles_per_metre_and_odd_sizes_are_cropped() {
        let r = Raster::from_fn(40, 70, 250.0, |y, x| (x + y) as f32);
        let s = radial_power_spectrum(&r);
        assert_eq!(s.frequency.len(), 16, "a 40×70 raster is measured on its central 32×32");
        assert!((s.frequency[0] - 1.0 / (32.0 * 250.0)).abs() < 1e-15);
        assert!(s.power.iter().all(|p| *p < 1e-12), "a plane is removed entirely: {:?}", s.power);
        assert!(Spectrum::mean(&[s.clone(), s.clone()]).is_some_and(|m| m == s));
    }

    /// A tile whose spectrum is the power law k^β, all crossing at ring 9 (so a mix's slope
    /// depends on how many of each it holds).
    fn tile(beta: f64) -> Spectrum {
        let frequency: Vec<f64> = (1..=32).map(|r| r as f64 / 64_000.0).collect();
        let power = frequency.iter().map(|f| (f / frequency[8]).powf(beta)).collect();
        Spectrum { frequency, power }
    }

    #[test]
    fn the_bootstrap_sd_grows_with_the_spread_between_tiles() {
        let alike: Vec<Spectrum> = (0..40).map(|i| tile(-2.8 + 0.001 * (i % 2) as f64)).collect();
        let mixed: Vec<Spectrum> = (0..40).map(|i| tile(if i % 2 == 0 { -2.4 } else { -3.2 })).collect();
        let (a, m) = (beta_sampling_sd(&alike), beta_sampling_sd(&mixed));
        assert!(a < 1e-3 && m > 0.02, "identical tiles {a}, mixed tiles {m}");
        assert_eq!(beta_sampling_sd(&mixed), m, "a fixed stream: the same answer every time");
        assert!(beta_sampling_sd(&mixed[..1]).is_nan());
    }

    #[test]
    fn real_splits_measure_how_far_real_sets_lie_apart_by_chance() {
        let alike: Vec<Spectrum> = (0..30).map(|_| tile(-2.8)).collect();
        let same = real_split_distances(&alike[..10], &alike[10..], None);
        assert_eq!(same.len(), REAL_SPLITS);
        assert!(same.iter().all(|d| *d < 1e-9), "identical tiles never differ: {:?}", same.last());
        let mixed: Vec<Spectrum> = (0..30).map(|i| tile(if i % 3 == 0 { -2.3 } else { -3.1 })).collect();
        let d = real_split_distances(&mixed[..10], &mixed[10..], None);
        assert!(d.windows(2).all(|w| w[0] <= w[1]), "sorted");
        assert!(d[d.len() / 2] > 0.01 && d[0] < d[d.len() - 1], "median {}", d[d.len() / 2]);
        assert_eq!(
            real_split_distances(&mixed[..10], &mixed[10..], None),
            d,
            "a fixed stream: the same answer every time"
        );
        assert!(real_split_distances(&mixed[..0], &mixed, None).is_empty());
        // Regions of alike tiles (each region one slope): dealt whole, sets differ more often
        // and by more than when their tiles are dealt one by one.
        // (Two rugged regions of six, so no deal leaves both sets the same mix.)
        let regional: Vec<Spectrum> = (0..30).map(|i| tile(if i / 5 < 2 { -2.3 } else { -3.1 })).collect();
        let keys: Vec<u64> = (0..30).map(|i| i / 5).collect();
        let by_tile = real_split_distances(&regional[..10], &regional[10..], None);
        let by_region = real_split_distances(&regional[..10], &regional[10..], Some(&keys));
        let median = |v: &[f64]| v[v.len() / 2];
        assert!(median(&by_region) > median(&by_tile), "{} vs {}", median(&by_region), median(&by_tile));
        assert!(real_split_distances(&regional[..10], &regional[10..], Some(&keys[1..])).is_empty(), "a key per tile");
    }
}
