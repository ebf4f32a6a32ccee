//! What every job on a shipped model starts from (`--generate-heldout`, `--counterpart` and
//! the four calibrations): the job's options, the model with its weights on the chosen
//! backend, its manifest's path, and the stage's prepared tiles encoded with its context.

use std::path::{Path, PathBuf};

use anyhow::anyhow;
use infiniterra_terrain::model::burn::tensor::Device;
use infiniterra_terrain::model::{load_model, ComputeBackend, LoadedModel};

use super::data::{read_split, TileSet};

/// A calibration of `<models>/<stage>.json` on `tiles` of the stage's training tiles (from
/// `<data>/<stage>/`), generating with seeds `seed`, `seed + 1`, … on `backend`.
#[derive(Clone, Copy, Debug)]
pub struct Calibration<'a> {
    /// The folder of shipped models.
    pub models: &'a Path,
    /// The stage.
    pub stage: &'a str,
    /// The prepared data folder (holding `<stage>/`).
    pub data: &'a Path,
    /// How many training tiles to generate counterparts of.
    pub tiles: usize,
    /// The first generation seed.
    pub seed: u64,
    /// Where the network runs.
    pub backend: ComputeBackend,
}

/// A shipped model loaded for a job, with the stage's prepared data folder.
pub(super) struct Shipped {
    /// The model (its manifest may be edited in memory to switch post-processing off).
    pub model: LoadedModel,
    /// The device its weights are on.
    pub device: Device,
    /// Its manifest, `<models>/<stage>.json` (what a calibration writes into).
    pub path: PathBuf,
    /// `<data>/<stage>/`.
    pub folder: PathBuf,
}

impl Shipped {
    /// Loads `<models>/<stage>.json` and its weights on `backend`.
    pub fn load(models: &Path, stage: &str, data: &Path, backend: ComputeBackend) -> anyhow::Result<Shipped> {
        let device = backend.device()?;
        let model = load_model(models, stage, &device)?;
        Ok(Shipped { model, device, path: models.join(format!("{stage}.json")), folder: data.join(stage) })
    }

    /// Loads the model a calibration works on.
    pub fn for_calibration(job: &Calibration) -> anyhow::Result<Shipped> {
        Shipped::load(job.models, job.stage, job.data, job.backend)
    }

    /// The stage's `split` (`train` or `heldout`) encoded with the model's context.
    pub fn tiles(&self, split: &str) -> anyhow::Result<TileSet> {
        read_split(&self.folder, split, 1, self.model.manifest.context).map_err(|e| anyhow!(e))
    }
}
