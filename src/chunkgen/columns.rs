//! Block columns of a rectangle as chunk generation needs them: the pipeline's elevation and climate
//! plus what is derived from neighbours (surface Y, slope, steepness).
//!
//! Every value depends only on global coordinates (the pipeline is seed-consistent), so two
//! chunks that share a border compute identical numbers for it.

use crate::terrain::pipeline::channel;
use crate::terrain::{Pipeline, Rect, Tile};

use super::Vertical;

/// The pipeline's answer for a rectangle of block columns, with each column's surface Y.
pub struct Columns {
    tile: Tile,
    surface: Vec<i32>,
}

impl Columns {
    /// Asks the pipeline for every column of `rect` (y = z, x = x).
    pub fn query(pipeline: &Pipeline, vertical: &Vertical, rect: Rect) -> Columns {
        Columns::from_tile(pipeline.columns(rect), vertical)
    }

    /// Wraps a pipeline answer (all [`channel`]s).
    pub fn from_tile(tile: Tile, vertical: &Vertical) -> Columns {
        let surface = tile.channel(channel::ELEVATION).iter().map(|&m| vertical.surface_y(m)).collect();
        Columns { tile, surface }
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

    /// Steepness of the land around the column, degrees: the smooth relief's slope (see
    /// [`channel::RELIEF_SLOPE`]), the same at any world scale. The faces a player sees are
    /// [`Columns::drop_blocks`].
    pub fn slope_deg(&self, x: i64, z: i64) -> f32 {
        self.get(channel::RELIEF_SLOPE, x, z)
    }

    /// How many blocks the ground falls from this column to its lowest 4-neighbour (0 when no
    /// neighbour is lower): the face a player sees, which decides bare rock.
    pub fn drop_blocks(&self, x: i64, z: i64) -> i32 {
        let y = self.surface_y(x, z);
        [(1, 0), (-1, 0), (0, 1), (0, -1)]
            .iter()
            .map(|&(ox, oz)| y - self.surface_y(x + ox, z + oz))
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
