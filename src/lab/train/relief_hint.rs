//! `infiniterra train STAGE --fit-relief-hint`: fitting a shipped model's relief hint on the
//! stage's training data (training does the same when it ships).

use std::path::Path;

use anyhow::{anyhow, Context};
use infiniterra_terrain::model::ModelManifest;

use super::stage::stage_data;

/// Fits the relief hint of the shipped `<models>/<stage>.json` on the stage's training data
/// (the crops and normalisation it was trained with) and writes it into the manifest; the
/// weights are untouched. Training does the same when it ships.
pub(super) fn fit_relief_hint(models: &Path, stage: &str, data: &Path, features: usize) -> anyhow::Result<()> {
    let path = models.join(format!("{stage}.json"));
    let text = std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let manifest: ModelManifest =
        serde_json::from_str(&text).with_context(|| format!("{} is not a model manifest", path.display()))?;
    let (train, heldout) = stage_data(stage, data, manifest.context).map_err(|e| anyhow!(e))?;
    let (crop, norm) = (manifest.training.crop, &manifest.normalisation);
    let hint = train
        .relief_hint(crop, norm, features)
        .ok_or_else(|| anyhow!("{}: the relief-hint fit is singular on this data", data.display()))?;
    println!(
        "relief hint of {}: coefficients {:?} on {:?}, R² {:.3}",
        path.display(),
        hint.coefficients,
        hint.features,
        hint.r2
    );
    // The fit is judged on crops it never saw: a bias there is relief the hint will not ask for.
    let (x, z) = heldout.relief_samples(crop, norm);
    let check = hint.check(&x, &z);
    println!(
        "on {} held-out crops: R² {:.3}, truth − hint {:+.3} z (rms {:.3})",
        z.len(),
        check.r2,
        check.bias,
        check.rms
    );
    let hint = serde_json::to_value(&hint)?;
    crate::lab::manifest_edit::edit_manifest(&path, |object| {
        object.insert("relief_hint".into(), hint);
        Ok(())
    })
}
