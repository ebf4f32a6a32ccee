//! Loading what `eval` compares: a generated heightmap (`.npy` + JSON sidecar) and a
//! reference (a prepared set directory, or one `.npy` + sidecar), cut into tiles of the
//! reference's size at the reference's resolution.

use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::EvalError;
use crate::export::{ExportMeta, Grid};
use crate::npy::read_npy_f32;
use crate::terrain::metrics::Raster;
use crate::terrain::pipeline::{BASE_METRES, BLOCKS_PER_MODEL_PIXEL};

/// Tile side when neither file says (the prepared sets' size).
pub const DEFAULT_TILE: usize = 256;

/// Side, in tiles, of the squares a prepared set's held-out region is made of (its manifest's
/// `heldout_region`): the tiles of one square are neighbours, alike, and held out together.
pub const REGION_SQUARE_TILES: i64 = 2;

/// The part of a prepared set's `manifest.json` that places its tiles.
#[derive(Debug, Deserialize)]
struct SetManifest {
    tiles: Vec<TileEntry>,
}

/// One tile of a prepared set: its split, its place in the set's tile grid, its index in the split.
#[derive(Debug, Deserialize)]
struct TileEntry {
    split: String,
    row: i64,
    col: i64,
    index: usize,
}

/// Which square of [`REGION_SQUARE_TILES`] tiles each tile of a prepared set lies in.
#[derive(Debug, Clone, PartialEq)]
pub struct Regions {
    /// One key per held-out tile, in the split's order.
    pub heldout: Vec<u64>,
    /// One key per training tile, in the split's order.
    pub train: Vec<u64>,
    /// Each tile's (row, column) in the set's tile grid: held-out tiles, then training tiles,
    /// in the splits' order (as [`Regions::pooled`]).
    pub cells: Vec<(i64, i64)>,
}

impl Regions {
    /// Reads `manifest.json` of a prepared set whose splits hold `counts` = (held-out, train)
    /// tiles; `None` when the set has no manifest.
    fn load(dir: &Path, counts: (usize, usize)) -> Result<Option<Regions>, EvalError> {
        let path = dir.join("manifest.json");
        let Ok(text) = std::fs::read_to_string(&path) else { return Ok(None) };
        let bad = |why: String| EvalError::Input(format!("{}: {why}", path.display()));
        let manifest: SetManifest =
            serde_json::from_str(&text).map_err(|e| bad(format!("not a prepared set's manifest: {e}")))?;
        let cells = |split: &str, count: usize| -> Result<Vec<(i64, i64)>, EvalError> {
            let mut cells = vec![None; count];
            for t in manifest.tiles.iter().filter(|t| t.split == split) {
                let slot = cells.get_mut(t.index).ok_or_else(|| {
                    bad(format!("{split} tile index {} is beyond the split's {count} tiles", t.index))
                })?;
                *slot = Some((t.row, t.col));
            }
            cells
                .into_iter()
                .enumerate()
                .map(|(i, k)| k.ok_or_else(|| bad(format!("lists no {split} tile with index {i}"))))
                .collect()
        };
        let (heldout, train) = (cells("heldout", counts.0)?, cells("train", counts.1)?);
        let square = |&(row, col): &(i64, i64)| {
            let (y, x) = (row.div_euclid(REGION_SQUARE_TILES), col.div_euclid(REGION_SQUARE_TILES));
            ((y as u64) << 32) ^ (x as u32 as u64)
        };
        Ok(Some(Regions {
            heldout: heldout.iter().map(square).collect(),
            train: train.iter().map(square).collect(),
            cells: heldout.into_iter().chain(train).collect(),
        }))
    }

    /// The keys of held-out then training tiles, as the real-vs-real splits pool them.
    pub fn pooled(&self) -> Vec<u64> {
        self.heldout.iter().chain(&self.train).copied().collect()
    }
}

/// The sidecar fields `eval` reads: export sidecars and prepared-set sidecars both have
/// `metres_per_pixel`; a stack of tiles says `tile`; an export says where it lies.
#[derive(Debug, Deserialize)]
struct Sidecar {
    metres_per_pixel: f64,
    #[serde(default)]
    tile: Option<usize>,
    #[serde(default)]
    x0: Option<i64>,
    #[serde(default)]
    z0: Option<i64>,
    #[serde(default)]
    grid: Option<Grid>,
    #[serde(default)]
    heldout_counterparts: Option<usize>,
}

/// One heightmap file and what its sidecar says about it.
#[derive(Debug)]
pub struct Heightmap {
    /// The array file.
    pub path: PathBuf,
    /// The whole array as one raster (a stack of tiles is N tiles stacked along rows).
    pub raster: Raster,
    /// Side of the stacked tiles, when the file is a stack.
    pub tile: Option<usize>,
    /// Global pixel coordinates (x, y) of the first pixel on this file's own grid, when known.
    pub origin: Option<(i64, i64)>,
    /// Array pixels per 500 m base pixel (the grid the learned windows' strides are counted
    /// on) along each axis.
    pub pixels_per_base_pixel: f64,
    /// `Some(n)`: the tiles are generated counterparts of the first `n` held-out tiles of a
    /// prepared set (`train <stage> --generate-heldout`), so they are compared with those.
    pub heldout_counterparts: Option<usize>,
}

impl Heightmap {
    /// Reads `path` and its sidecar `path.json`.
    pub fn load(path: &Path) -> Result<Heightmap, EvalError> {
        let ((rows, cols), data) = read_npy_f32(path).map_err(|e| EvalError::Input(e.to_string()))?;
        let json = ExportMeta::path_for(path);
        let text = std::fs::read_to_string(&json).map_err(|e| {
            EvalError::Input(format!(
                "cannot read {} (the sidecar saying the resolution of {}): {e}",
                json.display(),
                path.display()
            ))
        })?;
        let side: Sidecar = serde_json::from_str(&text)
            .map_err(|e| EvalError::Input(format!("{} is not valid sidecar JSON: {e}", json.display())))?;
        if !(side.metres_per_pixel.is_finite() && side.metres_per_pixel > 0.0) {
            return Err(EvalError::Input(format!(
                "{}: metres_per_pixel must be positive (got {})",
                json.display(),
                side.metres_per_pixel
            )));
        }
        if let Some(t) = side.tile {
            if t == 0 || t != cols || rows % t != 0 {
                return Err(EvalError::Input(format!(
                    "{}: a stack of {t}×{t} tiles needs {t} columns and a multiple of {t} rows, the array is {rows}×{cols}",
                    path.display()
                )));
            }
        }
        if rows < 3 || cols < 3 {
            return Err(EvalError::Input(format!("{} is {rows}×{cols}: too small to measure", path.display())));
        }
        let blocks_per_cell = side.grid.map_or(BLOCKS_PER_MODEL_PIXEL, Grid::blocks_per_cell);
        let origin = side.x0.zip(side.z0).map(|(x, z)| (x.div_euclid(blocks_per_cell), z.div_euclid(blocks_per_cell)));
        Ok(Heightmap {
            path: path.to_path_buf(),
            raster: Raster::new(rows, cols, side.metres_per_pixel, data),
            tile: side.tile,
            origin,
            // From the resolution, so a prepared stack (no grid) is handled like an export.
            pixels_per_base_pixel: BASE_METRES / side.metres_per_pixel,
            heldout_counterparts: side.heldout_counterparts,
        })
    }

    /// The separate pieces of the file: its tiles for a stack, else the whole map.
    pub fn pieces(&self) -> Vec<Raster> {
        match self.tile {
            Some(t) => self.raster.tiles(t),
            None => vec![self.raster.clone()],
        }
    }

    /// Tiles of `size` at `metres` per pixel: each piece is resampled (bilinear) when its
    /// resolution differs, then cut into whole tiles.
    pub fn tiles_at(&self, metres: f64, size: usize) -> Vec<Raster> {
        self.pieces()
            .into_iter()
            .map(|p| if (p.metres - metres).abs() > 1e-6 * metres { p.resample(metres) } else { p })
            .flat_map(|p| p.tiles(size))
            .collect()
    }
}

/// The reference: the held-out real region and, for a prepared set, its training region.
#[derive(Debug)]
pub struct Reference {
    /// What was named on the command line.
    pub path: PathBuf,
    /// The held-out split (or the one file given).
    pub heldout: Heightmap,
    /// The training split of a prepared set (the real-vs-real baseline).
    pub train: Option<Heightmap>,
    /// Tile side the metrics use.
    pub tile: usize,
    /// Where a prepared set's tiles lie (from its manifest), when it says.
    pub regions: Option<Regions>,
}

impl Reference {
    /// Reads a prepared set directory (`heldout.npy`, `train.npy` with their sidecars) or a
    /// single `.npy` with its sidecar.
    pub fn load(path: &Path) -> Result<Reference, EvalError> {
        if path.is_dir() {
            let heldout = Heightmap::load(&path.join("heldout.npy"))?;
            let train = Heightmap::load(&path.join("train.npy"))?;
            if (train.raster.metres - heldout.raster.metres).abs() > 1e-9 {
                return Err(EvalError::Input(format!("{}: train and held-out resolutions differ", path.display())));
            }
            let tile = heldout.tile.unwrap_or(DEFAULT_TILE);
            let count = |h: &Heightmap| h.raster.rows / h.tile.unwrap_or(h.raster.rows).max(1);
            let regions = Regions::load(path, (count(&heldout), count(&train)))?;
            return Ok(Reference { path: path.to_path_buf(), heldout, train: Some(train), tile, regions });
        }
        if !path.exists() {
            return Err(EvalError::Input(format!(
                "reference {} does not exist (run `infiniterra data prepare`, then name e.g. data/prepared/core)",
                path.display()
            )));
        }
        let heldout = Heightmap::load(path)?;
        let tile = heldout.tile.unwrap_or(DEFAULT_TILE);
        Ok(Reference { path: path.to_path_buf(), heldout, train: None, tile, regions: None })
    }

    /// Keeps only the first `n` held-out tiles (when there are more): a generated set of
    /// counterparts of the first `n` must be compared with those, not with all of them —
    /// tiles differ from region to region far more than a model's error. Returns whether it
    /// cut anything.
    pub fn first_heldout_tiles(&mut self, n: usize) -> bool {
        let Some(t) = self.heldout.tile else { return false };
        let r = &mut self.heldout.raster;
        if n == 0 || n * t >= r.rows {
            return false;
        }
        r.rows = n * t;
        r.data.truncate(r.rows * r.cols);
        if let Some(regions) = &mut self.regions {
            regions.heldout.truncate(n);
        }
        true
    }

    /// Reference resolution, metres per pixel.
    pub fn metres(&self) -> f64 {
        self.heldout.raster.metres
    }
}
