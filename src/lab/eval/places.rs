//! How far apart real *places* lie in slope distribution: the real-vs-real distance a
//! generated place is fairly judged against.
//!
//! The prepared sets hold their tiles out in small squares interleaved with training tiles
//! (their manifest's `heldout_region`), so the two splits sample the same ground everywhere and
//! their slope W1 (the table's "train (real)" column) is tile-sampling noise: 0.03° on a
//! 110 km savanna. A generated export is one place, and another real place of the same relief
//! class lies farther from the reference than that. Here the real tiles (both splits: nothing
//! trains on the block-scale sets) are cut into the four quarters of their tile grid, and each
//! quarter's slope distribution is measured against the other three quarters' — real ground
//! against real ground it does not contain.

use crate::terrain::metrics::wasserstein1;

/// The slope W1 of each quarter of the real landscape to the rest of it, beside the generated
/// terrain's W1 to the reference.
#[derive(Clone, Debug, PartialEq)]
pub struct PlaceFloor {
    /// Tiles in each quarter that has any (north-west, north-east, south-west, south-east).
    pub tiles: Vec<usize>,
    /// Each quarter's slope W1 to the other quarters, degrees, ascending.
    pub distances: Vec<f64>,
    /// The generated terrain's slope W1 to the reference, degrees.
    pub generated: f64,
    /// The splits' floor (training tiles to held-out tiles), degrees.
    pub floor: f64,
}

impl PlaceFloor {
    /// The median place's distance (the mean of the middle two for an even count).
    pub fn median(&self) -> f64 {
        let d = &self.distances;
        let n = d.len();
        if n % 2 == 1 {
            d[n / 2]
        } else {
            0.5 * (d[n / 2 - 1] + d[n / 2])
        }
    }

    /// Whether the generated terrain lies within 2× the median real place's distance.
    pub fn met(&self) -> bool {
        self.generated <= 2.0 * self.median()
    }
}

/// Cuts tiles by `cells` ((row, column) in the set's tile grid, one per entry of `slopes`) into
/// the quarters of their bounding grid (the odd middle row or column goes south or east) and
/// measures each quarter's slopes against all other tiles'. `None` when fewer than two quarters
/// hold tiles or the cells do not match the tiles.
pub fn place_floor(slopes: &[Vec<f32>], cells: &[(i64, i64)], generated: f64, floor: f64) -> Option<PlaceFloor> {
    if cells.len() != slopes.len() || cells.is_empty() {
        return None;
    }
    let span = |pick: fn(&(i64, i64)) -> i64| {
        let (lo, hi) = cells.iter().map(pick).fold((i64::MAX, i64::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)));
        lo + (hi - lo + 1) / 2
    };
    let (mid_row, mid_col) = (span(|c| c.0), span(|c| c.1));
    let quarter = |&(row, col): &(i64, i64)| 2 * usize::from(row >= mid_row) + usize::from(col >= mid_col);
    let (mut tiles, mut distances) = (Vec::new(), Vec::new());
    for q in 0..4 {
        let (inside, outside): (Vec<_>, Vec<_>) = cells.iter().zip(slopes).partition(|(c, _)| quarter(c) == q);
        if inside.is_empty() || outside.is_empty() {
            continue;
        }
        let gather = |part: Vec<(&(i64, i64), &Vec<f32>)>| -> Vec<f32> {
            part.into_iter().flat_map(|(_, s)| s.iter().copied()).collect()
        };
        tiles.push(inside.len());
        distances.push(wasserstein1(&gather(inside), &gather(outside)));
    }
    if distances.len() < 2 {
        return None;
    }
    distances.sort_unstable_by(f64::total_cmp);
    Some(PlaceFloor { tiles, distances, generated, floor })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Slopes of a tile: 100 values spread evenly over ±1° around `centre`.
    fn tile(centre: f32) -> Vec<f32> {
        (0..100).map(|i| centre + (i as f32 - 50.0) / 50.0).collect()
    }

    #[test]
    fn a_landscape_alike_everywhere_has_places_close_together_and_one_that_is_not_stands_out() {
        // A 4×4 grid of tiles.
        let cells: Vec<(i64, i64)> = (0..16).map(|i| (i / 4, i % 4)).collect();
        let alike: Vec<Vec<f32>> = cells.iter().map(|_| tile(10.0)).collect();
        let even = place_floor(&alike, &cells, 1.0, 0.0).unwrap();
        assert_eq!(even.tiles, vec![4, 4, 4, 4]);
        assert!(even.distances.iter().all(|&d| d < 1e-9), "{even:?}");
        assert!(!even.met(), "any distance is more than 2× nothing");

        // The south-east quarter 4° steeper: it lies 4° from the rest, each other quarter less.
        let steep: Vec<Vec<f32>> =
            cells.iter().map(|&(r, c)| tile(if r >= 2 && c >= 2 { 14.0 } else { 10.0 })).collect();
        let uneven = place_floor(&steep, &cells, 2.0, 0.0).unwrap();
        let top = *uneven.distances.last().unwrap();
        assert!((top - 4.0).abs() < 1e-6, "the steep quarter against the three others: {uneven:?}");
        // Each other quarter sees a third of the rest 4° steeper: W1 = 4/3.
        assert!(uneven.distances[..3].iter().all(|&d| (d - 4.0 / 3.0).abs() < 1e-6), "{uneven:?}");
        assert!((uneven.median() - 4.0 / 3.0).abs() < 1e-6);
        assert!(uneven.met(), "2.0 ≤ 2 × 4/3");
        assert!(!PlaceFloor { generated: 2.7, ..uneven }.met());
    }

    #[test]
    fn an_odd_grid_gives_its_middle_row_and_column_to_the_south_and_east_and_bad_cells_give_none() {
        let cells: Vec<(i64, i64)> = (0..25).map(|i| (i / 5 + 10, i % 5 - 3)).collect();
        let slopes: Vec<Vec<f32>> = cells.iter().map(|_| tile(5.0)).collect();
        let p = place_floor(&slopes, &cells, 0.0, 0.0).unwrap();
        // Rows 10..14 split at 12 (two north, three south); columns likewise.
        assert_eq!(p.tiles, vec![4, 6, 6, 9]);
        assert!(place_floor(&slopes[..3], &cells, 0.0, 0.0).is_none(), "cells and tiles differ in number");
        let one_quarter = vec![(0, 0), (0, 0)];
        assert!(place_floor(&slopes[..2], &one_quarter, 0.0, 0.0).is_none(), "one place has no other to meet");
    }
}
