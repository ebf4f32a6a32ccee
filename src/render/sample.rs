//! Sampling the pipeline for a map: which block column each image pixel shows, and how to
//! fetch a strip of pixels with as few and as small pipeline queries as possible.
//!
//! Pixel (px, py) shows the block column at the centre of its `zoom`×`zoom` footprint. The
//! pipeline answers dense rectangles only, so a strip's sampled cells are fetched as runs of
//! neighbouring rows; runs break where sampled rows are far apart (large zooms on the model
//! grid), so a continental map costs one model row per image row, not every row in between.

use std::ops::Range;

use crate::terrain::tile::div_floor;
use crate::terrain::{Rect, Tile};

/// Where a map's pixels fall on the block grid.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Geometry {
    /// Block x of the map's west edge.
    pub x0: i64,
    /// Block z of the map's north edge.
    pub z0: i64,
    /// Blocks per image pixel (≥ 1).
    pub zoom: i64,
}

impl Geometry {
    /// Block x shown by image column `px` (may be −1 or past the edge for the shading ring).
    pub(crate) fn block_x(&self, px: i64) -> i64 {
        self.x0 + px * self.zoom + self.zoom / 2
    }

    /// Block z shown by image row `py`.
    pub(crate) fn block_z(&self, py: i64) -> i64 {
        self.z0 + py * self.zoom + self.zoom / 2
    }
}

/// The grid the samples come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct CellGrid {
    /// Blocks per cell: 1 for block columns, 4 for model pixels.
    pub blocks_per_cell: i64,
    /// Largest gap between sampled rows still fetched in one query. Block columns are
    /// upsampled from a padded model query, so splitting them would recompute shared model
    /// rows: always merge. Model pixels are independent: skip rows further than 2 apart.
    pub max_row_gap: i64,
    /// Largest gap between sampled columns still fetched in one query. A query has a fixed
    /// cost of about four cells (measured: ~10 µs for 1×1 against ~2.3 µs per cell of a long
    /// row), so columns further apart than that are cheaper fetched one by one.
    pub max_col_gap: i64,
}

impl CellGrid {
    /// Block columns: everything in one query (see the field docs for why).
    pub(crate) const BLOCKS: CellGrid = CellGrid { blocks_per_cell: 1, max_row_gap: i64::MAX, max_col_gap: i64::MAX };
    /// Model pixels: sparse rows and columns fetched apart.
    pub(crate) const MODEL: CellGrid =
        CellGrid { blocks_per_cell: crate::terrain::pipeline::BLOCKS_PER_MODEL_PIXEL, max_row_gap: 2, max_col_gap: 4 };
}

/// Splits sorted cell coordinates into runs whose neighbours are at most `max_gap` apart:
/// `(first index, one past the last index)` per run.
fn runs(cells: &[i64], max_gap: i64) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = 0;
    for i in 1..=cells.len() {
        if i == cells.len() || cells[i] - cells[i - 1] > max_gap {
            out.push((start, i));
            start = i;
        }
    }
    out
}

/// Channel values at every pixel of a strip, row-major.
pub(crate) struct Samples {
    /// Number of pixel rows.
    pub rows: usize,
    /// Number of pixel columns.
    pub cols: usize,
    /// One plane per requested channel, in request order.
    pub planes: Vec<Vec<f32>>,
}

impl Samples {
    /// Value of plane `p` at strip row `r`, column `c`.
    pub(crate) fn get(&self, p: usize, r: usize, c: usize) -> f32 {
        debug_assert!(r < self.rows && c < self.cols, "({r},{c}) outside a {}x{} strip", self.rows, self.cols);
        self.planes[p][r * self.cols + c]
    }
}

/// Samples `channels` at image rows `rows` and columns `cols` (either may extend past the
/// image for the shading ring), fetching cells through `query`.
pub(crate) fn strip(
    geometry: &Geometry,
    grid: CellGrid,
    rows: Range<i64>,
    cols: Range<i64>,
    channels: &[usize],
    query: &mut dyn FnMut(Rect) -> Tile,
) -> Samples {
    let cell = |block: i64| div_floor(block, grid.blocks_per_cell);
    let cx: Vec<i64> = cols.clone().map(|px| cell(geometry.block_x(px))).collect();
    let cy: Vec<i64> = rows.clone().map(|py| cell(geometry.block_z(py))).collect();
    let (n_rows, n_cols) = (cy.len(), cx.len());
    let mut planes = vec![vec![0.0f32; n_rows * n_cols]; channels.len()];
    if n_rows == 0 || n_cols == 0 {
        return Samples { rows: n_rows, cols: n_cols, planes };
    }
    let col_runs = runs(&cx, grid.max_col_gap);
    for (r0, r1) in runs(&cy, grid.max_row_gap) {
        for &(c0, c1) in &col_runs {
            let rect = Rect::new(cy[r0], cx[c0], cy[r1 - 1] - cy[r0] + 1, cx[c1 - 1] - cx[c0] + 1);
            let tile = query(rect);
            for r in r0..r1 {
                let ly = (cy[r] - rect.y0) as usize;
                for c in c0..c1 {
                    let lx = (cx[c] - rect.x0) as usize;
                    for (p, &ch) in channels.iter().enumerate() {
                        planes[p][r * n_cols + c] = tile.at(ch, ly, lx);
                    }
                }
            }
        }
    }
    Samples { rows: n_rows, cols: n_cols, planes }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A synthetic two-channel field: channel 0 encodes the cell, channel 1 its negation.
    fn field(rect: Rect) -> Tile {
        let mut data = Vec::with_capacity(2 * rect.area());
        for sign in [1.0, -1.0] {
            for y in rect.y0..rect.y1() {
                for x in rect.x0..rect.x1() {
                    data.push(sign * (y * 1000 + x) as f32);
                }
            }
        }
        Tile::from_data(2, rect, data)
    }

    const BLOCKS: CellGrid = CellGrid::BLOCKS;
    const MODEL: CellGrid = CellGrid::MODEL;

    #[test]
    fn pixels_show_the_centre_of_their_footprint() {
        let g = Geometry { x0: -10, z0: 7, zoom: 3 };
        assert_eq!((g.block_x(0), g.block_z(0)), (-9, 8));
        assert_eq!((g.block_x(-1), g.block_z(2)), (-12, 14));
        let g = Geometry { x0: 0, z0: 0, zoom: 1 };
        assert_eq!(g.block_x(5), 5);
    }

    #[test]
    fn block_samples_pick_the_right_cells_in_one_query() {
        let g = Geometry { x0: -5, z0: 3, zoom: 2 };
        let mut queries = 0;
        let s = strip(&g, BLOCKS, -1..4, -1..3, &[1, 0], &mut |r| {
            queries += 1;
            field(r)
        });
        assert_eq!(queries, 1);
        assert_eq!((s.rows, s.cols), (5, 4));
        for r in 0..5 {
            for c in 0..4 {
                let (z, x) = (g.block_z(r as i64 - 1), g.block_x(c as i64 - 1));
                assert_eq!(s.get(1, r, c), (z * 1000 + x) as f32);
                assert_eq!(s.get(0, r, c), -s.get(1, r, c));
            }
        }
    }

    #[test]
    fn model_samples_use_floor_division_and_split_sparse_rows() {
        let g = Geometry { x0: -37, z0: -64, zoom: 16 };
        let mut rects = Vec::new();
        let s = strip(&g, MODEL, -1..3, -1..2, &[0], &mut |r| {
            rects.push(r);
            field(r)
        });
        // 16 blocks per pixel = 4 model rows apart: every row is its own one-row query.
        assert_eq!(rects.len(), 4);
        assert!(rects.iter().all(|r| r.h == 1 && r.w == 9));
        for r in 0..4 {
            for c in 0..3 {
                let (z, x) = (div_floor(g.block_z(r as i64 - 1), 4), div_floor(g.block_x(c as i64 - 1), 4));
                assert_eq!(s.get(0, r, c), (z * 1000 + x) as f32);
            }
        }
    }

    #[test]
    fn far_apart_model_pixels_are_fetched_one_by_one() {
        let g = Geometry { x0: 0, z0: 0, zoom: 64 };
        let mut rects = Vec::new();
        let s = strip(&g, MODEL, 0..2, 0..3, &[0], &mut |r| {
            rects.push(r);
            field(r)
        });
        assert_eq!(rects.len(), 6);
        assert!(rects.iter().all(|r| r.area() == 1));
        assert_eq!(s.get(0, 1, 2), (24 * 1000 + 40) as f32);
    }

    #[test]
    fn runs_split_at_large_gaps() {
        assert_eq!(runs(&[1, 2, 3, 10, 11, 20], 2), vec![(0, 3), (3, 5), (5, 6)]);
        assert_eq!(runs(&[5], 0), vec![(0, 1)]);
        assert_eq!(runs(&[1, 100], i64::MAX), vec![(0, 2)]);
    }

    #[test]
    fn dense_model_rows_share_a_query() {
        let g = Geometry { x0: 0, z0: 0, zoom: 4 };
        let mut queries = 0;
        strip(&g, MODEL, -1..65, -1..9, &[0], &mut |r| {
            queries += 1;
            field(r)
        });
        assert_eq!(queries, 1);
    }
}
