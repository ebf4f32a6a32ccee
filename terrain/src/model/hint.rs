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

/// Number of context features (a constant included).
pub const FEATURES: usize = 4;
/// Names of the features, in coefficient order, for the manifest and logs.
pub const FEATURE_NAMES: [&str; FEATURES] = ["1", "mean_low", "ln_std_low", "ln_mean_gradient_low"];

/// A linear predictor of the relief entry of the conditioning vector.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ReliefHint {
    /// What each coefficient multiplies ([`FEATURE_NAMES`]).
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
/// units (√m), as the model's conditioning channel holds it before normalisation.
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
    [1.0, mean / 100.0, (var.sqrt() + 1e-2).ln(), (gradient + 1e-3).ln()]
}

impl ReliefHint {
    /// Least-squares fit of `targets` on the feature rows `x`. `None` when the system is
    /// singular (too few or degenerate samples).
    pub fn fit(x: &[[f64; FEATURES]], targets: &[f64]) -> Option<ReliefHint> {
        assert_eq!(x.len(), targets.len());
        // Normal equations XᵀX·c = Xᵀy, solved by Gaussian elimination with partial pivoting
        // (4×4: no library needed).
        let mut a = [[0.0f64; FEATURES + 1]; FEATURES];
        for (row, &t) in x.iter().zip(targets) {
            for i in 0..FEATURES {
                for j in 0..FEATURES {
                    a[i][j] += row[i] * row[j];
                }
                a[i][FEATURES] += row[i] * t;
            }
        }
        for col in 0..FEATURES {
            let pivot = (col..FEATURES).max_by(|&p, &q| a[p][col].abs().total_cmp(&a[q][col].abs()))?;
            if a[pivot][col].abs() < 1e-9 {
                return None;
            }
            a.swap(col, pivot);
            let pivot_row = a[col];
            for (r, row) in a.iter_mut().enumerate() {
                if r != col {
                    let f = row[col] / pivot_row[col];
                    for (v, p) in row.iter_mut().zip(&pivot_row).skip(col) {
                        *v -= f * p;
                    }
                }
            }
        }
        let coefficients: Vec<f64> = (0..FEATURES).map(|i| a[i][FEATURES] / a[i][i]).collect();
        let mut hint = ReliefHint {
            features: FEATURE_NAMES.iter().map(|s| s.to_string()).collect(),
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
        let errors: Vec<f64> = x
            .iter()
            .zip(targets)
            .map(|(row, t)| t - row.iter().zip(&self.coefficients).map(|(f, c)| f * c).sum::<f64>())
            .collect();
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
        features(low, side).iter().zip(&self.coefficients).map(|(f, c)| f * c).sum::<f64>()
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
        if self.features != FEATURE_NAMES {
            return Err(format!("relief_hint.features = {:?}, this build computes {:?}", self.features, FEATURE_NAMES));
        }
        if self.coefficients.len() != FEATURES || self.coefficients.iter().any(|c| !c.is_finite()) {
            return Err(format!("relief_hint.coefficients must be {FEATURES} finite numbers"));
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
        let hint = ReliefHint::fit(&x, &y).expect("well-posed");
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
        assert_eq!(ReliefHint::fit(&x, &[1.0; 10]), None);
        let bad = ReliefHint { features: vec!["1".into()], coefficients: vec![0.0], ..Default::default() };
        assert!(bad.validate().unwrap_err().contains("relief_hint.features"));
    }
}
