//! Resampling between square grids of any two pixel sizes, for grids that do not nest (a
//! 1 km learned grid onto a 160 m model grid, the 8 km climate grid onto it).
//!
//! Pixel `i` of a grid of `to` metres has its centre at `(i + ½)·to` metres, which is
//! coordinate `(i + ½)·ratio − ½` on the grid of `from` metres (`ratio = to / from`). That
//! coordinate is computed from `i` alone, so a pixel's value depends only on its global index
//! and the source values: two requests agree bit for bit wherever they overlap.

use crate::tile::{Rect, Tile};

/// Source coordinate of target pixel `i`.
fn coord(i: i64, ratio: f64) -> f64 {
    (i as f64 + 0.5) * ratio - 0.5
}

/// The source index range `[lo, hi)` that target pixels `[d0, d1)` read with `reach` taps
/// before and `1 + reach` after the cell below them.
fn span(d0: i64, d1: i64, ratio: f64, reach: i64) -> (i64, i64) {
    (coord(d0, ratio).floor() as i64 - reach, coord(d1 - 1, ratio).floor() as i64 + 2 + reach)
}

/// The source rectangle [`bilinear`] reads for `target` (`reach` 0) or [`cubic`] (`reach` 1).
pub fn source_rect(target: &Rect, ratio: f64, reach: i64) -> Rect {
    let (y0, y1) = span(target.y0, target.y1(), ratio, reach);
    let (x0, x1) = span(target.x0, target.x1(), ratio, reach);
    Rect::new(y0, x0, y1 - y0, x1 - x0)
}

/// Index of the source cell below each target pixel (relative to `origin`) and the fraction
/// toward the next one.
fn taps(d0: i64, n: i64, ratio: f64, origin: i64) -> Taps {
    (d0..d0 + n)
        .map(|d| {
            let u = coord(d, ratio);
            let i = u.floor();
            ((i as i64 - origin) as usize, u - i)
        })
        .collect()
}

/// One axis's taps: for each target index, the source index at or before it and the fraction
/// toward the next.
type Taps = Vec<(usize, f64)>;

/// The row and column taps of `target` on `source`, which must cover
/// [`source_rect`]`(target, ratio, reach)`.
fn plan(source: &Tile, ratio: f64, target: Rect, reach: i64) -> (Taps, Taps) {
    let need = source_rect(&target, ratio, reach);
    assert!(source.rect.contains_rect(&need), "resampling {target:?} needs {need:?}, got {:?}", source.rect);
    (taps(target.y0, target.h, ratio, source.rect.y0), taps(target.x0, target.w, ratio, source.rect.x0))
}

/// Catmull-Rom weights of the taps at −1, 0, 1, 2 for fraction `t`.
fn catmull_rom(t: f64) -> [f64; 4] {
    let (t2, t3) = (t * t, t * t * t);
    [(-t3 + 2.0 * t2 - t) / 2.0, (3.0 * t3 - 5.0 * t2 + 2.0) / 2.0, (-3.0 * t3 + 4.0 * t2 + t) / 2.0, (t3 - t2) / 2.0]
}

/// Every channel of `source` bilinearly resampled onto `target` (`ratio` = target pixel /
/// source pixel); `source` must cover [`source_rect`]`(target, ratio, 0)`.
pub fn bilinear(source: &Tile, ratio: f64, target: Rect) -> Tile {
    let (ty, tx) = plan(source, ratio, target, 0);
    let sw = source.width();
    let mut out = Tile::zeros(source.channels, target);
    let mut k = 0;
    for c in 0..source.channels {
        let plane = source.channel(c);
        for &(iy, wy) in &ty {
            for &(ix, wx) in &tx {
                let at = |y: usize, x: usize| f64::from(plane[y * sw + x]);
                let top = at(iy, ix) + wx * (at(iy, ix + 1) - at(iy, ix));
                let bottom = at(iy + 1, ix) + wx * (at(iy + 1, ix + 1) - at(iy + 1, ix));
                out.data[k] = (top + wy * (bottom - top)) as f32;
                k += 1;
            }
        }
    }
    out
}

/// Every channel of `source` resampled onto `target` with the Catmull-Rom cubic (smooth
/// slopes across source cell borders, where bilinear leaves creases); `source` must cover
/// [`source_rect`]`(target, ratio, 1)`.
pub fn cubic(source: &Tile, ratio: f64, target: Rect) -> Tile {
    let (ty, tx) = plan(source, ratio, target, 1);
    let wx: Vec<[f64; 4]> = tx.iter().map(|&(_, t)| catmull_rom(t)).collect();
    let sw = source.width();
    let mut out = Tile::zeros(source.channels, target);
    let mut k = 0;
    for c in 0..source.channels {
        let plane = source.channel(c);
        for &(iy, ty) in &ty {
            let wy = catmull_rom(ty);
            for (&(ix, _), wx) in tx.iter().zip(&wx) {
                let mut v = 0.0;
                for (r, wr) in wy.iter().enumerate() {
                    let row = &plane[(iy + r - 1) * sw..];
                    let line: f64 = (0..4).map(|q| wx[q] * f64::from(row[ix + q - 1])).sum();
                    v += wr * line;
                }
                out.data[k] = v as f32;
                k += 1;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plane(rect: Rect, f: impl Fn(f64, f64) -> f64) -> Tile {
        let data = (rect.y0..rect.y1())
            .flat_map(|y| (rect.x0..rect.x1()).map(move |x| (y, x)))
            .map(|(y, x)| f(y as f64, x as f64) as f32)
            .collect();
        Tile::from_data(1, rect, data)
    }

    #[test]
    fn both_kernels_reproduce_a_plane_at_any_ratio() {
        let f = |y: f64, x: f64| 3.0 * y - 2.0 * x + 10.0;
        for ratio in [0.25, 0.32, 0.5, 0.8, 1.0 / 3.0] {
            let target = Rect::new(-17, 29, 13, 11);
            for (reach, up) in [(0, bilinear as fn(&Tile, f64, Rect) -> Tile), (1, cubic)] {
                let src = plane(source_rect(&target, ratio, reach), f);
                let out = up(&src, ratio, target);
                for y in target.y0..target.y1() {
                    for x in target.x0..target.x1() {
                        let want = f(coord(y, ratio), coord(x, ratio));
                        assert!((f64::from(out.get(0, y, x)) - want).abs() < 1e-3, "ratio {ratio} ({y},{x})");
                    }
                }
            }
        }
    }

    #[test]
    fn overlapping_requests_agree_bit_for_bit() {
        let f = |y: f64, x: f64| (y * 0.7).sin() * 100.0 + (x * 0.3).cos() * 50.0;
        let ratio = 0.32;
        let (a, b) = (Rect::new(0, 0, 40, 40), Rect::new(23, 17, 40, 40));
        let whole = plane(source_rect(&Rect::new(0, 0, 63, 57), ratio, 1), f);
        let ta = cubic(&whole.crop(source_rect(&a, ratio, 1)), ratio, a);
        let tb = cubic(&whole.crop(source_rect(&b, ratio, 1)), ratio, b);
        for y in 23..40 {
            for x in 17..40 {
                assert_eq!(ta.get(0, y, x).to_bits(), tb.get(0, y, x).to_bits());
            }
        }
    }
}
