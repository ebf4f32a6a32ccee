//! Seams: do window boundaries of the infinite-tensor engine show in the terrain?
//!
//! Windows of stride s tile the model grid, so any blending artefact sits on the lines
//! x ≡ o (mod s) and y ≡ o (mod s). The seam ratio compares the mean gradient magnitude across
//! those lines with the mean across all other pixel pairs: ≈ 1 means seamless, > 1 a visible
//! step or crease on the boundaries.

use super::Raster;

/// Where the window-boundary lines lie in a raster.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SeamLines {
    /// Pixels between boundary lines (the window stride on this raster's grid).
    pub stride: usize,
    /// Index of the first column that starts a window (boundary between it and the column before).
    pub col_offset: usize,
    /// Index of the first row that starts a window.
    pub row_offset: usize,
}

impl SeamLines {
    /// Lines every `stride` pixels for a raster whose first pixel sits at global grid
    /// coordinates (`x0`, `y0`): boundaries are where the global coordinate is a multiple of
    /// the stride (the engine's windows start at multiples of the stride plus its offset).
    pub fn for_origin(stride: usize, x0: i64, y0: i64) -> SeamLines {
        let s = stride.max(1) as i64;
        SeamLines {
            stride: stride.max(1),
            col_offset: (-x0).rem_euclid(s) as usize,
            row_offset: (-y0).rem_euclid(s) as usize,
        }
    }

    fn is_boundary(&self, index: usize, offset: usize) -> bool {
        index % self.stride == offset % self.stride
    }
}

/// Gradient sums on boundary lines and elsewhere; pooled over tiles before taking the ratio.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SeamStats {
    /// Σ |Δz| over neighbour pairs straddling a boundary line, metres.
    pub seam_sum: f64,
    /// Number of such pairs.
    pub seam_pairs: u64,
    /// Σ |Δz| over all other neighbour pairs.
    pub interior_sum: f64,
    /// Number of other pairs.
    pub interior_pairs: u64,
}

impl SeamStats {
    /// Adds another raster's sums.
    pub fn add(&mut self, o: SeamStats) {
        self.seam_sum += o.seam_sum;
        self.seam_pairs += o.seam_pairs;
        self.interior_sum += o.interior_sum;
        self.interior_pairs += o.interior_pairs;
    }

    /// Mean boundary gradient / mean interior gradient; NaN when either set is empty or the
    /// interior is perfectly flat.
    pub fn ratio(&self) -> f64 {
        if self.seam_pairs == 0 || self.interior_pairs == 0 || self.interior_sum == 0.0 {
            return f64::NAN;
        }
        (self.seam_sum / self.seam_pairs as f64) / (self.interior_sum / self.interior_pairs as f64)
    }
}

/// The seam sums of `r`: horizontal neighbour pairs (c−1, c) straddle a boundary when column
/// c starts a window; vertical pairs likewise for rows.
pub fn seam_ratio(r: &Raster, lines: SeamLines) -> SeamStats {
    let mut s = SeamStats::default();
    let mut add = |boundary: bool, d: f32| {
        if !d.is_finite() {
            return;
        }
        if boundary {
            s.seam_sum += d.abs() as f64;
            s.seam_pairs += 1;
        } else {
            s.interior_sum += d.abs() as f64;
            s.interior_pairs += 1;
        }
    };
    for y in 0..r.rows {
        for x in 0..r.cols {
            if x > 0 {
                add(lines.is_boundary(x, lines.col_offset), r.at(y, x) - r.at(y, x - 1));
            }
            if y > 0 {
                add(lines.is_boundary(y, lines.row_offset), r.at(y, x) - r.at(y - 1, x));
            }
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn smooth() -> Raster {
        Raster::from_fn(96, 96, 500.0, |y, x| {
            300.0 * ((x as f32 * 0.13).sin() + (y as f32 * 0.07).cos()) + 2.0 * x as f32
        })
    }

    #[test]
    fn a_smooth_field_is_seamless() {
        let ratio = seam_ratio(&smooth(), SeamLines::for_origin(32, 0, 0)).ratio();
        assert!((ratio - 1.0).abs() < 0.1, "ratio {ratio}");
    }

    #[test]
    fn steps_on_the_boundary_lines_raise_the_ratio() {
        let base = smooth();
        // A 40 m offset per window column: a step at every boundary line x ≡ 16 (mod 32).
        let stepped = Raster::from_fn(96, 96, 500.0, |y, x| base.at(y, x) + 40.0 * ((x + 16) / 32) as f32);
        let lines = SeamLines::for_origin(32, -16, 0);
        assert_eq!(lines.col_offset, 16);
        let ratio = seam_ratio(&stepped, lines).ratio();
        assert!(ratio > 1.5, "ratio {ratio}");
        let misplaced = seam_ratio(&stepped, SeamLines::for_origin(32, 0, 0)).ratio();
        assert!(misplaced < ratio, "lines elsewhere see less: {misplaced} vs {ratio}");
    }

    #[test]
    fn origins_map_to_offsets_with_floor_semantics() {
        assert_eq!(SeamLines::for_origin(32, 0, 0).col_offset, 0);
        assert_eq!(SeamLines::for_origin(32, 5, -5).col_offset, 27);
        assert_eq!(SeamLines::for_origin(32, 5, -5).row_offset, 5);
    }
}
