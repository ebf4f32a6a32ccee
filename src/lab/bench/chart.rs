//! The bench chart: one horizontal bar per measurement, each row scaled to its own goal so
//! quantities in different units sit side by side — the goal line at the same x on every
//! row, green bars where the goal is met, red where it is not, grey where there is no goal.

use std::path::Path;

use image::{Rgb, RgbImage};

use super::Measurement;
use crate::draw::{fill, text};

/// One bar: a measurement and, when it has one, the goal it is judged against.
pub struct Bar<'a> {
    /// What was measured.
    pub measurement: &'a Measurement,
    /// The goal, if the measurement has one.
    pub goal: Option<Goal>,
}

/// A goal: at least (`higher_is_better`) or at most this value, in the measurement's unit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Goal {
    /// The threshold, in the measurement's unit.
    pub value: f64,
    /// True: the goal is met at or above `value`; false: at or below it.
    pub higher_is_better: bool,
}

const WIDTH: u32 = 900;
/// Height of the title and legend above the rows.
const HEADER: u32 = 44;
/// Height of one row (a text line over its bar).
const ROW_H: u32 = 28;
/// Blank space under the last row.
const FOOTER: u32 = 8;
/// Left edge of the text and of the bars.
const LEFT: u32 = 12;
/// Pixels from a bar's start to its goal line (a bar at twice the goal is twice as long).
const SCALE: u32 = 400;
/// Top of a row's text line, from the row's top.
const TEXT_DY: u32 = 3;
/// Top of a row's bar, from the row's top.
const BAR_DY: u32 = 14;
/// Thickness of a bar.
const BAR_H: u32 = 11;

const PAPER: Rgb<u8> = Rgb([255, 255, 255]);
const STRIPE: Rgb<u8> = Rgb([244, 245, 247]);
const INK: Rgb<u8> = Rgb([30, 30, 30]);
const MUTED: Rgb<u8> = Rgb([110, 110, 110]);
const MET: Rgb<u8> = Rgb([46, 160, 67]);
const MISSED: Rgb<u8> = Rgb([210, 50, 50]);
const NO_GOAL: Rgb<u8> = Rgb([150, 150, 150]);
const MET_TEXT: Rgb<u8> = Rgb([20, 110, 40]);
const MISSED_TEXT: Rgb<u8> = Rgb([170, 30, 30]);

/// Draws `bars` as a horizontal bar chart, one row per bar, each row scaled to its own goal (the
/// goal line at a fixed x, bars green when the goal is met, red when not, grey without a goal —
/// then scaled to the row's own value), with the name, the value + unit, and "goal >= X" /
/// "goal <= X" written on the row, and a title line at the top. Bars longer than twice the goal
/// are clipped and marked ">>"; a value that is NaN, infinite, zero or negative draws no bar and
/// reads "n/a".
pub fn draw(title: &str, bars: &[Bar]) -> RgbImage {
    let height = HEADER + ROW_H * bars.len() as u32 + FOOTER;
    let mut img = RgbImage::from_pixel(WIDTH, height, PAPER);
    text(&mut img, LEFT as i64, 10, title, 1, INK);
    let legend = "green: goal met   red: goal missed   grey: no goal   |: the goal   >>: beyond 2x the goal";
    text(&mut img, LEFT as i64, 26, legend, 1, MUTED);
    for (i, bar) in bars.iter().enumerate() {
        draw_row(&mut img, i as u32, bar);
    }
    img
}

/// [`draw`], then writes the chart as a PNG at `path` (atomically).
pub fn save(path: &Path, title: &str, bars: &[Bar]) -> anyhow::Result<()> {
    crate::render::save_png(&draw(title, bars), path)?;
    Ok(())
}

/// Draws row `index` (0 at the top).
fn draw_row(img: &mut RgbImage, index: u32, bar: &Bar) {
    let top = HEADER + ROW_H * index;
    if index % 2 == 1 {
        fill(img, 0, top as i64, WIDTH, ROW_H, STRIPE);
    }
    let m = bar.measurement;
    let value = m.value;
    let valid = value.is_finite() && value > 0.0;
    let goal = bar.goal.filter(|g| g.value.is_finite() && g.value > 0.0);
    let met = goal.map(|g| if g.higher_is_better { value >= g.value } else { value <= g.value });

    // Text line: the name on the left, the value and the goal on the right.
    let mut right = if valid { format!("{} {}", number(value), m.unit) } else { "n/a".to_string() };
    if let Some(g) = bar.goal {
        let relation = if g.higher_is_better { ">=" } else { "<=" };
        right.push_str(&format!("   goal {relation} {}", number(g.value)));
    }
    let right_x = WIDTH as i64 - LEFT as i64 - 8 * right.chars().count() as i64;
    let value_colour = match (valid, met) {
        (true, Some(true)) => MET_TEXT,
        (true, Some(false)) => MISSED_TEXT,
        _ => INK,
    };
    text(img, right_x, (top + TEXT_DY) as i64, &right, 1, value_colour);
    let room = ((right_x - LEFT as i64 - 16) / 8).max(4) as usize;
    text(img, LEFT as i64, (top + TEXT_DY) as i64, &fit(&m.name, room), 1, INK);

    // The bar, scaled so the goal (or, without one, the value itself) sits SCALE pixels in.
    let bar_top = top + BAR_DY;
    if valid {
        let (reference, colour) = match (goal, met) {
            (Some(g), Some(true)) => (g.value, MET),
            (Some(g), _) => (g.value, MISSED),
            (None, _) => (value, NO_GOAL),
        };
        let ratio = value / reference;
        let clipped = ratio > 2.0;
        let length = ((ratio.min(2.0) * SCALE as f64).round() as u32).max(1);
        fill(img, LEFT as i64, bar_top as i64, length, BAR_H, colour);
        if clipped {
            text(img, (LEFT + 2 * SCALE + 4) as i64, (bar_top + (BAR_H - 8) / 2) as i64, ">>", 1, colour);
        }
    }
    if goal.is_some() {
        fill(img, (LEFT + SCALE - 1) as i64, bar_top as i64 - 2, 2, BAR_H + 4, INK);
    }
}

/// `value` with about four significant digits, trailing zeros dropped; "n/a" when it is not
/// finite.
fn number(value: f64) -> String {
    let magnitude = value.abs();
    let trim = |s: String| if s.contains('.') { s.trim_end_matches('0').trim_end_matches('.').to_string() } else { s };
    if !value.is_finite() {
        "n/a".to_string()
    } else if magnitude == 0.0 {
        "0".to_string()
    } else if !(1e-3..1e7).contains(&magnitude) {
        format!("{value:.3e}")
    } else if magnitude >= 1000.0 {
        format!("{value:.0}")
    } else if magnitude >= 100.0 {
        trim(format!("{value:.1}"))
    } else if magnitude >= 10.0 {
        trim(format!("{value:.2}"))
    } else if magnitude >= 1.0 {
        trim(format!("{value:.3}"))
    } else {
        trim(format!("{value:.4}"))
    }
}

/// `name` cut to at most `chars` characters, ending in ".." when cut.
fn fit(name: &str, chars: usize) -> String {
    if name.chars().count() <= chars {
        name.to_string()
    } else {
        let mut cut: String = name.chars().take(chars.saturating_sub(2)).collect();
        cut.push_str("..");
        cut
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn measurement(value: f64) -> Measurement {
        Measurement { name: format!("thing at {value}"), value, unit: "ms", runs: vec![value] }
    }

    /// Counts the pixels of `colour` in row `row`'s bar band.
    fn count_in_bar(img: &RgbImage, row: u32, colour: Rgb<u8>) -> usize {
        let top = HEADER + ROW_H * row + BAR_DY;
        (top..top + BAR_H)
            .flat_map(|y| (LEFT..LEFT + 2 * SCALE).map(move |x| (x, y)))
            .filter(|&(x, y)| *img.get_pixel(x, y) == colour)
            .count()
    }

    #[test]
    fn height_grows_by_one_row_per_bar() {
        let ms: Vec<Measurement> = (1..=5).map(|k| measurement(k as f64)).collect();
        for n in 0..=ms.len() {
            let bars: Vec<Bar> = ms[..n].iter().map(|m| Bar { measurement: m, goal: None }).collect();
            let img = draw("bench", &bars);
            assert_eq!(img.width(), WIDTH);
            assert_eq!(img.height(), HEADER + FOOTER + ROW_H * n as u32);
        }
    }

    #[test]
    fn met_goals_are_green_and_missed_ones_red() {
        let (fast, slow, many, none) = (measurement(5.0), measurement(20.0), measurement(50.0), measurement(3.0));
        let bars = [
            Bar { measurement: &fast, goal: Some(Goal { value: 10.0, higher_is_better: false }) },
            Bar { measurement: &slow, goal: Some(Goal { value: 10.0, higher_is_better: false }) },
            Bar { measurement: &many, goal: Some(Goal { value: 100.0, higher_is_better: true }) },
            Bar { measurement: &none, goal: None },
        ];
        let img = draw("bench", &bars);
        assert!(count_in_bar(&img, 0, MET) > 0);
        assert_eq!(count_in_bar(&img, 0, MISSED), 0);
        assert!(count_in_bar(&img, 1, MISSED) > 0);
        assert_eq!(count_in_bar(&img, 1, MET), 0);
        assert!(count_in_bar(&img, 2, MISSED) > 0, "50 is short of at least 100");
        assert!(count_in_bar(&img, 3, NO_GOAL) > 0);
        // Scaled to the goal: 5 against 10 is half as long as the goal line's distance.
        assert_eq!(count_in_bar(&img, 0, MET), (SCALE / 2 * BAR_H) as usize);
    }

    #[test]
    fn long_bars_are_clipped_at_twice_the_goal() {
        let huge = measurement(1e6);
        let bars = [Bar { measurement: &huge, goal: Some(Goal { value: 1.0, higher_is_better: true }) }];
        let img = draw("bench", &bars);
        assert_eq!(count_in_bar(&img, 0, MET), (2 * SCALE * BAR_H) as usize - 2 * BAR_H as usize);
        // The ">>" marker, right of the clipped bar.
        let top = HEADER + BAR_DY;
        let marker = (top..top + BAR_H)
            .flat_map(|y| (LEFT + 2 * SCALE..WIDTH).map(move |x| (x, y)))
            .any(|(x, y)| *img.get_pixel(x, y) == MET);
        assert!(marker);
    }

    #[test]
    fn bad_values_draw_no_bar_and_do_not_panic() {
        let ms = [
            measurement(f64::NAN),
            measurement(0.0),
            measurement(-3.0),
            measurement(f64::INFINITY),
            measurement(1e-300),
        ];
        let goals = [
            Some(Goal { value: 1.0, higher_is_better: true }),
            Some(Goal { value: f64::NAN, higher_is_better: false }),
            Some(Goal { value: 0.0, higher_is_better: false }),
            Some(Goal { value: -1.0, higher_is_better: true }),
            None,
        ];
        let bars: Vec<Bar> = ms.iter().zip(goals).map(|(m, goal)| Bar { measurement: m, goal }).collect();
        let img = draw("bench with a very long title ".repeat(10).as_str(), &bars);
        for row in 0..4 {
            for colour in [MET, MISSED, NO_GOAL] {
                assert_eq!(count_in_bar(&img, row, colour), 0, "row {row}");
            }
        }
        assert!(count_in_bar(&img, 4, NO_GOAL) > 0, "a tiny positive value still shows");
    }

    #[test]
    fn long_names_are_cut_to_fit() {
        assert_eq!(fit("short", 10), "short");
        assert_eq!(fit("a much longer name", 8), "a much..");
        let mut m = measurement(2.0);
        m.name = "x".repeat(500);
        let img = draw("bench", &[Bar { measurement: &m, goal: None }]);
        assert_eq!(img.width(), WIDTH);
    }

    #[test]
    fn numbers_are_short() {
        assert_eq!(number(12345.678), "12346");
        assert_eq!(number(4.56789), "4.568");
        assert_eq!(number(0.012345), "0.0123");
        assert_eq!(number(2.0), "2");
        assert_eq!(number(0.5), "0.5");
        assert_eq!(number(1500.0), "1500");
        assert_eq!(number(f64::NAN), "n/a");
    }

    #[test]
    fn save_writes_a_readable_png() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bench.png");
        let m = measurement(7.0);
        let bars = [Bar { measurement: &m, goal: Some(Goal { value: 10.0, higher_is_better: false }) }];
        save(&path, "bench", &bars).unwrap();
        let back = image::open(&path).unwrap().to_rgb8();
        assert_eq!(back, draw("bench", &bars));
    }
}
