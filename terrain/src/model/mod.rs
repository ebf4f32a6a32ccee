//! Learned stages: a small EDM2-style U-Net family, its EDM preconditioning, a few-step
//! sampler, and the shipped weights with their manifests.
//!
//! The same code serves training (on an autodiff device) and inference (on a plain device);
//! the backend is picked at run time through [`ComputeBackend`] — burn's pure-Rust CPU
//! backend (flex) by default, wgpu when the crate is built with the `wgpu` feature.
//!
//! Owns: network definitions, magnitude-preserving layers, noise embedding, EDM
//! preconditioning and sampling, weight files and manifests, the window functions that run a
//! model on the infinite grid. Must not touch: the engine's blending and cache (it plugs in
//! as a [`WindowFn`](crate::infinite::WindowFn)), the pipeline's stage choice, Minecraft.

mod cpu_conv;
mod edm;
pub mod equaliser;
pub mod hint;
pub mod infill;
mod layers;
pub mod projection;
mod rng;
mod sampler;
pub mod stage;
mod store;
mod unet;

use std::fmt;
use std::str::FromStr;

use burn::tensor::Device;

/// The burn version this crate is built against, for callers that build tensors and train
/// (the root crate's `train` module) without a second, possibly mismatched, dependency.
pub use burn;

pub use edm::{edm_loss, NoiseDistribution};
pub use equaliser::SpectralEqualiser;
pub use hint::{HintCheck, ReliefHint};
pub use infill::DepressionInfill;
pub use layers::{force_normalize, mp_cat, mp_silu, mp_sum, normalize_rows, pixel_norm, MpConv, MpLinear};
pub use projection::ContextProjection;
pub use rng::HostRng;
pub use sampler::{Guide, Sampler, SamplerKind};
pub use store::{
    load_model, load_model_file, load_model_from, save_model, sha256_file, sha256_hex, DataChecksum, Guidance,
    LoadedModel, ModelError, ModelManifest, Normalisation, Precision, TrainingRecord,
};
pub use unet::{UNet, UNetConfig};

/// Which burn backend runs the models.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ComputeBackend {
    /// burn's pure-Rust CPU backend (flex): always built, the default.
    #[default]
    Cpu,
    /// wgpu (Vulkan/Metal/DX12): only in builds with the `wgpu` cargo feature.
    Wgpu,
}

/// A backend name that is not known, or not built into this binary.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum BackendError {
    /// Not one of the names [`ComputeBackend`] accepts.
    #[error("unknown backend `{0}` (expected \"cpu\" or \"wgpu\")")]
    Unknown(String),
    /// Known, but compiled out.
    #[error("backend `{0}` is not built into this binary: rebuild with `cargo build --release --features {0}`")]
    NotBuilt(&'static str),
}

impl FromStr for ComputeBackend {
    type Err = BackendError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "cpu" | "flex" => Ok(ComputeBackend::Cpu),
            "wgpu" | "gpu" => Ok(ComputeBackend::Wgpu),
            _ => Err(BackendError::Unknown(s.to_string())),
        }
    }
}

impl fmt::Display for ComputeBackend {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            ComputeBackend::Cpu => "cpu",
            ComputeBackend::Wgpu => "wgpu",
        })
    }
}

impl ComputeBackend {
    /// The inference device of this backend (no autodiff).
    pub fn device(self) -> Result<Device, BackendError> {
        match self {
            ComputeBackend::Cpu => Ok(Device::flex()),
            #[cfg(feature = "wgpu")]
            ComputeBackend::Wgpu => Ok(Device::wgpu(Default::default())),
            #[cfg(not(feature = "wgpu"))]
            ComputeBackend::Wgpu => Err(BackendError::NotBuilt("wgpu")),
        }
    }

    /// The training device of this backend (records gradients).
    pub fn training_device(self) -> Result<Device, BackendError> {
        Ok(self.device()?.autodiff())
    }
}

#[cfg(test)]
mod tests;
