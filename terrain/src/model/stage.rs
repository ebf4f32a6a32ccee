//! Learned stages as window functions of the infinite-tensor engine.
//!
//! [`LearnedStage`] runs a stage's model on 64×64 windows of its own grid (the manifest's
//! stride: half a window unless it says otherwise; the core's is 48, a quarter overlap). Its conditioning is a field
//! `context.factor`× coarser than that grid (8× for the core: the coarse stage, or the layout
//! standing in for it), bilinearly upsampled from globally aligned cells so every window sees
//! the same values where windows overlap. Its noise comes from
//! [`GaussianNoise`] keyed by (seed, stage, sampler step, global tile), so the result is a pure
//! function of (seed, region). The whole few-step sampler runs inside each window (T = 1
//! blending step); each window's output passes the manifest's spectral equaliser and then its
//! depression infill, if any; overlapping outputs are blended by the engine's tent weights.

use std::sync::Arc;

use burn::tensor::{Device, Tensor, TensorData};

use super::equaliser::EqualiserKernel;
use super::infill::DepressionInfill;
use super::projection::ContextProjection;
use super::store::{LoadedModel, Normalisation};
use super::{Guidance, Guide, ReliefHint, Sampler, UNet};
use crate::encoding::{blur, signed_sqrt, signed_square, ContextSpec};
use crate::infinite::{Source, WindowFn, WindowIndex, WindowLayout};
use crate::noise::{GaussianNoise, NoiseKey};
use crate::tile::{Rect, Tile};
use crate::upsample;

/// Noise stream number of a stage (each stage draws its own noise, so two stages never
/// see correlated noise): coarse 1, core 2, detail 3.
pub fn noise_stream(stage: &str) -> u32 {
    match stage {
        "coarse" => 1,
        "core" => 2,
        "detail" => 3,
        _ => 15,
    }
}

/// A learned stage's model as a [`WindowFn`]: elevation in metres (one channel) on its grid,
/// generated as the residual over a context `context.factor`× coarser (the context source
/// gives plain box means or point values; the stage blurs them when training's low band was
/// blurred).
pub struct LearnedStage {
    name: String,
    net: UNet,
    guide: Option<(UNet, Guidance)>,
    device: Device,
    sampler: Sampler,
    norm: Normalisation,
    hint: Option<ReliefHint>,
    equaliser: Option<EqualiserKernel>,
    projection: Option<ContextProjection>,
    infill: Option<DepressionInfill>,
    spec: ContextSpec,
    coarse: Arc<dyn Source>,
    seed: u64,
    window: i64,
    stride: i64,
    batch: usize,
}

impl LearnedStage {
    /// The stage `model.manifest.stage` of world `seed`: `model` on `device`, conditioned on
    /// `coarse` (elevation in metres on a grid `context.factor`× coarser than the output),
    /// windows of the model's size and stride, `batch` windows per network call.
    pub fn new(model: LoadedModel, device: Device, coarse: Arc<dyn Source>, seed: u64, batch: usize) -> LearnedStage {
        let window = model.manifest.window as i64;
        let stride = model.manifest.window_stride() as i64;
        LearnedStage {
            name: model.manifest.stage.clone(),
            sampler: model.manifest.sampler.clone(),
            norm: model.manifest.normalisation.clone(),
            hint: model.manifest.relief_hint.clone(),
            equaliser: model.manifest.spectral_equaliser.as_ref().map(EqualiserKernel::new),
            projection: model.manifest.context_projection.clone(),
            infill: model.manifest.depression_infill.clone(),
            spec: model.manifest.context,
            guide: model.guide.zip(model.manifest.guidance.clone()),
            net: model.net,
            device,
            coarse,
            seed,
            window,
            stride,
            batch: batch.max(1),
        }
    }

    /// The conditioning of one window, in the network's units, and the un-normalised
    /// signed-sqrt low band the output is added to. Built exactly like training's low band:
    /// the coarse grid (box means) in signed sqrt, blurred if the stage's context is,
    /// bilinearly upsampled — the blur reads `BLUR_RADIUS` extra cells on each side, so
    /// neighbouring windows agree. Third, the window's own context cells in signed sqrt
    /// (unblurred, row-major): what its output's cell means should equal.
    pub(crate) fn context(&self, rect: Rect) -> (Vec<f32>, Vec<f32>, Vec<f32>) {
        let f = self.spec.factor as i64;
        let src = upsample::source_rect(&rect, f);
        let r = self.spec.margin() as i64;
        let padded = Rect::new(src.y0 - r, src.x0 - r, src.h + 2 * r, src.w + 2 * r);
        let h: Vec<f32> = self.coarse.query(padded).data.iter().map(|&e| signed_sqrt(e)).collect();
        let cells = {
            let (oy, ox) = (rect.y0.div_euclid(f) - padded.y0, rect.x0.div_euclid(f) - padded.x0);
            let n = rect.w / f;
            (0..rect.h / f)
                .flat_map(|y| {
                    let row = ((oy + y) * padded.w + ox) as usize;
                    h[row..row + n as usize].iter().copied()
                })
                .collect()
        };
        let blurred = if self.spec.blur { blur(&h, padded.h as usize, padded.w as usize) } else { h };
        let inner = (0..src.h)
            .flat_map(|y| {
                let row = ((y + r) * padded.w + r) as usize;
                blurred[row..row + src.w as usize].iter().copied()
            })
            .collect();
        let low = upsample::bilinear(&Tile::from_data(1, src, inner), f, rect).data;
        let cond = low.iter().map(|&v| (v - self.norm.cond_mean) / self.norm.cond_scale).collect();
        (cond, low, cells)
    }

    /// The conditioning vectors of windows whose low bands are `lows`, row-major
    /// `[windows, vector_dim]`: `[relief_z, 1]` predicted from each context when the manifest
    /// has a relief hint, otherwise zeros ("no hint": the network was trained with the vector
    /// dropped for a fifth of its samples). `None` for a network without a vector input.
    pub(crate) fn conditioning_vector(&self, lows: &[Vec<f32>]) -> Option<Vec<f32>> {
        let dim = self.net.config.vector_dim;
        if dim == 0 {
            return None;
        }
        let side = self.window as usize;
        let mut v = vec![0.0f32; lows.len() * dim];
        if let Some(hint) = &self.hint {
            for (row, low) in v.chunks_mut(dim).zip(lows) {
                row[0] = hint.predict(low, side);
                row[1] = 1.0;
            }
        }
        Some(v)
    }
}

impl WindowFn for LearnedStage {
    fn name(&self) -> &str {
        &self.name
    }

    fn channels(&self) -> usize {
        1
    }

    fn layout(&self) -> WindowLayout {
        WindowLayout::square(self.window, self.stride, 0)
    }

    fn batch_size(&self) -> usize {
        self.batch
    }

    fn eval(&self, windows: &[WindowIndex]) -> Vec<Tile> {
        let layout = self.layout();
        let (b, n) = (windows.len(), (self.window * self.window) as usize);
        let side = self.window as usize;
        let rects: Vec<Rect> = windows.iter().map(|&w| layout.rect(w)).collect();
        let mut cond = Vec::with_capacity(b * n);
        let mut lows = Vec::with_capacity(b);
        let mut cells = Vec::with_capacity(b);
        for &r in &rects {
            let (c, low, cell) = self.context(r);
            cond.extend_from_slice(&c);
            lows.push(low);
            cells.push(cell);
        }
        let noises: Vec<Tensor<4>> = (0..self.sampler.noises_needed())
            .map(|step| {
                let source = GaussianNoise {
                    key: NoiseKey { seed: self.seed, stage: noise_stream(&self.name), step: step as u32 },
                    channels: 1,
                };
                let mut values = Vec::with_capacity(b * n);
                for &r in &rects {
                    values.extend_from_slice(&source.query(r).data);
                }
                Tensor::from_data(TensorData::new(values, [b, 1, side, side]), &self.device)
            })
            .collect();
        let cond = Tensor::<4>::from_data(TensorData::new(cond, [b, 1, side, side]), &self.device);
        let vector = self
            .conditioning_vector(&lows)
            .map(|v| Tensor::<2>::from_data(TensorData::new(v, [b, self.net.config.vector_dim]), &self.device));
        let guide = self.guide.as_ref().map(|(net, g)| Guide { net, weight: g.weight, steps: g.steps });
        let out = self.sampler.sample_guided(&self.net, guide.as_ref(), &noises, Some(cond), vector);
        let values: Vec<f32> = out.into_data().try_into_vec().expect("the network outputs f32");
        rects
            .iter()
            .zip(lows)
            .zip(cells)
            .enumerate()
            .map(|(i, ((&r, low), cell))| {
                let residual = &values[i * n..(i + 1) * n];
                let h: Vec<f32> = low.iter().zip(residual).map(|(&l, &x)| l + x * self.norm.target_scale).collect();
                let h = match &self.projection {
                    Some(p) => p.apply(&h, side, self.spec.factor, &cell),
                    None => h,
                };
                let metres: Vec<f32> = h.into_iter().map(signed_square).collect();
                let metres = match &self.equaliser {
                    Some(kernel) => kernel.apply(&metres, side),
                    None => metres,
                };
                let metres = match &self.infill {
                    Some(infill) => infill.apply(&metres, side),
                    None => metres,
                };
                Tile::from_data(1, r, metres)
            })
            .collect()
    }
}
