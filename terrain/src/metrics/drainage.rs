//! Drainage: closed depressions found by Priority-Flood (Barnes, Lehman & Mulla 2014).
//!
//! Eroded real terrain drains: almost every cell has a downhill path to the sea or the map
//! edge. Noise terrain is full of closed basins. Filling every depression to its spill level
//! and counting what was filled measures that difference.

use std::cmp::{Ordering, Reverse};
use std::collections::BinaryHeap;

use super::Raster;

/// Depressions shallower than this (metres) are not counted: 1 m is below the vertical
/// precision of the GLOBE/GEBCO/ETOPO integer-metre sources, so shallower "pits" are
/// quantisation, not landforms.
pub const MIN_DEPRESSION_DEPTH_M: f32 = 1.0;

/// The 8 neighbours (D8 flow, the usual hydrology convention).
const NEIGHBOURS: [(isize, isize); 8] = [(-1, -1), (-1, 0), (-1, 1), (0, -1), (0, 1), (1, -1), (1, 0), (1, 1)];

/// A heap entry ordered by elevation, then by insertion order (so ties are deterministic).
#[derive(PartialEq)]
struct Cell(f32, u64, usize);

impl Eq for Cell {}

impl Ord for Cell {
    fn cmp(&self, other: &Cell) -> Ordering {
        self.0.total_cmp(&other.0).then(self.1.cmp(&other.1))
    }
}

impl PartialOrd for Cell {
    fn partial_cmp(&self, other: &Cell) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

fn neighbours(i: usize, rows: usize, cols: usize) -> impl Iterator<Item = usize> {
    let (y, x) = ((i / cols) as isize, (i % cols) as isize);
    NEIGHBOURS.iter().filter_map(move |&(dy, dx)| {
        let (ny, nx) = (y + dy, x + dx);
        (ny >= 0 && nx >= 0 && (ny as usize) < rows && (nx as usize) < cols).then(|| ny as usize * cols + nx as usize)
    })
}

/// The depression-filled surface: each cell raised to the lowest level at which water could
/// leave it for an outlet — the raster's edge, a non-finite (no-data) cell, or any cell at or
/// below `sea_level` when given (the sea swallows what flows into it).
pub fn priority_flood(r: &Raster, sea_level: Option<f32>) -> Vec<f32> {
    let (rows, cols) = (r.rows, r.cols);
    let mut filled = r.data.clone();
    let mut closed = vec![false; filled.len()];
    let mut open = BinaryHeap::new();
    let mut order = 0u64;
    for (i, &z) in r.data.iter().enumerate() {
        let (y, x) = (i / cols, i % cols);
        let edge = y == 0 || x == 0 || y + 1 == rows || x + 1 == cols;
        let outlet = !z.is_finite() || sea_level.is_some_and(|s| z <= s);
        if edge || outlet {
            closed[i] = true;
            open.push(Reverse(Cell(if z.is_finite() { z } else { f32::NEG_INFINITY }, order, i)));
            order += 1;
        }
    }
    while let Some(Reverse(Cell(_, _, c))) = open.pop() {
        for n in neighbours(c, rows, cols) {
            if !closed[n] {
                closed[n] = true;
                // f32::max ignores a NaN spill level, so a no-data outlet drains freely.
                filled[n] = filled[n].max(filled[c]);
                open.push(Reverse(Cell(filled[n], order, n)));
                order += 1;
            }
        }
    }
    filled
}

/// Depression statistics of one raster.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Depressions {
    /// Distinct filled depressions (8-connected areas raised by the fill) at least
    /// [`MIN_DEPRESSION_DEPTH_M`] deep.
    pub count: usize,
    /// Volume of all filling, m³.
    pub fill_volume_m3: f64,
    /// Area measured, km².
    pub area_km2: f64,
}

impl Depressions {
    /// Adds another raster's statistics (densities of a set of tiles are pooled, not averaged).
    pub fn add(&mut self, other: Depressions) {
        self.count += other.count;
        self.fill_volume_m3 += other.fill_volume_m3;
        self.area_km2 += other.area_km2;
    }

    /// Depressions per 1000 km².
    pub fn per_1000_km2(&self) -> f64 {
        1000.0 * self.count as f64 / self.area_km2
    }

    /// Fill volume per area, m³/km² (equal to the mean fill depth in metres × 10⁶).
    pub fn volume_per_km2(&self) -> f64 {
        self.fill_volume_m3 / self.area_km2
    }
}

/// Fills `r` (see [`priority_flood`]) and measures what was filled.
pub fn depressions(r: &Raster, sea_level: Option<f32>) -> Depressions {
    let filled = priority_flood(r, sea_level);
    let depth: Vec<f32> = filled.iter().zip(&r.data).map(|(f, z)| if z.is_finite() { f - z } else { 0.0 }).collect();
    let cell_m2 = r.metres * r.metres;
    let mut seen = vec![false; depth.len()];
    let mut count = 0;
    let mut stack = Vec::new();
    for start in 0..depth.len() {
        if seen[start] || depth[start] <= 0.0 {
            continue;
        }
        // Flood one connected filled area, tracking its deepest point.
        let mut deepest = 0.0f32;
        seen[start] = true;
        stack.push(start);
        while let Some(c) = stack.pop() {
            deepest = deepest.max(depth[c]);
            for n in neighbours(c, r.rows, r.cols) {
                if !seen[n] && depth[n] > 0.0 {
                    seen[n] = true;
                    stack.push(n);
                }
            }
        }
        if deepest >= MIN_DEPRESSION_DEPTH_M {
            count += 1;
        }
    }
    let fill_volume_m3 = depth.iter().map(|&d| d as f64).sum::<f64>() * cell_m2;
    Depressions { count, fill_volume_m3, area_km2: r.len() as f64 * cell_m2 / 1e6 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::fbm::Gaussian;

    /// The fill by brute force: start every interior cell at +∞ and relax
    /// `F = max(z, min(F of neighbours))` until nothing changes.
    fn relaxation_fill(r: &Raster) -> Vec<f32> {
        let (rows, cols) = (r.rows, r.cols);
        let mut f: Vec<f32> = (0..r.len())
            .map(|i| {
                let (y, x) = (i / cols, i % cols);
                if y == 0 || x == 0 || y + 1 == rows || x + 1 == cols {
                    r.data[i]
                } else {
                    f32::INFINITY
                }
            })
            .collect();
        loop {
            let mut changed = false;
            for i in 0..f.len() {
                let lowest = neighbours(i, rows, cols).map(|n| f[n]).fold(f32::INFINITY, f32::min);
                let v = r.data[i].max(lowest).min(f[i]);
                if v != f[i] {
                    f[i] = v;
                    changed = true;
                }
            }
            if !changed {
                return f;
            }
        }
    }

    #[test]
    fn priority_flood_equals_brute_force_relaxation() {
        let mut g = Gaussian::new(3);
        for trial in 0..20 {
            let (rows, cols) = (3 + trial % 7, 4 + (trial * 3) % 9);
            // Coarse integer values make many ties and flats, the hard cases.
            let r = Raster::from_fn(rows, cols, 1.0, |_, _| {
                if trial % 2 == 0 {
                    (g.next() * 3.0).round() as f32
                } else {
                    g.next() as f32
                }
            });
            assert_eq!(priority_flood(&r, None), relaxation_fill(&r), "trial {trial}: {r:?}");
        }
    }

    fn cone(depth: f32, radius: f32, inverted: bool) -> Raster {
        Raster::from_fn(41, 41, 10.0, |y, x| {
            let r = ((y as f32 - 20.0).powi(2) + (x as f32 - 20.0).powi(2)).sqrt() / radius;
            if inverted {
                depth * r.min(1.0)
            } else {
                depth * (1.0 - r).max(0.0)
            }
        })
    }

    #[test]
    fn an_upright_cone_has_no_pit() {
        let d = depressions(&cone(300.0, 15.0, false), None);
        assert_eq!((d.count, d.fill_volume_m3), (0, 0.0));
        assert!((d.area_km2 - 41.0 * 41.0 * 100.0 / 1e6).abs() < 1e-12);
    }

    #[test]
    fn an_inverted_cone_is_one_depression_of_the_cone_volume() {
        let (depth, radius_px) = (300.0, 15.0);
        let d = depressions(&cone(depth, radius_px, true), None);
        assert_eq!(d.count, 1);
        let radius_m = radius_px as f64 * 10.0;
        let analytic = std::f64::consts::PI * radius_m * radius_m * depth as f64 / 3.0;
        let error = (d.fill_volume_m3 - analytic).abs() / analytic;
        assert!(error < 0.02, "fill {} m³ vs cone {analytic} m³ ({:.1} %)", d.fill_volume_m3, error * 100.0);
    }

    #[test]
    fn shallow_pits_sea_and_no_data_are_not_depressions() {
        let mut r = Raster::from_fn(7, 7, 100.0, |_, _| 10.0);
        r.data[2 * 7 + 2] = 9.5; // 0.5 m: below the threshold, filled but not counted
        r.data[4 * 7 + 4] = -20.0; // below sea level: an outlet when the sea counts
        let d = depressions(&r, None);
        assert_eq!(d.count, 1, "the sub-sea hole is a depression without a sea");
        assert_eq!(depressions(&r, Some(0.0)).count, 0);
        r.data[4 * 7 + 4] = f32::NAN;
        let d = depressions(&r, None);
        assert_eq!(d.count, 0);
        assert!((d.fill_volume_m3 - 0.5 * 100.0 * 100.0).abs() < 1e-6, "only the shallow pit is filled");
    }
}
