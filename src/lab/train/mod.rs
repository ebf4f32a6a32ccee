//! `infiniterra train STAGE`: trains a learned stage on the prepared real data and ships its
//! weights to `models/<stage>.safetensors` + `models/<stage>.json`.
//!
//! Owns: the training loop (`trainer`: EDM loss, Adam, EMA, forced weight normalisation,
//! progress lines and preview PNGs), checkpoints under `models/checkpoints/<stage>/` that
//! resume exactly after an interruption (`checkpoint`), shipping (`ship`), and the jobs on a
//! shipped model (`heldout`, `relief_hint` and the calibrations, which load it through
//! `shipped`). What each stage is comes from the pipeline's stage table (`stage`). Must not
//! touch: network definitions and sampling (they live in `infiniterra_terrain::model`, shared
//! with inference), the pipeline, the command line (it converts its arguments into
//! [`TrainOptions`] and maps [`TrainError`] to exit codes).
//!
//! Determinism: every random number (initial weights, crops, flips, σ, noise) is drawn on the
//! host from ChaCha streams keyed by (seed, step, sample), so a run is a pure function of its
//! seed and a resumed run continues exactly where the interrupted one left off.

mod calibrate;
mod checkpoint;
pub mod data;
mod ema;
mod heldout;
mod infill;
mod options;
mod preview;
mod relief_hint;
mod response;
mod ship;
mod shipped;
mod spectrum;
mod stage;
mod trainer;

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use anyhow::anyhow;

pub use self::options::{TrainError, TrainOptions};
use self::stage::{stage_data, stage_spec};
use self::trainer::Trainer;

/// The training seed when `--seed` is not given.
pub const DEFAULT_SEED: u64 = 0;

/// Runs `infiniterra train`.
pub fn run(args: &TrainOptions, seed: Option<u64>) -> Result<(), TrainError> {
    let mut spec = stage_spec(&args.stage, args.smoke)?;
    if args.half_width {
        spec.config = spec.config.halved();
    }
    if let Some(real) = &args.counterpart {
        return heldout::compare(
            &args.out,
            &args.stage,
            real,
            &args.picture,
            seed.unwrap_or(DEFAULT_SEED),
            args.backend,
        )
        .map_err(TrainError::runtime);
    }
    if let Some(out) = &args.generate_heldout {
        let seed = seed.unwrap_or(DEFAULT_SEED);
        return heldout::generate(&args.out, &args.stage, &args.data, out, args.tiles, args.draws, seed, args.backend)
            .map_err(TrainError::runtime);
    }
    if args.fit_relief_hint {
        return relief_hint::fit_relief_hint(&args.out, &args.stage, &args.data, args.hint_features())
            .map_err(TrainError::runtime);
    }
    let job = shipped::Calibration {
        models: &args.out,
        stage: &args.stage,
        data: &args.data,
        tiles: args.tiles,
        seed: seed.unwrap_or(DEFAULT_SEED),
        backend: args.backend,
    };
    let calibration = if args.calibrate_relief_response {
        Some(response::run as fn(&shipped::Calibration) -> anyhow::Result<()>)
    } else if args.calibrate_spectrum {
        Some(spectrum::run as _)
    } else if args.calibrate_infill {
        Some(infill::run as _)
    } else if args.calibrate_relief_hint {
        Some(calibrate::run as _)
    } else {
        None
    };
    if let Some(calibrate) = calibration {
        return calibrate(&job).map_err(TrainError::runtime);
    }
    if args.crop == 0 || args.crop % spec.config.size_multiple().max(8) != 0 {
        return Err(TrainError::input(anyhow!("--crop must be a positive multiple of 8, got {}", args.crop)));
    }
    if args.batch == 0 || !(0.0..1.0).contains(&args.ema) || args.lr <= 0.0 {
        return Err(TrainError::input(anyhow!("--batch must be ≥ 1, --ema in [0, 1), --lr > 0")));
    }
    let (train, heldout) = if args.smoke {
        (data::synthetic_with(6, 128, spec.context), data::synthetic_with(2, 128, spec.context))
    } else {
        stage_data(&args.stage, &args.data, spec.context).map_err(|e| TrainError::input(anyhow!(e)))?
    };
    if train.min_tile() < args.crop {
        return Err(TrainError::input(anyhow!(
            "--crop {} exceeds the smallest tile ({})",
            args.crop,
            train.min_tile()
        )));
    }
    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        // A second Ctrl-C while the checkpoint is written falls back to the default (exit).
        let _ = ctrlc::set_handler(move || {
            if stop.swap(true, Ordering::SeqCst) {
                std::process::exit(130);
            }
            eprintln!("\ninterrupted: finishing the step, writing a checkpoint (Ctrl-C again to abort)");
        });
    }
    let mut trainer = Trainer::new(args, seed.unwrap_or(DEFAULT_SEED), spec, train, heldout)?;
    trainer.run(&stop).map_err(TrainError::runtime)
}

#[cfg(test)]
mod tests;
