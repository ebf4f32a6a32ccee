//! The realism table (metrics × columns) and the panels of the report image.

use std::fmt;

use image::Rgb;

use super::input::REGION_SQUARE_TILES;
use super::measure::SetMetrics;
use super::places::PlaceFloor;
use crate::draw::chart::{Panel, Series};
use crate::terrain::metrics::{chi2_distance, histogram, quantile_edges, real_split_distances, wasserstein1};

/// Quantile bins of the style histograms (fixed on the held-out reference).
pub const STYLE_BINS: usize = 20;

/// Key of the realism bar's spectral-slope line.
pub const SPECTRAL_SLOPE_KEY: &str = "spectral_slope_abs_delta";

/// Key of the realism bar's slope-distribution line (W1, degrees).
pub const SLOPE_W1_KEY: &str = "slope_w1_deg";

/// One column of the report: a set of tiles and how it is drawn.
pub struct Column {
    /// Header of the column.
    pub label: String,
    /// Colour in the image.
    pub colour: Rgb<u8>,
    /// Its metrics.
    pub metrics: SetMetrics,
}

/// The report: context lines, then a table whose first column is the reference.
#[derive(Clone, Debug, PartialEq)]
pub struct Report {
    /// What was compared, at which resolution, and any resampling.
    pub notes: Vec<String>,
    /// Column headers (reference first).
    pub columns: Vec<String>,
    /// (metric, one cell per column).
    pub rows: Vec<(String, Vec<String>)>,
    /// The realism bar of the learned terrain, when the real-vs-real floor is known.
    pub targets: Vec<Target>,
    /// The same lines with the training land (real) in place of the generated terrain: which of
    /// them real land itself meets.
    pub real_land: Vec<Target>,
    /// How far apart in β random sets of real tiles lie, when the floor is known.
    pub beta_splits: Option<BetaSplits>,
    /// How far apart the quarters of the real landscape lie in slope distribution, when the
    /// reference says where its tiles lie.
    pub places: Option<PlaceFloor>,
}

/// The spectral-slope distance between real sets by the choice of tiles alone
/// ([`real_split_distances`]): held-out and training tiles pooled and dealt at random — by
/// region when the reference says where its tiles lie — into a set the reference's size and
/// the rest.
#[derive(Clone, Debug, PartialEq)]
pub struct BetaSplits {
    /// Partitions drawn.
    pub splits: usize,
    /// Whether whole regions were dealt (else single tiles).
    pub by_region: bool,
    /// Tiles in the first set of each partition (the reference's count) and in the second.
    pub sizes: (usize, usize),
    /// Median |Δβ| over the partitions.
    pub median: f64,
    /// 90th percentile of |Δβ|.
    pub p90: f64,
    /// The realism bar's spectral line.
    pub line: f64,
    /// Fraction of partitions whose |Δβ| is within the line.
    pub within_line: f64,
    /// The generated terrain's |Δβ| to the reference.
    pub generated: f64,
    /// Fraction of partitions whose |Δβ| is larger than the generated terrain's: real sets
    /// that lie farther apart than the model lies from the reference.
    pub farther_than_generated: f64,
    /// The training land's |Δβ| to the reference (the real-vs-real floor).
    pub floor: f64,
    /// Every partition's |Δβ|, ascending.
    pub distances: Vec<f64>,
}

impl BetaSplits {
    fn new(reference: &SetMetrics, train: &SetMetrics, line: &Target, regions: Option<&[u64]>) -> Option<BetaSplits> {
        let floor = (train.beta - reference.beta).abs();
        // Keys only when they name every measured tile (odd-sized leftovers are not measured).
        let regions = regions.filter(|k| k.len() == reference.spectra.len() + train.spectra.len());
        let d = real_split_distances(&reference.spectra, &train.spectra, regions);
        if d.is_empty() {
            return None;
        }
        let quantile = |q: f64| d[((d.len() - 1) as f64 * q).round() as usize];
        let share = |keep: &dyn Fn(f64) -> bool| d.iter().filter(|&&x| keep(x)).count() as f64 / d.len() as f64;
        let (median, p90) = (quantile(0.5), quantile(0.9));
        let (within_line, farther_than_generated) = (share(&|x| x <= line.high), share(&|x| x > line.value));
        Some(BetaSplits {
            splits: d.len(),
            by_region: regions.is_some(),
            sizes: (reference.spectra.len(), train.spectra.len()),
            median,
            p90,
            line: line.high,
            within_line,
            generated: line.value,
            farther_than_generated,
            floor,
            distances: d,
        })
    }
}

/// One line of the realism bar (issue #4): a generated number and the range it must lie in.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Target {
    /// Short metric key (also the key recorded in a model manifest).
    pub key: String,
    /// The generated terrain's value.
    pub value: f64,
    /// Allowed range (inclusive).
    pub low: f64,
    /// Allowed range (inclusive).
    pub high: f64,
    /// How the range was set.
    pub rule: String,
    /// Whether the value lies in the range.
    pub pass: bool,
    /// For a distance: the fBm baseline's distance it is judged against (stable, unlike the
    /// real-vs-real floor, which can be near zero by chance on small sets).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fbm: Option<f64>,
}

impl Target {
    fn new(key: &str, value: f64, (low, high): (f64, f64), rule: String) -> Target {
        let pass = value.is_finite() && value >= low && value <= high;
        Target { key: key.into(), value, low, high, rule, pass, fbm: None }
    }

    /// A distance to the reference: at most 2× the real-vs-real floor and at most one fifth
    /// of the fBm baseline's distance.
    fn distance(key: &str, generated: f64, floor: f64, fbm: f64) -> Target {
        let high = (2.0 * floor).min(fbm / 5.0);
        let rule = format!("≤ min(2 × floor {floor:.3}, fBm {fbm:.3} / 5)");
        Target { fbm: Some(fbm), ..Target::new(key, generated, (0.0, high), rule) }
    }
}

/// The realism bar of `generated` (or any set judged in its place) against `reference`, with
/// `train` (other real tiles) as the real-vs-real floor and `fbm` as the procedural baseline.
fn bar([reference, generated, fbm, train]: [&SetMetrics; 4], slope_edges: &[f64], relief_edges: &[f64]) -> Vec<Target> {
    let slope_ref = histogram(&reference.slopes, slope_edges);
    let relief_ref = histogram(&reference.relief, relief_edges);
    type Distance = fn(&SetMetrics, &SetMetrics, &[f64], &[f64], &[f64], &[f64]) -> f64;
    let metrics: [(&str, Distance); 5] = [
        (SLOPE_W1_KEY, |m, r, _, _, _, _| wasserstein1(&m.slopes, &r.slopes)),
        ("slope_chi2", |m, _, se, sr, _, _| chi2_distance(&histogram(&m.slopes, se), sr)),
        ("relative_elevation_w1_m", |m, r, _, _, _, _| wasserstein1(&m.relief, &r.relief)),
        ("relative_elevation_chi2", |m, _, _, _, re, rr| chi2_distance(&histogram(&m.relief, re), rr)),
        (SPECTRAL_SLOPE_KEY, |m, r, _, _, _, _| (m.beta - r.beta).abs()),
    ];
    let mut out: Vec<Target> = metrics
        .iter()
        .map(|(key, d)| {
            let d = |m: &SetMetrics| d(m, reference, slope_edges, &slope_ref, relief_edges, &relief_ref);
            Target::distance(key, d(generated), d(train), d(fbm))
        })
        .collect();
    let real = reference.depressions.per_1000_km2();
    out.push(Target::new(
        "depressions_per_1000_km2",
        generated.depressions.per_1000_km2(),
        (real / 2.0, real * 2.0),
        format!("within 2× of real {real:.2}"),
    ));
    // The second drainage number of docs/realism.md. Like the depression density it is a per-area amount
    // dominated by a few tiles' large basins, so it gets the same rule (the real-vs-real
    // distance, a few per cent on ~100 tiles, would be a line no region of real land meets).
    let real = reference.depressions.volume_per_km2();
    out.push(Target::new(
        "fill_volume_per_km2",
        generated.depressions.volume_per_km2(),
        (real / 2.0, real * 2.0),
        format!("within 2× of real {real:.0}"),
    ));
    out.push(Target::new("seam_ratio", generated.seams.ratio(), (0.9, 1.1), "0.9–1.1".into()));
    out
}

/// Only the realism bar of columns (reference, generated, fBm, train (real)): what a
/// calibration needs from each trial, without the table, real land's bar or the splits.
pub fn targets(columns: &[Column]) -> Vec<Target> {
    let [r, g, f, t] = columns else { return Vec::new() };
    let slope_edges = quantile_edges(&r.metrics.slopes, STYLE_BINS);
    let relief_edges = quantile_edges(&r.metrics.relief, STYLE_BINS);
    bar([&r.metrics, &g.metrics, &f.metrics, &t.metrics], &slope_edges, &relief_edges)
}

fn cell(v: f64, decimals: usize) -> String {
    if v.is_finite() {
        format!("{v:.decimals$}")
    } else {
        "n/a".into()
    }
}

impl Report {
    /// Builds the table; `columns[0]` is the reference the distances are measured to, and
    /// `regions` (one key per reference then train tile) says which real tiles are neighbours.
    pub fn new(notes: Vec<String>, columns: &[Column], seam_caption: &str, regions: Option<&[u64]>) -> Report {
        let reference = &columns[0].metrics;
        let slope_edges = quantile_edges(&reference.slopes, STYLE_BINS);
        let relief_edges = quantile_edges(&reference.relief, STYLE_BINS);
        let slope_ref = histogram(&reference.slopes, &slope_edges);
        let relief_ref = histogram(&reference.relief, &relief_edges);
        let distance = |f: &dyn Fn(&SetMetrics) -> String| -> Vec<String> {
            std::iter::once("-".to_string()).chain(columns[1..].iter().map(|c| f(&c.metrics))).collect()
        };
        let value =
            |f: &dyn Fn(&SetMetrics) -> String| -> Vec<String> { columns.iter().map(|c| f(&c.metrics)).collect() };
        let mean = |v: &[f32]| v.iter().map(|&x| x as f64).sum::<f64>() / v.len() as f64;
        let rows = vec![
            ("tiles".to_string(), value(&|m| m.tiles.to_string())),
            ("land fraction (> 0 m)".into(), value(&|m| cell(m.land_fraction, 2))),
            ("elevation std per tile (m)".into(), value(&|m| cell(m.mean_tile_std, 0))),
            ("slope mean (°)".into(), value(&|m| cell(mean(&m.slopes), 2))),
            ("slope W1 to reference (°)".into(), distance(&|m| cell(wasserstein1(&m.slopes, &reference.slopes), 2))),
            (
                format!("slope χ² to reference ({STYLE_BINS} bins)"),
                distance(&|m| cell(chi2_distance(&histogram(&m.slopes, &slope_edges), &slope_ref), 3)),
            ),
            (
                "rel. elevation W1 to reference (m)".into(),
                distance(&|m| cell(wasserstein1(&m.relief, &reference.relief), 1)),
            ),
            (
                format!("rel. elevation χ² to reference ({STYLE_BINS} bins)"),
                distance(&|m| cell(chi2_distance(&histogram(&m.relief, &relief_edges), &relief_ref), 3)),
            ),
            ("spectral slope β (power ∝ k^β)".into(), value(&|m| cell(m.beta, 2))),
            ("β standard error (bootstrap over tiles)".into(), value(&|m| cell(m.beta_sd, 3))),
            ("|Δβ| to reference".into(), distance(&|m| cell((m.beta - reference.beta).abs(), 2))),
            ("depressions ≥ 1 m per 1000 km²".into(), value(&|m| cell(m.depressions.per_1000_km2(), 2))),
            ("fill volume per area (m³/km²)".into(), value(&|m| cell(m.depressions.volume_per_km2(), 0))),
            (format!("seam ratio ({seam_caption})"), value(&|m| cell(m.seams.ratio(), 3))),
        ];
        let (targets, real_land, beta_splits) = match columns {
            [r, g, f, t] => {
                let [r, g, f, t] = [&r.metrics, &g.metrics, &f.metrics, &t.metrics];
                let targets = bar([r, g, f, t], &slope_edges, &relief_edges);
                // Real land judged as if it were generated: the train split against the held-out.
                let real_land = bar([r, t, f, t], &slope_edges, &relief_edges);
                let splits = targets
                    .iter()
                    .find(|x| x.key == SPECTRAL_SLOPE_KEY)
                    .and_then(|l| BetaSplits::new(r, t, l, regions));
                (targets, real_land, splits)
            }
            _ => (Vec::new(), Vec::new(), None),
        };
        let labels = columns.iter().map(|c| c.label.clone()).collect();
        Report { notes, columns: labels, rows, targets, real_land, beta_splits, places: None }
    }

    /// The cell of `metric` in column `column`, if both exist (for tests and scripts).
    pub fn get(&self, metric: &str, column: usize) -> Option<&str> {
        self.rows
            .iter()
            .find(|(m, _)| m.starts_with(metric))
            .and_then(|(_, cells)| cells.get(column))
            .map(|s| s.as_str())
    }
}

impl fmt::Display for Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for n in &self.notes {
            writeln!(f, "{n}")?;
        }
        let first = self.rows.iter().map(|(m, _)| m.chars().count()).max().unwrap_or(6).max(6);
        let widths: Vec<usize> = self.columns.iter().map(|c| c.chars().count().max(10)).collect();
        write!(f, "\n{:<first$}", "metric")?;
        for (c, w) in self.columns.iter().zip(&widths) {
            write!(f, "  {c:>w$}")?;
        }
        writeln!(f)?;
        for (metric, cells) in &self.rows {
            // Pad by characters, not bytes: the labels hold °, χ², β.
            write!(f, "{metric}{}", " ".repeat(first - metric.chars().count()))?;
            for (c, w) in cells.iter().zip(&widths) {
                write!(f, "  {c:>w$}")?;
            }
            writeln!(f)?;
        }
        if !self.targets.is_empty() {
            let passed = self.targets.iter().filter(|t| t.pass).count();
            writeln!(f, "\nrealism bar (generated): {passed}/{} met", self.targets.len())?;
            for t in &self.targets {
                let verdict = if t.pass { "met" } else { "NOT met" };
                writeln!(f, "  {:<26} {:>12.4}  {:<8} {}", t.key, t.value, verdict, t.rule)?;
            }
        }
        if !self.real_land.is_empty() {
            let passed = self.real_land.iter().filter(|t| t.pass).count();
            let missed: Vec<String> =
                self.real_land.iter().filter(|t| !t.pass).map(|t| format!("{} {:.4}", t.key, t.value)).collect();
            write!(
                f,
                "the same lines for real land (train split in place of generated): {passed}/{} met",
                self.real_land.len()
            )?;
            if missed.is_empty() {
                writeln!(f)?;
            } else {
                writeln!(f, "; NOT met: {}", missed.join(", "))?;
            }
        }
        if let Some(b) = &self.beta_splits {
            writeln!(
                f,
                "real vs real by chance: {} random splits of the {} real tiles ({}) into {} + {}: |Δβ| median {:.3}, \
                 90th percentile {:.3}; within the line {:.3} in {:.0} % of them; farther apart than the \
                 generated terrain's {:.3} in {:.0} %",
                b.splits,
                b.sizes.0 + b.sizes.1,
                if b.by_region {
                    format!("dealt in whole {0}×{0}-tile squares, as the held-out split is", REGION_SQUARE_TILES)
                } else {
                    "dealt tile by tile".into()
                },
                b.sizes.0,
                b.sizes.1,
                b.median,
                b.p90,
                b.line,
                100.0 * b.within_line,
                b.generated,
                100.0 * b.farther_than_generated
            )?;
        }
        if let Some(p) = &self.places {
            let tiles: Vec<String> = p.tiles.iter().map(usize::to_string).collect();
            let distances: Vec<String> = p.distances.iter().map(|d| format!("{d:.2}")).collect();
            writeln!(
                f,
                "slope W1 between real places: the real tiles in the quarters of their grid ({} tiles), each \
                 against the other quarters: {}° (median {:.2}°; held-out to train, squares interleaved: {:.2}°); \
                 generated to the reference {:.2}° = {:.1}× the median place: {} (≤ 2×)",
                tiles.join(", "),
                distances.join(", "),
                p.median(),
                p.floor,
                p.generated,
                p.generated / p.median(),
                if p.met() { "met" } else { "NOT met" }
            )?;
        }
        Ok(())
    }
}

/// Slope histograms (percent of pixels per degree, log scale: real terrain's long tail of
/// steep slopes is where noise and eroded relief differ) of every column.
pub fn slope_panel(columns: &[Column]) -> Panel {
    let top = columns
        .iter()
        .filter_map(|c| {
            let mut s = c.metrics.slopes.clone();
            s.sort_unstable_by(f32::total_cmp);
            s.get(s.len().saturating_sub(1) * 995 / 1000).copied()
        })
        .fold(10.0f32, f32::max)
        .min(90.0)
        .ceil() as usize;
    let edges: Vec<f64> = (1..=top).map(|d| d as f64).collect();
    let series: Vec<Series> = columns
        .iter()
        .map(|c| {
            let h = histogram(&c.metrics.slopes, &edges);
            // The last bin is open-ended (everything steeper): not a per-degree density.
            let points = h[..top]
                .iter()
                .enumerate()
                .filter(|(_, p)| **p > 0.0)
                .map(|(d, p)| (d as f64 + 0.5, (100.0 * p).log10()))
                .collect();
            Series { label: c.label.clone(), colour: c.colour, points }
        })
        .collect();
    let y_hi = series.iter().flat_map(|s| s.points.iter().map(|p| p.1)).fold(0.0f64, f64::max).ceil().max(1.0);
    let y_lo = -3.0;
    Panel {
        title: "slope distribution".into(),
        x_caption: "slope (°)".into(),
        y_caption: "% of pixels per degree, log scale".into(),
        x_range: (0.0, top as f64),
        y_range: (y_lo, y_hi),
        x_ticks: ticks(0.0, top as f64, nice_step(top as f64 / 6.0)),
        y_ticks: (y_lo as i32..=y_hi as i32).map(|d| (d as f64, decade(d))).collect(),
        series,
    }
}

/// A decade's label: plain numbers near 1, exponents beyond.
fn decade(d: i32) -> String {
    if (-2..=2).contains(&d) {
        format!("{}", 10f64.powi(d))
    } else {
        format!("1e{d}")
    }
}

/// Radially averaged power spectra (log-log) of every column.
pub fn spectrum_panel(columns: &[Column]) -> Panel {
    let series: Vec<Series> = columns
        .iter()
        .map(|c| {
            let points = c.metrics.spectrum.as_ref().map_or_else(Vec::new, |s| {
                s.frequency
                    .iter()
                    .zip(&s.power)
                    .filter(|(_, p)| **p > 0.0)
                    .map(|(f, p)| ((f * 1000.0).log10(), p.log10()))
                    .collect()
            });
            Series { label: format!("{} β={}", c.label, cell(c.metrics.beta, 2)), colour: c.colour, points }
        })
        .collect();
    let all = || series.iter().flat_map(|s| s.points.iter());
    let (x_lo, x_hi) = all().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| (a.min(p.0), b.max(p.0)));
    let (y_lo, y_hi) = all().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| (a.min(p.1), b.max(p.1)));
    let (x_lo, x_hi, y_lo, y_hi) =
        if x_lo.is_finite() { (x_lo.floor(), x_hi.ceil(), y_lo.floor(), y_hi.ceil()) } else { (-3.0, 0.0, 0.0, 1.0) };
    Panel {
        title: "radially averaged power spectrum".into(),
        x_caption: "frequency (cycles/km)".into(),
        y_caption: "power (m^4), log scale".into(),
        x_range: (x_lo, x_hi),
        y_range: (y_lo, y_hi),
        x_ticks: (x_lo as i32..=x_hi as i32).map(|d| (d as f64, decade(d))).collect(),
        y_ticks: (y_lo as i32..=y_hi as i32)
            .step_by(((y_hi - y_lo) / 6.0).ceil().max(1.0) as usize)
            .map(|d| (d as f64, decade(d)))
            .collect(),
        series,
    }
}

/// The real-vs-real splits' |Δβ| as a cumulative curve (share of random real splits at most
/// this far apart), with the realism bar's line, the training land and the generated terrain
/// marked as vertical lines: where the line falls among real land's own distances.
pub fn beta_split_panel(b: &BetaSplits) -> Panel {
    let n = b.distances.len().max(1) as f64;
    let x_hi = (b.distances.last().copied().unwrap_or(0.1).max(b.generated).max(b.floor) * 10.0).ceil() / 10.0;
    let curve = b.distances.iter().enumerate().map(|(i, d)| (*d, (i + 1) as f64 / n));
    let points: Vec<(f64, f64)> = std::iter::once((0.0, 0.0)).chain(curve).collect();
    let mark = |label: String, colour: [u8; 3], x: f64| Series {
        label,
        colour: Rgb(colour),
        points: vec![(x, 0.0), (x, 1.0)],
    };
    let series = vec![
        Series {
            label: format!("real vs real, {} random splits", b.distances.len()),
            colour: Rgb([130, 130, 130]),
            points,
        },
        mark(format!("line {:.3}: {:.0} % of real splits within", b.line, 100.0 * b.within_line), [20, 20, 20], b.line),
        mark(format!("train vs held-out {:.3}", b.floor), [40, 90, 220], b.floor),
        mark(format!("generated {:.3}", b.generated), [210, 40, 30], b.generated),
    ];
    Panel {
        title: "spectral slope: real vs real by chance".into(),
        x_caption: "|Δβ| between the two sets".into(),
        y_caption: "share of splits at most this far apart".into(),
        x_range: (0.0, x_hi),
        y_range: (0.0, 1.0),
        x_ticks: ticks(0.0, x_hi, nice_step(x_hi / 5.0)),
        y_ticks: ticks(0.0, 1.0, 0.25),
        series,
    }
}

/// 1, 2 or 5 × 10ⁿ, the first at least `raw`.
fn nice_step(raw: f64) -> f64 {
    let base = 10f64.powf(raw.max(1e-9).log10().floor());
    [1.0, 2.0, 5.0, 10.0].iter().map(|m| m * base).find(|s| *s >= raw).unwrap_or(10.0 * base)
}

fn ticks(lo: f64, hi: f64, step: f64) -> Vec<(f64, String)> {
    let n = ((hi - lo) / step + 1e-9).floor() as usize;
    // As many decimals as the step has (0.25 → 2), so 3 × 0.05 prints as 0.15.
    let decimals = (0..6)
        .find(|&d| {
            let x = step * 10f64.powi(d);
            (x - x.round()).abs() < 1e-6
        })
        .unwrap_or(6) as usize;
    (0..=n).map(|k| lo + k as f64 * step).map(|v| (v, format!("{v:.decimals$}"))).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nice_steps_are_one_two_five() {
        assert_eq!(nice_step(7.0), 10.0);
        assert_eq!(nice_step(1.5), 2.0);
        assert_eq!(nice_step(0.3), 0.5);
        assert_eq!(ticks(0.0, 10.0, 5.0).len(), 3);
        let labels: Vec<String> = ticks(0.0, 0.2, 0.05).into_iter().map(|t| t.1).collect();
        assert_eq!(labels, ["0.00", "0.05", "0.10", "0.15", "0.20"]);
        assert_eq!(ticks(0.0, 1.0, 0.25)[1].1, "0.25");
    }
}
