//! Real terrain: getting the reference data (`infiniterra data fetch | prepare`, which run
//! the scripts in `scripts/data/`) and measuring generated terrain against it
//! (`infiniterra eval`, metrics in docs/realism.md).
//!
//! Owns: loading heightmaps and prepared sets, the baselines (fBm matched in amplitude,
//! real-vs-real), the realism table and the report image. The metric math lives in
//! `infiniterra_terrain::metrics`. Must not touch: the pipeline (generated terrain comes in
//! as an exported `.npy`), the command line's parsing beyond [`EvalOptions`].

mod input;
mod measure;
mod places;
mod report;

use std::path::{Path, PathBuf};

use image::Rgb;

pub use input::{Heightmap, Reference};
pub use places::PlaceFloor;
pub use report::{BetaSplits, Report, Target, SLOPE_W1_KEY, SPECTRAL_SLOPE_KEY};

use crate::terrain::metrics::{fbm, slope_degrees, Raster, SeamLines, FBM_BETA};
use crate::terrain::pipeline::BASE_METRES;
use report::Column;

/// Seed of the fBm baseline: fixed, so every report compares against the same noise.
pub const FBM_SEED: u64 = 0x1FB3_5EED;

/// What `infiniterra eval` compares and where it writes.
#[derive(Debug, Clone)]
pub struct EvalOptions {
    /// Generated heightmap: float32 `.npy` with its JSON sidecar (e.g. from
    /// `infiniterra export --grid model`).
    pub generated: PathBuf,
    /// Reference: a prepared set directory (e.g. `data/prepared/core`: held-out split is the
    /// reference, training split the real-vs-real baseline) or one `.npy` with its sidecar.
    pub reference: PathBuf,
    /// Report image (slope histograms and power spectra).
    pub out: PathBuf,
    /// Window stride of the generator in 500 m pixels: seams are measured on lines this far
    /// apart (32 = the pipeline's window stride).
    pub seam_stride: usize,
    /// Model manifest (e.g. `models/core.json`) whose `realism` numbers are replaced by this
    /// report's generated values and realism bar (needs a reference with a train split).
    pub record: Option<PathBuf>,
    /// Generated tiles with less land than this fraction (above 0 m) are left out: a land-only
    /// reference (the block-scale sets) is judged against generated land, not coast and sea.
    pub min_land: f64,
}

/// Why an evaluation failed.
#[derive(Debug, thiserror::Error)]
pub enum EvalError {
    /// A missing, unreadable or inconsistent input (exit status 2).
    #[error("{0}")]
    Input(String),
    /// The report image could not be written (exit status 1).
    #[error("cannot write {path}: {source}")]
    Output {
        /// The image.
        path: PathBuf,
        /// Why.
        source: image::ImageError,
    },
}

/// The fBm baseline: one tile per generated tile, same size, with that tile's mean and
/// standard deviation (so amplitude matches tile by tile), β = [`FBM_BETA`].
fn fbm_like(tiles: &[Raster]) -> Vec<Raster> {
    tiles
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let (mean, std) = t.mean_std();
            let mut f = fbm(t.rows, t.cols, t.metres, FBM_BETA, FBM_SEED + i as u64);
            f.data.iter_mut().for_each(|v| *v = (mean + std * *v as f64) as f32);
            f
        })
        .collect()
}

/// The realism bar of `generated` against `reference`, with `floor` (other real tiles) as the
/// real-vs-real floor and fBm matched to each generated tile as the procedural baseline —
/// what `run` reports, without the table or the image (for calibrating on training tiles).
/// Seam lines are taken every `seam_stride` pixels from each tile's corner.
pub fn realism_bar(reference: &[Raster], generated: &[Raster], floor: &[Raster], seam_stride: usize) -> Vec<Target> {
    let lines = SeamLines::for_origin(seam_stride.max(2), 0, 0);
    let set = |tiles: &[Raster]| measure::measure(tiles, lines, &mut |_, _| {});
    let column =
        |label: &str, tiles: &[Raster]| Column { label: label.into(), colour: Rgb([0, 0, 0]), metrics: set(tiles) };
    let columns = [
        column("reference", reference),
        column("generated", generated),
        column("fBm", &fbm_like(generated)),
        column("train (real)", floor),
    ];
    report::targets(&columns)
}

/// Runs the evaluation: measures generated, fBm, reference and (for a prepared set) training
/// tiles, writes the image to `args.out` and returns the table. `progress(done, total)` counts tiles.
pub fn run(args: &EvalOptions, progress: &mut dyn FnMut(u64, u64)) -> Result<Report, EvalError> {
    if args.seam_stride < 2 {
        return Err(EvalError::Input(format!("--seam-stride {} is too small (at least 2)", args.seam_stride)));
    }
    let mut reference = Reference::load(&args.reference)?;
    let generated = Heightmap::load(&args.generated)?;
    if let Some(n) = generated.heldout_counterparts {
        if reference.train.is_some() && reference.first_heldout_tiles(n) {
            eprintln!(
                "{} holds counterparts of the first {n} held-out tiles: the reference is those {n}",
                args.generated.display()
            );
        }
    }
    let (metres, size) = (reference.metres(), reference.tile);
    let all_tiles = generated.tiles_at(metres, size);
    let cut = all_tiles.len();
    let gen_tiles: Vec<Raster> = all_tiles.into_iter().filter(|t| land_fraction(t) >= args.min_land).collect();
    if gen_tiles.is_empty() {
        return Err(EvalError::Input(format!(
            "{} yields no tile to measure ({cut} tiles, none with at least {} land)",
            args.generated.display(),
            args.min_land
        )));
    }
    if gen_tiles.len() < cut {
        eprintln!("{} of {cut} generated tiles have less than {} land: left out", cut - gen_tiles.len(), args.min_land);
    }
    let ref_tiles = reference.heldout.tiles_at(metres, size);
    let train_tiles = reference.train.as_ref().map(|t| t.tiles_at(metres, size)).unwrap_or_default();
    let fbm_tiles = fbm_like(&gen_tiles);

    // Seams are a property of the generator's grid: measure them at its native resolution on
    // its own window lines; the other columns show the same statistic on lines the same
    // distance apart, which is what "no seams" looks like.
    let stride_metres = args.seam_stride as f64 * BASE_METRES;
    let ref_lines = SeamLines::for_origin(((stride_metres / metres).round() as usize).max(2), 0, 0);
    let total = (gen_tiles.len() * 2 + ref_tiles.len() + train_tiles.len()) as u64;
    let mut done = 0;
    let mut set = |tiles: &[Raster]| {
        let m = measure::measure(tiles, ref_lines, &mut |d, _| progress(done + d, total));
        done += tiles.len() as u64;
        m
    };
    let mut columns = vec![
        Column { label: "reference".into(), colour: Rgb([20, 20, 20]), metrics: set(&ref_tiles) },
        Column { label: "generated".into(), colour: Rgb([210, 40, 30]), metrics: set(&gen_tiles) },
        Column { label: "fBm".into(), colour: Rgb([40, 90, 220]), metrics: set(&fbm_tiles) },
    ];
    if !train_tiles.is_empty() {
        columns.push(Column { label: "train (real)".into(), colour: Rgb([130, 130, 130]), metrics: set(&train_tiles) });
    }
    columns[1].metrics.seams = native_seams(&generated, args.seam_stride);

    let notes = notes(args, &reference, &generated, gen_tiles.len(), stride_metres);
    let regions = reference.regions.as_ref().map(|r| r.pooled());
    let caption = format!("lines every {:.0} km", stride_metres / 1000.0);
    let mut table = Report::new(notes, &columns, &caption, regions.as_deref());
    // Real places against each other (both splits: the tiles' grid says where they lie),
    // beside the bar's slope line for the generated terrain and for the training land.
    let slope_line = |bar: &[Target]| bar.iter().find(|t| t.key == SLOPE_W1_KEY).map(|t| t.value);
    if let (Some(r), Some(generated), Some(floor)) =
        (&reference.regions, slope_line(&table.targets), slope_line(&table.real_land))
    {
        let slopes: Vec<Vec<f32>> = ref_tiles.iter().chain(&train_tiles).map(slope_degrees).collect();
        table.places = places::place_floor(&slopes, &r.cells, generated, floor);
    }
    let mut panels = vec![report::slope_panel(&columns), report::spectrum_panel(&columns)];
    panels.extend(table.beta_splits.as_ref().map(report::beta_split_panel));
    let image = crate::draw::chart::draw(&table.notes, &panels);
    save(&image, &args.out)?;
    if let Some(manifest) = &args.record {
        record(manifest, &table)?;
    }
    Ok(table)
}

/// Replaces the `realism` object of the JSON manifest at `path` with the report's realism bar
/// (value, range, verdict per metric), keeping every other field as it is.
fn record(path: &Path, report: &Report) -> Result<(), EvalError> {
    if report.targets.is_empty() {
        return Err(EvalError::Input(format!(
            "--record {}: the reference has no train split, so there is no real-vs-real floor to record against",
            path.display()
        )));
    }
    let mut realism = serde_json::Map::new();
    for t in &report.targets {
        realism.insert(t.key.clone(), serde_json::json!(t.value));
        realism.insert(format!("{}_met", t.key), serde_json::json!(if t.pass { 1.0 } else { 0.0 }));
    }
    // What real land scores on the same lines, kept beside the model's numbers so a reader can
    // tell a line the model misses from one that real terrain misses too.
    let real_met = report.real_land.iter().filter(|t| t.pass).count();
    realism.insert("real_land_lines_met".into(), serde_json::json!(real_met as f64));
    if let Some(b) = &report.beta_splits {
        realism.insert("real_split_abs_delta_beta_median".into(), serde_json::json!(b.median));
        realism.insert("real_split_abs_delta_beta_p90".into(), serde_json::json!(b.p90));
        realism.insert("real_split_within_spectral_line".into(), serde_json::json!(b.within_line));
        realism.insert("real_split_farther_than_generated".into(), serde_json::json!(b.farther_than_generated));
    }
    crate::lab::manifest_edit::edit_manifest(path, |object| {
        object.insert("realism".into(), serde_json::Value::Object(realism));
        Ok(())
    })
    .map_err(|e| EvalError::Input(format!("--record: {e:#}")))
}

/// Fraction of a tile above the sea.
fn land_fraction(t: &Raster) -> f64 {
    t.data.iter().filter(|&&v| v > measure::SEA_LEVEL_M).count() as f64 / t.data.len().max(1) as f64
}

/// The generated map's seam sums on its own window lines (whole map: its origin places the
/// lines; a stack of tiles: lines from each tile's corner).
fn native_seams(generated: &Heightmap, stride_model_px: usize) -> crate::terrain::metrics::SeamStats {
    let stride = ((stride_model_px as f64 * generated.pixels_per_base_pixel).round() as usize).max(2);
    let (x0, y0) = match (generated.tile, generated.origin) {
        (None, Some(origin)) => origin,
        _ => (0, 0),
    };
    let lines = SeamLines::for_origin(stride, x0, y0);
    let mut stats = crate::terrain::metrics::SeamStats::default();
    for piece in generated.pieces() {
        stats.add(crate::terrain::metrics::seam_ratio(&piece, lines));
    }
    stats
}

fn notes(
    args: &EvalOptions,
    reference: &Reference,
    generated: &Heightmap,
    gen_tiles: usize,
    stride_m: f64,
) -> Vec<String> {
    let (metres, size) = (reference.metres(), reference.tile);
    let g = &generated.raster;
    let mut notes = vec![
        format!(
            "reference: {} ({} m/px, {size}x{size} tiles){}",
            args.reference.display(),
            metres,
            if reference.train.is_some() { "; held-out split vs train split" } else { "" }
        ),
        format!(
            "generated: {} ({}x{} px at {} m/px) -> {gen_tiles} tiles",
            args.generated.display(),
            g.rows,
            g.cols,
            g.metres
        ),
    ];
    if (g.metres - metres).abs() > 1e-6 * metres {
        notes.push(format!("  resampled bilinearly from {} m to the reference's {} m per pixel", g.metres, metres));
    }
    notes.push(format!(
        "fBm: β = {FBM_BETA}, seed {FBM_SEED:#x}, each tile matched to the generated tile's mean and std; \
         seams on lines every {:.0} km (--seam-stride {} model px)",
        stride_m / 1000.0,
        args.seam_stride
    ));
    notes
}

fn save(image: &image::RgbImage, path: &Path) -> Result<(), EvalError> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|e| EvalError::Output { path: path.to_path_buf(), source: image::ImageError::IoError(e) })?;
    }
    image.save(path).map_err(|source| EvalError::Output { path: path.to_path_buf(), source })
}

#[cfg(test)]
mod tests;
