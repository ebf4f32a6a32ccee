//! A heightmap on square pixels of known size: the unit every metric works on.

/// Elevation in metres on a `rows × cols` grid of square `metres`-sized pixels, row-major
/// (row 0 north, column 0 west).
#[derive(Clone, Debug, PartialEq)]
pub struct Raster {
    /// Number of rows.
    pub rows: usize,
    /// Number of columns.
    pub cols: usize,
    /// Pixel side, metres.
    pub metres: f64,
    /// `rows × cols` elevations, metres.
    pub data: Vec<f32>,
}

impl Raster {
    /// A raster from its values; panics when `data` does not hold `rows × cols` values.
    pub fn new(rows: usize, cols: usize, metres: f64, data: Vec<f32>) -> Raster {
        assert_eq!(data.len(), rows * cols, "a {rows}×{cols} raster needs {} values", rows * cols);
        Raster { rows, cols, metres, data }
    }

    /// A raster of `rows × cols` values from a function of (row, column).
    pub fn from_fn(rows: usize, cols: usize, metres: f64, mut f: impl FnMut(usize, usize) -> f32) -> Raster {
        let data = (0..rows * cols).map(|i| f(i / cols, i % cols)).collect();
        Raster { rows, cols, metres, data }
    }

    /// The value at (row, column).
    pub fn at(&self, r: usize, c: usize) -> f32 {
        self.data[r * self.cols + c]
    }

    /// Number of pixels.
    pub fn len(&self) -> usize {
        self.data.len()
    }

    /// True when the raster has no pixel.
    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    /// Mean and standard deviation of the values (f64 accumulation: 10⁶ pixels of
    /// kilometres would lose metres in f32).
    pub fn mean_std(&self) -> (f64, f64) {
        let n = self.data.len().max(1) as f64;
        let mean = self.data.iter().map(|&v| v as f64).sum::<f64>() / n;
        let var = self.data.iter().map(|&v| (v as f64 - mean).powi(2)).sum::<f64>() / n;
        (mean, var.sqrt())
    }

    /// The `rows × cols` block whose top-left pixel is (`r0`, `c0`).
    pub fn crop(&self, r0: usize, c0: usize, rows: usize, cols: usize) -> Raster {
        assert!(r0 + rows <= self.rows && c0 + cols <= self.cols, "crop outside the raster");
        let mut data = Vec::with_capacity(rows * cols);
        for r in r0..r0 + rows {
            data.extend_from_slice(&self.data[r * self.cols + c0..r * self.cols + c0 + cols]);
        }
        Raster { rows, cols, metres: self.metres, data }
    }

    /// Non-overlapping `size × size` tiles, row by row; a raster smaller than `size` along an
    /// axis is one tile as large as it allows (so small inputs still get measured).
    pub fn tiles(&self, size: usize) -> Vec<Raster> {
        let (th, tw) = (size.min(self.rows), size.min(self.cols));
        if th == 0 || tw == 0 {
            return Vec::new();
        }
        let mut out = Vec::new();
        for r in (0..=self.rows - th).step_by(th) {
            for c in (0..=self.cols - tw).step_by(tw) {
                out.push(self.crop(r, c, th, tw));
            }
        }
        out
    }

    /// Bilinear resampling to pixels of `metres` over the same extent (pixel centres aligned,
    /// edges clamped). Downsampling by a whole factor 2 averages 2×2 blocks exactly; by more
    /// than 2, bilinear taps alone would alias the short wavelengths back into the spectrum
    /// (40 m blocks judged at 93 m), so the raster is first blurred with the Gaussian the real
    /// sets get in `scripts/data/geo.py` (σ = (f − 1)/2 source pixels).
    pub fn resample(&self, metres: f64) -> Raster {
        let scale = metres / self.metres;
        if scale > 2.0 + 1e-9 {
            let blurred = self.gaussian_blur((scale - 1.0) / 2.0);
            return blurred.bilinear(metres);
        }
        self.bilinear(metres)
    }

    /// Separable Gaussian blur of standard deviation `sigma` pixels, edges clamped (the
    /// `nearest` mode of the real sets' blur).
    pub fn gaussian_blur(&self, sigma: f64) -> Raster {
        let radius = (3.0 * sigma).ceil() as i64;
        let weights: Vec<f64> = (-radius..=radius).map(|d| (-0.5 * (d as f64 / sigma).powi(2)).exp()).collect();
        let total: f64 = weights.iter().sum();
        let pass = |src: &[f32], n_rows: usize, n_cols: usize, along_rows: bool| -> Vec<f32> {
            (0..n_rows * n_cols)
                .map(|i| {
                    let (r, c) = ((i / n_cols) as i64, (i % n_cols) as i64);
                    let sum: f64 = (-radius..=radius)
                        .zip(&weights)
                        .map(|(d, w)| {
                            let (rr, cc) = if along_rows {
                                ((r + d).clamp(0, n_rows as i64 - 1), c)
                            } else {
                                (r, (c + d).clamp(0, n_cols as i64 - 1))
                            };
                            w * src[rr as usize * n_cols + cc as usize] as f64
                        })
                        .sum();
                    (sum / total) as f32
                })
                .collect()
        };
        let across = pass(&self.data, self.rows, self.cols, false);
        let data = pass(&across, self.rows, self.cols, true);
        Raster { rows: self.rows, cols: self.cols, metres: self.metres, data }
    }

    /// Bilinear taps only (see [`Raster::resample`]).
    fn bilinear(&self, metres: f64) -> Raster {
        let scale = metres / self.metres;
        let rows = ((self.rows as f64 / scale).floor() as usize).max(1);
        let cols = ((self.cols as f64 / scale).floor() as usize).max(1);
        let tap = |i: usize, n: usize| {
            let x = ((i as f64 + 0.5) * scale - 0.5).clamp(0.0, (n - 1) as f64);
            let i0 = (x.floor() as usize).min(n.saturating_sub(2));
            let i1 = (i0 + 1).min(n - 1);
            (i0, i1, x - i0 as f64)
        };
        let data = (0..rows * cols)
            .map(|i| {
                let (r0, r1, ty) = tap(i / cols, self.rows);
                let (c0, c1, tx) = tap(i % cols, self.cols);
                let top = self.at(r0, c0) as f64 * (1.0 - tx) + self.at(r0, c1) as f64 * tx;
                let bottom = self.at(r1, c0) as f64 * (1.0 - tx) + self.at(r1, c1) as f64 * tx;
                (top * (1.0 - ty) + bottom * ty) as f32
            })
            .collect();
        Raster { rows, cols, metres, data }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_whole_blocks_only() {
        let r = Raster::from_fn(10, 7, 1.0, |y, x| (y * 7 + x) as f32);
        let t = r.tiles(3);
        assert_eq!(t.len(), 3 * 2);
        assert_eq!(t[1].data, vec![3.0, 4.0, 5.0, 10.0, 11.0, 12.0, 17.0, 18.0, 19.0]);
        assert_eq!(r.tiles(64).len(), 1, "a small raster is one tile");
    }

    #[test]
    fn halving_the_resolution_averages_blocks_and_planes_stay_planes() {
        let r = Raster::from_fn(4, 4, 500.0, |y, x| (y * 4 + x) as f32);
        let h = r.resample(1000.0);
        assert_eq!((h.rows, h.cols, h.metres), (2, 2, 1000.0));
        assert_eq!(h.data, vec![2.5, 4.5, 10.5, 12.5]);
        let plane = Raster::from_fn(9, 9, 100.0, |y, x| 2.0 * x as f32 - y as f32);
        let up = plane.resample(50.0);
        assert_eq!((up.rows, up.cols), (18, 18));
        let (a, b) = (up.at(5, 5), up.at(5, 7));
        assert!(((b - a) - 2.0).abs() < 1e-5, "plane slope lost: {a} {b}");
    }

    #[test]
    fn downsampling_by_more_than_two_blurs_away_what_the_new_grid_cannot_hold() {
        // A checkerboard (the shortest wavelength there is) is damped to a fraction of what
        // bilinear taps alone keep of it as a coarse pattern (away from the clamped edges); a
        // plane stays a plane.
        let checker = Raster::from_fn(64, 64, 40.0, |y, x| if (y + x) % 2 == 0 { 100.0 } else { -100.0 });
        let coarse = checker.resample(93.0);
        let worst = |r: &Raster| {
            (1..r.rows - 1)
                .flat_map(|y| (1..r.cols - 1).map(move |x| (y, x)))
                .map(|(y, x)| r.at(y, x).abs())
                .fold(0.0f32, f32::max)
        };
        let aliased = worst(&checker.bilinear(93.0));
        assert!(aliased > 30.0, "bilinear taps alone keep {aliased} m");
        assert!(worst(&coarse) < 0.2 * aliased, "aliased: {} m away from the edges", worst(&coarse));
        let plane = Raster::from_fn(64, 64, 40.0, |y, x| 3.0 * x as f32 + y as f32);
        let p = plane.resample(93.0);
        let step = p.at(10, 11) - p.at(10, 10);
        assert!((step - 3.0 * 93.0 / 40.0).abs() < 1e-3, "plane slope lost: {step}");
    }
}
