//! Checkpoints under `<out>/checkpoints/<stage>/`: what they record besides tensors, where
//! their files lie, and writing them so that an interruption never leaves a broken one.

use std::path::PathBuf;

use infiniterra_terrain::model::{NoiseDistribution, Normalisation, UNetConfig};
use serde::{Deserialize, Serialize};

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
