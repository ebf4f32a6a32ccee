//! Block columns of a rectangle as chunk generation needs them: the pipeline's elevation and climate
//! plus what is derived from neighbours (surface Y, slope, steepness).
//!
//! Every value depends only on global coordinates (the pipeline is seed-consistent), so two
//! chunks that share a border compute identical numbers for it.

use crate::terrain::hydrology::{Kind, WaterColumns};
use crate::terrain::pipeline::channel;
use crate::terrain::{Pipeline, Rect, Tile};

/// [`channel::WATER`]'s code for a lake.
const LAKE: u8 = Kind::Lake as u8;
/// [`channel::WATER`]'s code for a dry lake bed.
const DRY_BED: u8 = Kind::Dry as u8;

use super::Vertical;

/// The pipeline's answer for a rectangle of block columns, with each column's ground and
/// water.
pub struct Columns {
    tile: Tile,
    surface: Vec<i32>,
    /// Block Y of the top water block, or [`DRY`].
    water: Vec<i32>,
}

/// [`Columns::water_top_y`]'s mark for a column without water.
const DRY: i32 = i32::MIN;

/// What water stands over a column.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Water {
    /// None.
    Dry,
    /// The sea (or ground below sea level), to the sea's water top.
    Sea,
    /// A river.
    River,
    /// A lake.
    Lake,
}

impl Columns {
    /// Asks the pipeline for every column of `rect` (y = z, x = x). Banks are settled with
    /// the columns around `rect` too, so any two queries agree on every column they share.
    pub fn query(pipeline: &Pipeline, vertical: &Vertical, rect: Rect) -> Columns {
        Columns::from_tile(pipeline.columns(rect.pad(1)), vertical).crop(rect)
    }

    /// Wraps a pipeline answer (all [`channel`]s): each column's ground and water, and banks
    /// raised where a river or lake would otherwise stand against air (its outermost columns
    /// lack the neighbours to settle that: [`Columns::query`] crops them off).
    pub fn from_tile(tile: Tile, vertical: &Vertical) -> Columns {
        let mut surface: Vec<i32> = tile.channel(channel::ELEVATION).iter().map(|&m| vertical.surface_y(m)).collect();
        let sea_top = vertical.water_top_y();
        let water: Vec<i32> = surface
            .iter()
            .zip(tile.channel(channel::WATER).iter().zip(tile.channel(channel::WATER_LEVEL)))
            .map(|(&ground, (&kind, &level))| {
                let inland = matches!(kind as u8, WaterColumns::RIVER | LAKE) && !level.is_nan();
                let top = if inland { vertical.surface_y(level) } else { DRY };
                let top = if ground < sea_top { top.max(sea_top) } else { top };
                if top > ground {
                    top
                } else {
                    DRY
                }
            })
            .collect();
        // A river or lake's water must meet ground at every height it stands at, never air:
        // dry ground beside it rises to its water top (a bank).
        let (h, w) = (tile.rect.h as usize, tile.rect.w as usize);
        for y in 1..h.saturating_sub(1) {
            for x in 1..w.saturating_sub(1) {
                let i = y * w + x;
                if water[i] != DRY {
                    continue;
                }
                let bank = [i - 1, i + 1, i - w, i + w].iter().map(|&j| water[j]).max().unwrap_or(DRY);
                surface[i] = surface[i].max(bank);
            }
        }
        Columns { tile, surface, water }
    }

    /// The columns of `rect` (inside these).
    fn crop(&self, rect: Rect) -> Columns {
        let r = self.tile.rect;
        let pick = |v: &[i32]| -> Vec<i32> {
            (rect.y0..rect.y1())
                .flat_map(|z| (rect.x0..rect.x1()).map(move |x| ((z - r.y0) * r.w + (x - r.x0)) as usize))
                .map(|i| v[i])
                .collect()
        };
        Columns { tile: self.tile.crop(rect), surface: pick(&self.surface), water: pick(&self.water) }
    }

    /// The rectangle covered.
    pub fn rect(&self) -> Rect {
        self.tile.rect
    }

    fn index(&self, x: i64, z: i64) -> usize {
        let r = self.tile.rect;
        assert!(z >= r.y0 && z < r.y1() && x >= r.x0 && x < r.x1(), "column ({x}, {z}) outside {r:?}");
        ((z - r.y0) * r.w + (x - r.x0)) as usize
    }

    /// One channel of the column at block (`x`, `z`).
    pub fn get(&self, c: usize, x: i64, z: i64) -> f32 {
        self.tile.get(c, z, x)
    }

    /// Surface elevation, metres above sea level.
    pub fn elevation(&self, x: i64, z: i64) -> f32 {
        self.get(channel::ELEVATION, x, z)
    }

    /// Block Y of the topmost ground block (see [`Vertical::surface_y`]).
    pub fn surface_y(&self, x: i64, z: i64) -> i32 {
        self.surface[self.index(x, z)]
    }

    /// Block Y of the top water block over the column (sea, river or lake), if any.
    pub fn water_top_y(&self, x: i64, z: i64) -> Option<i32> {
        Some(self.water[self.index(x, z)]).filter(|&y| y != DRY)
    }

    /// True when water stands over the column.
    pub fn is_wet(&self, x: i64, z: i64) -> bool {
        self.water[self.index(x, z)] != DRY
    }

    /// Blocks of water over the column's ground (0 on dry land).
    pub fn water_depth(&self, x: i64, z: i64) -> i32 {
        self.water_top_y(x, z).map_or(0, |top| top - self.surface_y(x, z))
    }

    /// What water stands over the column.
    pub fn water(&self, x: i64, z: i64) -> Water {
        if !self.is_wet(x, z) {
            return Water::Dry;
        }
        match self.get(channel::WATER, x, z) as u8 {
            WaterColumns::RIVER => Water::River,
            LAKE => Water::Lake,
            _ => Water::Sea,
        }
    }

    /// True for the bed of a dry lake (an endorheic basin too arid to fill).
    pub fn is_dry_bed(&self, x: i64, z: i64) -> bool {
        self.get(channel::WATER, x, z) as u8 == DRY_BED && !self.is_wet(x, z)
    }

    /// Steepness of the land around the column, degrees: the smooth relief's slope (see
    /// [`channel::RELIEF_SLOPE`]), the same at any world scale. The faces a player sees are
    /// [`Columns::drop_blocks`].
    pub fn slope_deg(&self, x: i64, z: i64) -> f32 {
        self.get(channel::RELIEF_SLOPE, x, z)
    }

    /// How many blocks the ground falls from this column to its lowest 4-neighbour's ground
    /// or water top (0 when no neighbour is lower): the face a player sees, which decides
    /// bare rock. A river's bank is not a cliff because its channel is deep.
    pub fn drop_blocks(&self, x: i64, z: i64) -> i32 {
        let y = self.surface_y(x, z);
        [(1, 0), (-1, 0), (0, 1), (0, -1)]
            .iter()
            .map(|&(ox, oz)| {
                let (nx, nz) = (x + ox, z + oz);
                y - self.surface_y(nx, nz).max(self.water_top_y(nx, nz).unwrap_or(i32::MIN))
            })
            .max()
            .unwrap_or(0)
            .max(0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::terrain::TerrainSettings;

    fn tile_with_elevation(rect: Rect, f: impl Fn(i64, i64) -> f32) -> Tile {
        let mut tile = Tile::zeros(channel::COUNT, rect);
        let w = rect.w as usize;
        for (i, v) in tile.channel_mut(channel::ELEVATION).iter_mut().enumerate() {
            *v = f(rect.x0 + (i % w) as i64, rect.y0 + (i / w) as i64);
        }
        tile
    }

    #[test]
    fn drops_count_the_blocks_to_the_lowest_neighbour() {
        let v = Vertical::from_world(&crate::config::WorldSettings::default());
        // Rises 125 m per block east.
        let cols = Columns::from_tile(tile_with_elevation(Rect::new(0, 0, 3, 3), |x, _| x as f32 * 125.0), &v);
        assert_eq!(cols.drop_blocks(1, 1), 5, "125 m = 5 blocks of 25 m");
        let flat = Columns::from_tile(tile_with_elevation(Rect::new(0, 0, 3, 3), |_, _| 300.0), &v);
        assert_eq!((flat.slope_deg(1, 1), flat.drop_blocks(1, 1)), (0.0, 0));
    }

    #[test]
    fn overlapping_queries_agree_on_shared_columns() {
        let pipeline = Pipeline::new(7, &TerrainSettings::default());
        let v = Vertical::from_world(&crate::config::WorldSettings::default());
        let a = Columns::query(&pipeline, &v, Rect::new(-1, -1, 18, 18));
        let b = Columns::query(&pipeline, &v, Rect::new(-1, 14, 18, 18));
        for z in 0..16 {
            for x in 14..17 {
                assert_eq!(a.elevation(x, z).to_bits(), b.elevation(x, z).to_bits(), "({x},{z})");
            }
            // Slopes need both neighbours inside both rectangles.
            assert_eq!(a.slope_deg(15, z).to_bits(), b.slope_deg(15, z).to_bits());
            assert_eq!(a.drop_blocks(15, z), b.drop_blocks(15, z));
        }
    }
}
