//! Every metric of one set of tiles, pooled over the set: distributions keep (a regular
//! subsample of) every pixel's value, spectra are averaged, counts and sums are added.

use crate::terrain::metrics::{
    beta_sampling_sd, depressions, fit_beta, radial_power_spectrum, relative_elevation, seam_ratio, slope_degrees,
    Depressions, Raster, SeamLines, SeamStats, Spectrum, RELIEF_RADIUS,
};

/// Most values kept per distribution: W1 sorts them, and 2·10⁶ already pins every quantile
/// far below the differences that matter.
const MAX_SAMPLES: usize = 2_000_000;

/// Sea level for drainage, metres: cells at or below it are outlets (the sea takes what flows
/// in), so only land depressions count, in real and generated terrain alike.
pub const SEA_LEVEL_M: f32 = 0.0;

/// The pooled metrics of one set of tiles.
#[derive(Clone, Debug)]
pub struct SetMetrics {
    /// Tiles measured.
    pub tiles: usize,
    /// Fraction of pixels above sea level.
    pub land_fraction: f64,
    /// Mean over tiles of the tile's elevation standard deviation, metres.
    pub mean_tile_std: f64,
    /// Slope samples, degrees.
    pub slopes: Vec<f32>,
    /// Relative-elevation samples, metres.
    pub relief: Vec<f32>,
    /// Mean radially averaged power spectrum (tiles of the set's modal size).
    pub spectrum: Option<Spectrum>,
    /// Fitted spectral slope of the mean spectrum.
    pub beta: f64,
    /// Standard error of `beta` from the choice of tiles (bootstrap over the tiles).
    pub beta_sd: f64,
    /// Each tile's spectrum (those of the modal size): what the real-vs-real splits deal out.
    pub spectra: Vec<Spectrum>,
    /// Pooled depression statistics.
    pub depressions: Depressions,
    /// Pooled seam sums.
    pub seams: SeamStats,
}

/// Keeps every `step`-th value so a set never holds more than [`MAX_SAMPLES`].
struct Sampler {
    step: usize,
    seen: usize,
    kept: Vec<f32>,
}

impl Sampler {
    fn new(total: usize) -> Sampler {
        Sampler { step: total.div_ceil(MAX_SAMPLES).max(1), seen: 0, kept: Vec::new() }
    }

    fn extend(&mut self, values: Vec<f32>) {
        for v in values {
            if self.seen % self.step == 0 {
                self.kept.push(v);
            }
            self.seen += 1;
        }
    }
}

/// Measures `tiles`; seams use `lines` on every tile. `progress(done, total)` counts tiles.
pub fn measure(tiles: &[Raster], lines: SeamLines, progress: &mut dyn FnMut(u64, u64)) -> SetMetrics {
    let interior = |t: &Raster, margin: usize| t.rows.saturating_sub(2 * margin) * t.cols.saturating_sub(2 * margin);
    let mut slopes = Sampler::new(tiles.iter().map(|t| interior(t, 1)).sum());
    let mut relief = Sampler::new(tiles.iter().map(|t| interior(t, RELIEF_RADIUS)).sum());
    let (mut land, mut pixels, mut std_sum) = (0usize, 0usize, 0.0);
    let mut drainage = Depressions::default();
    let mut seams = SeamStats::default();
    let mut spectra = Vec::new();
    for (i, t) in tiles.iter().enumerate() {
        slopes.extend(slope_degrees(t));
        relief.extend(relative_elevation(t, RELIEF_RADIUS));
        land += t.data.iter().filter(|&&v| v > SEA_LEVEL_M).count();
        pixels += t.len();
        std_sum += t.mean_std().1;
        drainage.add(depressions(t, Some(SEA_LEVEL_M)));
        seams.add(seam_ratio(t, lines));
        spectra.push(radial_power_spectrum(t));
        progress(i as u64 + 1, tiles.len() as u64);
    }
    // Tiles of a set share a size except for odd leftovers: average the common rings.
    let modal = spectra.iter().map(|s| s.power.len()).max().unwrap_or(0);
    let same: Vec<Spectrum> = spectra.into_iter().filter(|s| s.power.len() == modal && modal > 0).collect();
    let spectrum = Spectrum::mean(&same);
    let beta_sd = beta_sampling_sd(&same);
    SetMetrics {
        tiles: tiles.len(),
        land_fraction: land as f64 / pixels.max(1) as f64,
        mean_tile_std: std_sum / tiles.len().max(1) as f64,
        slopes: slopes.kept,
        relief: relief.kept,
        beta: spectrum.as_ref().map_or(f64::NAN, fit_beta),
        beta_sd,
        spectrum,
        spectra: same,
        depressions: drainage,
        seams,
    }
}
