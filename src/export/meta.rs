//! The JSON sidecar of an export (`FILE.json` beside `FILE.npy`): where the array lies in the
//! world and how it was made, so analysis never has to guess units, grid or provenance.

use std::fmt;
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use super::ExportError;
use crate::npy::tmp_path;
use crate::terrain::pipeline::BLOCKS_PER_MODEL_PIXEL;

/// Which grid an export samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Grid {
    /// One value per block column (upsampled and carved: what the world is built from).
    Block,
    /// One value per model pixel (the upsampling's source, what the models produce).
    Model,
}

impl Grid {
    /// The name used on the command line and in the JSON.
    pub fn name(self) -> &'static str {
        match self {
            Grid::Block => "block",
            Grid::Model => "model",
        }
    }

    /// Blocks per array cell along each axis.
    pub fn blocks_per_cell(self) -> i64 {
        match self {
            Grid::Block => 1,
            Grid::Model => BLOCKS_PER_MODEL_PIXEL,
        }
    }

    /// Horizontal size of one array cell in a world of `block_metres` blocks, metres.
    pub fn metres_per_pixel(self, block_metres: f64) -> f64 {
        block_metres * self.blocks_per_cell() as f64
    }
}

impl fmt::Display for Grid {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// What an export's values are.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum Quantity {
    /// Ground elevation, metres (river channels and valleys carved in at the block grid).
    #[default]
    Elevation,
    /// Water surface of rivers and lakes, metres; NaN where there is none (block grid only;
    /// the sea's is 0).
    WaterLevel,
    /// Discharge of the river or lake over the column, m³/s, 0 elsewhere: upstream area
    /// weighted by runoff (block grid only).
    Discharge,
    /// The surface a real DEM records, metres: the water surface over rivers, lakes and the
    /// sea, the ground elsewhere (block grid only). Radar and laser DEMs (SRTM, whose water
    /// bodies were also flattened to their shore level) see water, not river beds, so this is
    /// what generated terrain is judged on against them.
    Surface,
}

impl Quantity {
    /// Its values over a tile of the pipeline's channels, row-major: a channel itself where
    /// the quantity is one.
    pub fn values(self, tile: &crate::terrain::Tile) -> std::borrow::Cow<'_, [f32]> {
        use crate::terrain::pipeline::channel;
        let plain = |c: usize| std::borrow::Cow::Borrowed(tile.channel(c));
        match self {
            Quantity::Elevation => plain(channel::ELEVATION),
            Quantity::WaterLevel => plain(channel::WATER_LEVEL),
            Quantity::Discharge => plain(channel::DISCHARGE),
            Quantity::Surface => tile
                .channel(channel::ELEVATION)
                .iter()
                .zip(tile.channel(channel::WATER_LEVEL))
                // NaN water (none there) loses to the ground in `max`.
                .map(|(&ground, &water)| ground.max(water))
                .collect::<Vec<f32>>()
                .into(),
        }
    }
}

/// A grid name other than `block` or `model`.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown grid `{given}` (allowed: block, model)")]
pub struct UnknownGrid {
    /// The name as given.
    pub given: String,
}

impl FromStr for Grid {
    type Err = UnknownGrid;

    fn from_str(s: &str) -> Result<Grid, UnknownGrid> {
        match s.trim().to_ascii_lowercase().as_str() {
            "block" => Ok(Grid::Block),
            "model" => Ok(Grid::Model),
            _ => Err(UnknownGrid { given: s.to_string() }),
        }
    }
}

/// How metres map to block heights in the world this export belongs to; recorded so an
/// analysis can reproduce the world's Y values from the metres in the array.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Vertical {
    /// Block Y of sea level (0 m).
    pub sea_level_y: i32,
    /// Metres of elevation per block of height.
    pub metres_per_block: f64,
}

/// Everything about an exported array besides its values (the `FILE.json` contents).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ExportMeta {
    /// Block x of the west edge of the array's first cell.
    pub x0: i64,
    /// Block z of the north edge of the array's first cell.
    pub z0: i64,
    /// Array columns (cells of `grid`).
    pub width: usize,
    /// Array rows (cells of `grid`).
    pub height: usize,
    /// The grid sampled.
    pub grid: Grid,
    /// Horizontal size of one cell, metres.
    pub metres_per_pixel: f64,
    /// World seed.
    pub seed: u64,
    /// What the values are (older sidecars, without it, are elevation).
    #[serde(default)]
    pub quantity: Quantity,
    /// Pipeline stages that produced the values.
    pub stages: Vec<String>,
    /// The world's vertical scale.
    pub vertical: Vertical,
}

impl ExportMeta {
    /// Where the metadata of the array at `npy` lives: the same name with `.json`.
    pub fn path_for(npy: &Path) -> PathBuf {
        npy.with_extension("json")
    }

    /// Reads metadata written by an export.
    pub fn read(path: &Path) -> Result<ExportMeta, ExportError> {
        let text = std::fs::read_to_string(path)
            .map_err(|source| ExportError::ReadMeta { path: path.to_path_buf(), source })?;
        serde_json::from_str(&text).map_err(|source| ExportError::BadMeta { path: path.to_path_buf(), source })
    }

    /// Writes the metadata to `path` atomically (via `path.tmp`).
    pub(crate) fn write(&self, path: &Path) -> io::Result<()> {
        let mut text = serde_json::to_string_pretty(self).map_err(io::Error::other)?;
        text.push('\n');
        let tmp = tmp_path(path);
        let result = std::fs::File::create(&tmp).and_then(|mut f| {
            f.write_all(text.as_bytes())?;
            f.sync_all()
        });
        match result.and_then(|()| std::fs::rename(&tmp, path)) {
            Ok(()) => Ok(()),
            Err(e) => {
                let _ = std::fs::remove_file(&tmp);
                Err(e)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_names_round_trip() {
        for g in [Grid::Block, Grid::Model] {
            assert_eq!(g.name().parse::<Grid>(), Ok(g));
            assert_eq!(serde_json::to_string(&g).unwrap(), format!("\"{g}\""));
        }
        let err = "chunk".parse::<Grid>().unwrap_err().to_string();
        assert!(err.contains("chunk") && err.contains("block") && err.contains("model"), "{err}");
    }

    #[test]
    fn metres_per_pixel_follow_the_grid() {
        assert_eq!(Grid::Block.metres_per_pixel(40.0), 40.0);
        assert_eq!(Grid::Model.metres_per_pixel(40.0), 160.0);
    }

    #[test]
    fn json_sidecar_sits_beside_the_array() {
        assert_eq!(ExportMeta::path_for(Path::new("out/h.npy")), PathBuf::from("out/h.json"));
        assert_eq!(ExportMeta::path_for(Path::new("h")), PathBuf::from("h.json"));
    }

    #[test]
    fn meta_round_trips_through_a_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.json");
        let meta = ExportMeta {
            x0: -8,
            z0: 4,
            width: 3,
            height: 2,
            grid: Grid::Model,
            metres_per_pixel: 500.0,
            seed: u64::MAX,
            quantity: Quantity::Discharge,
            stages: vec!["layout".into()],
            vertical: Vertical { sea_level_y: 63, metres_per_block: 25.0 },
        };
        meta.write(&path).unwrap();
        assert_eq!(ExportMeta::read(&path).unwrap(), meta);
        std::fs::write(&path, "{\"x0\": 1}").unwrap();
        let err = ExportMeta::read(&path).unwrap_err().to_string();
        assert!(err.contains("m.json"), "{err}");
    }
}
