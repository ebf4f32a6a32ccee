//! Calibrating a stage's depression infill on training tiles.
//!
//! The shipped model (relief hint, response curve and spectral equaliser as they are)
//! generates counterparts of real **training** tiles with the infill off and then with depth
//! scales from deep to shallow; each set is scored against those tiles with the realism
//! bar's own yardsticks (as the relief-hint calibration does, [`score`] and [`Trial::beats`]),
//! and the best — possibly "off" — is written into the manifest.
//!
//! The spectral-slope line is left out of that judgement: the spectrum belongs to the
//! equaliser, which is calibrated again afterwards with the infill on (`--calibrate-spectrum`
//! measures the windows' final output). Judged by an equaliser calibrated without it, any
//! infill would look like a spectral error it is about to have corrected.

use std::time::Instant;

use infiniterra_terrain::model::DepressionInfill;

use super::calibrate::{best, score, BarSets, Trial};
use super::shipped::{Calibration, Shipped};
use crate::lab::eval::SPECTRAL_SLOPE_KEY;

/// Depth scales tried after "off", metres, deepest first, halving: from about the depth of
/// real closed basins 30–60 km across at 1 km (60 m on held-out land, 16–32 km ones 40 m)
/// down to a few metres. All are tried: the fill-volume line is met only by the shallower
/// ones, while the slope lines drift the other way, so the score is not monotone.
pub const DEPTH_SCALES_M: [f64; 5] = [80.0, 40.0, 20.0, 10.0, 5.0];

/// "off" for `None`, the depth scale otherwise.
fn label(depth: Option<f64>) -> String {
    depth.map_or("off".into(), |c| format!("{c} m"))
}

/// Measures `<models>/<stage>.json` on the job's training tiles for each depth scale and writes
/// the best as its `depression_infill` (or removes it when "off" is best).
pub fn run(job: &Calibration) -> anyhow::Result<()> {
    let shipped = Shipped::for_calibration(job)?;
    let train = shipped.tiles("train")?;
    let Shipped { mut model, device, path, folder } = shipped;
    let (stage, seed) = (job.stage, job.seed);
    let sets = BarSets::new(&train, &folder, job.tiles, &model)?;
    let count = sets.tiles.len();

    let started = Instant::now();
    // Trials carry the depth scale in `offset`; "off" is an infinite depth scale.
    let mut tried: Vec<Trial> = Vec::new();
    for depth in std::iter::once(None).chain(DEPTH_SCALES_M.iter().map(|&c| Some(c))) {
        model.manifest.depression_infill = depth.map(|c| DepressionInfill { depth_scale_m: c });
        let mut targets = sets
            .judge(&model, &device, seed, |i| eprint!("\r  depth scale {}: tile {}/{count}   ", label(depth), i + 1));
        targets.retain(|t| t.key != SPECTRAL_SLOPE_KEY); // the equaliser's line, not the infill's
        let trial = Trial {
            offset: depth.unwrap_or(f64::INFINITY),
            met: targets.iter().filter(|t| t.pass).count(),
            score: score(&targets),
        };
        let (fill, real) = targets
            .iter()
            .find(|t| t.key == "fill_volume_per_km2")
            .map_or((f64::NAN, f64::NAN), |t| (t.value, (t.low * t.high).sqrt()));
        eprintln!(
            "\rcalibrate {stage}: depth scale {} → score {:.3} ({}/{} met on {count} training tiles; fill {fill:.0} m³/km², real {real:.0}; {:.0} s)",
            label(depth),
            trial.score,
            trial.met,
            targets.len(),
            started.elapsed().as_secs_f64()
        );
        let missed: Vec<&str> = targets.iter().filter(|t| !t.pass).map(|t| t.key.as_str()).collect();
        if !missed.is_empty() {
            eprintln!("  not met: {}", missed.join(", "));
        }
        tried.push(trial);
    }
    let chosen = best(&tried).expect("depth scales were tried");
    let depth = chosen.offset.is_finite().then_some(chosen.offset);
    let summary: Vec<String> = tried
        .iter()
        .map(|t| format!("{}: {} met, {:.3}", label(t.offset.is_finite().then_some(t.offset)), t.met, t.score))
        .collect();
    println!(
        "depression infill of {}: {} ({} lines met, score {:.3}; tried {})",
        path.display(),
        label(depth),
        chosen.met,
        chosen.score,
        summary.join("; ")
    );
    crate::lab::manifest_edit::edit_manifest(&path, |object| {
        match depth {
            Some(c) => {
                object.insert("depression_infill".into(), serde_json::to_value(DepressionInfill { depth_scale_m: c })?)
            }
            None => object.remove("depression_infill"),
        };
        Ok(())
    })
}
