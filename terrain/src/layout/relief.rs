//! The raw relief field: domain-warped continental fBm, ridged mountain ranges inside
//! low-frequency belts, and small-scale detail, calibrated and quantile-mapped on a sample.

use super::fbm::{smoothstep, Fbm};
use super::hypsometry::{quantile, Hypsometry, Ranks};
use super::LayoutSettings;
use crate::noise::hash3;

/// Noise component tags (keep every component's octaves independent).
const WARP_Y: u64 = 1;
const WARP_X: u64 = 2;
const CONTINENT_LOW: u64 = 3;
const CONTINENT_HIGH: u64 = 4;
const BELTS: u64 = 5;
const RIDGES: u64 = 6;
const DETAIL: u64 = 7;
const SAMPLE: u64 = 8;

/// Octaves of the continental value counted as "low frequency" (wavelengths L … L/8).
const LOW_OCTAVES: u32 = 4;
/// Shortest continental wavelength, metres.
const CONTINENT_SHORTEST_M: f64 = 5_000.0;
/// Longest and shortest detail wavelengths, metres.
const DETAIL_LONGEST_M: f64 = 16_000.0;
const DETAIL_SHORTEST_M: f64 = 1_000.0;
/// Domain-warp displacement as a fraction of the continent scale.
const WARP_FRACTION: f64 = 0.25;
/// Height of a mountain crest over its surroundings, in standard deviations of the
/// continental value (ranks are what matter, so only ratios between components count).
const MOUNTAIN_AMPLITUDE: f64 = 3.0;
/// Factor on the continental value's rise above the coast: continental interiors are mostly
/// plains and shields, so the high ranks go to the mountain belts.
const INTERIOR_RISE: f64 = 0.4;
/// Detail amplitude on plains and extra in mountains, in the same units.
const DETAIL_PLAIN: f64 = 0.04;
const DETAIL_MOUNTAIN: f64 = 0.25;
/// Width of the belt mask's soft edge, in belt-value units.
const BELT_EDGE: f64 = 0.12;
/// Side of the calibration sample's jittered lattice, and its spacing in continent scales.
const SAMPLE_SIDE: i64 = 80;
const SAMPLE_SPACING: f64 = 0.5;

/// The noise components before calibration.
#[derive(Clone, Debug)]
struct Noises {
    warp_y: Fbm,
    warp_x: Fbm,
    warp_m: f64,
    low: Fbm,
    high: Fbm,
    belts: Fbm,
    ridges: Fbm,
    detail: Fbm,
}

/// The large-scale values at one point, from which the raw field is assembled.
#[derive(Clone, Copy, Debug)]
struct Base {
    /// Domain-warped coordinates, metres.
    wy: f64,
    wx: f64,
    /// Continental value from the low octaves only.
    low: f64,
    /// Full continental value (low + high octaves).
    full: f64,
    /// Belt value in [0, 1]: high along the zero lines of a low-frequency noise.
    belt: f64,
}

impl Noises {
    fn new(seed: u64, s: &LayoutSettings) -> Noises {
        let l = s.continent_scale_km * 1000.0;
        let low_shortest = l / f64::from(1u32 << (LOW_OCTAVES - 1));
        let high_amplitude = 0.5f64.powi(LOW_OCTAVES as i32);
        Noises {
            warp_y: Fbm::new(seed, WARP_Y, l, l / 2.0, 1.0, 0.5),
            warp_x: Fbm::new(seed, WARP_X, l, l / 2.0, 1.0, 0.5),
            warp_m: WARP_FRACTION * l,
            low: Fbm::new(seed, CONTINENT_LOW, l, low_shortest, 1.0, 0.5),
            high: Fbm::new(seed, CONTINENT_HIGH, low_shortest / 2.0, CONTINENT_SHORTEST_M, high_amplitude, 0.5),
            belts: Fbm::new(seed, BELTS, l, l / 2.0, 1.0, 0.4),
            ridges: Fbm::new(seed, RIDGES, l / 6.0, l / 24.0, 1.0, 0.5),
            detail: Fbm::new(seed, DETAIL, DETAIL_LONGEST_M.min(l / 8.0), DETAIL_SHORTEST_M, 1.0, 0.5),
        }
    }

    fn warp(&self, y: f64, x: f64) -> (f64, f64) {
        (y + self.warp_m * self.warp_y.at(y, x), x + self.warp_m * self.warp_x.at(y, x))
    }

    fn base(&self, y: f64, x: f64) -> Base {
        let (wy, wx) = self.warp(y, x);
        let low = self.low.at(wy, wx);
        // The high octaves are not warped: warping stretches short wavelengths into streaks.
        let full = low + self.high.at(y, x);
        let belt = 1.0 - self.belts.at(wy, wx).abs();
        Base { wy, wx, low, full, belt }
    }
}

/// Thresholds measured on the calibration sample.
#[derive(Clone, Copy, Debug)]
struct Calibration {
    /// Standard deviation of the full continental value (the unit of the raw field).
    sigma: f64,
    /// Full continental value at the coast (its ocean-fraction quantile).
    coast: f64,
    /// Low continental value at the coast and deep inland (continentality 0 and 1).
    coast_low: f64,
    inland_low: f64,
    /// Belt value above which mountain ranges appear; `None` with no mountains at all.
    belt: Option<f64>,
}

impl Calibration {
    fn new(bases: &[Base], s: &LayoutSettings) -> Calibration {
        let sorted = |f: fn(&Base) -> f64| {
            let mut v: Vec<f64> = bases.iter().map(f).collect();
            v.sort_by(f64::total_cmp);
            v
        };
        let (full, low, belt) = (sorted(|b| b.full), sorted(|b| b.low), sorted(|b| b.belt));
        let n = full.len() as f64;
        let mean = full.iter().sum::<f64>() / n;
        let sigma = (full.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt().max(1e-9);
        let p = s.ocean_fraction;
        let coast_low = quantile(&low, p);
        // Deep inland = the innermost quarter of the land by low continental value.
        let inland_low = quantile(&low, p + 0.75 * (1.0 - p)).max(coast_low + 1e-6);
        // Share of the area inside mountain belts: 0 none, ~1/3 Earth-like, all at 3.
        let coverage = (s.mountain_frequency / 3.0).clamp(0.0, 1.0);
        let belt = (coverage > 0.0).then(|| quantile(&belt, 1.0 - coverage));
        Calibration { sigma, coast: quantile(&full, p), coast_low, inland_low, belt }
    }
}

/// The calibrated, quantile-mapped relief of one seed.
#[derive(Clone, Debug)]
pub(crate) struct Relief {
    noises: Noises,
    cal: Calibration,
    ranks: Ranks,
    hypsometry: Hypsometry,
}

impl Relief {
    /// Builds the noises, then calibrates thresholds and the rank map on a deterministic
    /// jittered lattice spanning 40 continent scales per side.
    pub(crate) fn new(seed: u64, s: &LayoutSettings) -> Relief {
        let noises = Noises::new(seed, s);
        let spacing = SAMPLE_SPACING * s.continent_scale_km * 1000.0;
        let points: Vec<(f64, f64)> = (0..SAMPLE_SIDE * SAMPLE_SIDE)
            .map(|i| {
                let h = hash3(seed ^ SAMPLE, i / SAMPLE_SIDE, i % SAMPLE_SIDE);
                let jitter = |bits: u64| (bits & 0xffff_ffff) as f64 / (1u64 << 32) as f64;
                let y = ((i / SAMPLE_SIDE - SAMPLE_SIDE / 2) as f64 + jitter(h)) * spacing;
                let x = ((i % SAMPLE_SIDE - SAMPLE_SIDE / 2) as f64 + jitter(h >> 32)) * spacing;
                (y, x)
            })
            .collect();
        let bases: Vec<Base> = points.iter().map(|&(y, x)| noises.base(y, x)).collect();
        let cal = Calibration::new(&bases, s);
        let mut relief = Relief {
            noises,
            cal,
            ranks: Ranks::new(vec![0.0, 1.0]),
            hypsometry: Hypsometry::new(s.ocean_fraction, s.mountain_frequency),
        };
        let raw = points.iter().zip(&bases).map(|(&(y, x), b)| relief.raw(b, y, x)).collect();
        relief.ranks = Ranks::new(raw);
        relief
    }

    /// Weight of mountain ranges in [0, 1]: inside a belt and on land (or just off the coast,
    /// which gives island arcs).
    fn mountain_weight(&self, b: &Base) -> f64 {
        let Some(threshold) = self.cal.belt else { return 0.0 };
        let belt = smoothstep(threshold - 0.5 * BELT_EDGE, threshold + 0.5 * BELT_EDGE, b.belt);
        let (c, s) = (self.cal.coast, self.cal.sigma);
        belt * smoothstep(c - 0.05 * s, c + 0.3 * s, b.full)
    }

    /// The raw scalar: continental value + ranges + detail (larger in mountains).
    fn raw(&self, b: &Base, y: f64, x: f64) -> f64 {
        let m = self.mountain_weight(b);
        let ranges = if m > 0.0 { m * (0.15 + 0.85 * self.noises.ridges.ridged(b.wy, b.wx)) } else { 0.0 };
        let detail = (DETAIL_PLAIN + DETAIL_MOUNTAIN * m) * self.noises.detail.at(y, x);
        let coast = self.cal.coast;
        let continental = if b.full > coast { coast + INTERIOR_RISE * (b.full - coast) } else { b.full };
        continental + self.cal.sigma * (MOUNTAIN_AMPLITUDE * ranges + detail)
    }

    /// Elevation in metres at a point in metres.
    pub(crate) fn elevation(&self, y: f64, x: f64) -> f64 {
        let b = self.noises.base(y, x);
        self.hypsometry.elevation(self.ranks.rank(self.raw(&b, y, x)))
    }

    /// Continentality in [0, 1] from the low-frequency continental value only, so it is
    /// smooth: 0 at and beyond the coast, 1 deep inland.
    pub(crate) fn continentality(&self, y: f64, x: f64) -> f64 {
        let (wy, wx) = self.noises.warp(y, x);
        smoothstep(self.cal.coast_low, self.cal.inland_low, self.noises.low.at(wy, wx))
    }
}
