//! Quantile mapping: the raw noise field's empirical distribution (raw value → rank) and
//! Earth-like hypsometric curves (rank → metres), so the layout's elevations follow real
//! distributions whatever the noise's own statistics are.

/// Quantiles shared by the land tables.
const LAND_U: [f64; 14] = [0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95, 0.98, 0.995, 1.0];
/// Earth's land hypsometry, metres at [`LAND_U`]. Starts at 1 m so land is strictly above
/// the sea.
const EARTH_LAND_M: [f64; 14] =
    [1.0, 40.0, 110.0, 200.0, 300.0, 430.0, 580.0, 800.0, 1150.0, 1800.0, 2600.0, 3800.0, 5000.0, 6500.0];
/// Land without mountain ranges (`mountain_frequency = 0`): the lowlands and old shields of
/// Earth's curve, topping out at high plateaus.
const LOWLAND_M: [f64; 14] =
    [1.0, 30.0, 80.0, 140.0, 200.0, 270.0, 350.0, 450.0, 580.0, 800.0, 1000.0, 1300.0, 1700.0, 2200.0];
/// Earth's ocean hypsometry from the deepest trench up to the coast: (quantile, metres).
/// Ends at −1 m so the sea is strictly below sea level.
const OCEAN: [(f64, f64); 11] = [
    (0.0, -8000.0),
    (0.02, -6500.0),
    (0.1, -5600.0),
    (0.3, -4800.0),
    (0.5, -4200.0),
    (0.7, -3300.0),
    (0.8, -2500.0),
    (0.86, -1200.0),
    (0.9, -200.0),
    (0.95, -80.0),
    (1.0, -1.0),
];

/// Piecewise-linear interpolation in a table sorted by its first column (clamped at ends).
pub(crate) fn interp(table: &[(f64, f64)], u: f64) -> f64 {
    let i = table.partition_point(|&(k, _)| k <= u).clamp(1, table.len() - 1);
    let ((u0, v0), (u1, v1)) = (table[i - 1], table[i]);
    let t = ((u - u0) / (u1 - u0)).clamp(0.0, 1.0);
    v0 + t * (v1 - v0)
}

/// The `u`-quantile of sorted values, linearly interpolated.
pub(crate) fn quantile(sorted: &[f64], u: f64) -> f64 {
    let pos = u.clamp(0.0, 1.0) * (sorted.len() - 1) as f64;
    let i = (pos.floor() as usize).min(sorted.len() - 1);
    let j = (i + 1).min(sorted.len() - 1);
    sorted[i] + (pos - i as f64) * (sorted[j] - sorted[i])
}

/// The empirical distribution of a sample: maps a value to its rank u ∈ (0, 1), strictly
/// increasing, with exponential tails beyond the sample's extremes.
#[derive(Clone)]
pub(crate) struct Ranks {
    sorted: Vec<f64>,
    /// Spread of the lowest and highest 1/64 of the sample: how fast the tails approach 0 and 1.
    tail_lo: f64,
    tail_hi: f64,
}

impl std::fmt::Debug for Ranks {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Ranks({} samples)", self.sorted.len())
    }
}

impl Ranks {
    /// The distribution of `values` (at least two).
    pub(crate) fn new(mut values: Vec<f64>) -> Ranks {
        values.sort_by(f64::total_cmp);
        let n = values.len();
        let m = (n / 64).max(1);
        let tail_lo = (values[m] - values[0]).max(1e-12);
        let tail_hi = (values[n - 1] - values[n - 1 - m]).max(1e-12);
        Ranks { sorted: values, tail_lo, tail_hi }
    }

    /// The rank of `r`: (i + 1 + fraction) / (n + 1) between the sample's i-th and (i+1)-th
    /// values.
    pub(crate) fn rank(&self, r: f64) -> f64 {
        let s = &self.sorted;
        let (n, step) = (s.len(), 1.0 / (s.len() + 1) as f64);
        // Hyperbolic tails: continuous at the extremes, never reaching 0 or 1.
        if r <= s[0] {
            return step / (1.0 + (s[0] - r) / self.tail_lo);
        }
        if r >= s[n - 1] {
            return 1.0 - step / (1.0 + (r - s[n - 1]) / self.tail_hi);
        }
        let i = s.partition_point(|&v| v <= r).saturating_sub(1).min(n - 2);
        let gap = s[i + 1] - s[i];
        let frac = if gap > 0.0 { ((r - s[i]) / gap).clamp(0.0, 1.0) } else { 0.0 };
        (i as f64 + 1.0 + frac) * step
    }
}

/// Rank → elevation: the lowest `ocean_fraction` of ranks are sea floor, the rest land.
#[derive(Clone, Debug)]
pub(crate) struct Hypsometry {
    ocean_fraction: f64,
    /// The land curve for this mountain frequency (blend of lowland and Earth curves).
    land: Vec<(f64, f64)>,
    /// Exponent pushing land ranks up (1 − (1 − u)^k) for more mountainous worlds.
    land_push: f64,
}

impl Hypsometry {
    /// The curves for an ocean fraction and a mountain frequency (0 none, 1 Earth, 3 most):
    /// below 1 the land curve blends toward lowlands, above 1 more land is pushed up it.
    pub(crate) fn new(ocean_fraction: f64, mountain_frequency: f64) -> Hypsometry {
        let f = mountain_frequency.clamp(0.0, 1.0);
        let land = LAND_U
            .iter()
            .zip(EARTH_LAND_M.iter().zip(&LOWLAND_M))
            .map(|(&u, (&earth, &low))| (u, low + f * (earth - low)))
            .collect();
        Hypsometry { ocean_fraction: ocean_fraction.clamp(0.0, 0.999), land, land_push: mountain_frequency.max(1.0) }
    }

    /// Elevation in metres at rank `u` ∈ (0, 1): < 0 below the ocean fraction, > 0 above.
    pub(crate) fn elevation(&self, u: f64) -> f64 {
        let p = self.ocean_fraction;
        if u < p {
            interp(&OCEAN, u / p).min(-1.0)
        } else {
            let v = ((u - p) / (1.0 - p)).clamp(0.0, 1.0);
            let v = 1.0 - (1.0 - v).powf(self.land_push);
            interp(&self.land, v).max(1.0)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranks_are_strictly_increasing_and_inside_the_unit_interval() {
        let r = Ranks::new((0..100).map(|i| (i as f64 * 0.37).sin()).collect());
        let mut last = 0.0;
        for k in -300..300 {
            let u = r.rank(k as f64 * 0.01);
            assert!(u > 0.0 && u < 1.0 && u > last, "rank {u} after {last}");
            last = u;
        }
    }

    #[test]
    fn coastline_separates_sea_from_land() {
        let h = Hypsometry::new(0.6, 1.0);
        assert!(h.elevation(0.599_999) < 0.0 && h.elevation(0.6) > 0.0);
        assert!(h.elevation(1e-9) <= -7999.0 && h.elevation(1.0) >= 6499.0);
        assert!((h.elevation(0.8) - 430.0).abs() < 1e-6, "land median");
    }
}
