//! The U-Net family: EDM2's magnitude-preserving blocks in a small, CPU-sized layout, with
//! EDM preconditioning so the same module is the denoiser D(x; σ).

use burn::module::{Module, Param};
use burn::tensor::module::{avg_pool2d, interpolate};
use burn::tensor::ops::{AvgPoolOptions, InterpolateMode, InterpolateOptions};
use burn::tensor::{Device, Tensor, TensorData};
use serde::{Deserialize, Serialize};

use super::layers::{mp_cat, mp_silu, mp_sum, pixel_norm, Fourier, MpConv, MpLinear};
use super::rng::HostRng;

/// Residual branch weight in blocks' MP-sum (EDM2's `res_balance`).
const RES_BALANCE: f32 = 0.3;
/// Skip-connection weight in decoder MP-cat (EDM2's `concat_balance`).
const CONCAT_BALANCE: f32 = 0.5;
/// Weight of the conditioning vector against the noise embedding (EDM2's `label_balance`).
const VECTOR_BALANCE: f32 = 0.5;
/// Seed of the fixed Fourier frequencies (part of the architecture, not of a run).
const FOURIER_SEED: u64 = 0x4544_4d32;

/// The architecture of one U-Net: everything needed to rebuild it before loading weights.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UNetConfig {
    /// Channels generated (the noisy input and the output).
    pub channels_out: usize,
    /// Spatial conditioning channels concatenated to the noisy input.
    pub channels_cond: usize,
    /// Length of the conditioning vector (0: none).
    pub vector_dim: usize,
    /// Feature channels per resolution level, finest first; each level halves the resolution.
    pub channels: Vec<usize>,
    /// Extra blocks at the coarsest level between encoder and decoder.
    pub mid_blocks: usize,
    /// Width of the noise (and vector) embedding.
    pub emb_channels: usize,
    /// Number of Fourier features of the noise level.
    pub fourier_channels: usize,
    /// Standard deviation of the training targets (EDM's σ_data).
    pub sigma_data: f32,
}

impl UNetConfig {
    /// The core stage's default: 3 levels of 32/64/96 channels, ~0.9 M parameters,
    /// ≈ 0.3 M multiply–adds per pixel.
    pub fn core() -> UNetConfig {
        UNetConfig {
            channels_out: 1,
            channels_cond: 1,
            vector_dim: 2,
            channels: vec![32, 64, 96],
            mid_blocks: 1,
            emb_channels: 128,
            fourier_channels: 64,
            sigma_data: 0.5,
        }
    }

    /// This shape at half the width (channels, embedding and Fourier features halved): ≈ ¼
    /// of the multiply–adds per pixel. The core's half is the detail stage's shape, and the
    /// core's autoguidance guide (see [`Guidance`](super::Guidance)).
    pub fn halved(&self) -> UNetConfig {
        UNetConfig {
            channels: self.channels.iter().map(|&c| (c / 2).max(1)).collect(),
            emb_channels: (self.emb_channels / 2).max(1),
            fourier_channels: (self.fourier_channels / 2).max(2),
            ..self.clone()
        }
    }

    /// The detail stage's default: the core's shape at half the width (≈ ¼ of its cost per
    /// pixel), since it runs on 4× the pixels with twice the window overlap.
    pub fn detail() -> UNetConfig {
        UNetConfig::core().halved()
    }

    /// A very small network for tests.
    pub fn tiny() -> UNetConfig {
        UNetConfig {
            channels_out: 1,
            channels_cond: 1,
            vector_dim: 2,
            channels: vec![8, 16],
            mid_blocks: 1,
            emb_channels: 16,
            fourier_channels: 8,
            sigma_data: 0.5,
        }
    }

    /// Checks the configuration describes a buildable network.
    pub fn validate(&self) -> Result<(), String> {
        if self.channels_out == 0 {
            return Err("channels_out must be at least 1".into());
        }
        if self.channels.is_empty() || self.channels.contains(&0) {
            return Err("channels needs at least one level, none of them 0".into());
        }
        if self.channels.len() > 6 {
            return Err("at most 6 levels".into());
        }
        if self.emb_channels == 0 || self.fourier_channels == 0 {
            return Err("emb_channels and fourier_channels must be at least 1".into());
        }
        if !(self.sigma_data.is_finite() && self.sigma_data > 0.0) {
            return Err("sigma_data must be positive".into());
        }
        Ok(())
    }

    /// Windows must be divisible by this (every level halves the resolution).
    pub fn size_multiple(&self) -> usize {
        1 << (self.channels.len() - 1)
    }
}

/// One residual block: MP-conv 3×3 → embedding modulation → MP-conv 3×3, MP-summed with the
/// (possibly 1×1-projected) input.
#[derive(Module, Debug)]
pub struct Block {
    /// 1×1 projection when the channel count changes.
    pub skip: Option<MpConv>,
    /// First 3×3 convolution.
    pub conv0: MpConv,
    /// Second 3×3 convolution.
    pub conv1: MpConv,
    /// Embedding → per-channel scale.
    pub emb: MpLinear,
    /// Learned gain of the modulation (starts at 0: no modulation).
    pub emb_gain: Param<Tensor<1>>,
    /// Encoder blocks pixel-normalise their input; decoder blocks do not (EDM2).
    #[module(skip)]
    pub encoder: bool,
}

impl Block {
    fn new(cin: usize, cout: usize, cemb: usize, encoder: bool, rng: &mut HostRng, device: &Device) -> Block {
        Block {
            skip: (cin != cout).then(|| MpConv::new(cin, cout, 1, rng, device)),
            conv0: MpConv::new(if encoder { cout } else { cin }, cout, 3, rng, device),
            conv1: MpConv::new(cout, cout, 3, rng, device),
            emb: MpLinear::new(cemb, cout, rng, device),
            emb_gain: Param::from_data(TensorData::new(vec![0.0f32], [1]), device),
            encoder,
        }
    }

    fn forward(&self, x: Tensor<4>, emb: &Tensor<2>) -> Tensor<4> {
        let mut x = x;
        if self.encoder {
            if let Some(skip) = &self.skip {
                x = skip.forward(x);
            }
            x = pixel_norm(x);
        }
        let y = self.conv0.forward_silu(x.clone(), None);
        let scale = self.emb.forward_gain(emb.clone(), self.emb_gain.val()).add_scalar(1.0);
        let y = self.conv1.forward_silu(y, Some(scale));
        if !self.encoder {
            if let Some(skip) = &self.skip {
                x = skip.forward(x);
            }
        }
        mp_sum(x, y, RES_BALANCE)
    }

    /// Multiply–adds per pixel of this block's resolution.
    fn macs_per_pixel(&self) -> usize {
        self.skip.as_ref().map_or(0, |s| s.macs_per_pixel()) + self.conv0.macs_per_pixel() + self.conv1.macs_per_pixel()
    }
}

/// A magnitude-preserving U-Net wrapped in EDM preconditioning.
#[derive(Module, Debug)]
pub struct UNet {
    /// 3×3 input convolution over `[c_in·x, cond, 1]`.
    pub conv_in: MpConv,
    /// One encoder block per level (levels after the first start with a 2× average pool).
    pub enc: Vec<Block>,
    /// Blocks at the coarsest level.
    pub mid: Vec<Block>,
    /// One decoder block per level, coarsest first, each fed the MP-cat of the upsampled
    /// features and the encoder's output at that level.
    pub dec: Vec<Block>,
    /// 3×3 output convolution.
    pub conv_out: MpConv,
    /// Output gain, starting at 0 so an untrained network outputs c_skip·x.
    pub out_gain: Param<Tensor<1>>,
    /// Fourier features → embedding.
    pub noise_emb: MpLinear,
    /// Conditioning vector → embedding.
    pub vector_emb: Option<MpLinear>,
    /// Fixed Fourier frequencies (derived from a constant seed).
    #[module(skip)]
    pub fourier: Fourier,
    /// The architecture.
    #[module(skip)]
    pub config: UNetConfig,
}

impl UNet {
    /// A freshly initialised network; weights are a pure function of `seed`.
    pub fn new(config: &UNetConfig, seed: u64, device: &Device) -> UNet {
        if let Err(e) = config.validate() {
            panic!("invalid U-Net configuration: {e}");
        }
        let mut rng = HostRng::keyed(seed, 0x696e_6974, 0, 0);
        let ch = &config.channels;
        let cemb = config.emb_channels;
        // +1: the constant-ones channel that stands in for biases.
        let conv_in = MpConv::new(config.channels_out + config.channels_cond + 1, ch[0], 3, &mut rng, device);
        let mut enc = Vec::with_capacity(ch.len());
        for (l, &c) in ch.iter().enumerate() {
            let cin = if l == 0 { ch[0] } else { ch[l - 1] };
            enc.push(Block::new(cin, c, cemb, true, &mut rng, device));
        }
        let deepest = ch[ch.len() - 1];
        let mid = (0..config.mid_blocks).map(|_| Block::new(deepest, deepest, cemb, false, &mut rng, device)).collect();
        let mut dec = Vec::with_capacity(ch.len());
        let mut incoming = deepest;
        for &c in ch.iter().rev() {
            dec.push(Block::new(incoming + c, c, cemb, false, &mut rng, device));
            incoming = c;
        }
        UNet {
            conv_in,
            enc,
            mid,
            dec,
            conv_out: MpConv::new(ch[0], config.channels_out, 3, &mut rng, device),
            out_gain: Param::from_data(TensorData::new(vec![0.0f32], [1]), device),
            noise_emb: MpLinear::new(config.fourier_channels, cemb, &mut rng, device),
            vector_emb: (config.vector_dim > 0).then(|| MpLinear::new(config.vector_dim, cemb, &mut rng, device)),
            fourier: Fourier::new(config.fourier_channels, FOURIER_SEED),
            config: config.clone(),
        }
    }

    /// The raw network F(x_in; c_noise, vector): `x_in` is `[batch, channels_out +
    /// channels_cond, h, w]`, `c_noise` is `[batch]`.
    pub fn raw(&self, x_in: Tensor<4>, c_noise: Tensor<1>, vector: Option<Tensor<2>>) -> Tensor<4> {
        let [b, _, h, w] = x_in.dims();
        let device = x_in.device();
        let mut emb = self.noise_emb.forward(self.fourier.embed(c_noise));
        if let (Some(layer), Some(v)) = (&self.vector_emb, vector) {
            let dim = v.dims()[1] as f32;
            emb = mp_sum(emb, layer.forward(v.mul_scalar(dim.sqrt())), VECTOR_BALANCE);
        }
        let emb = mp_silu(emb);

        let ones = Tensor::<4>::ones([b, 1, h, w], &device);
        let mut x = self.conv_in.forward(Tensor::cat(vec![x_in, ones], 1));
        let mut skips = Vec::with_capacity(self.enc.len());
        for (l, block) in self.enc.iter().enumerate() {
            if l > 0 {
                x = avg_pool2d(x, AvgPoolOptions::new([2, 2]));
            }
            x = block.forward(x, &emb);
            skips.push(x.clone());
        }
        for block in &self.mid {
            x = block.forward(x, &emb);
        }
        for (k, block) in self.dec.iter().enumerate() {
            let skip = skips.pop().expect("one skip per level");
            if k > 0 {
                let [_, _, sh, sw] = skip.dims();
                x = interpolate(x, InterpolateOptions::new(InterpolateMode::Nearest).with_output_size([sh, sw]));
            }
            x = block.forward(mp_cat(x, skip, CONCAT_BALANCE), &emb);
        }
        self.conv_out.forward_gain(x, self.out_gain.val())
    }

    /// The EDM denoiser D(x; σ) = c_skip·x + c_out·F(c_in·x, cond; ln(σ)/4, vector), for
    /// `x` of shape `[batch, channels_out, h, w]`, per-sample `sigma` of shape `[batch]`,
    /// `cond` of shape `[batch, channels_cond, h, w]` (when the network has any) and `vector`
    /// of shape `[batch, vector_dim]` (zeros mean "no vector").
    pub fn denoise(
        &self,
        x: Tensor<4>,
        sigma: Tensor<1>,
        cond: Option<Tensor<4>>,
        vector: Option<Tensor<2>>,
    ) -> Tensor<4> {
        let b = x.dims()[0];
        let sd = self.config.sigma_data;
        let s2 = sigma.clone().square();
        let denom = s2.clone().add_scalar(sd * sd);
        let c_skip = denom.clone().recip().mul_scalar(sd * sd).reshape([b, 1, 1, 1]);
        let c_out = (sigma.clone().mul_scalar(sd) / denom.clone().sqrt()).reshape([b, 1, 1, 1]);
        let c_in = denom.sqrt().recip().reshape([b, 1, 1, 1]);
        let c_noise = sigma.log().div_scalar(4.0);
        let scaled = x.clone() * c_in;
        let x_in = match cond {
            Some(c) if self.config.channels_cond > 0 => Tensor::cat(vec![scaled, c], 1),
            _ => scaled,
        };
        let f = self.raw(x_in, c_noise, vector);
        x * c_skip + f * c_out
    }

    /// Trainable parameters.
    pub fn parameters(&self) -> usize {
        self.num_params()
    }

    /// Multiply–adds of one forward pass per pixel at full resolution (convolutions only:
    /// they are > 95 % of the work). FLOPs are twice this.
    pub fn macs_per_pixel(&self) -> f64 {
        let levels = self.config.channels.len();
        let scale = |l: usize| 1.0 / (1u64 << (2 * l)) as f64;
        let mut macs = self.conv_in.macs_per_pixel() as f64 + self.conv_out.macs_per_pixel() as f64;
        for (l, b) in self.enc.iter().enumerate() {
            macs += b.macs_per_pixel() as f64 * scale(l);
        }
        for b in &self.mid {
            macs += b.macs_per_pixel() as f64 * scale(levels - 1);
        }
        for (k, b) in self.dec.iter().enumerate() {
            macs += b.macs_per_pixel() as f64 * scale(levels - 1 - k);
        }
        macs
    }
}
