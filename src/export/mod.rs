//! `infiniterra export`: raw heightmaps for analysis — elevation in metres as a NumPy `.npy`
//! array (row-major z then x) with a JSON sidecar saying where it lies and how it was made.
//!
//! Owns: the sidecar format ([`ExportMeta`]), streaming a
//! region out of the pipeline. Must not touch: terrain internals (only `Pipeline::model` /
//! `Pipeline::columns`), the command line.

mod meta;

use std::path::{Path, PathBuf};

pub use meta::{ExportMeta, Grid, Quantity, UnknownGrid, Vertical};

use crate::npy::NpyWriter;
use crate::terrain::tile::div_floor;
use crate::terrain::{Pipeline, Rect, Tile};

/// Cells fetched per pipeline query: large enough to amortise per-query work, small enough
/// (~20 MB of five-channel answers) that huge exports stream in bounded memory.
const CELLS_PER_STRIP: i64 = 1 << 20;

/// A region to export. Coordinates are block coordinates (x east, z south), whatever grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ExportRequest {
    /// Block x of the region's west edge.
    pub x0: i64,
    /// Block z of the region's north edge.
    pub z0: i64,
    /// Width in blocks (> 0).
    pub width: i64,
    /// Height in blocks (> 0).
    pub height: i64,
    /// The grid to sample: every block column, or every model pixel covering the region.
    pub grid: Grid,
    /// What to write.
    pub quantity: Quantity,
}

/// What an export wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct ExportSummary {
    /// The array file.
    pub npy: PathBuf,
    /// Its JSON sidecar.
    pub json: PathBuf,
    /// Array shape, (rows, columns) = (z, x).
    pub shape: (usize, usize),
    /// Lowest elevation, metres (NaN values are ignored).
    pub min: f32,
    /// Highest elevation, metres.
    pub max: f32,
}

/// Why an export failed.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// A non-positive region size.
    #[error("the export size must be positive (got {width}x{height} blocks)")]
    BadSize {
        /// Width asked for, blocks.
        width: i64,
        /// Height asked for, blocks.
        height: i64,
    },
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
    /// A vertical scale that cannot map metres to blocks.
    #[error("metres_per_block must be positive and finite (got {0})")]
    BadVertical(f64),
    /// Water is decided at the block grid only.
    #[error("--quantity {0:?} is only on the block grid (--grid block)")]
    QuantityNeedsBlocks(Quantity),
    /// The output would collide with its own sidecar.
    #[error("the output {0} must not end in .json: the metadata is written beside it as FILE.json")]
    OutputIsJson(PathBuf),
    /// Writing a file failed.
    #[error("cannot write {path}: {source}")]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// Reading a sidecar failed.
    #[error("cannot read {path}: {source}")]
    ReadMeta {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A sidecar that is not export metadata.
    #[error("{path} is not valid export metadata: {source}")]
    BadMeta {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        source: serde_json::Error,
    },
}

impl ExportError {
    /// True when the request itself is wrong (exit code 2, "bad usage or bad input"), false
    /// when a file could not be read or written (exit code 1).
    pub fn is_bad_input(&self) -> bool {
        matches!(
            self,
            ExportError::BadSize { .. }
                | ExportError::OutOfRange { .. }
                | ExportError::BadVertical(_)
                | ExportError::OutputIsJson(_)
                | ExportError::QuantityNeedsBlocks(_)
        )
    }
}

/// Exports the elevation of `req`'s region to `out` (`.npy`, float32 metres) and its
/// sidecar `out` with `.json`. `progress(done, total)` counts array rows.
pub fn export(
    pipeline: &Pipeline,
    req: &ExportRequest,
    vertical: &Vertical,
    out: &Path,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<ExportSummary, ExportError> {
    let rect = cells(req)?;
    if !(vertical.metres_per_block.is_finite() && vertical.metres_per_block > 0.0) {
        return Err(ExportError::BadVertical(vertical.metres_per_block));
    }
    let json = ExportMeta::path_for(out);
    if json == out {
        return Err(ExportError::OutputIsJson(out.to_path_buf()));
    }
    if req.quantity != Quantity::Elevation && req.grid != Grid::Block {
        return Err(ExportError::QuantityNeedsBlocks(req.quantity));
    }
    // Elevation alone where it will do: the climate channels would cost more than the
    // terrain itself.
    let mut query = |r: Rect| match (req.grid, req.quantity) {
        (Grid::Block, Quantity::Elevation) => pipeline.elevation_columns(r),
        (Grid::Block, _) => pipeline.columns(r),
        (Grid::Model, _) => pipeline.elevation(r),
    };
    let (min, max) = write_array(out, rect, req.quantity, &mut query, progress)?;

    let cell = req.grid.blocks_per_cell();
    let meta = ExportMeta {
        x0: rect.x0 * cell,
        z0: rect.y0 * cell,
        width: rect.w as usize,
        height: rect.h as usize,
        grid: req.grid,
        metres_per_pixel: req.grid.metres_per_pixel(pipeline.block_metres()),
        seed: pipeline.seed(),
        quantity: req.quantity,
        stages: pipeline.active_stages(),
        vertical: *vertical,
    };
    meta.write(&json).map_err(|source| ExportError::Write { path: json.clone(), source })?;
    Ok(ExportSummary { npy: out.to_path_buf(), json, shape: (meta.height, meta.width), min, max })
}

/// The cells of `req.grid` covering the requested block region (y = z, x = x).
fn cells(req: &ExportRequest) -> Result<Rect, ExportError> {
    if req.width <= 0 || req.height <= 0 {
        return Err(ExportError::BadSize { width: req.width, height: req.height });
    }
    let out_of_range = || ExportError::OutOfRange { x0: req.x0, z0: req.z0, width: req.width, height: req.height };
    let x_last = req.x0.checked_add(req.width - 1).ok_or_else(out_of_range)?;
    let z_last = req.z0.checked_add(req.height - 1).ok_or_else(out_of_range)?;
    let cell = req.grid.blocks_per_cell();
    let (x0, z0) = (div_floor(req.x0, cell), div_floor(req.z0, cell));
    let (x1, z1) = (div_floor(x_last, cell), div_floor(z_last, cell));
    Ok(Rect::new(z0, x0, z1 - z0 + 1, x1 - x0 + 1))
}

/// Streams `quantity` over `rect` from `query` into the `.npy` at `path` in strips of rows;
/// returns (min, max), NaN ignored.
fn write_array(
    path: &Path,
    rect: Rect,
    quantity: Quantity,
    query: &mut dyn FnMut(Rect) -> Tile,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<(f32, f32), ExportError> {
    let write_err = |source| ExportError::Write { path: path.to_path_buf(), source };
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        // Batch jobs write into per-shard folders: create them rather than fail.
        std::fs::create_dir_all(dir).map_err(|source| ExportError::Write { path: dir.to_path_buf(), source })?;
    }
    let mut writer = NpyWriter::create(path, (rect.h as usize, rect.w as usize)).map_err(write_err)?;
    let strip_rows = (CELLS_PER_STRIP / rect.w).clamp(1, rect.h);
    let (mut min, mut max) = (f32::INFINITY, f32::NEG_INFINITY);
    let mut y = rect.y0;
    while y < rect.y1() {
        let rows = strip_rows.min(rect.y1() - y);
        let tile = query(Rect::new(y, rect.x0, rows, rect.w));
        let values = quantity.values(&tile);
        for &v in values.iter().filter(|v| !v.is_nan()) {
            min = min.min(v);
            max = max.max(v);
        }
        writer.write(&values).map_err(write_err)?;
        y += rows;
        progress((y - rect.y0) as u64, rect.h as u64);
    }
    writer.finish().map_err(write_err)?;
    Ok((min, max))
}

#[cfg(test)]
mod tests;
