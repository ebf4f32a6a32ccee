//! The relief comparison: hillshades of generated mountains, hills and plains beside real
//! elevation tiles of the same kind, at the same metres per pixel and the same ground extent,
//! under the same sun and vertical exaggeration — so a reader judges the relief itself, not
//! the drawing.
//!
//! Both sides are picked by the same measure, the standard deviation of elevation over a
//! window: the highest of the land windows stands for mountains, the median for hills, the
//! lowest for plains. Generated windows tile a searched area of the world (measured on the
//! model grid, drawn from the block columns, one block per pixel); real ones are the tiles of
//! a prepared set, resampled bilinearly to the block size when their pixels differ.

use std::path::Path;

use image::{imageops, Rgb, RgbImage};

use super::eval::Reference;
use crate::draw;
use crate::render::{panel, ramp, shade, RenderError};
use crate::terrain::metrics::Raster;
use crate::terrain::pipeline::BLOCKS_PER_MODEL_PIXEL;
use crate::terrain::tile::div_floor;
use crate::terrain::{Pipeline, Rect};

/// The area of the world searched for generated windows (block coordinates, x east, z south).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CompareRequest {
    /// Block x of the area's west edge.
    pub x0: i64,
    /// Block z of the area's north edge.
    pub z0: i64,
    /// Width in blocks.
    pub width: i64,
    /// Height in blocks.
    pub height: i64,
}

/// A window (or tile) counts as land when at least this share of it is above the sea: the
/// comparison is about the relief of land, and real tiles are land.
const LAND_SHARE: f64 = 0.95;

/// Panels are magnified (nearest neighbour) to at least this width so their titles fit.
const MIN_PANEL_PX: u32 = 420;

/// The three kinds of relief, in the figure's row order, and where each sits in a list sorted
/// by relief (0 lowest, 1 highest).
const KINDS: [(&str, f64); 3] =
    [("mountains (highest sd)", 1.0), ("hills (median sd)", 0.5), ("plains (lowest sd)", 0.0)];

/// A generated window: its north-west block, its sd of elevation (m) and share of land.
#[derive(Clone, Copy, Debug)]
struct Window {
    x: i64,
    z: i64,
    sd: f64,
    land: f64,
}

/// Draws the comparison of generated windows in `req`'s area with the tiles of the prepared
/// set `real` (`heldout.npy` and `train.npy` with their sidecars); `progress(done, total)`
/// counts steps.
pub fn render_relief_comparison(
    pipeline: &Pipeline,
    real: &Path,
    req: &CompareRequest,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<RgbImage, RenderError> {
    let block_m = pipeline.block_metres();
    let reference = Reference::load(real).map_err(|e| RenderError::Real(e.to_string()))?;
    let real_m = reference.metres();
    let set = real.file_name().map_or_else(|| real.display().to_string(), |n| n.to_string_lossy().into_owned());

    // Real tiles at the block size, cut square.
    let mut tiles = Vec::new();
    for (split, map) in [("heldout", Some(&reference.heldout)), ("train", reference.train.as_ref())] {
        for (i, piece) in map.into_iter().flat_map(|m| m.pieces()).enumerate() {
            tiles.push((format!("{set} {split} tile {i}"), piece));
        }
    }
    let resampled = (real_m - block_m).abs() > 1e-6 * block_m;
    let tiles: Vec<(String, Raster)> = tiles
        .into_iter()
        .filter(|(_, t)| t.data.iter().all(|v| v.is_finite()))
        .map(|(label, t)| (label, if resampled { t.resample(block_m) } else { t }))
        .map(|(label, t)| {
            let n = t.rows.min(t.cols);
            (label, t.crop(0, 0, n, n))
        })
        .filter(|(_, t)| t.rows >= 3)
        .collect();
    let n = tiles.iter().map(|(_, t)| t.rows).min().ok_or_else(|| {
        RenderError::NoWindows(format!("{}: no tile without missing values to compare with", real.display()))
    })?;
    let real_picks = pick(tiles.into_iter().map(|(label, t)| (label, t.crop(0, 0, n, n))).collect());

    // Generated windows of the same extent: n blocks.
    let windows = measure_windows(pipeline, req, n as i64, progress)?;
    let generated: Vec<(String, Raster)> = pick_candidates(windows)
        .into_iter()
        .map(|(label, (x, z))| {
            let tile = pipeline.elevation_columns(Rect::new(z, x, n as i64, n as i64));
            (label, Raster::new(n, n, block_m, tile.channel(0).to_vec()))
        })
        .collect();

    let exaggeration = shade::exaggeration(block_m);
    let extent = n as f64 * block_m;
    let header = [
        format!(
            "Relief on foot: generated terrain (left, seed {}, {} m per block) beside real elevation (right, {set})",
            pipeline.seed(),
            block_m
        ),
        format!(
            "each panel {} px = {:.2} km square at {} m/px, one block per pixel; same sun (north-west, 45°), same \
             vertical exaggeration ×{:.2}",
            n,
            extent / 1000.0,
            block_m,
            exaggeration
        ),
        format!(
            "picked by the standard deviation (sd) of elevation over the window: land windows of x {}..{}, z {}..{} \
             and the set's land tiles",
            req.x0,
            req.x0 + req.width,
            req.z0,
            req.z0 + req.height
        ),
    ];
    let real_note = if resampled {
        format!("{real_m} m/px resampled (bilinear) to {block_m} m/px")
    } else {
        format!("{real_m} m/px, native")
    };
    let mut rows = Vec::new();
    for (k, (kind, _)) in KINDS.iter().enumerate() {
        let (glabel, g) = &generated[k];
        let (rlabel, r) = &real_picks[k];
        rows.push([
            Panel {
                title: [format!("generated {kind}"), format!("{glabel}, {block_m} m/px"), stats_line(g)],
                image: hillshade(g, exaggeration),
            },
            Panel {
                title: [format!("real {kind}"), format!("{rlabel}, {real_note}"), stats_line(r)],
                image: hillshade(r, exaggeration),
            },
        ]);
    }
    Ok(layout(&header, rows))
}

/// sd and range of a panel's elevations, and its extent.
fn stats_line(r: &Raster) -> String {
    let (_, sd) = r.mean_std();
    let (lo, hi) = r.data.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    format!(
        "{:.2} km across; relief {:.0} m ({:.0}..{:.0} m), sd {:.0} m",
        r.cols as f64 * r.metres / 1000.0,
        hi - lo,
        lo,
        hi,
        sd
    )
}

/// Measures every whole `n`-block window tiling the area (from its north-west corner) on the
/// model grid; returns where each lies with its sd and share of land.
fn measure_windows(
    pipeline: &Pipeline,
    req: &CompareRequest,
    n: i64,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<Vec<Window>, RenderError> {
    if req.width <= 0 || req.height <= 0 {
        return Err(RenderError::BadSize { width: req.width, height: req.height });
    }
    let (cols, rows) = (req.width / n, req.height / n);
    if cols == 0 || rows == 0 {
        return Err(RenderError::NoWindows(format!(
            "the area {}x{} blocks holds no window of {n}x{n} blocks (the real tiles' extent): search a larger area",
            req.width, req.height
        )));
    }
    let m = BLOCKS_PER_MODEL_PIXEL;
    let mut out = Vec::new();
    for wr in 0..rows {
        let z = req.z0 + wr * n;
        // One model query per row of windows.
        let (my0, my1) = (div_floor(z, m), div_floor(z + n - 1, m) + 1);
        let (mx0, mx1) = (div_floor(req.x0, m), div_floor(req.x0 + cols * n - 1, m) + 1);
        let tile = pipeline.elevation(Rect::new(my0, mx0, my1 - my0, mx1 - mx0));
        for wc in 0..cols {
            let x = req.x0 + wc * n;
            let (ax, bx) = (div_floor(x, m), div_floor(x + n - 1, m) + 1);
            let values: Vec<f32> = (my0..my1)
                .flat_map(|my| (ax..bx).map(move |mx| (my, mx)))
                .map(|(my, mx)| tile.get(0, my, mx))
                .collect();
            let land = values.iter().filter(|&&v| v > 0.0).count() as f64 / values.len() as f64;
            out.push(Window { x, z, sd: sd(&values), land });
        }
        progress(wr as u64 + 1, rows as u64);
    }
    Ok(out)
}

fn sd(values: &[f32]) -> f64 {
    let n = values.len().max(1) as f64;
    let mean = values.iter().map(|&v| v as f64).sum::<f64>() / n;
    (values.iter().map(|&v| (v as f64 - mean).powi(2)).sum::<f64>() / n).sqrt()
}

/// The generated windows for the three kinds, among land windows (all windows when none is
/// land), labelled with their coordinates.
fn pick_candidates(windows: Vec<Window>) -> Vec<(String, (i64, i64))> {
    let land: Vec<Window> = windows.iter().filter(|w| w.land >= LAND_SHARE).copied().collect();
    let mut ranked = if land.is_empty() { windows } else { land };
    ranked.sort_by(|a, b| a.sd.total_cmp(&b.sd));
    KINDS
        .iter()
        .map(|&(_, at)| {
            let w = ranked[rank(ranked.len(), at)];
            (format!("x {}, z {}", w.x, w.z), (w.x, w.z))
        })
        .collect()
}

/// The real tiles for the three kinds, by the same rule as [`pick_candidates`].
fn pick(tiles: Vec<(String, Raster)>) -> Vec<(String, Raster)> {
    let land_share = |r: &Raster| r.data.iter().filter(|&&v| v > 0.0).count() as f64 / r.len().max(1) as f64;
    let any_land = tiles.iter().any(|(_, t)| land_share(t) >= LAND_SHARE);
    let mut ranked: Vec<(f64, String, Raster)> = tiles
        .into_iter()
        .filter(|(_, t)| !any_land || land_share(t) >= LAND_SHARE)
        .map(|(label, t)| (t.mean_std().1, label, t))
        .collect();
    ranked.sort_by(|a, b| a.0.total_cmp(&b.0));
    KINDS
        .iter()
        .map(|&(_, at)| {
            let (_, label, t) = &ranked[rank(ranked.len(), at)];
            (label.clone(), t.clone())
        })
        .collect()
}

/// Index of the element at fraction `at` (0 first, 0.5 median, 1 last) of `len` sorted ones.
fn rank(len: usize, at: f64) -> usize {
    ((len.saturating_sub(1)) as f64 * at).round() as usize
}

/// Land base colour under the hillshade, and the sea's.
const LAND: [f32; 3] = [236.0, 232.0, 222.0];
const SEA: [f32; 3] = [168.0, 196.0, 226.0];

/// Grey hillshade of `r`, one pixel per raster pixel: the map renderer's sun and shading.
fn hillshade(r: &Raster, exaggeration: f32) -> RgbImage {
    let (rows, cols) = (r.rows as i64, r.cols as i64);
    let at = |y: i64, x: i64| r.at(y.clamp(0, rows - 1) as usize, x.clamp(0, cols - 1) as usize);
    RgbImage::from_fn(r.cols as u32, r.rows as u32, |x, y| {
        let (x, y) = (x as i64, y as i64);
        let light =
            shade::illumination(at(y, x - 1), at(y, x + 1), at(y - 1, x), at(y + 1, x), r.metres as f32, exaggeration);
        let (base, strength) = if at(y, x) < 0.0 { (SEA, 0.3) } else { (LAND, 1.0) };
        ramp::to_rgb(shade::apply(base, light, strength))
    })
}

/// One panel of the figure: its title lines and its picture.
struct Panel {
    title: [String; 3],
    image: RgbImage,
}

const INK: Rgb<u8> = Rgb([24, 24, 24]);

/// The header lines above rows of (generated, real) panels, panels magnified to be legible.
fn layout(header: &[String], rows: Vec<[Panel; 2]>) -> RgbImage {
    let side = rows.iter().flat_map(|r| r.iter()).map(|p| p.image.width()).max().unwrap_or(1).max(1);
    let mag = MIN_PANEL_PX.div_ceil(side).max(1);
    let panel_px = side * mag;
    let header_width = header.iter().map(|h| draw::width(h, 1)).max().unwrap_or(0);
    let scale = 1;
    let margin = 12;
    let line = draw::GLYPH + 4;
    let width = (2 * panel_px + 3 * margin).max(header_width + 2 * margin);
    let block = 3 * line + 4 + panel_px + margin;
    let top = margin + header.len() as u32 * line + margin;
    let height = top + rows.len() as u32 * block;
    let mut img = RgbImage::from_pixel(width, height, panel::BACKGROUND);
    for (i, h) in header.iter().enumerate() {
        draw::text(&mut img, margin as i64, (margin + i as u32 * line) as i64, h, scale, INK);
    }
    for (r, row) in rows.iter().enumerate() {
        let y0 = top + r as u32 * block;
        for (c, p) in row.iter().enumerate() {
            let x0 = margin + c as u32 * (panel_px + margin);
            for (i, t) in p.title.iter().enumerate() {
                draw::text(&mut img, x0 as i64, (y0 + i as u32 * line) as i64, t, scale, INK);
            }
            let big = imageops::resize(&p.image, p.image.width() * mag, p.image.height() * mag, imageops::Nearest);
            let y = y0 + 3 * line + 4;
            imageops::replace(&mut img, &big, x0 as i64, y as i64);
            draw::outline(&mut img, x0 as i64 - 1, y as i64 - 1, big.width() as i64 + 2, big.height() as i64 + 2, INK);
        }
    }
    img
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::npy::write_npy_f32;

    /// A prepared set of `count` `t`×`t` tiles per split at `metres` per pixel in `dir`:
    /// tile `i` is a ridge pattern of amplitude `100·(i+1)` m on 500 m of land.
    fn synthetic_set(dir: &Path, t: usize, count: usize, metres: f64) {
        std::fs::create_dir_all(dir).unwrap();
        for split in ["heldout", "train"] {
            let mut data = Vec::new();
            for i in 0..count {
                for y in 0..t {
                    for x in 0..t {
                        let phase = (x as f32 * 0.4).sin() * (y as f32 * 0.3).cos();
                        data.push(500.0 + 100.0 * (i + 1) as f32 * phase);
                    }
                }
            }
            write_npy_f32(&dir.join(format!("{split}.npy")), (count * t, t), &data).unwrap();
            let side = serde_json::json!({ "metres_per_pixel": metres, "tile": t, "count": count });
            std::fs::write(dir.join(format!("{split}.json")), side.to_string()).unwrap();
        }
    }

    fn pipeline() -> Pipeline {
        let config = crate::config::Config::default();
        Pipeline::new(5, &config.terrain())
    }

    #[test]
    fn the_figure_renders_from_a_synthetic_set_and_picks_by_relief() {
        let dir = tempfile::tempdir().unwrap();
        let set = dir.path().join("synthetic-60m");
        // 32 px of 60 m = 1920 m = 48 blocks of 40 m.
        synthetic_set(&set, 32, 4, 60.0);
        let p = pipeline();
        let req = CompareRequest { x0: -96, z0: -96, width: 192, height: 192 };
        let mut steps = 0;
        let img = render_relief_comparison(&p, &set, &req, &mut |d, _| steps = d).unwrap();
        assert_eq!(steps, 192 / (32.0 * 60.0 / p.block_metres()).floor() as u64);
        assert!(img.width() >= 2 * MIN_PANEL_PX && img.height() > 3 * MIN_PANEL_PX);
        // Not blank: lit and shaded slopes in the panels.
        let dark = img.pixels().filter(|p| p[0] < 180 && p[0] > 40).count();
        assert!(dark > 1000, "{dark} shaded pixels");

        // The real picks: the highest-sd tile for mountains, the lowest for plains.
        let reference = Reference::load(&set).unwrap();
        let tiles: Vec<_> =
            reference.heldout.pieces().into_iter().enumerate().map(|(i, t)| (format!("h{i}"), t)).collect();
        let picked = pick(tiles);
        assert_eq!((picked[0].0.as_str(), picked[2].0.as_str()), ("h3", "h0"));
    }

    #[test]
    fn deterministic() {
        let dir = tempfile::tempdir().unwrap();
        synthetic_set(dir.path(), 16, 3, 40.0);
        let p = pipeline();
        let req = CompareRequest { x0: 0, z0: 0, width: 64, height: 32 };
        let a = render_relief_comparison(&p, dir.path(), &req, &mut |_, _| {}).unwrap();
        let b = render_relief_comparison(&p, dir.path(), &req, &mut |_, _| {}).unwrap();
        assert!(a == b);
    }

    #[test]
    fn errors_name_the_missing_or_malformed_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = pipeline();
        let req = CompareRequest { x0: 0, z0: 0, width: 256, height: 256 };
        let missing = dir.path().join("nowhere");
        let err = render_relief_comparison(&p, &missing, &req, &mut |_, _| {}).unwrap_err().to_string();
        assert!(err.contains("nowhere"), "{err}");

        let set = dir.path().join("broken");
        synthetic_set(&set, 16, 2, 40.0);
        std::fs::write(set.join("train.npy"), b"not an array").unwrap();
        let err = render_relief_comparison(&p, &set, &req, &mut |_, _| {}).unwrap_err().to_string();
        assert!(err.contains("train.npy"), "{err}");

        std::fs::write(set.join("heldout.json"), b"{").unwrap();
        let err = render_relief_comparison(&p, &set, &req, &mut |_, _| {}).unwrap_err().to_string();
        assert!(err.contains("heldout.json"), "{err}");
    }

    #[test]
    fn an_area_smaller_than_a_window_says_so() {
        let dir = tempfile::tempdir().unwrap();
        synthetic_set(dir.path(), 32, 2, 40.0);
        let req = CompareRequest { x0: 0, z0: 0, width: 16, height: 64 };
        let err = render_relief_comparison(&pipeline(), dir.path(), &req, &mut |_, _| {}).unwrap_err();
        assert!(matches!(err, RenderError::NoWindows(_)), "{err}");
    }
}
