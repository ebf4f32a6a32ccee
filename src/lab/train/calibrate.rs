//! Calibrating the relief hint's offset on training tiles.
//!
//! The hint predicts how much relief a window should have and the network is asked for it
//! through its conditioning vector, but a few-step sampler driven by a small, briefly trained
//! network draws less than it is asked for (its samples regress towards the mean: on training
//! tiles the shipped core drew slopes half as steep as the real ones). One scalar added to
//! every prediction corrects that. It is chosen the way the realism bar judges terrain: the
//! shipped model generates counterparts of real **training** tiles (never held-out ones)
//! for a grid of offsets, each set is scored against those tiles with the bar's own yardsticks,
//! and the best offset is written into the manifest. The weights are untouched.

use std::path::Path;
use std::time::Instant;

use anyhow::anyhow;
use infiniterra_terrain::encoding::signed_square;
use infiniterra_terrain::model::burn::tensor::Device;
use infiniterra_terrain::model::{LoadedModel, ReliefHint};

use super::data::{EncodedTile, TileSet};
use super::heldout::counterpart;
use super::shipped::{Calibration, Shipped};
use crate::lab::eval::{realism_bar, Target};
use crate::terrain::metrics::Raster;

/// Offsets tried first (z units): 0, 0.2, … up to [`GRID_MAX`], until two in a row fall
/// short of the best so far (see [`Trial::beats`]); the best is then refined by ±[`REFINE`].
const GRID_STEP: f64 = 0.2;
/// The largest offset the sweep tries (3 z units: far beyond any roughness in the data).
pub(super) const GRID_MAX: f64 = 3.0;
/// Refinement step around the best grid offset.
pub(super) const REFINE: f64 = 0.1;

/// How far a generated set is from the bar, averaged over its metrics: each distance in
/// units of the bar's fBm line (distance / (fBm's distance / 5): 1 on the line), the
/// depression density and fill volume as |log₂(generated / real)| (1 at the "within 2×" edge). Below 1 on
/// every metric means those lines are met. The real-vs-real floor is left out on purpose: on
/// a few dozen tiles it can be near zero by chance, and dividing by it turns noise into the
/// score. Seams do not depend on the offset and are left out too.
pub fn score(targets: &[Target]) -> f64 {
    let parts: Vec<f64> = targets
        .iter()
        .filter_map(|t| match (t.key.as_str(), t.fbm) {
            ("seam_ratio", _) => None,
            ("depressions_per_1000_km2" | "fill_volume_per_km2", _) => {
                Some((t.value / (t.low * t.high).sqrt()).log2().abs())
            }
            (_, Some(fbm)) => Some(t.value / (fbm / 5.0).max(f64::MIN_POSITIVE)),
            (_, None) => None,
        })
        .collect();
    if parts.iter().any(|p| !p.is_finite()) || parts.is_empty() {
        return f64::INFINITY;
    }
    parts.iter().sum::<f64>() / parts.len() as f64
}

/// One offset's result on the calibration tiles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Trial {
    /// The hint offset tried.
    pub offset: f64,
    /// Lines of the realism bar met.
    pub met: usize,
    /// [`score`] of the set.
    pub score: f64,
}

impl Trial {
    /// The bar's own judgement first — more of its lines met — then the nearer [`score`].
    /// The score alone averages ratios, so one metric far off (closed depressions, say) can
    /// outweigh three that moved onto their lines.
    pub fn beats(&self, other: &Trial) -> bool {
        self.met > other.met || (self.met == other.met && self.score < other.score)
    }
}

/// The best of `tried` by [`Trial::beats`] (the earliest among equals).
pub(super) fn best(tried: &[Trial]) -> Option<Trial> {
    tried.iter().copied().reduce(|best, t| if t.beats(&best) { t } else { best })
}

/// `count` tiles spread evenly over `tiles`, starting at `phase` of the spacing (0 or ½), so
/// two calls with different phases pick disjoint sets.
pub(super) fn spread(tiles: &[EncodedTile], count: usize, phase: f64) -> Vec<&EncodedTile> {
    let step = tiles.len() as f64 / count.max(1) as f64;
    (0..count.min(tiles.len())).map(|i| &tiles[(((i as f64 + phase) * step) as usize).min(tiles.len() - 1)]).collect()
}

/// A real tile as elevations in metres.
pub(super) fn raster(tile: &EncodedTile, metres: f64) -> Raster {
    Raster::new(tile.size, tile.size, metres, tile.h.iter().map(|&v| signed_square(v)).collect())
}

/// What a bar-scored calibration generates and judges against: `count` training tiles spread
/// over the split, and as many others (disjoint) for the real-vs-real floor.
pub(super) struct BarSets<'a> {
    /// The tiles whose counterparts are generated.
    pub tiles: Vec<&'a EncodedTile>,
    reference: Vec<Raster>,
    floor: Vec<Raster>,
    metres: f64,
    seam_stride: usize,
}

impl<'a> BarSets<'a> {
    /// The sets for `model` from `train` (read from `folder`, named in the error when it has
    /// fewer than 4 tiles).
    pub fn new(train: &'a TileSet, folder: &Path, count: usize, model: &LoadedModel) -> anyhow::Result<BarSets<'a>> {
        if train.tiles.len() < 4 {
            anyhow::bail!(
                "{}: {} training tiles; calibrating needs at least 4 (half to generate, half for the real-vs-real floor)",
                folder.display(),
                train.tiles.len()
            );
        }
        let count = count.clamp(2, train.tiles.len() / 2);
        let metres = model.manifest.metres_per_pixel;
        let tiles = spread(&train.tiles, count, 0.0);
        let floor = spread(&train.tiles, count, 0.5).into_iter().map(|t| raster(t, metres)).collect();
        let reference = tiles.iter().map(|t| raster(t, metres)).collect();
        Ok(BarSets { tiles, reference, floor, metres, seam_stride: model.manifest.window_stride() })
    }

    /// `model`'s counterparts of the tiles (seeds `seed`, `seed + 1`, …) judged by the realism
    /// bar; `progress(i)` is called before tile i.
    pub fn judge(&self, model: &LoadedModel, device: &Device, seed: u64, progress: impl Fn(usize)) -> Vec<Target> {
        let generated: Vec<Raster> = self
            .tiles
            .iter()
            .enumerate()
            .map(|(i, t)| {
                progress(i);
                let h = counterpart(model, device, &t.h, t.size, seed + i as u64).0;
                Raster::new(t.size, t.size, self.metres, h)
            })
            .collect();
        realism_bar(&self.reference, &generated, &self.floor, self.seam_stride)
    }
}

/// What the hint calibrations start from: the shipped model with its post-processing off, its
/// relief hint, and the stage's training tiles.
pub(super) struct Hinted {
    pub shipped: Shipped,
    pub hint: ReliefHint,
    pub train: TileSet,
}

/// Loads the job's model and training tiles; an error naming the command that fits a hint
/// when the model has none.
pub(super) fn load_hinted(job: &Calibration) -> anyhow::Result<Hinted> {
    let mut shipped = Shipped::for_calibration(job)?;
    let manifest = &mut shipped.model.manifest;
    // Both calibrations measure the network's own answer: the steps after it in each window
    // (context projection, equaliser, infill) are calibrated on it afterwards.
    manifest.context_projection = None;
    manifest.spectral_equaliser = None;
    manifest.depression_infill = None;
    let Some(hint) = manifest.relief_hint.clone() else {
        anyhow::bail!(
            "{} has no relief hint to calibrate: run `infiniterra train {} --fit-relief-hint` first",
            shipped.path.display(),
            job.stage
        );
    };
    let train = shipped.tiles("train")?;
    Ok(Hinted { shipped, hint, train })
}

/// Writes `fields` into the `relief_hint` object of the manifest at `path`, leaving the rest
/// of the file as it was.
pub(super) fn write_hint_fields(path: &Path, fields: Vec<(&str, serde_json::Value)>) -> anyhow::Result<()> {
    crate::lab::manifest_edit::edit_manifest(path, |object| {
        let hint = object
            .get_mut("relief_hint")
            .and_then(|h| h.as_object_mut())
            .ok_or_else(|| anyhow!("{}: relief_hint vanished while calibrating", path.display()))?;
        for (key, value) in fields {
            hint.insert(key.into(), value);
        }
        Ok(())
    })
}

/// Runs the calibration for `<models>/<stage>.json` on the job's training tiles and writes the
/// chosen `relief_hint.offset` into the manifest.
pub fn run(job: &Calibration) -> anyhow::Result<()> {
    let Hinted { shipped: Shipped { mut model, device, path, folder }, train, .. } = load_hinted(job)?;
    let (stage, seed) = (job.stage, job.seed);
    let sets = BarSets::new(&train, &folder, job.tiles, &model)?;
    let count = sets.tiles.len();

    let started = Instant::now();
    let mut tried: Vec<Trial> = Vec::new();
    let mut evaluate = |offset: f64, tried: &mut Vec<Trial>| {
        if let Some(hint) = model.manifest.relief_hint.as_mut() {
            hint.offset = offset;
        }
        let targets = sets.judge(&model, &device, seed, |_| {});
        let s = score(&targets);
        let met = targets.iter().filter(|t| t.pass).count();
        let elapsed = started.elapsed().as_secs_f64();
        eprintln!(
            "calibrate {stage}: offset {offset:+.2} → score {s:.3} ({met}/{} met on {count} training tiles; {elapsed:.0} s)",
            targets.len()
        );
        tried.push(Trial { offset, met, score: s });
    };
    let steps = (GRID_MAX / GRID_STEP).round() as usize;
    let mut short = 0;
    for offset in (0..=steps).map(|i| i as f64 * GRID_STEP) {
        let before = best(&tried);
        evaluate(offset, &mut tried);
        let latest = *tried.last().expect("just tried");
        short = if before.is_some_and(|b| !latest.beats(&b)) { short + 1 } else { 0 };
        if short == 2 {
            break;
        }
    }
    let best_grid = best(&tried).map_or(0.0, |t| t.offset);
    for offset in [best_grid - REFINE, best_grid + REFINE] {
        if offset >= 0.0 {
            evaluate(offset, &mut tried);
        }
    }
    let chosen = best(&tried).expect("offsets were tried");
    let best = chosen.offset;
    let summary: Vec<String> =
        tried.iter().map(|t| format!("{:+.2}: {} met, {:.3}", t.offset, t.met, t.score)).collect();
    println!(
        "relief hint of {}: offset {best:+.2} ({} lines met, score {:.3}; tried {})",
        path.display(),
        chosen.met,
        chosen.score,
        summary.join("; ")
    );

    write_hint_fields(&path, vec![("offset", serde_json::json!(best))])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn target(key: &str, value: f64, low: f64, high: f64, fbm: Option<f64>) -> Target {
        let pass = value >= low && value <= high;
        Target { key: key.into(), value, low, high, rule: String::new(), pass, fbm }
    }

    #[test]
    fn the_score_counts_distances_in_units_of_the_fbm_line() {
        let on_the_lines = [
            target("slope_w1_deg", 0.2, 0.0, 0.2, Some(1.0)),
            target("depressions_per_1000_km2", 20.0, 5.0, 20.0, None),
            target("fill_volume_per_km2", 1e6, 1e6, 4e6, None),
            target("seam_ratio", 3.0, 0.9, 1.1, None),
        ];
        // Distance at fBm / 5: 1; depressions 2× real and fill volume ½ real: |log₂ 2| = 1;
        // seams ignored.
        assert!((score(&on_the_lines) - 1.0).abs() < 1e-12);
        let better = [
            target("slope_w1_deg", 0.1, 0.0, 0.2, Some(1.0)),
            target("depressions_per_1000_km2", 10.0, 5.0, 20.0, None),
        ];
        assert!((score(&better) - 0.25).abs() < 1e-12);
        // A near-zero floor (tiny `high`) does not blow the score up: only fBm scales it.
        let tiny_floor = [target("slope_w1_deg", 0.1, 0.0, 1e-9, Some(1.0))];
        assert!((score(&tiny_floor) - 0.5).abs() < 1e-12);
        let broken = [target("slope_w1_deg", f64::NAN, 0.0, 0.2, Some(1.0))];
        assert_eq!(score(&broken), f64::INFINITY);
    }

    #[test]
    fn more_lines_met_beat_a_nearer_score_and_equals_keep_the_first() {
        let t = |offset, met, score| Trial { offset, met, score };
        // 0.6 meets four lines with one metric far off; 0.2 is nearer on average with two.
        let tried = [t(0.0, 2, 5.2), t(0.2, 2, 3.3), t(0.4, 2, 4.3), t(0.6, 4, 5.4)];
        assert_eq!(best(&tried).unwrap().offset, 0.6);
        // Among equal counts the lower score wins, and an exact tie keeps the earlier offset.
        assert_eq!(best(&tried[..3]).unwrap().offset, 0.2);
        assert_eq!(best(&[t(0.2, 3, 1.0), t(0.4, 3, 1.0)]).unwrap().offset, 0.2);
        assert_eq!(best(&[]), None);
    }
}
