//! The relief hint: a window's expected roughness, predicted from its context alone.
//!
//! The networks are trained with a conditioning vector `[relief_z, present]`, where `relief_z`
//! is the z-scored ln standard deviation of the crop's own residual (the relief the model is
//! asked to draw); it is dropped (all zeros) for a fifth of the samples so the model also
//! works without it. Unconditioned, a model trained on gentler land than it is asked to
//! draw regresses towards the average roughness of its training set, so great ranges come
//! out too smooth. The hint closes that gap without peeking at the answer: a linear model of
//! `relief_z` on statistics of the window's low band — the only thing the pipeline knows
//! there — fitted by least squares on the training crops.

use serde::{Deserialize, Serialize};

use crate::encoding::box_downsample;

/// Every context statistic this build can compute, in the order [`features`] returns them, by
/// the names the manifest and logs use. A manifest's hint names the ones it was fitted on, so
/// a hint fitted on fewer (an older fit) keeps working. The first [`BASE_FEATURES`] (the
/// shipped core's hint) explain 86–88 % of the variance of the core's `relief_z` (training /
/// held-out windows); with the block statistics 90–93 %, the rms error falling from 0.355 to
/// 0.275 z on held-out land (4,000 crops each).
pub const FEATURE_NAMES: [&str; 8] = [
    "1",
    "mean_low",
    "ln_std_low",
    "ln_mean_gradient_low",
    "ln_mean_laplacian_blocks",
    "ln_max_abs_blocks",
    "land_fraction_blocks",
    "ln_median_gradient_blocks",
];
/// Number of features a fit can use (a constant included).
pub const FEATURES: usize = FEATURE_NAMES.len();
/// The leading features a fit uses unless asked for the block statistics: the shipped core's.
pub const BASE_FEATURES: usize = 4;
/// Side of the blocks the `*_blocks` statistics average the low band over, pixels: the core's
/// context cell, so the statistics see the 8 km grid the pipeline conditions on (for other
/// stages simply a coarser view of their low band).
pub const BLOCK: usize = 8;

/// A linear predictor of the relief entry of the conditioning vector.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ReliefHint {
    /// What each coefficient multiplies (names from [`FEATURE_NAMES`]).
    pub features: Vec<String>,
    /// One coefficient per feature.
    pub coefficients: Vec<f64>,
    /// Fraction of the variance of `relief_z` the fit explains on its training crops.
    pub r2: f64,
    /// Added to every prediction, in z units. A few-step sampler driven by a small, briefly
    /// trained network draws less relief than the vector asks for (its samples regress
    /// towards the mean); asking for a little more restores the real amount. Chosen by
    /// `infiniterra train STAGE --calibrate-relief-hint` on training tiles; 0 until then.
    #[serde(default)]
    pub offset: f64,
    /// The network's response curve, inverted: knots `[prediction, extra]` (predictions
    /// ascending) of a piecewise-linear extra added to each prediction, flat beyond the end
    /// knots. One offset cannot serve every window: the network draws gentle land about as
    /// rough as it is asked to but falls further short the more relief it is asked for, so
    /// rugged windows need a larger extra than flat ones. Measured by
    /// `infiniterra train STAGE --calibrate-relief-response` on training tiles; empty until then.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub response: Vec<[f64; 2]>,
}

/// How a hint's predictions compare with the true `relief_z` of a set of crops.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HintCheck {
    /// Fraction of the variance explained.
    pub r2: f64,
    /// Mean of truth − prediction, z units: positive when the hint asks for too little.
    pub bias: f64,
    /// Root mean square of truth − prediction, z units.
    pub rms: f64,
}

/// The context statistics of one square window of side `side`: its low band in signed-sqrt
/// units (√m), as the model's conditioning channel holds it before normalisation. All of
/// [`FEATURE_NAMES`], in that order. The block statistics read the means of [`BLOCK`]-sided
/// blocks (0 where the window holds fewer than 3×3 of them or is not made of whole blocks).
pub fn features(low: &[f32], side: usize) -> [f64; FEATURES] {
    assert_eq!(low.len(), side * side);
    let n = low.len() as f64;
    let mean = low.iter().map(|&v| v as f64).sum::<f64>() / n;
    let var = low.iter().map(|&v| (v as f64 - mean).powi(2)).sum::<f64>() / n;
    let mut gradient = 0.0f64;
    for y in 0..side - 1 {
        for x in 0..side - 1 {
            let v = low[y * side + x];
            gradient += ((low[y * side + x + 1] - v).abs() + (low[(y + 1) * side + x] - v).abs()) as f64;
        }
    }
    let gradient = gradient / ((side - 1) * (side - 1)) as f64;
    let [laplacian, max_abs, land, median_gradient] = block_statistics(low, side);
    [1.0, mean / 100.0, (var.sqrt() + 1e-2).ln(), (gradient + 1e-3).ln(), laplacian, max_abs, land, median_gradient]
}

/// Statistics of the [`BLOCK`]-sided block means `c` (k×k) of a window's low band: ln of the
/// mean |discrete Laplacian| over interior blocks, ln(max |c| + 1), the fraction of blocks
/// above sea level, and ln of the median gradient magnitude (central differences, one-sided
/// at the edges). Where relief changes within a window (a range rising from a plain) the
/// first and last see it; the window's standard deviation and mean gradient do not.
fn block_statistics(low: &[f32], side: usize) -> [f64; 4] {
    let k = side / BLOCK;
    if k < 3 || side % BLOCK != 0 {
        return [0.0; 4];
    }
    let c: Vec<f64> = box_downsample(low, side, side, BLOCK).into_iter().map(f64::from).collect();
    let at = |y: usize, x: usize| c[y * k + x];
    let mut laplacian = 0.0;
    for y in 1..k - 1 {
        for x in 1..k - 1 {
            laplacian += (4.0 * at(y, x) - at(y - 1, x) - at(y + 1, x) - at(y, x - 1) - at(y, x + 1)).abs();
        }
    }
    let laplacian = laplacian / ((k - 2) * (k - 2)) as f64;
    let max_abs = c.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let land = c.iter().filter(|&&v| v > 0.0).count() as f64 / (k * k) as f64;
    // Central differences inside, one-sided at the edges (numpy's `gradient`).
    let derivative = |i: usize, get: &dyn Fn(usize) -> f64| match i {
        0 => get(1) - get(0),
        i if i == k - 1 => get(k - 1) - get(k - 2),
        i => (get(i + 1) - get(i - 1)) / 2.0,
    };
    let mut magnitudes: Vec<f64> = (0..k * k)
        .map(|i| {
            let (y, x) = (i / k, i % k);
            let dy = derivative(y, &|j| at(j, x));
            let dx = derivative(x, &|j| at(y, j));
            dy.hypot(dx)
        })
        .collect();
    magnitudes.sort_by(f64::total_cmp);
    let m = magnitudes.len();
    let median = if m % 2 == 1 { magnitudes[m / 2] } else { (magnitudes[m / 2 - 1] + magnitudes[m / 2]) / 2.0 };
    [(laplacian + 1e-3).ln(), (max_abs + 1.0).ln(), land, (median + 1e-3).ln()]
}

/// Index into [`FEATURE_NAMES`] of each named feature; `None` for a name this build does not know.
fn feature_indices(names: &[String]) -> Option<Vec<usize>> {
    names.iter().map(|name| FEATURE_NAMES.iter().position(|k| k == name)).collect()
}

impl ReliefHint {
    /// Least-squares fit of `targets` on the first `count` features of the rows `x` (see
    /// [`FEATURE_NAMES`]; [`BASE_FEATURES`] or [`FEATURES`]).
    /// Features that do not vary over the samples (every block above sea level, say) are left
    /// out of the fit and of the hint, so they cannot make the system singular. `None` when
    /// nothing but the constant varies, or the rest is degenerate (collinear).
    pub fn fit(x: &[[f64; FEATURES]], targets: &[f64], count: usize) -> Option<ReliefHint> {
        assert_eq!(x.len(), targets.len());
        let first = x.first()?;
        let used: Vec<usize> = (0..count.min(FEATURES))
            .filter(|&i| i == 0 || x.iter().any(|row| (row[i] - first[i]).abs() > 1e-12))
            .collect();
        if used.len() < 2 {
            return None;
        }
        // Normal equations XᵀX·c = Xᵀy, solved by Gaussian elimination with partial pivoting
        // (at most 8×8: no library needed).
        let m = used.len();
        let mut a = vec![vec![0.0f64; m + 1]; m];
        for (row, &t) in x.iter().zip(targets) {
            for (i, &fi) in used.iter().enumerate() {
                for (j, &fj) in used.iter().enumerate() {
                    a[i][j] += row[fi] * row[fj];
                }
                a[i][m] += row[fi] * t;
            }
        }
        for col in 0..m {
            let pivot = (col..m).max_by(|&p, &q| a[p][col].abs().total_cmp(&a[q][col].abs()))?;
            if a[pivot][col].abs() < 1e-9 {
                return None;
            }
            a.swap(col, pivot);
            let pivot_row = a[col].clone();
            for (r, row) in a.iter_mut().enumerate() {
                if r != col {
                    let f = row[col] / pivot_row[col];
                    for (v, p) in row.iter_mut().zip(&pivot_row).skip(col) {
                        *v -= f * p;
                    }
                }
            }
        }
        let coefficients: Vec<f64> = (0..m).map(|i| a[i][m] / a[i][i]).collect();
        if coefficients.iter().any(|c| !c.is_finite()) {
            return None;
        }
        let mut hint = ReliefHint {
            features: used.iter().map(|&i| FEATURE_NAMES[i].to_string()).collect(),
            coefficients,
            r2: 0.0,
            offset: 0.0,
            response: Vec::new(),
        };
        hint.r2 = hint.check(x, targets).r2;
        Some(hint)
    }

    /// How well the fit (without its offset) predicts `targets` from the feature rows `x`:
    /// on its own crops that is the fit's R²; on held-out crops it shows whether the hint
    /// carries over, and which way it errs.
    pub fn check(&self, x: &[[f64; FEATURES]], targets: &[f64]) -> HintCheck {
        assert_eq!(x.len(), targets.len());
        let n = targets.len().max(1) as f64;
        let mean = targets.iter().sum::<f64>() / n;
        let total: f64 = targets.iter().map(|t| (t - mean).powi(2)).sum();
        let errors: Vec<f64> = x.iter().zip(targets).map(|(row, t)| t - self.combine(row)).collect();
        let residual: f64 = errors.iter().map(|e| e * e).sum();
        HintCheck {
            r2: if total > 0.0 { 1.0 - residual / total } else { 0.0 },
            bias: errors.iter().sum::<f64>() / n,
            rms: (residual / n).sqrt(),
        }
    }

    /// The fit's estimate of the true `relief_z` of a window whose low band is `low` (side
    /// `side`): what the window should look like, before any correction for the network.
    pub fn expected(&self, low: &[f32], side: usize) -> f64 {
        self.combine(&features(low, side))
    }

    /// The linear combination of this hint's features out of a row of all of them.
    fn combine(&self, all: &[f64; FEATURES]) -> f64 {
        // Looked up by name on every call (eight string compares at most, no allocation): a
        // window's network evaluation costs milliseconds, this nanoseconds.
        self.features
            .iter()
            .zip(&self.coefficients)
            .map(|(name, c)| {
                let i = FEATURE_NAMES.iter().position(|k| k == name).expect("validated: every feature is known");
                all[i] * c
            })
            .sum::<f64>()
    }

    /// What the network is asked for in a window whose low band is `low` (side `side`): the
    /// expected relief, plus the response curve's extra there, plus the offset.
    pub fn predict(&self, low: &[f32], side: usize) -> f32 {
        let expected = self.expected(low, side);
        (expected + self.extra(expected) + self.offset) as f32
    }

    /// The response curve at `expected` (0 without one): linear between knots, flat beyond.
    pub fn extra(&self, expected: f64) -> f64 {
        let knots = &self.response;
        match knots.iter().position(|k| k[0] > expected) {
            None => knots.last().map_or(0.0, |k| k[1]),
            Some(0) => knots[0][1],
            Some(i) => {
                let ([x0, y0], [x1, y1]) = (knots[i - 1], knots[i]);
                y0 + (y1 - y0) * (expected - x0) / (x1 - x0)
            }
        }
    }

    /// Checks the manifest entry has the shape this code computes.
    pub fn validate(&self) -> Result<(), String> {
        if feature_indices(&self.features).is_none() || self.features.is_empty() {
            return Err(format!(
                "relief_hint.features = {:?}: each must be one this build computes, {:?}",
                self.features, FEATURE_NAMES
            ));
        }
        if self.coefficients.len() != self.features.len() || self.coefficients.iter().any(|c| !c.is_finite()) {
            return Err(format!(
                "relief_hint.coefficients must be {} finite numbers, one per feature",
                self.features.len()
            ));
        }
        if !self.offset.is_finite() {
            return Err(format!("relief_hint.offset = {} is not a finite number", self.offset));
        }
        if self.response.iter().flatten().any(|v| !v.is_finite())
            || self.response.windows(2).any(|w| w[1][0] <= w[0][0])
        {
            return Err(format!(
                "relief_hint.response = {:?}: knots must be finite [prediction, extra] pairs with predictions strictly ascending",
                self.response
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fit_recovers_a_linear_relation_and_predict_applies_it() {
        // Windows of rising roughness: sine ridges of growing amplitude on a sloping base.
        let side = 16;
        let windows: Vec<Vec<f32>> = (1..40)
            .map(|k| {
                (0..side * side)
                    .map(|i| {
                        let (y, x) = ((i / side) as f32, (i % side) as f32);
                        10.0 + k as f32 + (k as f32 * 0.3) * (x * 0.7).sin() + 0.05 * y * (k % 3) as f32
                    })
                    .collect()
            })
            .collect();
        let x: Vec<[f64; FEATURES]> = windows.iter().map(|w| features(w, side)).collect();
        let truth = [0.5, -2.0, 1.5, 0.25];
        let y: Vec<f64> = x.iter().map(|f| f.iter().zip(&truth).map(|(a, b)| a * b).sum()).collect();
        let hint = ReliefHint::fit(&x, &y, FEATURES).expect("well-posed");
        for (c, t) in hint.coefficients.iter().zip(truth) {
            assert!((c - t).abs() < 1e-6, "{:?} vs {truth:?}", hint.coefficients);
        }
        assert!(hint.r2 > 0.999_999);
        // Truth half a unit above every prediction: a bias of +0.5, nothing else.
        let raised: Vec<f64> = y.iter().map(|v| v + 0.5).collect();
        let check = hint.check(&x, &raised);
        assert!((check.bias - 0.5).abs() < 1e-6 && (check.rms - 0.5).abs() < 1e-6, "{check:?}");
        assert!((hint.predict(&windows[7], side) as f64 - y[7]).abs() < 1e-4);
        hint.validate().expect("fresh fit is valid");
        // Asked for fewer, the fit uses only the leading features (side 16: the block
        // statistics are constant here, so both fits use the first four).
        let base = ReliefHint::fit(&x, &y, BASE_FEATURES).expect("well-posed");
        assert_eq!(base.features, FEATURE_NAMES[..BASE_FEATURES]);
        assert_eq!(ReliefHint::fit(&x, &y, 2).expect("two features").features, ["1", "mean_low"]);
        // The calibration offset shifts every prediction by itself, nothing else.
        let shifted = ReliefHint { offset: 0.75, ..hint.clone() };
        assert!((shifted.predict(&windows[7], side) - hint.predict(&windows[7], side) - 0.75).abs() < 1e-5);
        assert!(ReliefHint { offset: f64::NAN, ..hint }.validate().unwrap_err().contains("relief_hint.offset"));
    }

    #[test]
    fn the_response_curve_adds_its_extra_by_expected_relief_and_stays_flat_beyond_its_knots() {
        let hint = ReliefHint {
            features: FEATURE_NAMES.iter().map(|s| s.to_string()).collect(),
            coefficients: vec![0.0; FEATURES],
            response: vec![[-1.0, 0.0], [1.0, 1.0], [2.0, 2.5]],
            ..Default::default()
        };
        hint.validate().expect("ascending knots are valid");
        for (at, extra) in [(-5.0, 0.0), (-1.0, 0.0), (0.0, 0.5), (1.0, 1.0), (1.5, 1.75), (2.0, 2.5), (9.0, 2.5)] {
            assert!((hint.extra(at) - extra).abs() < 1e-12, "extra({at}) = {} not {extra}", hint.extra(at));
        }
        // Zero coefficients: every window's expected relief is 0, so it is asked for 0 + 0.5.
        assert!((hint.predict(&[1.0; 16], 4) - 0.5).abs() < 1e-6);
        assert_eq!(ReliefHint::default().extra(3.0), 0.0, "no curve, no extra");
        let unsorted = ReliefHint { response: vec![[1.0, 0.0], [1.0, 1.0]], ..hint };
        assert!(unsorted.validate().unwrap_err().contains("relief_hint.response"));
    }

    #[test]
    fn a_degenerate_sample_set_is_refused_and_a_foreign_manifest_entry_is_named() {
        let flat = vec![3.0f32; 64];
        let x = vec![features(&flat, 8); 10];
        assert_eq!(ReliefHint::fit(&x, &[1.0; 10], FEATURES), None);
        let bad = ReliefHint {
            features: vec!["1".into(), "ln_roughness_of_something_else".into()],
            coefficients: vec![0.0; 2],
            ..Default::default()
        };
        assert!(bad.validate().unwrap_err().contains("ln_roughness_of_something_else"));
        let short =
            ReliefHint { features: vec!["1".into(), "mean_low".into()], coefficients: vec![0.0], ..Default::default() };
        assert!(short.validate().unwrap_err().contains("relief_hint.coefficients"));
    }

    /// A manifest fitted on the first four features (before the block statistics) still
    /// predicts exactly what it predicted: the same linear combination of the same values.
    #[test]
    fn a_hint_fitted_on_fewer_features_keeps_its_meaning() {
        let side = 64;
        let low: Vec<f32> =
            (0..side * side).map(|i| 20.0 + ((i % side) as f32 * 0.2).sin() * (i / side) as f32 * 0.3).collect();
        let all = features(&low, side);
        let old = ReliefHint {
            features: FEATURE_NAMES[..4].iter().map(|s| s.to_string()).collect(),
            coefficients: vec![3.0, -0.19, -0.62, 1.47],
            ..Default::default()
        };
        old.validate().expect("a four-feature hint is valid");
        let want = 3.0 - 0.19 * all[1] - 0.62 * all[2] + 1.47 * all[3];
        assert!((old.expected(&low, side) - want).abs() < 1e-12);
    }

    /// The block statistics: a window that is a plain on one side and a range on the other has
    /// a larger median gradient and Laplacian than a uniform slope with the same spread, and
    /// the land fraction counts blocks above sea level.
    #[test]
    fn block_statistics_see_where_relief_changes() {
        let side = 64;
        let ramp: Vec<f32> = (0..side * side).map(|i| (i % side) as f32 - 32.0).collect();
        let step: Vec<f32> = (0..side * side)
            .map(|i| if (i % side) < 40 { -10.0 } else { 20.0 + 3.0 * ((i % side) as f32 - 40.0) })
            .collect();
        let (r, s) = (features(&ramp, side), features(&step, side));
        assert!((r[6] - 0.5).abs() < 1e-12, "half the ramp's blocks lie above sea level: {}", r[6]);
        assert!(s[4] > r[4] + 1.0, "a kink has curvature, a ramp none: {} vs {}", s[4], r[4]);
        assert!(s[5] > r[5], "max |block|: {} vs {}", s[5], r[5]);
        assert_eq!(features(&ramp[..16 * 16], 16)[4..], [0.0; 4], "fewer than 3×3 blocks: no block statistics");
    }
}
