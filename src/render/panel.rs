//! The information panel under a map: title lines, a colour legend with ticks and units, and
//! a scale bar in blocks and kilometres — so a PNG on its own says what it shows.

use image::{Rgb, RgbImage};

use super::ramp::to_rgb;
use crate::draw::{self, outline, GLYPH};

/// Panel background.
pub(crate) const BACKGROUND: Rgb<u8> = Rgb([250, 250, 248]);
const INK: Rgb<u8> = Rgb([24, 24, 24]);
const GREY: Rgb<u8> = Rgb([150, 150, 150]);

/// Narrowest frame: room for an 80-column title line at text scale 1.
pub(crate) const MIN_FRAME_WIDTH: u32 = 80 * GLYPH;
/// Frames at least this wide get double-size text so it stays legible when viewed scaled
/// down.
const WIDE_FRAME: u32 = 1600;
/// Title lines in every panel.
pub(crate) const TITLE_LINES: usize = 3;

/// How a layer's colour legend is drawn.
pub(crate) struct Legend {
    /// What the colours mean, with units, e.g. `elevation (m)`.
    pub caption: &'static str,
    /// Bar position (0 = left end, 1 = right end) → value.
    pub value_at: fn(f32) -> f32,
    /// Value → bar position (the inverse of `value_at`), for placing ticks.
    pub position_of: fn(f32) -> f32,
    /// Value → colour, the same function the map uses.
    pub colour: fn(f32) -> [f32; 3],
    /// Values to tick and label, in increasing order.
    pub ticks: &'static [f32],
}

/// Text scale for a frame `width` pixels wide.
pub(crate) fn text_scale(width: u32) -> u32 {
    if width >= WIDE_FRAME {
        2
    } else {
        1
    }
}

/// Vertical layout in font pixels (multiply by the text scale).
const MARGIN: u32 = 8;
const LINE: u32 = GLYPH + 4;
const BAR: u32 = 12;
const TICK: u32 = 3;
const SCALE_BAR: u32 = 5;

/// Height of the panel at text `scale`.
pub(crate) fn height(scale: u32) -> u32 {
    let title = TITLE_LINES as u32 * LINE;
    let legend = LINE + BAR + TICK + 2 + GLYPH;
    let scale_bar = LINE + SCALE_BAR;
    scale * (MARGIN + title + MARGIN + legend + MARGIN + scale_bar + MARGIN)
}

/// Draws the panel into the rows of `img` from `top` down.
pub(crate) fn draw(
    img: &mut RgbImage,
    top: u32,
    title: &[String],
    legend: &Legend,
    (metres_per_px, block_metres): (f64, f64),
    scale: u32,
) {
    let width = img.width();
    draw::fill(img, 0, top as i64, width, img.height() - top, BACKGROUND);
    let s = scale as i64;
    let margin = MARGIN as i64 * s;
    let mut y = top as i64 + margin;
    for line in title {
        draw::text(img, margin, y, line, scale, INK);
        y += LINE as i64 * s;
    }
    y += margin;
    y = draw_legend(img, margin, y, legend, scale);
    y += margin;
    draw_scale_bar(img, margin, y, (metres_per_px, block_metres), scale);
}

/// Draws the legend at (`x`, `y`); returns the y below it.
fn draw_legend(img: &mut RgbImage, x: i64, y: i64, legend: &Legend, scale: u32) -> i64 {
    let s = scale as i64;
    draw::text(img, x, y, legend.caption, scale, INK);
    let bar_top = y + LINE as i64 * s;
    let bar_w = (img.width() as i64 - 2 * x).min(400 * s).max(1);
    let bar_h = BAR * scale;
    for i in 0..bar_w {
        let value = (legend.value_at)((i as f32 + 0.5) / bar_w as f32);
        draw::fill(img, x + i, bar_top, 1, bar_h, to_rgb((legend.colour)(value)));
    }
    outline(img, x, bar_top, bar_w, bar_h as i64, INK);

    let tick_top = bar_top + bar_h as i64;
    let label_top = tick_top + (TICK as i64 + 2) * s;
    // Labels are centred on their tick; one that would overlap its left neighbour is skipped
    // (its tick stays), so dense ticks on narrow maps stay readable.
    let mut free_from = i64::MIN;
    for &v in legend.ticks {
        let tx = x + ((legend.position_of)(v).clamp(0.0, 1.0) * (bar_w - 1) as f32).round() as i64;
        draw::fill(img, tx, tick_top, scale, TICK * scale, INK);
        let label = number(v);
        let lw = draw::width(&label, scale) as i64;
        let lx = (tx - lw / 2).clamp(0, (img.width() as i64 - lw).max(0));
        if lx >= free_from {
            draw::text(img, lx, label_top, &label, scale, INK);
            free_from = lx + lw + GLYPH as i64 * s;
        }
    }
    label_top + GLYPH as i64 * s
}

/// Draws a scale bar at (`x`, `y`) about a quarter of the frame wide, labelled in blocks and
/// kilometres.
fn draw_scale_bar(img: &mut RgbImage, x: i64, y: i64, (metres_per_px, block_metres): (f64, f64), scale: u32) {
    let s = scale as i64;
    let target_px = (img.width() as f64 / 4.0).min(300.0 * scale as f64);
    let km = nice_length_km(target_px * metres_per_px / 1000.0);
    let px = ((km * 1000.0 / metres_per_px).round() as i64).max(1);
    let blocks = km * 1000.0 / block_metres;
    let label = format!("{} blocks = {} km", number(blocks as f32), number(km as f32));
    draw::text(img, x, y, &label, scale, INK);
    let bar_top = y + LINE as i64 * s;
    let bar_h = (SCALE_BAR * scale) as i64;
    // Alternating quarters, as on printed maps, so fractions of the length can be read off.
    for q in 0..4 {
        let (a, b) = (x + px * q / 4, x + px * (q + 1) / 4);
        let colour = if q % 2 == 0 { INK } else { GREY };
        draw::fill(img, a, bar_top, (b - a).max(1) as u32, bar_h as u32, colour);
    }
    outline(img, x, bar_top, px, bar_h, INK);
}

/// The largest 1, 2 or 5 × 10ⁿ kilometres not longer than `max_km` (at least 1 km, the
/// smallest length that is a whole number of blocks at 125 m per block).
pub(crate) fn nice_length_km(max_km: f64) -> f64 {
    let mut best = 1.0;
    let mut decade = 1.0;
    while decade <= max_km {
        for m in [1.0, 2.0, 5.0] {
            if m * decade <= max_km {
                best = m * decade;
            }
        }
        decade *= 10.0;
    }
    best
}

/// A legend or scale number: whole numbers without a decimal point.
fn number(v: f32) -> String {
    if v.fract() == 0.0 {
        format!("{}", v as i64)
    } else {
        format!("{v:.1}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scale_bar_lengths_are_round() {
        assert_eq!(nice_length_km(0.3), 1.0);
        assert_eq!(nice_length_km(1.0), 1.0);
        assert_eq!(nice_length_km(3.9), 2.0);
        assert_eq!(nice_length_km(7.0), 5.0);
        assert_eq!(nice_length_km(1234.0), 1000.0);
    }

    #[test]
    fn numbers_print_without_spurious_decimals() {
        assert_eq!(number(-6000.0), "-6000");
        assert_eq!(number(0.0), "0");
        assert_eq!(number(2.5), "2.5");
    }

    #[test]
    fn panel_fills_its_rows_and_writes_a_legend() {
        let legend = Legend {
            caption: "test (u)",
            value_at: |t| t,
            position_of: |v| v,
            colour: |v| [255.0 * v, 0.0, 255.0 * (1.0 - v)],
            ticks: &[0.0, 0.5, 1.0],
        };
        let mut img = RgbImage::from_pixel(MIN_FRAME_WIDTH, 10 + height(1), Rgb([1, 2, 3]));
        draw(&mut img, 10, &["line".to_string()], &legend, (125.0, 125.0), 1);
        assert_eq!(*img.get_pixel(0, 9), Rgb([1, 2, 3]), "rows above the panel are untouched");
        assert!(img.enumerate_pixels().filter(|(_, y, _)| *y >= 10).all(|(_, _, p)| *p != Rgb([1, 2, 3])));
        let reddish = img.pixels().filter(|p| p[0] > 200 && p[2] < 50).count();
        let bluish = img.pixels().filter(|p| p[2] > 200 && p[0] < 50).count();
        assert!(reddish > 0 && bluish > 0, "the legend bar shows both ends of the ramp");
    }
}
