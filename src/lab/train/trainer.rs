//! The training loop: EDM loss, Adam, EMA, forced weight normalisation, progress lines,
//! validation losses and preview PNGs; a run starts fresh, from its checkpoint or from a
//! shipped model.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use anyhow::{anyhow, bail, Context};
use infiniterra_terrain::model::burn::module::Module;
use infiniterra_terrain::model::burn::optim::{AdamConfig, GradientsParams, ModuleOptimizer};
use infiniterra_terrain::model::burn::tensor::{Device, Tensor, TensorData};
use infiniterra_terrain::model::{edm_loss, force_normalize, load_model_file, NoiseDistribution, UNet};

use super::checkpoint::{CheckpointPaths, CheckpointState};
use super::data::{Batch, TileSet};
use super::stage::StageSpec;
use super::{ema, preview, TrainError, TrainOptions};

/// A training run in progress.
pub(super) struct Trainer {
    /// The run's options (batch, crop and schedule as the checkpoint or shipped record says).
    pub args: TrainOptions,
    /// The stage's resolution, sampler, context and stride (what `ship` writes).
    pub spec: StageSpec,
    /// The autodiff device the network trains on.
    pub device: Device,
    /// The plain device of the EMA network (validation, previews, shipping).
    pub plain: Device,
    /// The network being trained.
    pub net: UNet,
    /// Its exponential moving average: the weights that ship.
    pub ema: UNet,
    /// Adam.
    pub optim: ModuleOptimizer,
    /// Step, seed, schedule, losses: what a checkpoint records besides tensors.
    pub state: CheckpointState,
    /// The training split.
    pub train: TileSet,
    /// The held-out split (validation losses, previews).
    pub heldout: TileSet,
    /// The training noise levels.
    pub noise: NoiseDistribution,
    /// Where the checkpoint goes.
    pub paths: CheckpointPaths,
}

impl Trainer {
    pub(super) fn new(
        args: &TrainOptions,
        seed: u64,
        spec: StageSpec,
        train: TileSet,
        heldout: TileSet,
    ) -> Result<Trainer, TrainError> {
        let plain = args.backend.device().map_err(TrainError::input)?;
        let device = plain.clone().autodiff();
        let paths = CheckpointPaths { dir: args.out.join("checkpoints").join(&args.stage) };
        let optim = AdamConfig::new().with_beta_1(0.9).with_beta_2(0.99).with_epsilon(1e-8).init();
        let (net, ema, optim, state) = if args.resume {
            let text = std::fs::read_to_string(paths.state()).map_err(|e| {
                TrainError::input(anyhow!(
                    "cannot resume: {} ({e}); start a new run without --resume",
                    paths.state().display()
                ))
            })?;
            let state: CheckpointState = serde_json::from_str(&text).map_err(|e| {
                TrainError::input(anyhow!("{} is not a checkpoint state: {e}", paths.state().display()))
            })?;
            if state.stage != args.stage || state.config != spec.config {
                return Err(TrainError::input(anyhow!(
                    "{} belongs to another stage or architecture; start a new run without --resume",
                    paths.state().display()
                )));
            }
            let load = |path: PathBuf, dev: &Device| {
                UNet::new(&state.config, state.seed, dev)
                    .try_load_file(&path)
                    .map_err(|e| TrainError::input(anyhow!("cannot resume from {}: {e}", path.display())))
            };
            let net = load(paths.model(), &device)?;
            let ema = load(paths.ema(), &plain)?;
            let optim = optim
                .load(paths.optim())
                .map_err(|e| TrainError::input(anyhow!("cannot resume from {}: {e}", paths.optim().display())))?;
            eprintln!("resuming {} at step {} (seed {})", state.stage, state.step, state.seed);
            (net, ema, optim, state)
        } else if let Some(path) = &args.init_from {
            let load =
                |dev: &Device| load_model_file(path, dev).map_err(|e| TrainError::input(anyhow!("--init-from: {e}")));
            let shipped = load(&plain)?;
            let m = &shipped.manifest;
            if m.stage != args.stage || m.architecture != spec.config || m.context != spec.context {
                return Err(TrainError::input(anyhow!(
                    "--init-from {}: a `{}` model of another architecture cannot continue as stage `{}`",
                    path.display(),
                    m.stage,
                    args.stage
                )));
            }
            let t = &m.training;
            let state = CheckpointState {
                stage: args.stage.clone(),
                step: t.steps,
                seed: t.seed,
                batch: t.batch,
                crop: t.crop,
                lr: t.learning_rate,
                lr_ref_steps: if t.lr_ref_steps > 0 { t.lr_ref_steps } else { args.lr_ref_steps },
                ema: t.ema_beta,
                config: m.architecture.clone(),
                normalisation: m.normalisation.clone(),
                wall_seconds: t.wall_seconds,
                losses: Vec::new(),
                validation: Vec::new(),
                continues: Some((m.recreate.clone(), path.clone())),
                noise: NoiseDistribution { p_mean: args.p_mean, p_std: args.p_std },
            };
            eprintln!(
                "continuing {} from {} at step {} (seed {})",
                state.stage,
                path.display(),
                state.step,
                state.seed
            );
            let net = load(&device)?.net;
            (net, shipped.net, optim, state)
        } else {
            let normalisation = train.normalisation(args.crop, spec.config.sigma_data);
            let net = UNet::new(&spec.config, seed, &device);
            let ema = UNet::new(&spec.config, seed, &plain);
            let state = CheckpointState {
                stage: args.stage.clone(),
                step: 0,
                seed,
                batch: args.batch,
                crop: args.crop,
                lr: args.lr,
                lr_ref_steps: args.lr_ref_steps,
                ema: args.ema,
                config: spec.config.clone(),
                normalisation,
                wall_seconds: 0.0,
                losses: Vec::new(),
                validation: Vec::new(),
                continues: None,
                noise: NoiseDistribution { p_mean: args.p_mean, p_std: args.p_std },
            };
            (net, ema, optim, state)
        };
        let noise = state.noise;
        let mut t =
            Trainer { args: args.clone(), spec, device, plain, net, ema, optim, state, train, heldout, noise, paths };
        // A resumed run keeps its batch, crop and schedule: they define which samples each
        // step sees, and changing them would silently make it a different run.
        t.args.batch = t.state.batch;
        t.args.crop = t.state.crop;
        t.args.lr = t.state.lr;
        t.args.lr_ref_steps = t.state.lr_ref_steps;
        t.args.ema = t.state.ema;
        Ok(t)
    }

    fn learning_rate(&self, step: u64) -> f64 {
        let r = (step as f64 / self.state.lr_ref_steps.max(1) as f64).max(1.0);
        self.state.lr as f64 / r.sqrt()
    }

    fn tensor4(&self, v: &[f32], b: usize, c: usize, s: usize, dev: &Device) -> Tensor<4> {
        Tensor::from_data(TensorData::new(v.to_vec(), [b, c, s, s]), dev)
    }

    /// One optimiser step; returns the loss.
    fn step(&mut self, batch: &Batch) -> f32 {
        let (b, s) = (batch.size, batch.crop);
        let dev = self.device.clone();
        let clean = self.tensor4(&batch.clean, b, 1, s, &dev);
        let noise = self.tensor4(&batch.noise, b, 1, s, &dev);
        let cond = self.tensor4(&batch.cond, b, 1, s, &dev);
        let vector = Tensor::<2>::from_data(TensorData::new(batch.vector.clone(), [b, 2]), &dev);
        let loss = edm_loss(&self.net, clean, noise, &batch.sigma, Some(cond), Some(vector));
        let value = loss.clone().inner().into_data().try_into_vec::<f32>().map(|v| v[0]).unwrap_or(f32::NAN);
        let grads = GradientsParams::from_grads(loss.backward(), &self.net);
        let lr = self.learning_rate(self.state.step);
        self.net = force_normalize(self.optim.step(lr, self.net.clone(), grads));
        // Warm-up of the EMA (as in many diffusion codebases): early on, average over the
        // steps taken so far rather than over mostly-random initial weights.
        let t = self.state.step as f32;
        let beta = self.state.ema.min((1.0 + t) / (10.0 + t));
        self.ema = ema::blend(self.ema.clone(), &self.net, beta);
        self.state.step += 1;
        value
    }

    /// Validation loss of the EMA network on a fixed held-out batch at fixed noise levels.
    fn validate(&self, batch: &Batch) -> f32 {
        let (b, s) = (batch.size, batch.crop);
        let dev = &self.plain;
        let loss = edm_loss(
            &self.ema,
            self.tensor4(&batch.clean, b, 1, s, dev),
            self.tensor4(&batch.noise, b, 1, s, dev),
            &batch.sigma,
            Some(self.tensor4(&batch.cond, b, 1, s, dev)),
            Some(Tensor::from_data(TensorData::new(batch.vector.clone(), [b, 2]), dev)),
        );
        loss.into_data().try_into_vec::<f32>().map(|v| v[0]).unwrap_or(f32::NAN)
    }

    pub(super) fn run(&mut self, stop: &AtomicBool) -> anyhow::Result<()> {
        let started = Instant::now();
        let wall_before = self.state.wall_seconds;
        let params = self.net.parameters();
        let macs = self.net.macs_per_pixel();
        eprintln!(
            "training {}: {} parameters, {:.0} kMAC/pixel ({:.2} GFLOP per {}² sample forward), {} train / {} held-out tiles",
            self.args.stage,
            params,
            macs / 1e3,
            2.0 * macs * (self.args.crop * self.args.crop) as f64 / 1e9,
            self.args.crop,
            self.train.tiles.len(),
            self.heldout.tiles.len()
        );
        let n = &self.state.normalisation;
        eprintln!(
            "normalisation: target_scale {:.3}, cond {:.2}±{:.2}, relief ln-std {:.2}±{:.2}; step {} of {}, batch {}, seed {}",
            n.target_scale,
            n.cond_mean,
            n.cond_scale,
            n.relief_mean,
            n.relief_std,
            self.state.step,
            self.args.steps,
            self.args.batch,
            self.state.seed
        );
        // Fixed validation noise levels spread over the training distribution.
        let mut val_batch = self.heldout.fixed_batch(16, self.args.crop, &self.state.normalisation, &self.noise);
        val_batch.sigma = (0..16).map(|i| (-2.4 + 4.8 * i as f32 / 15.0).exp()).collect();
        let preview_batch = self.heldout.fixed_batch(4, self.args.crop, &self.state.normalisation, &self.noise);

        let (mut interval_loss, mut interval_n, mut interval_start) = (0f64, 0u64, Instant::now());
        let start_step = self.state.step;
        while self.state.step < self.args.steps {
            let batch = self.train.batch(
                self.state.seed,
                self.state.step,
                self.args.batch,
                self.args.crop,
                &self.state.normalisation,
                &self.noise,
            );
            let loss = self.step(&batch);
            if !loss.is_finite() {
                self.checkpoint(wall_before + started.elapsed().as_secs_f64())?;
                bail!("loss became {loss} at step {}: lower --lr and resume", self.state.step);
            }
            interval_loss += loss as f64;
            interval_n += 1;
            let step = self.state.step;
            let timed_out = self.args.minutes.is_some_and(|m| started.elapsed().as_secs_f64() >= m * 60.0);
            let done = step >= self.args.steps || stop.load(Ordering::SeqCst) || timed_out;
            if step % self.args.log_every == 0 || done {
                let secs = interval_start.elapsed().as_secs_f64().max(1e-9);
                let rate = (interval_n as usize * self.args.batch) as f64 / secs;
                let mean = (interval_loss / interval_n.max(1) as f64) as f32;
                self.state.losses.push((step, mean));
                let elapsed = started.elapsed().as_secs_f64();
                let per_step = elapsed / (step - start_step).max(1) as f64;
                let eta = per_step * (self.args.steps - step) as f64;
                println!(
                    "step {step}/{}  loss {mean:.4}  {rate:.1} samples/s  lr {:.2e}  elapsed {}  eta {}",
                    self.args.steps,
                    self.learning_rate(step),
                    hms(elapsed),
                    hms(eta)
                );
                (interval_loss, interval_n, interval_start) = (0.0, 0, Instant::now());
            }
            if step % self.args.preview_every == 0 || done {
                let v = self.validate(&val_batch);
                self.state.validation.push((step, v));
                let png = self.paths.dir.join(format!("samples_{step:06}.png"));
                preview::write(&png, &self.ema, &preview_batch, &self.state.normalisation, &self.plain)
                    .with_context(|| format!("writing {}", png.display()))?;
                println!("step {step}: validation loss {v:.4} (EMA), samples in {}", png.display());
            }
            if step % self.args.checkpoint_every == 0 || done {
                self.checkpoint(wall_before + started.elapsed().as_secs_f64())?;
            }
            if done {
                break;
            }
        }
        self.state.wall_seconds = wall_before + started.elapsed().as_secs_f64();
        self.ship()
    }
}

/// Seconds as h:mm:ss.
fn hms(secs: f64) -> String {
    let s = if secs.is_finite() { secs.max(0.0) as u64 } else { 0 };
    format!("{}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60)
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
