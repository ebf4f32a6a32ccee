//! Shipping a trained stage: the EMA weights and their manifest (resolution, context, relief
//! hint, training record, data checksums and the command that recreates them) to
//! `<out>/<stage>.safetensors` + `<out>/<stage>.json`.

use std::path::Path;

use infiniterra_terrain::model::{
    save_model, DataChecksum, ModelManifest, NoiseDistribution, Precision, TrainingRecord,
};

use super::trainer::Trainer;

impl Trainer {
    /// Writes the EMA weights and manifest to `<out>/<stage>.*`.
    pub(super) fn ship(&self) -> anyhow::Result<()> {
        let mut manifest = ModelManifest::new(&self.args.stage, self.state.config.clone(), self.spec.sampler.clone());
        manifest.metres_per_pixel = self.spec.metres_per_pixel;
        manifest.window = self.spec.window;
        manifest.stride = self.spec.stride;
        manifest.context = self.spec.context;
        manifest.context_projection = self.spec.projection.clone();
        manifest.normalisation = self.state.normalisation.clone();
        manifest.relief_hint =
            self.train.relief_hint(self.state.crop, &self.state.normalisation, self.args.hint_features());
        manifest.training = TrainingRecord {
            steps: self.state.step,
            batch: self.state.batch,
            crop: self.state.crop,
            seed: self.state.seed,
            learning_rate: self.state.lr,
            ema_beta: self.state.ema,
            lr_ref_steps: self.state.lr_ref_steps,
            noise: (self.state.noise != NoiseDistribution::default()).then_some(self.state.noise),
            final_loss: self.state.losses.last().map_or(f32::NAN, |l| l.1),
            wall_seconds: self.state.wall_seconds,
        };
        // Paths relative to the working directory when they lie below it, so the manifest
        // reads the same on every checkout.
        let cwd = std::env::current_dir().unwrap_or_default();
        manifest.data = self
            .train
            .checksums
            .iter()
            .chain(&self.heldout.checksums)
            .map(|c| {
                let file = Path::new(&c.file).strip_prefix(&cwd).map_or(c.file.clone(), |p| p.display().to_string());
                DataChecksum { file, sha256: c.sha256.clone() }
            })
            .collect();
        // The command that reproduces these exact weights (a --minutes run stops at a
        // machine-dependent step; this names the step it reached).
        let s = &self.state;
        let this_run = format!(
            "infiniterra train {}{}{} --steps {} --seed {} --batch {} --crop {} --lr {} --lr-ref-steps {} --ema {}{} --precision {}",
            s.stage,
            // A guide is the half-width network in its own folder (`models/guide/`).
            if self.args.half_width { format!(" --half-width --out {}", self.args.out.display()) } else { String::new() },
            s.continues.as_ref().map_or(String::new(), |(_, from)| format!(" --init-from {}", from.display())),
            s.step,
            s.seed,
            s.batch,
            s.crop,
            s.lr,
            s.lr_ref_steps,
            s.ema,
            if s.noise == NoiseDistribution::default() {
                String::new()
            } else {
                format!(" --p-mean {} --p-std {}", s.noise.p_mean, s.noise.p_std)
            },
            match self.args.precision {
                Precision::F16 => "f16",
                Precision::F32 => "f32",
            }
        );
        // A continued run is reproduced by the commands that made its starting point, then
        // this one (which reads the manifest the earlier ones wrote).
        manifest.recreate = match &s.continues {
            Some((before, _)) if !before.is_empty() => format!("{before} && {this_run}"),
            _ => this_run,
        };
        if let Some(&(_, v)) = self.state.validation.last() {
            manifest.realism.insert("validation_edm_loss".into(), v as f64);
        }
        let written = save_model(&self.args.out, &self.ema, manifest, self.args.precision)?;
        println!(
            "wrote {} ({} bytes, {} parameters, {} steps) and {}",
            self.args.out.join(&written.weights).display(),
            written.weights_bytes,
            written.parameters,
            written.training.steps,
            self.args.out.join(format!("{}.json", written.stage)).display()
        );
        Ok(())
    }
}
