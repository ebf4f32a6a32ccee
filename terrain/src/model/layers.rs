//! Magnitude-preserving layers (EDM2: Karras et al., "Analyzing and Improving the Training
//! Dynamics of Diffusion Models", 2024).
//!
//! Every layer keeps activations near unit variance by construction rather than through
//! normalisation layers with learned statistics: weights are normalised to unit norm per
//! output unit (and forced back to it after every optimiser step), sums and concatenations are
//! rescaled so their magnitude is preserved, and SiLU is divided by its output magnitude on a
//! unit normal input. No biases: a constant-ones input channel plays that role.

use burn::module::{Module, ModuleMapper, Param};
use burn::tensor::activation::silu;
use burn::tensor::module::conv2d;
use burn::tensor::ops::ConvOptions;
use burn::tensor::{Device, Tensor, TensorData};

use super::cpu_conv::{self, Pre, SILU_MAGNITUDE};
use super::rng::HostRng;

/// Keeps the weight norm away from zero (EDM2's value).
const NORM_EPS: f32 = 1e-4;

/// Normalises every "row" (everything but dim 0) of a weight to RMS 1, i.e. to norm √fan_in.
pub fn normalize_rows<const D: usize>(w: Tensor<D>) -> Tensor<D> {
    let dims = w.dims();
    let rows = dims[0];
    let fan_in: usize = dims[1..].iter().product();
    let flat: Tensor<2> = w.reshape([rows, fan_in]);
    let rms = flat.clone().square().sum_dim(1).sqrt().div_scalar((fan_in as f32).sqrt()).add_scalar(NORM_EPS);
    (flat / rms).reshape(dims)
}

/// SiLU scaled to unit output magnitude.
pub fn mp_silu<const D: usize>(x: Tensor<D>) -> Tensor<D> {
    silu(x).div_scalar(SILU_MAGNITUDE)
}

/// `(1−t)·a + t·b`, rescaled so two uncorrelated unit-variance inputs give unit variance.
pub fn mp_sum<const D: usize>(a: Tensor<D>, b: Tensor<D>, t: f32) -> Tensor<D> {
    let norm = ((1.0 - t).powi(2) + t * t).sqrt();
    (a.mul_scalar(1.0 - t) + b.mul_scalar(t)).div_scalar(norm)
}

/// Channel concatenation (dim 1) weighting `a` by `1−t` and `b` by `t` while keeping the
/// total magnitude, whatever the two channel counts.
pub fn mp_cat(a: Tensor<4>, b: Tensor<4>, t: f32) -> Tensor<4> {
    let (na, nb) = (a.dims()[1] as f32, b.dims()[1] as f32);
    let c = ((na + nb) / ((1.0 - t).powi(2) + t * t)).sqrt();
    let wa = c / na.sqrt() * (1.0 - t);
    let wb = c / nb.sqrt() * t;
    Tensor::cat(vec![a.mul_scalar(wa), b.mul_scalar(wb)], 1)
}

/// Pixel norm: every pixel's channel vector scaled to RMS 1 (EDM2 normalises encoder
/// activations this way instead of using group norm).
pub fn pixel_norm(x: Tensor<4>) -> Tensor<4> {
    let rms = x.clone().square().mean_dim(1).sqrt().add_scalar(NORM_EPS);
    x / rms
}

/// A weight tensor of `shape` drawn from N(0, 1) on the host.
fn randn_param<const D: usize>(shape: [usize; D], rng: &mut HostRng, device: &Device) -> Param<Tensor<D>> {
    let n = shape.iter().product();
    Param::from_data(TensorData::new(rng.normals(n), shape), device)
}

/// A magnitude-preserving 2-D convolution ("same" zero padding, stride 1, no bias).
#[derive(Module, Debug)]
pub struct MpConv {
    /// `[out, in, k, k]`; its rows are kept at unit RMS.
    pub weight: Param<Tensor<4>>,
}

impl MpConv {
    /// A `k × k` convolution from `cin` to `cout` channels with N(0, 1) initial weights.
    pub fn new(cin: usize, cout: usize, k: usize, rng: &mut HostRng, device: &Device) -> MpConv {
        MpConv { weight: randn_param([cout, cin, k, k], rng, device) }
    }

    /// The effective (normalised, scaled) kernel: every output unit has norm `gain`.
    fn kernel(&self) -> Tensor<4> {
        let w = self.weight.val();
        let [_, cin, kh, kw] = w.dims();
        normalize_rows(w).div_scalar(((cin * kh * kw) as f32).sqrt())
    }

    /// Convolves with an output gain of 1.
    pub fn forward(&self, x: Tensor<4>) -> Tensor<4> {
        self.conv(x, self.kernel())
    }

    /// Convolves with a learned scalar gain (shape `[1]`), as EDM2's zero-initialised output
    /// layer does so the network starts as the identity of its preconditioning.
    pub fn forward_gain(&self, x: Tensor<4>, gain: Tensor<1>) -> Tensor<4> {
        self.conv(x, self.kernel() * gain.reshape([1, 1, 1, 1]))
    }

    /// `conv(mp_silu(x · scale))` with `scale` one factor per image and input channel
    /// (`[batch, c_in]`) or none: the activation in front of every block convolution. On the
    /// CPU at inference the activation is fused into the convolution's padding pass.
    pub fn forward_silu(&self, x: Tensor<4>, scale: Option<Tensor<2>>) -> Tensor<4> {
        let kernel = self.kernel();
        if cpu_conv::applies(&x, &kernel) {
            let factors: Option<Vec<f32>> =
                scale.map(|s| s.into_data().try_into_vec().expect("f32 modulation on a flex device"));
            return cpu_conv::conv_same(x, kernel, Pre::Silu(factors.as_deref()));
        }
        let x = match scale {
            Some(s) => {
                let [b, c] = s.dims();
                x * s.reshape([b, c, 1, 1])
            }
            None => x,
        };
        self.conv(mp_silu(x), kernel)
    }

    fn conv(&self, x: Tensor<4>, w: Tensor<4>) -> Tensor<4> {
        if cpu_conv::applies(&x, &w) {
            return cpu_conv::conv_same(x, w, Pre::Identity);
        }
        let k = w.dims()[2];
        let pad = k / 2;
        conv2d(x, w, None, ConvOptions::new([1, 1], [pad, pad], [1, 1], 1))
    }

    /// Multiply–adds per output pixel.
    pub fn macs_per_pixel(&self) -> usize {
        self.weight.dims().iter().product()
    }
}

/// A magnitude-preserving fully connected layer (no bias).
#[derive(Module, Debug)]
pub struct MpLinear {
    /// `[out, in]`; its rows are kept at unit RMS.
    pub weight: Param<Tensor<2>>,
}

impl MpLinear {
    /// A layer from `cin` to `cout` features with N(0, 1) initial weights.
    pub fn new(cin: usize, cout: usize, rng: &mut HostRng, device: &Device) -> MpLinear {
        MpLinear { weight: randn_param([cout, cin], rng, device) }
    }

    fn matrix(&self) -> Tensor<2> {
        let w = self.weight.val();
        let cin = w.dims()[1];
        normalize_rows(w).div_scalar((cin as f32).sqrt())
    }

    /// `x · Wᵀ` for `x` of shape `[batch, in]`.
    pub fn forward(&self, x: Tensor<2>) -> Tensor<2> {
        Self::apply(x, self.matrix())
    }

    /// `x · Wᵀ · gain` with a learned scalar gain (shape `[1]`).
    pub fn forward_gain(&self, x: Tensor<2>, gain: Tensor<1>) -> Tensor<2> {
        Self::apply(x, self.matrix() * gain.reshape([1, 1]))
    }

    /// `x · wᵀ`; at inference on the CPU row by row, so a sample's result does not depend on
    /// the batch it is in (see [`cpu_conv::linear`]).
    fn apply(x: Tensor<2>, w: Tensor<2>) -> Tensor<2> {
        if cpu_conv::plain(&x) && cpu_conv::plain(&w) {
            return cpu_conv::linear(x, w);
        }
        x.matmul(w.transpose())
    }
}

/// Forced weight normalisation: after each optimiser step every convolution and linear
/// weight (rank ≥ 2) is reset to unit-RMS rows. Without it Adam's updates grow the weight
/// norms and so shrink the effective learning rate over training (EDM2 §2.3). Scalar gains
/// (rank 1) are left alone.
pub fn force_normalize<M: Module>(module: M) -> M {
    struct Normalizer;
    impl ModuleMapper for Normalizer {
        fn map_float<const D: usize>(&mut self, param: Param<Tensor<D>>) -> Param<Tensor<D>> {
            if D < 2 {
                return param;
            }
            let (id, tensor, mapper) = param.consume();
            let tracked = tensor.is_autodiff();
            let require_grad = tensor.is_require_grad();
            let mut value = normalize_rows(tensor.inner());
            if tracked {
                value = value.autodiff();
                if require_grad {
                    value = value.require_grad();
                }
            }
            Param::from_mapped_value(id, value, mapper)
        }
    }
    module.map(&mut Normalizer)
}

/// Fourier features of the noise level: `√2·cos(2π(f·c + φ))` with fixed random `f ~ N(0,1)`
/// and `φ ~ U(0,1)`, as a `[batch, n]` tensor. The frequencies are a pure function of
/// `seed`, so they need not be stored with the weights.
#[derive(Clone, Debug, PartialEq)]
pub struct Fourier {
    freqs: Vec<f32>,
    phases: Vec<f32>,
}

impl Fourier {
    /// `n` features drawn from the stream keyed by `seed`.
    pub fn new(n: usize, seed: u64) -> Fourier {
        let mut rng = HostRng::keyed(seed, 0x466f_7572, 0, 0);
        let freqs = rng.normals(n);
        let phases = (0..n).map(|_| rng.uniform() as f32).collect();
        Fourier { freqs, phases }
    }

    /// The features of `c` (shape `[batch]`).
    pub fn embed(&self, c: Tensor<1>) -> Tensor<2> {
        let device = c.device();
        let n = self.freqs.len();
        let tau = std::f32::consts::TAU;
        let f: Vec<f32> = self.freqs.iter().map(|v| v * tau).collect();
        let p: Vec<f32> = self.phases.iter().map(|v| v * tau).collect();
        let f = Tensor::<2>::from_data(TensorData::new(f, [1, n]), &device);
        let p = Tensor::<2>::from_data(TensorData::new(p, [1, n]), &device);
        let batch = c.dims()[0];
        (c.reshape([batch, 1]) * f + p).cos().mul_scalar(std::f32::consts::SQRT_2)
    }
}
