//! Pixels, rectangles and lines, clipped to the image.

use image::{Rgb, RgbImage};

/// Sets the pixel at (`x`, `y`) when it lies inside the image.
pub fn put(img: &mut RgbImage, x: i64, y: i64, colour: Rgb<u8>) {
    if x >= 0 && y >= 0 && (x as u32) < img.width() && (y as u32) < img.height() {
        img.put_pixel(x as u32, y as u32, colour);
    }
}

/// Fills a `w`×`h` rectangle at (`x`, `y`), clipped to the image.
pub fn fill(img: &mut RgbImage, x: i64, y: i64, w: u32, h: u32, colour: Rgb<u8>) {
    let (iw, ih) = (img.width() as i64, img.height() as i64);
    for py in y.max(0)..(y + h as i64).min(ih) {
        for px in x.max(0)..(x + w as i64).min(iw) {
            img.put_pixel(px as u32, py as u32, colour);
        }
    }
}

/// A one-pixel frame just outside the `w`×`h` rectangle at (`x`, `y`).
pub fn outline(img: &mut RgbImage, x: i64, y: i64, w: i64, h: i64, colour: Rgb<u8>) {
    fill(img, x - 1, y - 1, w as u32 + 2, 1, colour);
    fill(img, x - 1, y + h, w as u32 + 2, 1, colour);
    fill(img, x - 1, y, 1, h as u32, colour);
    fill(img, x + w, y, 1, h as u32, colour);
}

/// A line from `a` to `b`, `width` pixels thick (a square brush along a DDA walk).
pub fn line(img: &mut RgbImage, a: (f64, f64), b: (f64, f64), width: i64, colour: Rgb<u8>) {
    let steps = (b.0 - a.0).abs().max((b.1 - a.1).abs()).ceil().max(1.0) as i64;
    for s in 0..=steps {
        let t = s as f64 / steps as f64;
        let (x, y) = ((a.0 + t * (b.0 - a.0)).round() as i64, (a.1 + t * (b.1 - a.1)).round() as i64);
        for dy in 0..width {
            for dx in 0..width {
                put(img, x + dx - width / 2, y + dy - width / 2, colour);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const WHITE: Rgb<u8> = Rgb([255, 255, 255]);
    const BLACK: Rgb<u8> = Rgb([0, 0, 0]);

    #[test]
    fn shapes_are_clipped_and_outlines_sit_outside_their_box() {
        let mut img = RgbImage::from_pixel(10, 10, WHITE);
        fill(&mut img, -5, -5, 8, 8, BLACK);
        assert_eq!(img.pixels().filter(|p| **p == BLACK).count(), 9);
        let mut img = RgbImage::from_pixel(10, 10, WHITE);
        outline(&mut img, 2, 2, 4, 4, BLACK);
        assert_eq!(img.pixels().filter(|p| **p == BLACK).count(), 4 * 4 + 4);
        assert_eq!(*img.get_pixel(3, 3), WHITE);
        line(&mut img, (-3.0, 0.0), (20.0, 9.0), 2, BLACK);
    }
}
