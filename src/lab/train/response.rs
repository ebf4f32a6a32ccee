//! Measuring how the network answers its relief hint, and inverting that answer.
//!
//! The hint estimates each window's true roughness (`relief_z`) from its context, and the
//! network is asked for it through its conditioning vector. Asked for `z`, the few-step
//! sampler draws less, and how much less depends on `z`: gentle windows come out about as
//! rough as asked, rugged ones fall further short the more they are asked for (on training
//! tiles the first unblurred-context core drew its roughest sixth of windows 0.65 z short at
//! no offset, its gentlest sixth 0.04 z over). One offset for all windows cannot fix both; on
//! held-out land, rougher than the training set, the shortfall in the ranges shows as slopes
//! that are too gentle. So the calibration probes the response: it generates counterparts of
//! real **training** tiles with the hint raised by a few fixed offsets, measures the relief
//! each window came out with, and, per band of expected relief, finds the extra that makes the
//! drawn relief equal the real one — the knots of the hint's `response` curve. Minutes, not
//! the hour a retraining takes; the weights are untouched.

use std::time::Instant;

use infiniterra_terrain::encoding::signed_sqrt;
use infiniterra_terrain::model::{Normalisation, ReliefHint};

use super::calibrate::{load_hinted, spread, write_hint_fields, Hinted};
use super::data::{crop_of, log_std, EncodedTile};
use super::heldout::counterpart;
use super::shipped::{Calibration, Shipped};

/// Offsets the hint is raised by while probing (z units). The largest needs to reach past
/// what the roughest windows need (≈ 2 for the first unblurred-context core).
pub const PROBE_OFFSETS: [f64; 3] = [0.0, 1.0, 2.0];
/// Bands of expected relief, each with the same number of windows: one knot each.
const BANDS: usize = 6;
/// The extra a knot may take (z units): beyond this the network is asked for roughness it
/// never saw in training, and a band that seems to need more is noise or a network that no
/// longer answers.
const EXTRA_RANGE: (f64, f64) = (-1.0, 3.0);
/// Smallest response (drawn z per asked z) the inversion divides by.
const MIN_RESPONSE: f64 = 0.05;

/// One window of a probed training tile.
#[derive(Clone, Debug, PartialEq)]
pub struct Probe {
    /// The hint's estimate from the window's context.
    pub expected: f64,
    /// The real window's `relief_z`.
    pub truth: f64,
    /// The generated window's `relief_z` at each of the probe offsets.
    pub drawn: Vec<f64>,
}

/// The response curve's knots from probes drawn at `offsets` (ascending): windows sorted by
/// expected relief into [`BANDS`] equal bands; in each, the extra at which the mean drawn
/// relief (linear in the offset between probes, extended along the end segments) meets the
/// mean real relief. Knot abscissae are the bands' mean expected relief.
pub fn knots(probes: &[Probe], offsets: &[f64]) -> Vec<[f64; 2]> {
    assert!(offsets.len() >= 2 && offsets.windows(2).all(|w| w[1] > w[0]), "offsets must ascend");
    let mut sorted: Vec<&Probe> = probes.iter().filter(|p| p.drawn.len() == offsets.len()).collect();
    sorted.sort_by(|a, b| a.expected.total_cmp(&b.expected));
    let bands = BANDS.min(sorted.len());
    let mut out: Vec<[f64; 2]> = Vec::new();
    for b in 0..bands {
        let band = &sorted[b * sorted.len() / bands..(b + 1) * sorted.len() / bands];
        let n = band.len() as f64;
        let expected = band.iter().map(|p| p.expected).sum::<f64>() / n;
        let truth = band.iter().map(|p| p.truth).sum::<f64>() / n;
        let drawn: Vec<f64> = (0..offsets.len()).map(|k| band.iter().map(|p| p.drawn[k]).sum::<f64>() / n).collect();
        // The segment that brackets the real relief, or the end segment towards it.
        let last = offsets.len() - 2;
        let k = (0..=last).find(|&k| truth <= drawn[k + 1]).unwrap_or(last);
        let slope = ((drawn[k + 1] - drawn[k]) / (offsets[k + 1] - offsets[k])).max(MIN_RESPONSE);
        let extra = (offsets[k] + (truth - drawn[k]) / slope).clamp(EXTRA_RANGE.0, EXTRA_RANGE.1);
        match out.last() {
            // Equal abscissae (many windows with the same estimate) would make the curve a step.
            Some(prev) if expected <= prev[0] => {}
            _ => out.push([expected, extra]),
        }
    }
    out
}

/// `relief_z` of every `window`-sided crop of `h` (side `size`, its smooth context `low`)
/// at stride `window / 2`, row-major: crops every half window, a dense sample of the relief
/// windows see (the core's own windows lie every three quarters of one).
fn crop_reliefs(h: &[f32], low: &[f32], size: usize, window: usize, norm: &Normalisation) -> Vec<f64> {
    let tile = EncodedTile { size, h: h.to_vec(), low: low.to_vec() };
    crop_origins(size, window)
        .map(|(y, x)| {
            let residual = crop_of(&tile, y, x, window, 0, |t, k| t.h[k] - t.low[k]);
            (log_std(&residual) - norm.relief_mean as f64) / norm.relief_std as f64
        })
        .collect()
}

fn crop_origins(size: usize, window: usize) -> impl Iterator<Item = (usize, usize)> {
    let stride = (window / 2).max(1);
    let n = if size >= window { (size - window) / stride + 1 } else { 0 };
    (0..n * n).map(move |i| ((i / n) * stride, (i % n) * stride))
}

/// Probes `<models>/<stage>.json` on the job's training tiles and writes the response curve
/// (with the offset reset to 0) into the manifest.
pub fn run(job: &Calibration) -> anyhow::Result<()> {
    let Hinted { shipped: Shipped { mut model, device, path, folder }, hint, train } = load_hinted(job)?;
    let (stage, seed, count) = (job.stage, job.seed, job.tiles);
    let spec = model.manifest.context;
    let tiles = spread(&train.tiles, count.clamp(1, train.tiles.len().max(1)), 0.0);
    let (window, norm) = (model.manifest.window, model.manifest.normalisation.clone());

    let mut probes: Vec<Probe> = Vec::new();
    for t in &tiles {
        let truths = crop_reliefs(&t.h, &t.low, t.size, window, &norm);
        for ((y, x), truth) in crop_origins(t.size, window).zip(truths) {
            let low = crop_of(t, y, x, window, 0, |t, k| t.low[k]);
            probes.push(Probe { expected: hint.expected(&low, window), truth, drawn: Vec::new() });
        }
    }
    let started = Instant::now();
    for offset in PROBE_OFFSETS {
        model.manifest.relief_hint = Some(ReliefHint { offset, response: Vec::new(), ..hint.clone() });
        let mut next = probes.iter_mut();
        for (i, t) in tiles.iter().enumerate() {
            let metres = counterpart(&model, &device, &t.h, t.size, seed + i as u64).0;
            let h: Vec<f32> = metres.iter().map(|&e| signed_sqrt(e)).collect();
            let low = spec.smooth(&h, t.size, t.size);
            for drawn in crop_reliefs(&h, &low, t.size, window, &norm) {
                next.next().expect("one probe per crop").drawn.push(drawn);
            }
        }
        let mean = |f: &dyn Fn(&Probe) -> f64| probes.iter().map(f).sum::<f64>() / probes.len().max(1) as f64;
        eprintln!(
            "calibrate {stage}: hint {offset:+.1} → drawn − real relief {:+.3} z over {} windows of {} training tiles ({:.0} s)",
            mean(&|p| p.drawn.last().copied().unwrap_or(0.0) - p.truth),
            probes.len(),
            tiles.len(),
            started.elapsed().as_secs_f64()
        );
    }
    let response = knots(&probes, &PROBE_OFFSETS);
    if response.is_empty() {
        anyhow::bail!("{}: no windows to probe (tiles smaller than the {window}-pixel window?)", folder.display());
    }
    let shown: Vec<String> = response.iter().map(|[x, e]| format!("{x:+.2} → {e:+.2}")).collect();
    println!("relief hint of {}: response (expected → extra) {}; offset reset to 0", path.display(), shown.join(", "));
    write_hint_fields(&path, vec![("response", serde_json::to_value(&response)?), ("offset", serde_json::json!(0.0))])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A network that draws `gain·asked + bias` where asked = expected + offset.
    fn probes(gain: impl Fn(f64) -> f64, n: usize) -> Vec<Probe> {
        (0..n)
            .map(|i| {
                let expected = -2.0 + 4.0 * i as f64 / n as f64;
                let drawn = PROBE_OFFSETS.iter().map(|o| gain(expected) * (expected + o)).collect();
                Probe { expected, truth: expected, drawn }
            })
            .collect()
    }

    #[test]
    fn a_network_that_draws_what_it_is_asked_needs_no_extra() {
        let k = knots(&probes(|_| 1.0, 600), &PROBE_OFFSETS);
        assert_eq!(k.len(), BANDS);
        assert!(k.windows(2).all(|w| w[1][0] > w[0][0]), "abscissae ascend: {k:?}");
        assert!(k.iter().all(|[_, e]| e.abs() < 1e-9), "{k:?}");
    }

    #[test]
    fn the_knots_invert_a_response_that_weakens_with_relief() {
        // Drawn relief: full for gentle windows (expected < 0), 0.8 of the asked for rugged.
        let gain = |x: f64| if x < 0.0 { 1.0 } else { 0.8 };
        let k = knots(&probes(gain, 600), &PROBE_OFFSETS);
        for [x, e] in &k {
            // Asked x + e, drawn gain·(x + e) = x ⇒ e = x/gain − x.
            let want = x / gain(*x) - x;
            assert!((e - want).abs() < 0.1, "knot at {x:+.2}: extra {e:+.3}, the network needs {want:+.3}");
        }
        assert!(k.last().unwrap()[1] > 0.3, "the roughest band is asked for more: {k:?}");
        // An absurd shortfall is capped, not followed.
        let k = knots(&probes(|_| 0.0, 60), &PROBE_OFFSETS);
        assert!(k.iter().all(|[_, e]| (EXTRA_RANGE.0..=EXTRA_RANGE.1).contains(e)), "{k:?}");
    }

    #[test]
    fn crops_lie_on_the_window_grid() {
        let origins: Vec<_> = crop_origins(128, 64).collect();
        assert_eq!(origins, vec![(0, 0), (0, 32), (0, 64), (32, 0), (32, 32), (32, 64), (64, 0), (64, 32), (64, 64)]);
        assert_eq!(crop_origins(32, 64).count(), 0);
    }
}
