//! Calibrating a stage's spectral equaliser on training tiles.
//!
//! The shipped model (its relief hint, response curve and depression infill as they are, its
//! old equaliser off) generates counterparts of real **training** tiles; the mean radial
//! power spectra of the real and the generated tiles give, per wavelength, the amplitude gain
//! √(real / generated) that [`SpectralEqualiser`] applies. A pass with the equaliser on
//! measures what the kernel left and refines the gains; a last pass shows the result. Run it
//! after the response curve (the curve sets how much relief each window gets, the equaliser
//! only how it is shared out over wavelengths), and again after `--calibrate-infill`: the
//! infill follows the equaliser in each window, and what is measured is the final output.

use std::time::Instant;

use anyhow::anyhow;
use infiniterra_terrain::metrics::{fit_beta, radial_power_spectrum, Raster, Spectrum};
use infiniterra_terrain::model::burn::tensor::Device;
use infiniterra_terrain::model::equaliser::band_gain;
use infiniterra_terrain::model::{LoadedModel, SpectralEqualiser};

use super::calibrate::{raster as real_raster, spread};
use super::data::EncodedTile;
use super::heldout::counterpart;
use super::shipped::{Calibration, Shipped};

/// Kernel radius, pixels: reaches the 32-pixel wavelengths the core falls short at (a
/// quarter of the tile, the longest the realism bar's spectral fit uses) for 49² multiply-adds
/// per pixel, well under 1 % of the four network calls'.
pub const RADIUS: usize = 24;
/// Generation passes with the equaliser on: all but the last refine the gains, the last
/// shows the result.
pub const PASSES: usize = 2;
/// Knot wavelengths, pixels: half-octave steps over the rings the realism bar fits (a
/// quarter of a 256-pixel tile down to 4 pixels) and on to the finest ring, 2 pixels. The first knot,
/// the longest, keeps gain 1 (the context decides those scales).
pub const KNOTS: [f64; 11] = [64.0, 45.25, 32.0, 22.63, 16.0, 11.31, 8.0, 5.66, 4.0, 2.83, 2.0];

fn raster(size: usize, metres: f64, values: Vec<f32>) -> Raster {
    Raster::new(size, size, metres, values)
}

/// The mean spectrum of `model`'s counterparts of `tiles` (seeds `seed`, `seed + 1`, …), with
/// a progress line (`what`, tiles done, rate, ETA) on stderr.
fn generated_spectrum(
    model: &LoadedModel,
    device: &Device,
    tiles: &[&EncodedTile],
    seed: u64,
    what: &str,
) -> Option<Spectrum> {
    let metres = model.manifest.metres_per_pixel;
    let started = Instant::now();
    let spectra: Vec<Spectrum> = tiles
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let generated = counterpart(model, device, &t.h, t.size, seed + i as u64).0;
            let secs = started.elapsed().as_secs_f64();
            let left = (tiles.len() - i - 1) as f64 * secs / (i + 1) as f64;
            eprint!(
                "\r  {what}: tile {}/{} ({:.2} tiles/s, ETA {left:.0} s)   ",
                i + 1,
                tiles.len(),
                (i + 1) as f64 / secs
            );
            radial_power_spectrum(&raster(t.size, metres, generated))
        })
        .collect();
    eprintln!();
    Spectrum::mean(&spectra)
}

/// Amplitude ratio generated / real at each knot wavelength, for the log.
fn ratios(real: &Spectrum, generated: &Spectrum, metres: f64) -> String {
    KNOTS
        .iter()
        .map(|&l| {
            let ratio = band_gain(generated, real, metres, l).unwrap_or(f64::NAN);
            format!("{:.0} km ×{ratio:.2}", l * metres / 1000.0)
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// Measures `<models>/<stage>.json` on the job's training tiles and writes its
/// `spectral_equaliser` into the manifest.
pub fn run(job: &Calibration) -> anyhow::Result<()> {
    let shipped = Shipped::for_calibration(job)?;
    let train = shipped.tiles("train")?;
    let Shipped { mut model, device, path, folder } = shipped;
    let (stage, seed, count) = (job.stage, job.seed, job.tiles);
    model.manifest.spectral_equaliser = None;
    let tiles = spread(&train.tiles, count.clamp(1, train.tiles.len().max(1)), 0.0);
    let metres = model.manifest.metres_per_pixel;
    let real: Vec<Spectrum> = tiles.iter().map(|t| radial_power_spectrum(&real_raster(t, metres))).collect();
    let real = Spectrum::mean(&real).ok_or_else(|| anyhow!("{}: no training tiles of one size", folder.display()))?;
    let started = Instant::now();
    let before = generated_spectrum(&model, &device, &tiles, seed, "without an equaliser")
        .ok_or_else(|| anyhow!("no counterparts"))?;
    eprintln!(
        "calibrate {stage}: {} training tiles generated without an equaliser ({:.0} s): β {:.3} (real {:.3}); generated/real amplitude {}",
        tiles.len(),
        started.elapsed().as_secs_f64(),
        fit_beta(&before),
        fit_beta(&real),
        ratios(&real, &before, metres)
    );
    let mut eq = SpectralEqualiser::from_spectra(&real, &before, metres, RADIUS, &KNOTS)
        .ok_or_else(|| anyhow!("{}: tiles too small for the {}-pixel knots", folder.display(), KNOTS[0]))?;
    // The kernel's radius smooths the gain curve (by about a quarter octave at 32 pixels), so
    // one pass undershoots the narrow 16–32 km dip; a second pass multiplies in what is left.
    for pass in 1..=PASSES {
        eq.validate(model.manifest.window)
            .map_err(|e| anyhow!("the measured gains are out of range ({e}): is this model trained?"))?;
        model.manifest.spectral_equaliser = Some(eq.clone());
        let after = generated_spectrum(&model, &device, &tiles, seed, &format!("pass {pass}/{PASSES}"))
            .ok_or_else(|| anyhow!("no counterparts"))?;
        eprintln!(
            "calibrate {stage}: pass {pass}/{PASSES} with the equaliser ({:.0} s): β {:.3} (real {:.3}); generated/real amplitude {}",
            started.elapsed().as_secs_f64(),
            fit_beta(&after),
            fit_beta(&real),
            ratios(&real, &after, metres)
        );
        if pass < PASSES {
            eq = eq.refined(&real, &after, metres);
        }
    }
    let shown: Vec<String> = eq.gains.iter().map(|[l, g]| format!("{:.0} km ×{g:.2}", l * metres / 1000.0)).collect();
    println!("spectral equaliser of {}: radius {RADIUS} px, gains {}", path.display(), shown.join(", "));
    crate::lab::manifest_edit::edit_manifest(&path, |object| {
        object.insert("spectral_equaliser".into(), serde_json::to_value(&eq)?);
        Ok(())
    })
}
