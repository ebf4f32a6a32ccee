//! EDM training objective (Karras et al. 2022): log-normal noise levels and the loss weight
//! that makes every σ contribute equally at initialisation.

use burn::tensor::{Tensor, TensorData};
use serde::{Deserialize, Serialize};

use super::rng::HostRng;
use super::unet::UNet;

/// The training distribution of noise levels: ln σ ~ N(p_mean, p_std²).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct NoiseDistribution {
    /// Mean of ln σ.
    pub p_mean: f32,
    /// Standard deviation of ln σ.
    pub p_std: f32,
}

impl Default for NoiseDistribution {
    /// EDM's image values: most training effort goes to σ ≈ 0.1–1.5 (σ_data = 0.5), where
    /// the structure a few-step sampler must get right is decided.
    fn default() -> Self {
        NoiseDistribution { p_mean: -1.2, p_std: 1.2 }
    }
}

impl NoiseDistribution {
    /// `n` noise levels.
    pub fn sample(&self, rng: &mut HostRng, n: usize) -> Vec<f32> {
        (0..n).map(|_| (self.p_mean as f64 + self.p_std as f64 * rng.normal()).exp() as f32).collect()
    }
}

/// The EDM loss `E[λ(σ)·‖D(y + σn; σ) − y‖²]` with `λ(σ) = (σ² + σ_d²)/(σ·σ_d)²`, averaged
/// over the batch and pixels. `clean` and `noise` are `[batch, channels_out, h, w]`; `sigma`
/// holds one level per sample. Returns a one-element tensor that carries the gradient.
pub fn edm_loss(
    net: &UNet,
    clean: Tensor<4>,
    noise: Tensor<4>,
    sigma: &[f32],
    cond: Option<Tensor<4>>,
    vector: Option<Tensor<2>>,
) -> Tensor<1> {
    let device = clean.device();
    let b = sigma.len();
    assert_eq!(clean.dims()[0], b, "one σ per sample");
    let sd = net.config.sigma_data;
    let weights: Vec<f32> = sigma.iter().map(|&s| (s * s + sd * sd) / (s * sd).powi(2)).collect();
    let sig = Tensor::<1>::from_data(TensorData::new(sigma.to_vec(), [b]), &device);
    let weight = Tensor::<4>::from_data(TensorData::new(weights, [b, 1, 1, 1]), &device);
    let noisy = clean.clone() + noise * sig.clone().reshape([b, 1, 1, 1]);
    let denoised = net.denoise(noisy, sig, cond, vector);
    ((denoised - clean).square() * weight).mean()
}
