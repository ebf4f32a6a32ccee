//! Line charts with axes: panels of curves side by side under a few lines of text, with
//! tick marks, grid lines, captions and a legend (the realism report's slope histograms and
//! power spectra).

use image::{Rgb, RgbImage};

use super::{line, text};

/// One curve: its legend label, colour and points (already in plot units).
pub struct Series {
    /// Legend text.
    pub label: String,
    /// Line colour.
    pub colour: Rgb<u8>,
    /// (x, y) points in the panel's data units.
    pub points: Vec<(f64, f64)>,
}

/// One panel: title, axis captions, data ranges and tick marks (position, label).
pub struct Panel {
    /// Title above the frame.
    pub title: String,
    /// Caption under the x axis.
    pub x_caption: String,
    /// Caption above the y axis.
    pub y_caption: String,
    /// Data range of x.
    pub x_range: (f64, f64),
    /// Data range of y.
    pub y_range: (f64, f64),
    /// Ticks along x.
    pub x_ticks: Vec<(f64, String)>,
    /// Ticks along y.
    pub y_ticks: Vec<(f64, String)>,
    /// The curves.
    pub series: Vec<Series>,
}

const INK: Rgb<u8> = Rgb([30, 30, 30]);
const GRID: Rgb<u8> = Rgb([225, 225, 222]);
const PAPER: Rgb<u8> = Rgb([252, 252, 250]);
const PANEL_W: u32 = 620;
const PANEL_H: u32 = 460;
const MARGIN: (u32, u32, u32, u32) = (78, 20, 44, 60); // left, right, top, bottom

/// Draws `p` with its top-left corner at (`left`, `top`).
fn draw_panel(img: &mut RgbImage, left: u32, top: u32, p: &Panel) {
    let (x0, y0) = ((left + MARGIN.0) as f64, (top + MARGIN.2) as f64);
    let (w, h) = ((PANEL_W - MARGIN.0 - MARGIN.1) as f64, (PANEL_H - MARGIN.2 - MARGIN.3) as f64);
    let sx = |v: f64| x0 + (v - p.x_range.0) / (p.x_range.1 - p.x_range.0) * w;
    let sy = |v: f64| y0 + h - (v - p.y_range.0) / (p.y_range.1 - p.y_range.0) * h;
    for (v, label) in &p.x_ticks {
        line(img, (sx(*v), y0), (sx(*v), y0 + h), 1, GRID);
        line(img, (sx(*v), y0 + h), (sx(*v), y0 + h + 5.0), 1, INK);
        text(img, sx(*v) as i64 - 4 * label.chars().count() as i64, (y0 + h + 9.0) as i64, label, 1, INK);
    }
    for (v, label) in &p.y_ticks {
        line(img, (x0, sy(*v)), (x0 + w, sy(*v)), 1, GRID);
        line(img, (x0 - 5.0, sy(*v)), (x0, sy(*v)), 1, INK);
        text(img, x0 as i64 - 9 - 8 * label.chars().count() as i64, sy(*v) as i64 - 4, label, 1, INK);
    }
    line(img, (x0, y0), (x0, y0 + h), 1, INK);
    line(img, (x0, y0 + h), (x0 + w, y0 + h), 1, INK);
    text(img, left as i64 + MARGIN.0 as i64, top as i64 + 8, &p.title, 1, INK);
    text(img, left as i64 + 8, top as i64 + 26, &p.y_caption, 1, INK);
    let caption_x = x0 + w / 2.0 - 4.0 * p.x_caption.chars().count() as f64;
    text(img, caption_x as i64, (y0 + h + 30.0) as i64, &p.x_caption, 1, INK);
    let inside = |(x, y): (f64, f64)| {
        x >= p.x_range.0 && x <= p.x_range.1 && y >= p.y_range.0 && y <= p.y_range.1 && x.is_finite() && y.is_finite()
    };
    for s in &p.series {
        for pair in s.points.windows(2) {
            if inside(pair[0]) && inside(pair[1]) {
                line(img, (sx(pair[0].0), sy(pair[0].1)), (sx(pair[1].0), sy(pair[1].1)), 2, s.colour);
            }
        }
    }
    // Legend in the top-right corner of the frame.
    let lx = (x0 + w) as i64 - 8 - 8 * p.series.iter().map(|s| s.label.chars().count()).max().unwrap_or(0) as i64 - 28;
    for (k, s) in p.series.iter().enumerate() {
        let ly = y0 as i64 + 10 + 14 * k as i64;
        line(img, (lx as f64, ly as f64 + 3.0), (lx as f64 + 20.0, ly as f64 + 3.0), 3, s.colour);
        text(img, lx + 26, ly, &s.label, 1, INK);
    }
}

/// The report image: `header` lines of text above the panels, side by side.
pub fn draw(header: &[String], panels: &[Panel]) -> RgbImage {
    let header_h = 12 + 12 * header.len() as u32;
    let mut img = RgbImage::from_pixel(PANEL_W * panels.len().max(1) as u32, header_h + PANEL_H, PAPER);
    for (k, l) in header.iter().enumerate() {
        text(&mut img, 10, 8 + 12 * k as i64, l, 1, INK);
    }
    for (k, p) in panels.iter().enumerate() {
        draw_panel(&mut img, PANEL_W * k as u32, header_h, p);
    }
    img
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn panels_draw_curves_inside_their_frame_and_text_in_greek_too() {
        let p = Panel {
            title: "β test".into(),
            x_caption: "x".into(),
            y_caption: "y".into(),
            x_range: (0.0, 1.0),
            y_range: (0.0, 1.0),
            x_ticks: vec![(0.5, "0.5".into())],
            y_ticks: vec![(0.5, "0.5".into())],
            series: vec![Series { label: "a".into(), colour: Rgb([200, 0, 0]), points: vec![(0.0, 0.0), (1.0, 1.0)] }],
        };
        let img = draw(&["header χ²".into()], &[p]);
        assert_eq!(img.width(), PANEL_W);
        let red = img.pixels().filter(|px| **px == Rgb([200, 0, 0])).count();
        assert!(red > 300, "the diagonal is drawn ({red} px)");
    }
}
