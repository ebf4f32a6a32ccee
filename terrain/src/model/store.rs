//! Shipped weights: `models/<stage>.safetensors` plus `models/<stage>.json`, the manifest
//! that says what the weights are (architecture, normalisation, sampler), where they came
//! from (training record, data checksums) and how good they are (realism numbers).
//!
//! Loading checks the manifest, the file size and its SHA-256 before touching burn, so a
//! missing, truncated or swapped file fails with an error that names the file and the command
//! that recreates it, never with a panic deep inside a tensor library.

use std::collections::BTreeMap;
use std::io::{self, Read};
use std::path::{Path, PathBuf};

use burn::store::{FloatCastAdapter, ModuleSnapshot, SafetensorsStore};
use burn::tensor::{DType, Device};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use super::equaliser::SpectralEqualiser;
use super::hint::ReliefHint;
use super::infill::DepressionInfill;
use super::projection::ContextProjection;
use super::sampler::Sampler;
use super::unet::{UNet, UNetConfig};
use crate::encoding::ContextSpec;
use crate::model_files::ModelFiles;

/// Version of the manifest layout; bumped on incompatible changes.
const MANIFEST_VERSION: u32 = 1;

/// Storage precision of a weight file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Precision {
    /// 32-bit floats: bit-exact with the trained model.
    #[default]
    F32,
    /// 16-bit floats: half the size; weights are unit-norm rows, well inside f16's range.
    F16,
}

/// How a stage maps its physical values to the network's and back.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Normalisation {
    /// Generated values are `target / target_scale` in the network (so their std is σ_data).
    pub target_scale: f32,
    /// Conditioning channels are `(cond − cond_mean) / cond_scale`.
    pub cond_mean: f32,
    /// See `cond_mean`.
    pub cond_scale: f32,
    /// The relief entry of the conditioning vector is `(ln std − relief_mean) / relief_std`.
    pub relief_mean: f32,
    /// See `relief_mean`.
    pub relief_std: f32,
}

/// A file the model was trained on, with its checksum.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DataChecksum {
    /// Path as given to the trainer.
    pub file: String,
    /// SHA-256, lowercase hex.
    pub sha256: String,
}

/// How a stage is autoguided (see [`Guide`](super::Guide)).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Guidance {
    /// The guide's own manifest, relative to this manifest's folder (e.g. `guide/core.json`).
    pub guide: String,
    /// Guidance weight `w` (1: the main model alone; the paper's best are 1.5–3).
    pub weight: f32,
    /// How many of the sampler's first steps are guided (each costs the guide's network call).
    pub steps: usize,
}

/// What training produced the weights.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TrainingRecord {
    /// Optimiser steps.
    pub steps: u64,
    /// Samples per step.
    pub batch: usize,
    /// Crop side, pixels.
    pub crop: usize,
    /// The run's seed.
    pub seed: u64,
    /// Reference learning rate.
    pub learning_rate: f32,
    /// EMA decay of the shipped weights.
    pub ema_beta: f32,
    /// Steps before the learning rate decays (0 in manifests written before it was recorded).
    #[serde(default)]
    pub lr_ref_steps: u64,
    /// Training noise levels, when not EDM's default (`ln σ ~ N(−1.2, 1.2²)`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noise: Option<super::edm::NoiseDistribution>,
    /// Mean loss over the last logging interval.
    pub final_loss: f32,
    /// Wall-clock seconds spent training (all sessions).
    pub wall_seconds: f64,
}

/// Everything known about a shipped model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelManifest {
    /// Layout version of this file.
    pub version: u32,
    /// Stage name (`core`, `coarse`, `detail`).
    pub stage: String,
    /// Weight file name, relative to the manifest's folder.
    pub weights: String,
    /// SHA-256 of the weight file.
    pub weights_sha256: String,
    /// Size of the weight file in bytes.
    pub weights_bytes: u64,
    /// Storage precision.
    pub precision: Precision,
    /// The network.
    pub architecture: UNetConfig,
    /// Trainable parameters.
    pub parameters: usize,
    /// Multiply–adds per output pixel of one denoiser evaluation.
    pub macs_per_pixel: f64,
    /// Real size of one pixel the model was trained at, metres.
    pub metres_per_pixel: f64,
    /// Window side the model is meant to run on, pixels.
    pub window: usize,
    /// Distance between neighbouring windows, pixels (0, as in older manifests: half the
    /// window, i.e. 50 % overlap).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub stride: usize,
    /// How the stage's context is made from the grid above it (older manifests: the 8×
    /// blurred Laplacian low band).
    #[serde(default)]
    pub context: ContextSpec,
    /// Value mapping.
    pub normalisation: Normalisation,
    /// Predicts the relief entry of the conditioning vector from the context; without it the
    /// stage runs with the vector dropped (zeros), as older manifests did.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub relief_hint: Option<ReliefHint>,
    /// A fixed filter on the stage's output that corrects its power spectrum (none: the
    /// output as the network draws it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spectral_equaliser: Option<SpectralEqualiser>,
    /// Back-projection of each window's output onto its context cells, before the equaliser
    /// (none: cell means as the network draws them).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub context_projection: Option<ContextProjection>,
    /// Sediment infill of closed basins in each window's output, after the equaliser (none:
    /// basins as the network draws them).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depression_infill: Option<DepressionInfill>,
    /// The sampler to run it with.
    pub sampler: Sampler,
    /// Autoguidance by a weaker model of the same stage (none: the model runs alone).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub guidance: Option<Guidance>,
    /// How it was trained.
    pub training: TrainingRecord,
    /// What it was trained on.
    pub data: Vec<DataChecksum>,
    /// Realism numbers (metric key of docs/realism.md → value), filled in by evaluation.
    pub realism: BTreeMap<String, f64>,
    /// The command that recreates the weights.
    pub recreate: String,
}

fn is_zero(v: &usize) -> bool {
    *v == 0
}

impl ModelManifest {
    /// Distance between neighbouring windows, pixels.
    pub fn window_stride(&self) -> usize {
        if self.stride == 0 {
            self.window / 2
        } else {
            self.stride
        }
    }

    /// A manifest for `stage` with `architecture`; the weight fields are filled in by
    /// [`save_model`].
    pub fn new(stage: &str, architecture: UNetConfig, sampler: Sampler) -> ModelManifest {
        ModelManifest {
            version: MANIFEST_VERSION,
            stage: stage.to_string(),
            weights: format!("{stage}.safetensors"),
            weights_sha256: String::new(),
            weights_bytes: 0,
            precision: Precision::F32,
            architecture,
            parameters: 0,
            macs_per_pixel: 0.0,
            metres_per_pixel: 0.0,
            window: 64,
            stride: 0,
            context: ContextSpec::default(),
            normalisation: Normalisation::default(),
            relief_hint: None,
            spectral_equaliser: None,
            context_projection: None,
            depression_infill: None,
            sampler,
            guidance: None,
            training: TrainingRecord::default(),
            data: Vec::new(),
            realism: BTreeMap::new(),
            recreate: format!("infiniterra train {stage}"),
        }
    }
}

/// Why a model could not be loaded or saved.
#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    /// A file is not there.
    #[error("model file {path} is missing: run `{command}` to create it")]
    Missing {
        /// The file.
        path: PathBuf,
        /// What recreates it.
        command: String,
    },
    /// A file is there but unusable.
    #[error("model file {path} is unusable ({reason}): run `{command}` to recreate it")]
    Corrupt {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
        /// What recreates it.
        command: String,
    },
    /// Reading or writing failed for another reason.
    #[error("cannot access {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: io::Error,
    },
}

/// A loaded network with its manifest (cloning shares the weight tensors).
#[derive(Clone, Debug)]
pub struct LoadedModel {
    /// The network, on the requested device.
    pub net: UNet,
    /// Its manifest.
    pub manifest: ModelManifest,
    /// The autoguidance guide's network, when the manifest names one.
    pub guide: Option<UNet>,
}

/// SHA-256 of bytes, lowercase hex.
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes).iter().map(|b| format!("{b:02x}")).collect()
}

/// SHA-256 of a file, streamed.
pub fn sha256_file(path: &Path) -> io::Result<String> {
    let mut f = std::fs::File::open(path)?;
    let mut hasher = Sha256::new();
    let mut buf = vec![0u8; 1 << 20];
    loop {
        let n = f.read(&mut buf)?;
        if n == 0 {
            break;
        }
        hasher.update(&buf[..n]);
    }
    Ok(hasher.finalize().iter().map(|b| format!("{b:02x}")).collect())
}

/// Writes `bytes` to `path` through a temporary sibling, so a crash never leaves a half file.
fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), ModelError> {
    let io_err = |source| ModelError::Io { path: path.to_path_buf(), source };
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(io_err)?;
    }
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    let tmp = PathBuf::from(tmp);
    std::fs::write(&tmp, bytes).map_err(io_err)?;
    std::fs::rename(&tmp, path).map_err(io_err)
}

/// Saves `net` as `<dir>/<stage>.safetensors` in `precision` and `manifest` (with the weight
/// fields filled in) as `<dir>/<stage>.json`. Returns the manifest as written.
pub fn save_model(
    dir: &Path,
    net: &UNet,
    mut manifest: ModelManifest,
    precision: Precision,
) -> Result<ModelManifest, ModelError> {
    let weights_path = dir.join(format!("{}.safetensors", manifest.stage));
    // One metadata entry only: burn keeps metadata in a HashMap, so several entries would be
    // written in a random order and identical weights would get different checksums.
    let mut store = SafetensorsStore::from_bytes(None).clear_metadata().metadata("stage", manifest.stage.clone());
    if precision == Precision::F16 {
        store = store.with_to_adapter(FloatCastAdapter::to(DType::F16));
    }
    let corrupt =
        |reason: String| ModelError::Corrupt { path: weights_path.clone(), reason, command: manifest.recreate.clone() };
    net.save_into(&mut store).map_err(|e| corrupt(format!("serialising: {e}")))?;
    let bytes = store.get_bytes().map_err(|e| corrupt(format!("serialising: {e}")))?;
    write_atomic(&weights_path, &bytes)?;

    manifest.version = MANIFEST_VERSION;
    manifest.weights = format!("{}.safetensors", manifest.stage);
    manifest.weights_sha256 = sha256_hex(&bytes);
    manifest.weights_bytes = bytes.len() as u64;
    manifest.precision = precision;
    manifest.architecture = net.config.clone();
    manifest.parameters = net.parameters();
    manifest.macs_per_pixel = net.macs_per_pixel();
    let json = serde_json::to_string_pretty(&manifest).expect("a manifest always serialises");
    write_atomic(&dir.join(format!("{}.json", manifest.stage)), format!("{json}\n").as_bytes())?;
    Ok(manifest)
}

/// Loads `<dir>/<stage>.json` and the weights it names onto `device`, verifying size and
/// checksum first.
pub fn load_model(dir: &Path, stage: &str, device: &Device) -> Result<LoadedModel, ModelError> {
    load_model_from(&ModelFiles::Dir(dir.to_path_buf()), stage, device)
}

/// Loads `<stage>.json` of `files` (a folder, or the models built into the binary) and the
/// weights it names onto `device`, verifying size and checksum first.
pub fn load_model_from(files: &ModelFiles, stage: &str, device: &Device) -> Result<LoadedModel, ModelError> {
    load_manifest_at(files, Path::new(&format!("{stage}.json")), device)
}

/// Loads a model from the path of its manifest.
pub fn load_model_file(manifest_path: &Path, device: &Device) -> Result<LoadedModel, ModelError> {
    let dir = manifest_path.parent().unwrap_or(Path::new("."));
    let name = manifest_path.file_name().map_or_else(|| manifest_path.to_path_buf(), PathBuf::from);
    load_manifest_at(&ModelFiles::Dir(dir.to_path_buf()), &name, device)
}

/// Loads the model whose manifest is `rel` in `files`; every file it names is relative to the
/// manifest's folder.
fn load_manifest_at(files: &ModelFiles, rel: &Path, device: &Device) -> Result<LoadedModel, ModelError> {
    let manifest_path = files.shown(rel);
    let manifest_path = manifest_path.as_path();
    let stage = rel.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    let default_command = format!("infiniterra train {stage}");
    let text = match files.read(rel) {
        Ok(bytes) => String::from_utf8_lossy(&bytes).into_owned(),
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            return Err(ModelError::Missing { path: manifest_path.to_path_buf(), command: default_command })
        }
        Err(source) => return Err(ModelError::Io { path: manifest_path.to_path_buf(), source }),
    };
    let manifest: ModelManifest = serde_json::from_str(&text).map_err(|e| ModelError::Corrupt {
        path: manifest_path.to_path_buf(),
        reason: format!("not a model manifest: {e}"),
        command: default_command.clone(),
    })?;
    let command = if manifest.recreate.is_empty() { default_command } else { manifest.recreate.clone() };
    let manifest_corrupt =
        |reason: String| ModelError::Corrupt { path: manifest_path.to_path_buf(), reason, command: command.clone() };
    if manifest.version != MANIFEST_VERSION {
        return Err(manifest_corrupt(format!(
            "manifest version {} (this build reads {MANIFEST_VERSION})",
            manifest.version
        )));
    }
    manifest.architecture.validate().map_err(|e| manifest_corrupt(format!("architecture: {e}")))?;
    manifest.sampler.validate().map_err(|e| manifest_corrupt(format!("sampler: {e}")))?;
    // Scales divide values on the way in: zero or non-finite ones would turn the terrain into
    // NaN rather than fail here.
    let n = &manifest.normalisation;
    for (name, v) in [("target_scale", n.target_scale), ("cond_scale", n.cond_scale), ("relief_std", n.relief_std)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(manifest_corrupt(format!("normalisation.{name} = {v} (must be a positive number)")));
        }
    }
    if let Some(hint) = &manifest.relief_hint {
        hint.validate().map_err(manifest_corrupt)?;
    }
    if let Some(eq) = &manifest.spectral_equaliser {
        eq.validate(manifest.window).map_err(manifest_corrupt)?;
    }
    if let Some(infill) = &manifest.depression_infill {
        infill.validate().map_err(manifest_corrupt)?;
    }
    if let Some(projection) = &manifest.context_projection {
        projection.validate(manifest.context.blur).map_err(manifest_corrupt)?;
        // A window's cells are whole context cells only when every window starts on one.
        if manifest.window_stride() % manifest.context.factor != 0 {
            return Err(manifest_corrupt(format!(
                "context_projection needs windows on context cells: stride {} is not a multiple of context.factor = {}",
                manifest.window_stride(),
                manifest.context.factor
            )));
        }
    }
    if !(manifest.metres_per_pixel.is_finite() && manifest.metres_per_pixel > 0.0) {
        return Err(manifest_corrupt(format!("metres_per_pixel = {} (must be positive)", manifest.metres_per_pixel)));
    }
    if manifest.window < 8 || manifest.window % 8 != 0 {
        return Err(manifest_corrupt(format!("window = {} (must be a multiple of 8, at least 8)", manifest.window)));
    }
    if manifest.stride > manifest.window {
        return Err(manifest_corrupt(format!("stride = {} exceeds window = {}", manifest.stride, manifest.window)));
    }
    manifest.context.validate().map_err(manifest_corrupt)?;
    if manifest.window % manifest.context.factor != 0 {
        return Err(manifest_corrupt(format!(
            "window = {} is not a multiple of context.factor = {}",
            manifest.window, manifest.context.factor
        )));
    }

    let dir = rel.parent().unwrap_or(Path::new(""));
    let weights_rel = dir.join(&manifest.weights);
    let weights_path = files.shown(&weights_rel);
    let corrupt = |reason: String| ModelError::Corrupt { path: weights_path.clone(), reason, command: command.clone() };
    let bytes = match files.read(&weights_rel) {
        Ok(b) => b.into_owned(),
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            return Err(ModelError::Missing { path: weights_path.clone(), command: command.clone() })
        }
        Err(source) => return Err(ModelError::Io { path: weights_path.clone(), source }),
    };
    if bytes.len() as u64 != manifest.weights_bytes {
        return Err(corrupt(format!("{} bytes, the manifest says {}", bytes.len(), manifest.weights_bytes)));
    }
    let sha = sha256_hex(&bytes);
    if sha != manifest.weights_sha256 {
        return Err(corrupt(format!("SHA-256 {sha} does not match the manifest's {}", manifest.weights_sha256)));
    }

    let mut net = UNet::new(&manifest.architecture, 0, device);
    let mut store = SafetensorsStore::from_bytes(Some(bytes));
    if manifest.precision == Precision::F16 {
        store = store.with_from_adapter(FloatCastAdapter::to(DType::F32));
    }
    let result = net.load_from(&mut store).map_err(|e| corrupt(format!("reading tensors: {e}")))?;
    if !result.errors.is_empty() || !result.missing.is_empty() {
        let missing: Vec<&str> = result.missing.iter().map(|(p, _)| p.as_str()).collect();
        return Err(corrupt(format!(
            "tensors do not fit the architecture: missing {missing:?}, errors {:?}",
            result.errors
        )));
    }
    let guide = match &manifest.guidance {
        None => None,
        // The guide's own errors name its files and the command that recreates it.
        Some(g) => Some(load_guide(files, dir, g, &manifest, device)?),
    };
    Ok(LoadedModel { net, manifest, guide })
}

/// Loads the guide a manifest's `guidance` names and checks it can guide `main`: the same
/// normalisation and conditioning (both networks see the same inputs), no guide of its own.
fn load_guide(
    files: &ModelFiles,
    dir: &Path,
    g: &Guidance,
    main: &ModelManifest,
    device: &Device,
) -> Result<UNet, ModelError> {
    let rel = dir.join(&g.guide);
    let path = files.shown(&rel);
    let corrupt = |reason: String| ModelError::Corrupt { path: path.clone(), reason, command: main.recreate.clone() };
    if !(g.weight.is_finite() && (0.0..=10.0).contains(&g.weight)) || g.steps == 0 {
        return Err(corrupt(format!(
            "guidance weight {} / steps {} (the weight must be in 0..=10, steps at least 1)",
            g.weight, g.steps
        )));
    }
    let guide = load_manifest_at(files, &rel, device)?;
    let (a, b) = (&guide.manifest, main);
    if a.guidance.is_some() {
        return Err(corrupt("a guide cannot have a guide of its own".into()));
    }
    if a.normalisation != b.normalisation
        || a.context != b.context
        || a.window != b.window
        || a.architecture.channels_cond != b.architecture.channels_cond
        || a.architecture.vector_dim != b.architecture.vector_dim
        || a.architecture.channels_out != b.architecture.channels_out
        || a.architecture.sigma_data != b.architecture.sigma_data
    {
        return Err(corrupt(format!(
            "its inputs differ from {}'s (normalisation, context, window or conditioning channels)",
            b.stage
        )));
    }
    Ok(guide.net)
}
