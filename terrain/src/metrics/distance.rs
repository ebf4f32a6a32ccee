//! Distances between distributions of samples: Wasserstein-1 and χ² on histograms whose
//! bins are fixed by quantiles of the reference (equal mass per bin for real terrain, so
//! every bin carries the same weight whatever the units).

/// Finite values sorted ascending (NaN and ±∞ dropped: they have no place in a CDF).
fn sorted(values: &[f32]) -> Vec<f64> {
    let mut v: Vec<f64> = values.iter().filter(|v| v.is_finite()).map(|&v| v as f64).collect();
    v.sort_unstable_by(f64::total_cmp);
    v
}

/// Wasserstein-1 (earth mover's) distance between two empirical distributions, in their
/// units: `∫ |F_a(t) − F_b(t)| dt`, exact for samples of any sizes. NaN when either is empty.
/// Identical samples give 0; `b = a + c` gives `|c|`.
pub fn wasserstein1(a: &[f32], b: &[f32]) -> f64 {
    let (a, b) = (sorted(a), sorted(b));
    if a.is_empty() || b.is_empty() {
        return f64::NAN;
    }
    let (na, nb) = (a.len() as f64, b.len() as f64);
    let (mut i, mut j) = (0, 0);
    let mut total = 0.0;
    let mut t = a[0].min(b[0]);
    // Walk the merged sample; between consecutive points both CDFs are constant.
    while i < a.len() || j < b.len() {
        let next = match (a.get(i), b.get(j)) {
            (Some(&x), Some(&y)) => x.min(y),
            (Some(&x), None) => x,
            (None, Some(&y)) => y,
            (None, None) => break,
        };
        total += (i as f64 / na - j as f64 / nb).abs() * (next - t);
        t = next;
        while i < a.len() && a[i] == t {
            i += 1;
        }
        while j < b.len() && b[j] == t {
            j += 1;
        }
    }
    total
}

/// The `bins − 1` interior bin edges that split `reference` into `bins` equal-mass bins
/// (the outer bins are open-ended, so any value falls in some bin).
pub fn quantile_edges(reference: &[f32], bins: usize) -> Vec<f64> {
    let s = sorted(reference);
    if s.is_empty() || bins < 2 {
        return Vec::new();
    }
    (1..bins).map(|k| s[((k * s.len()) / bins).min(s.len() - 1)]).collect()
}

/// Fractions of `values` in each of the `edges.len() + 1` bins (value `v` goes to the first
/// bin whose upper edge exceeds it). All zeros for no finite value.
pub fn histogram(values: &[f32], edges: &[f64]) -> Vec<f64> {
    let mut counts = vec![0.0; edges.len() + 1];
    let mut n = 0.0;
    for &v in values.iter().filter(|v| v.is_finite()) {
        counts[edges.partition_point(|&e| e <= v as f64)] += 1.0;
        n += 1.0;
    }
    if n > 0.0 {
        counts.iter_mut().for_each(|c| *c /= n);
    }
    counts
}

/// Symmetric χ² distance between two histograms of fractions, `½ Σ (p−q)²/(p+q)`, in
/// [0, 1]: 0 for identical histograms, 1 for disjoint ones.
pub fn chi2_distance(p: &[f64], q: &[f64]) -> f64 {
    assert_eq!(p.len(), q.len(), "histograms of different bins");
    0.5 * p.iter().zip(q).filter(|(a, b)| *a + *b > 0.0).map(|(a, b)| (a - b).powi(2) / (a + b)).sum::<f64>()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn w1_of_identical_samples_is_zero_and_of_shifted_ones_the_shift() {
        let a: Vec<f32> = (0..1000).map(|i| ((i * 37) % 101) as f32 * 0.5).collect();
        assert_eq!(wasserstein1(&a, &a), 0.0);
        let mut shuffled = a.clone();
        shuffled.reverse();
        assert_eq!(wasserstein1(&a, &shuffled), 0.0, "order must not matter");
        let b: Vec<f32> = a.iter().map(|v| v + 3.25).collect();
        assert!((wasserstein1(&a, &b) - 3.25).abs() < 1e-9);
        assert!((wasserstein1(&b, &a) - 3.25).abs() < 1e-9);
    }

    #[test]
    fn w1_handles_samples_of_different_sizes() {
        // {0, 1} against {0, 0, 1, 1}: same distribution.
        assert_eq!(wasserstein1(&[0.0, 1.0], &[0.0, 0.0, 1.0, 1.0]), 0.0);
        // Point masses at 0 and 2.
        assert!((wasserstein1(&[0.0], &[2.0, 2.0, 2.0]) - 2.0).abs() < 1e-12);
        assert!(wasserstein1(&[], &[1.0]).is_nan());
    }

    #[test]
    fn quantile_bins_hold_equal_mass_of_the_reference() {
        let r: Vec<f32> = (0..1000).map(|i| i as f32).collect();
        let edges = quantile_edges(&r, 4);
        assert_eq!(edges, vec![250.0, 500.0, 750.0]);
        assert_eq!(histogram(&r, &edges), vec![0.25; 4]);
        let h = histogram(&[-5.0, 100.0, 900.0, 2000.0, f32::NAN], &edges);
        assert_eq!(h, vec![0.5, 0.0, 0.0, 0.5]);
    }

    #[test]
    fn chi2_is_zero_for_equal_and_one_for_disjoint_histograms() {
        assert_eq!(chi2_distance(&[0.25; 4], &[0.25; 4]), 0.0);
        assert!((chi2_distance(&[0.5, 0.5, 0.0, 0.0], &[0.0, 0.0, 0.5, 0.5]) - 1.0).abs() < 1e-12);
    }
}
