//! Window layouts on one axis and on the plane, κ(R), and the tent blending weights.

use crate::tile::{div_ceil, div_floor, Rect};

/// Weight at a window's border: small but non-zero, so every covered cell has a positive
/// weight sum even where only one window's edge reaches it (as in the paper).
pub const EDGE_WEIGHT: f32 = 1e-3;

/// How windows tile one axis: window `i` covers `[offset + i·stride, offset + i·stride + size)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Axis {
    /// Window length in cells.
    pub size: i64,
    /// Distance between consecutive windows' starts.
    pub stride: i64,
    /// Start of window 0.
    pub offset: i64,
}

impl Axis {
    /// An axis layout; `stride` must not exceed `size` or some cells would be uncovered.
    pub const fn new(size: i64, stride: i64, offset: i64) -> Axis {
        Axis { size, stride, offset }
    }

    /// First cell of window `i`.
    pub fn start(&self, i: i64) -> i64 {
        self.offset + i * self.stride
    }

    /// Indices of the windows touching `[start, stop)`, inclusive: κ(R) on this axis.
    pub fn windows(&self, start: i64, stop: i64) -> (i64, i64) {
        let lo = div_ceil(start - self.offset - self.size + 1, self.stride);
        let hi = div_floor(stop - 1 - self.offset, self.stride);
        (lo, hi)
    }

    /// The most windows that can touch a span of `len` cells, wherever it lies.
    pub fn max_windows(&self, len: i64) -> i64 {
        div_ceil(len + self.size - 1, self.stride)
    }

    /// Separable tent weights for one window: 1 at the centre, [`EDGE_WEIGHT`] at both ends.
    /// Windows that do not overlap (stride = size) weigh 1 everywhere: each cell has one
    /// window, and its value passes through bit for bit.
    pub fn tent(&self) -> Vec<f32> {
        let n = self.size as usize;
        if n == 1 || self.stride >= self.size {
            return vec![1.0; n];
        }
        let c = (n - 1) as f64 / 2.0;
        (0..n)
            .map(|k| {
                let d = ((k as f64) - c).abs() / c;
                (EDGE_WEIGHT as f64 + (1.0 - EDGE_WEIGHT as f64) * (1.0 - d)) as f32
            })
            .collect()
    }
}

/// A window layout on the plane: one [`Axis`] for rows (y) and one for columns (x).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct WindowLayout {
    /// Rows.
    pub y: Axis,
    /// Columns.
    pub x: Axis,
}

/// A window's position in its layout's grid of windows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct WindowIndex {
    /// Row of windows.
    pub iy: i64,
    /// Column of windows.
    pub ix: i64,
}

impl WindowLayout {
    /// The same square layout on both axes.
    pub const fn square(size: i64, stride: i64, offset: i64) -> WindowLayout {
        let a = Axis::new(size, stride, offset);
        WindowLayout { y: a, x: a }
    }

    /// The cells window `i` covers.
    pub fn rect(&self, i: WindowIndex) -> Rect {
        Rect::new(self.y.start(i.iy), self.x.start(i.ix), self.y.size, self.x.size)
    }

    /// κ(R): every window touching `r`, in row-major order (the order contributions are
    /// summed in, which is what makes results independent of how a region was queried).
    pub fn windows(&self, r: &Rect) -> Vec<WindowIndex> {
        let (y0, y1) = self.y.windows(r.y0, r.y1());
        let (x0, x1) = self.x.windows(r.x0, r.x1());
        let mut out = Vec::with_capacity(((y1 - y0 + 1).max(0) * (x1 - x0 + 1).max(0)) as usize);
        for iy in y0..=y1 {
            for ix in x0..=x1 {
                out.push(WindowIndex { iy, ix });
            }
        }
        out
    }

    /// Upper bound on |κ(R)| for any `h × w` query, wherever it lies.
    pub fn max_windows(&self, h: i64, w: i64) -> i64 {
        self.y.max_windows(h) * self.x.max_windows(w)
    }

    /// Checks the layout covers every cell.
    pub fn validate(&self) -> Result<(), String> {
        for (name, a) in [("y", self.y), ("x", self.x)] {
            if a.size < 1 || a.stride < 1 || a.stride > a.size {
                return Err(format!("axis {name}: need 1 <= stride <= size, got size {} stride {}", a.size, a.stride));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kappa_lists_exactly_the_windows_that_touch() {
        let a = Axis::new(8, 4, 1);
        for start in -40..40 {
            for len in 1..20 {
                let (lo, hi) = a.windows(start, start + len);
                for i in lo - 3..=hi + 3 {
                    let (s, e) = (a.start(i), a.start(i) + a.size);
                    let touches = s < start + len && e > start;
                    assert_eq!(touches, (lo..=hi).contains(&i), "start {start} len {len} window {i}");
                }
                assert!(hi - lo < a.max_windows(len));
            }
        }
    }

    #[test]
    fn tent_is_one_in_the_middle_and_epsilon_at_the_edges() {
        let t = Axis::new(9, 4, 0).tent();
        assert_eq!(t[4], 1.0);
        assert!((t[0] - EDGE_WEIGHT).abs() < 1e-9 && (t[8] - EDGE_WEIGHT).abs() < 1e-9);
        assert!(t.windows(2).take(4).all(|p| p[0] < p[1]));
    }

    #[test]
    fn far_coordinates_do_not_overflow() {
        let a = Axis::new(64, 32, 0);
        let (lo, hi) = a.windows(-30_000_000, -30_000_000 + 512);
        assert!((a.max_windows(512) - 1..=a.max_windows(512)).contains(&(hi - lo + 1)));
        let (lo, hi) = a.windows(30_000_000 - 512, 30_000_000);
        assert!(hi - lo < a.max_windows(512));
    }
}
