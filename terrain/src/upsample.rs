//! Bilinear upsampling between grids whose cells nest (`factor` fine cells per coarse cell).
//!
//! Fine cell `d` has its centre at coarse coordinate `(d + ½)/f − ½`, written exactly as the
//! fraction `(2d + 1 − f) / 2f`. Everything is integer arithmetic up to the final blend, so a
//! fine cell's value depends only on its global index and the coarse values — two adjacent
//! requests agree bit for bit on their shared border.

use crate::tile::{div_floor, Rect, Tile};

fn source_span(d0: i64, d1: i64, f: i64) -> (i64, i64) {
    (div_floor(2 * d0 + 1 - f, 2 * f), div_floor(2 * (d1 - 1) + 1 - f, 2 * f) + 1)
}

/// The coarse rectangle needed to upsample `fine` by `factor` (one cell of padding where the
/// blend reaches across a coarse cell border).
pub fn source_rect(fine: &Rect, factor: i64) -> Rect {
    let (y0, y1) = source_span(fine.y0, fine.y1(), factor);
    let (x0, x1) = source_span(fine.x0, fine.x1(), factor);
    Rect::new(y0, x0, y1 - y0 + 1, x1 - x0 + 1)
}

/// Index of the coarse cell below fine cell `d` and the blend weight toward the next one.
fn taps(d0: i64, n: i64, f: i64, origin: i64) -> Vec<(usize, f32)> {
    (d0..d0 + n)
        .map(|d| {
            let num = 2 * d + 1 - f;
            let i = div_floor(num, 2 * f);
            let t = (num - i * 2 * f) as f32 / (2 * f) as f32;
            ((i - origin) as usize, t)
        })
        .collect()
}

/// Upsamples every channel of `coarse` onto `fine` (which must be covered per
/// [`source_rect`]).
pub fn bilinear(coarse: &Tile, factor: i64, fine: Rect) -> Tile {
    let need = source_rect(&fine, factor);
    assert!(coarse.rect.contains_rect(&need), "upsampling {fine:?} needs {need:?}, got {:?}", coarse.rect);
    let ty = taps(fine.y0, fine.h, factor, coarse.rect.y0);
    let tx = taps(fine.x0, fine.w, factor, coarse.rect.x0);
    let (cw, ch) = (coarse.width(), coarse.height());
    let mut out = Tile::zeros(coarse.channels, fine);
    let mut i = 0;
    for c in 0..coarse.channels {
        let plane = &coarse.data[c * cw * ch..(c + 1) * cw * ch];
        for &(iy, wy) in &ty {
            let (r0, r1) = (&plane[iy * cw..(iy + 1) * cw], &plane[(iy + 1) * cw..(iy + 2) * cw]);
            for &(ix, wx) in &tx {
                let top = r0[ix] + wx * (r0[ix + 1] - r0[ix]);
                let bottom = r1[ix] + wx * (r1[ix + 1] - r1[ix]);
                out.data[i] = top + wy * (bottom - top);
                i += 1;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(rect: Rect) -> Tile {
        let data = (rect.y0..rect.y1()).flat_map(|y| (rect.x0..rect.x1()).map(move |x| (3 * y + x) as f32)).collect();
        Tile::from_data(1, rect, data)
    }

    #[test]
    fn a_linear_ramp_stays_linear() {
        let fine = Rect::new(-9, 13, 11, 7);
        let coarse = ramp(source_rect(&fine, 4));
        let up = bilinear(&coarse, 4, fine);
        for y in fine.y0..fine.y1() {
            for x in fine.x0..fine.x1() {
                let cy = (y as f32 + 0.5) / 4.0 - 0.5;
                let cx = (x as f32 + 0.5) / 4.0 - 0.5;
                assert!((up.get(0, y, x) - (3.0 * cy + cx)).abs() < 1e-4);
            }
        }
    }

    #[test]
    fn neighbouring_requests_agree_bit_for_bit() {
        let big = Rect::new(-40, -40, 80, 80);
        let coarse = ramp(source_rect(&big, 4)).crop(source_rect(&big, 4));
        let all = bilinear(&coarse, 4, big);
        for r in [Rect::new(-40, -40, 16, 16), Rect::new(-24, -40, 16, 16), Rect::new(5, 7, 3, 30)] {
            let part = bilinear(&coarse.crop(source_rect(&r, 4)), 4, r);
            assert_eq!(part, all.crop(r));
        }
    }
}
