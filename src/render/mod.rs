//! `infiniterra render`: maps of what the terrain pipeline answers, as images a person can
//! read on their own — a shaded map plus a panel with title, legend and scale bar.
//!
//! Owns: layers and their colours, sampling the pipeline for a map, the hillshade, the panel.
//! Must not touch: terrain internals (only `Pipeline::model` / `Pipeline::columns`), the
//! command line (the CLI parses flags into a [`RenderRequest`] and reports errors).

mod biomes;
mod cutaway;
mod layer;
mod oblique;
pub(crate) mod panel;
pub(crate) mod ramp;
mod sample;
pub(crate) mod shade;
mod water;

use std::path::{Path, PathBuf};

use image::{Rgb, RgbImage};

pub use biomes::render_biomes;
pub use cutaway::{render_cutaway, CutawayRequest, MAX_CUTAWAY_WIDTH};
pub use layer::{Layer, UnknownLayer};
pub use oblique::{render_oblique, ObliqueRequest, MAX_OBLIQUE_SIDE};
pub use water::render_water;

use crate::terrain::pipeline::{channel, BLOCKS_PER_MODEL_PIXEL};
use crate::terrain::tile::div_ceil;
use crate::terrain::{Pipeline, Rect, Tile};
use sample::{CellGrid, Geometry, Samples};

/// Largest image side, pixels: a 16384² RGB map is already 800 MB in memory.
pub const MAX_IMAGE_SIDE: i64 = 16_384;

/// Image rows fetched per pipeline query at most; also how often `progress` is called.
const MAX_STRIP_ROWS: i64 = 64;

/// One map to draw. Coordinates are block coordinates (x east, z south).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RenderRequest {
    /// Block x of the map's west edge.
    pub x0: i64,
    /// Block z of the map's north edge.
    pub z0: i64,
    /// Width in blocks (> 0).
    pub width: i64,
    /// Height in blocks (> 0).
    pub height: i64,
    /// Blocks per image pixel (≥ 1).
    pub zoom: i64,
    /// What to show.
    pub layer: Layer,
}

/// Why a map cannot be drawn.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// The biome layer needs the biome rules: use [`render_biomes`].
    #[error("the biome layer is drawn by render_biomes, which needs the biome rules")]
    BiomeNeedsRules,
    /// Zoom below one block per pixel.
    #[error("zoom must be at least 1 block per pixel (got {0})")]
    BadZoom(i64),
    /// A non-positive map size.
    #[error("the map size must be positive (got {width}x{height} blocks)")]
    BadSize {
        /// Width asked for, blocks.
        width: i64,
        /// Height asked for, blocks.
        height: i64,
    },
    /// The image would be too large to hold.
    #[error(
        "a {width}x{height}-block map at zoom {zoom} would be {width_px}x{height_px} pixels; the most is {max} \
         pixels per side (raise the zoom or shrink the size)"
    )]
    TooLarge {
        /// Width asked for, blocks.
        width: i64,
        /// Height asked for, blocks.
        height: i64,
        /// Zoom asked for.
        zoom: i64,
        /// Resulting image width.
        width_px: i64,
        /// Resulting image height.
        height_px: i64,
        /// [`MAX_IMAGE_SIDE`].
        max: i64,
    },
    /// An oblique view larger than [`MAX_OBLIQUE_SIDE`] on a side.
    #[error("a {width}x{height}-block oblique view is too large; the most is {max} blocks per side")]
    ViewTooLarge {
        /// Width asked for, blocks.
        width: i64,
        /// Height asked for, blocks.
        height: i64,
        /// [`MAX_OBLIQUE_SIDE`].
        max: i64,
    },
    /// The real elevation set of a relief comparison is missing or malformed (the message
    /// names the file).
    #[error("{0}")]
    Real(String),
    /// No window of the searched area (or no real tile) is usable for a relief comparison.
    #[error("{0}")]
    NoWindows(String),
    /// The region runs past the range of block coordinates.
    #[error("the region x {x0}+{width}, z {z0}+{height} runs past the range of block coordinates")]
    OutOfRange {
        /// West edge.
        x0: i64,
        /// North edge.
        z0: i64,
        /// Width, blocks.
        width: i64,
        /// Height, blocks.
        height: i64,
    },
    /// The PNG could not be written.
    #[error("cannot write {path}: {source}")]
    Write {
        /// The file being written.
        path: PathBuf,
        /// What went wrong.
        source: image::ImageError,
    },
}

impl RenderError {
    /// True when the request itself is wrong (exit code 2, "bad usage or bad input"), false
    /// when the map could not be written (exit code 1).
    pub fn is_bad_input(&self) -> bool {
        !matches!(self, RenderError::Write { .. })
    }
}

/// Draws the map `req` asks for. `progress(done, total)` is called after each strip with
/// image rows done and image rows in all.
pub fn render(
    pipeline: &Pipeline,
    req: &RenderRequest,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<RgbImage, RenderError> {
    let style = layer::style(req.layer).ok_or(RenderError::BiomeNeedsRules)?;
    let size = check(req)?;
    let title = title_lines(req, pipeline.seed(), &pipeline.active_stages(), pipeline.block_metres());
    // Below 4 blocks per pixel the map resolves single blocks, so it reads the upsampled
    // block grid the world is built from; from 4 up it reads model pixels directly, which is
    // exact at zoom 4 and avoids upsampling work that sampling would throw away.
    // An elevation map needs no climate (channel 0 is elevation either way), which makes
    // maps of huge areas far cheaper.
    let elevation_only = req.layer == Layer::Elevation;
    let (grid, mut query): (CellGrid, Box<dyn FnMut(Rect) -> Tile>) =
        match (req.zoom < BLOCKS_PER_MODEL_PIXEL, elevation_only) {
            (true, true) => (CellGrid::BLOCKS, Box::new(|r| pipeline.elevation_columns(r))),
            (true, false) => (CellGrid::BLOCKS, Box::new(|r| pipeline.columns(r))),
            (false, true) => (CellGrid::MODEL, Box::new(|r| pipeline.elevation(r))),
            (false, false) => (CellGrid::MODEL, Box::new(|r| pipeline.model(r))),
        };
    Ok(draw(req, size, &style, &title, (grid, pipeline.block_metres()), &mut *query, progress))
}

/// Writes `img` as a PNG at `path`, atomically: a reader never sees a half-written map.
pub fn save_png(img: &RgbImage, path: &Path) -> Result<(), RenderError> {
    let err = |source| RenderError::Write { path: path.to_path_buf(), source };
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    let tmp = PathBuf::from(tmp);
    img.save_with_format(&tmp, image::ImageFormat::Png).map_err(err)?;
    std::fs::rename(&tmp, path).map_err(|e| err(image::ImageError::IoError(e)))
}

/// Validates the request; returns the map's size in pixels.
pub(crate) fn check(req: &RenderRequest) -> Result<(u32, u32), RenderError> {
    if req.zoom < 1 {
        return Err(RenderError::BadZoom(req.zoom));
    }
    if req.width <= 0 || req.height <= 0 {
        return Err(RenderError::BadSize { width: req.width, height: req.height });
    }
    // The shading ring reaches one pixel (zoom blocks) past each edge.
    let reach = |start: i64, len: i64| {
        start.checked_sub(req.zoom).is_some() && start.checked_add(len).and_then(|e| e.checked_add(req.zoom)).is_some()
    };
    if !(reach(req.x0, req.width) && reach(req.z0, req.height)) {
        return Err(RenderError::OutOfRange { x0: req.x0, z0: req.z0, width: req.width, height: req.height });
    }
    // A partial last pixel still shows the blocks it covers.
    let (w, h) = (div_ceil(req.width, req.zoom), div_ceil(req.height, req.zoom));
    if w > MAX_IMAGE_SIDE || h > MAX_IMAGE_SIDE {
        return Err(RenderError::TooLarge {
            width: req.width,
            height: req.height,
            zoom: req.zoom,
            width_px: w,
            height_px: h,
            max: MAX_IMAGE_SIDE,
        });
    }
    Ok((w as u32, h as u32))
}

pub(crate) fn title_lines(req: &RenderRequest, seed: u64, stages: &[String], block_metres: f64) -> Vec<String> {
    let stages = if stages.is_empty() { "none".to_string() } else { stages.join(", ") };
    vec![
        format!("{} - seed {} - stages: {}", req.layer, seed, stages),
        format!(
            "x {}..{}, z {}..{} ({}×{} blocks)",
            req.x0,
            req.x0.saturating_add(req.width),
            req.z0,
            req.z0.saturating_add(req.height),
            req.width,
            req.height
        ),
        format!("zoom {} blocks/px = {}/px", req.zoom, distance(req.zoom as f64 * block_metres)),
    ]
}

/// A horizontal distance for people: metres below a kilometre, kilometres above.
fn distance(metres: f64) -> String {
    if metres < 1000.0 {
        format!("{} m", (metres * 10.0).round() / 10.0)
    } else {
        format!("{} km", (metres / 100.0).round() / 10.0)
    }
}

/// Image rows per strip: enough that the ring rows re-fetched per strip cost little, few
/// enough that one query stays near 4M cells (~80 MB of five-channel answers).
fn strip_rows(width_px: u32, zoom: i64) -> i64 {
    let cells_per_px = match zoom {
        z if z < BLOCKS_PER_MODEL_PIXEL => z * z,
        // Model rows at most 2 apart share a query (see `CellGrid::max_row_gap`).
        z if z < 3 * BLOCKS_PER_MODEL_PIXEL => (z / BLOCKS_PER_MODEL_PIXEL + 1).pow(2),
        // Sparser rows are fetched one by one: the strip height does not grow the queries.
        _ => 1,
    };
    (4_000_000 / ((width_px as i64 + 2) * cells_per_px)).clamp(16, MAX_STRIP_ROWS)
}

/// Draws map and panel from cells fetched through `query` on `grid` (blocks of
/// `block_metres`).
fn draw(
    req: &RenderRequest,
    (width, height): (u32, u32),
    style: &layer::Style,
    title: &[String],
    (grid, block_metres): (CellGrid, f64),
    query: &mut dyn FnMut(Rect) -> Tile,
    progress: &mut dyn FnMut(u64, u64),
) -> RgbImage {
    let frame_width = width.max(panel::MIN_FRAME_WIDTH);
    let scale = panel::text_scale(frame_width);
    let mut img = RgbImage::from_pixel(frame_width, height + panel::height(scale), panel::BACKGROUND);

    let geometry = Geometry { x0: req.x0, z0: req.z0, zoom: req.zoom };
    let metres_per_px = req.zoom as f64 * block_metres;
    let shading = Shading { spacing: metres_per_px as f32, exaggeration: shade::exaggeration(metres_per_px) };
    let channels = [channel::ELEVATION, style.channel];
    let rows_per_strip = strip_rows(width, req.zoom);
    let (w, h) = (width as i64, height as i64);
    let mut top = 0;
    while top < h {
        let bottom = (top + rows_per_strip).min(h);
        // One extra pixel on every side: the hillshade needs each pixel's neighbours.
        let s = sample::strip(&geometry, grid, top - 1..bottom + 1, -1..w + 1, &channels, query);
        for py in top..bottom {
            for px in 0..w {
                let colour = pixel(style, &shading, &s, (py - top + 1) as usize, (px + 1) as usize);
                img.put_pixel(px as u32, py as u32, colour);
            }
        }
        top = bottom;
        progress(top as u64, h as u64);
    }

    panel::draw(&mut img, height, title, &style.legend, (metres_per_px, block_metres), scale);
    img
}

struct Shading {
    spacing: f32,
    exaggeration: f32,
}

const COASTLINE: [f32; 3] = [30.0, 30.0, 30.0];

/// The colour of the pixel at strip row `r`, column `c` (plane 0 elevation, plane 1 value).
fn pixel(style: &layer::Style, shading: &Shading, s: &Samples, r: usize, c: usize) -> Rgb<u8> {
    let e = s.get(0, r, c);
    let (west, east, north, south) = (s.get(0, r, c - 1), s.get(0, r, c + 1), s.get(0, r - 1, c), s.get(0, r + 1, c));
    let light = shade::illumination(west, east, north, south, shading.spacing, shading.exaggeration);
    let strength = if e < 0.0 { style.sea_shading } else { style.land_shading };
    let mut colour = shade::apply((style.legend.colour)(s.get(1, r, c)), light, strength);
    if style.coastline && e >= 0.0 && [west, east, north, south].iter().any(|&n| n < 0.0) {
        for (v, k) in colour.iter_mut().zip(COASTLINE) {
            *v = 0.4 * *v + 0.6 * k;
        }
    }
    ramp::to_rgb(colour)
}

#[cfg(test)]
mod tests;
