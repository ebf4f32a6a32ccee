//! Checkpoints under `<out>/checkpoints/<stage>/`: what they record besides tensors, where
//! their files lie, and writing them so that an interruption never leaves a broken one.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, Context};
use infiniterra_terrain::model::burn::module::Module;
use infiniterra_terrain::model::{NoiseDistribution, Normalisation, UNetConfig};
use serde::{Deserialize, Serialize};

use super::trainer::Trainer;

/// What a checkpoint records besides tensors.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub(super) struct CheckpointState {
    /// The stage trained.
    pub stage: String,
    /// Optimiser steps taken.
    pub step: u64,
    /// The training seed.
    pub seed: u64,
    /// Samples per step.
    pub batch: usize,
    /// Side of the training crops, pixels.
    pub crop: usize,
    /// Reference learning rate.
    pub lr: f32,
    /// Steps before the learning rate decays.
    pub lr_ref_steps: u64,
    /// EMA decay.
    pub ema: f32,
    /// The network's shape.
    pub config: UNetConfig,
    /// How elevations are scaled into the network.
    pub normalisation: Normalisation,
    /// Wall time spent training so far, seconds.
    pub wall_seconds: f64,
    /// (step, mean training loss over the logging interval).
    pub losses: Vec<(u64, f32)>,
    /// (step, validation loss).
    pub validation: Vec<(u64, f32)>,
    /// For a run started with `--init-from`: the command that made the weights it started
    /// from, and that manifest's path (both go into the shipped `recreate`).
    #[serde(default)]
    pub continues: Option<(String, PathBuf)>,
    /// Training noise levels (checkpoints written before they were recorded used EDM's).
    #[serde(default)]
    pub noise: NoiseDistribution,
}

/// Paths of a stage's checkpoint.
pub(super) struct CheckpointPaths {
    /// `<out>/checkpoints/<stage>/`.
    pub dir: PathBuf,
}

impl CheckpointPaths {
    pub(super) fn state(&self) -> PathBuf {
        self.dir.join("state.json")
    }
    pub(super) fn model(&self) -> PathBuf {
        self.dir.join("model.bpk")
    }
    pub(super) fn ema(&self) -> PathBuf {
        self.dir.join("ema.bpk")
    }
    pub(super) fn optim(&self) -> PathBuf {
        self.dir.join("optim.bpk")
    }
}

impl Trainer {
    /// Writes the checkpoint (model, EMA, optimiser, state), each through a temporary file
    /// and the state last, so an interruption mid-write leaves the previous one usable.
    pub(super) fn checkpoint(&mut self, wall_seconds: f64) -> anyhow::Result<()> {
        self.state.wall_seconds = wall_seconds;
        std::fs::create_dir_all(&self.paths.dir).with_context(|| format!("creating {}", self.paths.dir.display()))?;
        let tmp = |p: &Path| p.with_extension("tmp.bpk");
        let (model, ema, optim) = (self.paths.model(), self.paths.ema(), self.paths.optim());
        self.net.clone().save_file(tmp(&model)).map_err(|e| anyhow!("writing {}: {e}", model.display()))?;
        self.ema.clone().save_file(tmp(&ema)).map_err(|e| anyhow!("writing {}: {e}", ema.display()))?;
        self.optim.save(tmp(&optim)).map_err(|e| anyhow!("writing {}: {e}", optim.display()))?;
        let state_tmp = self.paths.state().with_extension("json.tmp");
        std::fs::write(&state_tmp, serde_json::to_string_pretty(&self.state)?)
            .with_context(|| format!("writing {}", state_tmp.display()))?;
        for p in [&model, &ema, &optim] {
            std::fs::rename(tmp(p), p).with_context(|| format!("moving {} into place", p.display()))?;
        }
        std::fs::rename(&state_tmp, self.paths.state())
            .with_context(|| format!("writing {}", self.paths.state().display()))?;
        Ok(())
    }
}
