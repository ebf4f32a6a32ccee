//! Preview sheets written during training: for a few fixed held-out crops, the real terrain,
//! the smooth context the model is given, and samples from three sampler settings, as
//! hillshaded relief. Fixed noise makes sheets of different steps comparable.

use std::path::Path;

use infiniterra_terrain::encoding::signed_square;
use infiniterra_terrain::model::{burn, HostRng, Normalisation, Sampler, SamplerKind, UNet};

use burn::tensor::{Device, Tensor, TensorData};

use super::data::Batch;

/// Pixels per crop pixel in the sheet.
const ZOOM: usize = 2;
/// Gap between panels.
const GAP: usize = 4;

/// The sampler settings compared on each sheet.
fn samplers() -> Vec<(&'static str, Sampler)> {
    vec![
        ("shipped: dpm++2m 4", Sampler::few_step()),
        ("euler 4", Sampler::karras(SamplerKind::Euler, 4, 0.05, 80.0, 7.0)),
        ("euler 24", Sampler::karras(SamplerKind::Euler, 24, 0.02, 80.0, 7.0)),
    ]
}

/// Generated residuals (network units) for `batch` with each preview sampler.
pub fn generate(net: &UNet, batch: &Batch, device: &Device) -> Vec<Vec<f32>> {
    let (b, s) = (batch.size, batch.crop);
    let cond = Tensor::<4>::from_data(TensorData::new(batch.cond.clone(), [b, 1, s, s]), device);
    let vector = Tensor::<2>::from_data(TensorData::new(batch.vector.clone(), [b, 2]), device);
    samplers()
        .into_iter()
        .map(|(_, sampler)| {
            let mut rng = HostRng::keyed(0, 0x7368_6565, 0, 0);
            let noise: Vec<Tensor<4>> = (0..sampler.noises_needed())
                .map(|_| Tensor::from_data(TensorData::new(rng.normals(b * s * s), [b, 1, s, s]), device))
                .collect();
            let out = sampler.sample(net, &noise, Some(cond.clone()), Some(vector.clone()));
            out.into_data().try_into_vec::<f32>().unwrap_or_default()
        })
        .collect()
}

/// Writes the sheet for `batch` (rows: crops; columns: real, context, samples).
pub fn write(path: &Path, net: &UNet, batch: &Batch, norm: &Normalisation, device: &Device) -> anyhow::Result<()> {
    let (b, s) = (batch.size, batch.crop);
    let n = s * s;
    let samples = generate(net, batch, device);
    let to_metres = |residual: &[f32], low: &[f32]| -> Vec<f32> {
        residual.iter().zip(low).map(|(&r, &l)| signed_square(l + r * norm.target_scale)).collect()
    };
    let cols = 2 + samples.len();
    let panel = s * ZOOM;
    let (w, h) = (cols * panel + (cols + 1) * GAP, b * panel + (b + 1) * GAP);
    let mut img = image::RgbImage::from_pixel(w as u32, h as u32, image::Rgb([255, 255, 255]));
    for i in 0..b {
        let low = &batch.low[i * n..(i + 1) * n];
        let real = to_metres(&batch.clean[i * n..(i + 1) * n], low);
        let context: Vec<f32> = low.iter().map(|&l| signed_square(l)).collect();
        let mut panels = vec![real, context];
        panels.extend(samples.iter().map(|v| to_metres(&v[i * n..(i + 1) * n], low)));
        // One elevation range per row (from the real terrain) so panels compare directly.
        let (lo, hi) = panels[0].iter().fold((f32::MAX, f32::MIN), |(a, b), &v| (a.min(v), b.max(v)));
        for (c, p) in panels.iter().enumerate() {
            draw(&mut img, p, s, GAP + c * (panel + GAP), GAP + i * (panel + GAP), lo, hi, ZOOM);
        }
    }
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    img.save(path)?;
    Ok(())
}

/// Draws square `panels` (metres, `side`² each, one shared elevation range taken from the
/// first) side by side under a `title`, at one image pixel per grid pixel.
pub fn side_by_side(path: &Path, title: &str, panels: &[&[f32]], side: usize) -> anyhow::Result<()> {
    let top = 28;
    let (w, h) = (panels.len() * side + (panels.len() + 1) * GAP, top + side + GAP);
    let mut img = image::RgbImage::from_pixel(w as u32, h as u32, image::Rgb([255, 255, 255]));
    crate::draw::text(&mut img, GAP as i64, 8, title, 1, image::Rgb([0, 0, 0]));
    let (lo, hi) = panels[0].iter().fold((f32::MAX, f32::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    for (c, p) in panels.iter().enumerate() {
        draw(&mut img, p, side, GAP + c * (side + GAP), top, lo, hi, 1);
    }
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)?;
    }
    img.save(path)?;
    Ok(())
}

/// Draws one panel at `zoom` image pixels per grid pixel: hypsometric ramp times a hillshade
/// from the north-west.
#[allow(clippy::too_many_arguments)]
fn draw(img: &mut image::RgbImage, metres: &[f32], s: usize, x0: usize, y0: usize, lo: f32, hi: f32, zoom: usize) {
    // Pixels are ~1 km; exaggerate slopes so low relief still reads.
    let spacing = 1000.0 / 4.0;
    let at = |y: usize, x: usize| metres[y.min(s - 1) * s + x.min(s - 1)];
    for y in 0..s {
        for x in 0..s {
            let dzdx = (at(y, x + 1) - at(y, x.saturating_sub(1))) / (2.0 * spacing);
            let dzdy = (at(y + 1, x) - at(y.saturating_sub(1), x)) / (2.0 * spacing);
            let (nx, ny, nz) = (-dzdx, -dzdy, 1.0f32);
            let len = (nx * nx + ny * ny + nz * nz).sqrt();
            let shade = ((-nx - ny + nz) / (len * 3f32.sqrt())).clamp(0.0, 1.0);
            let t = ((at(y, x) - lo) / (hi - lo).max(1.0)).clamp(0.0, 1.0);
            let sea = at(y, x) < 0.0;
            let base = if sea { [70.0, 110.0, 170.0] } else { [90.0 + 120.0 * t, 120.0 + 90.0 * t, 70.0 + 150.0 * t] };
            let px = image::Rgb(base.map(|c| (c * (0.35 + 0.65 * shade)).clamp(0.0, 255.0) as u8));
            for dy in 0..zoom {
                for dx in 0..zoom {
                    img.put_pixel((x0 + x * zoom + dx) as u32, (y0 + y * zoom + dy) as u32, px);
                }
            }
        }
    }
}
