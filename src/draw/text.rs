//! Bitmap text with the public-domain 8×8 font, scaled by whole pixels.
//!
//! ASCII, Latin-1 (`°`, `²`, `×`, …) and Greek (`β`, `χ`, `Δ`); anything else draws as `?` so
//! a label never silently loses characters. Pixels outside the image are clipped, so long
//! lines are cut at the edge instead of panicking.

use font8x8::{UnicodeFonts, BASIC_FONTS, GREEK_FONTS, LATIN_FONTS};
use image::{Rgb, RgbImage};

use super::shapes::fill;

/// Glyph cell size in font pixels (before scaling).
pub const GLYPH: u32 = 8;

/// The glyph of `ch`: one byte per row, bit 0 the leftmost pixel.
fn glyph(ch: char) -> [u8; 8] {
    BASIC_FONTS
        .get(ch)
        .or_else(|| LATIN_FONTS.get(ch))
        .or_else(|| GREEK_FONTS.get(ch))
        .unwrap_or_else(|| BASIC_FONTS.get('?').unwrap_or([0; 8]))
}

/// Width in image pixels of `text` at `scale`.
pub fn width(text: &str, scale: u32) -> u32 {
    text.chars().count() as u32 * GLYPH * scale
}

/// Draws `text` with its top-left corner at (`x`, `y`), each font pixel `scale`×`scale` image
/// pixels; returns the x just past the text.
pub fn text(img: &mut RgbImage, x: i64, y: i64, text: &str, scale: u32, colour: Rgb<u8>) -> i64 {
    let step = (GLYPH * scale) as i64;
    let mut cx = x;
    for ch in text.chars() {
        let rows = glyph(ch);
        for (gy, bits) in rows.iter().enumerate() {
            for gx in 0..8 {
                if bits & (1 << gx) != 0 {
                    fill(img, cx + gx * scale as i64, y + gy as i64 * scale as i64, scale, scale, colour);
                }
            }
        }
        cx += step;
    }
    cx
}

#[cfg(test)]
mod tests {
    use super::*;

    const WHITE: Rgb<u8> = Rgb([255, 255, 255]);
    const BLACK: Rgb<u8> = Rgb([0, 0, 0]);

    fn inked(img: &RgbImage) -> Vec<(u32, u32)> {
        img.enumerate_pixels().filter(|(_, _, p)| **p == BLACK).map(|(x, y, _)| (x, y)).collect()
    }

    #[test]
    fn text_is_drawn_inside_its_box() {
        let mut img = RgbImage::from_pixel(100, 40, WHITE);
        let end = text(&mut img, 10, 5, "Hi 42", 2, BLACK);
        assert_eq!(end, 10 + width("Hi 42", 2) as i64);
        let ink = inked(&img);
        assert!(ink.len() > 50, "only {} pixels inked", ink.len());
        for (x, y) in ink {
            assert!((10..90).contains(&x) && (5..21).contains(&y), "pixel ({x},{y}) outside the text box");
        }
    }

    #[test]
    fn ascii_degree_and_times_are_the_legacy_glyphs_and_greek_is_drawn() {
        use font8x8::legacy::{BASIC_LEGACY, LATIN_LEGACY};
        for c in 0u8..128 {
            assert_eq!(glyph(c as char), BASIC_LEGACY[c as usize], "{c}");
        }
        for c in ['°', '×'] {
            assert_eq!(glyph(c), LATIN_LEGACY[c as usize - 0xA0], "{c}");
        }
        for c in ['β', 'χ', 'Δ'] {
            assert_ne!(glyph(c), glyph('?'), "{c}");
        }
    }

    #[test]
    fn degree_sign_and_unknown_characters_draw_something() {
        for s in ["°", "×", "€"] {
            let mut img = RgbImage::from_pixel(8, 8, WHITE);
            text(&mut img, 0, 0, s, 1, BLACK);
            assert!(!inked(&img).is_empty(), "{s} drew nothing");
        }
    }

    #[test]
    fn drawing_off_the_edge_is_clipped() {
        let mut img = RgbImage::from_pixel(10, 10, WHITE);
        text(&mut img, -20, -3, "WWWWWW", 3, BLACK);
        text(&mut img, 5, 5, "W", 4, BLACK);
        assert!(!inked(&img).is_empty());
    }
}
