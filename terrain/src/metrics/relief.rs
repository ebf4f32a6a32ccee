//! Relative elevation: height above (or below) the mean of the surrounding window — the
//! "style" of relief (sharp ridges, broad valleys) with the regional level removed.

use super::Raster;

/// Default window radius, pixels: a 17×17 window (17 km at 1 km pixels, 8.5 km at 500 m),
/// the scale of individual ridges and valleys.
pub const RELIEF_RADIUS: usize = 8;

/// `z − mean(z over the (2·radius+1)² window)` for every pixel whose window lies inside the
/// raster (no padding, so edges add no artefacts). Uses a summed-area table in f64.
pub fn relative_elevation(r: &Raster, radius: usize) -> Vec<f32> {
    let k = 2 * radius + 1;
    if r.rows < k || r.cols < k {
        return Vec::new();
    }
    let w = r.cols + 1;
    let mut sat = vec![0.0f64; (r.rows + 1) * w];
    for y in 0..r.rows {
        let mut row = 0.0;
        for x in 0..r.cols {
            row += r.at(y, x) as f64;
            sat[(y + 1) * w + x + 1] = sat[y * w + x + 1] + row;
        }
    }
    let area = (k * k) as f64;
    let mut out = Vec::with_capacity((r.rows - k + 1) * (r.cols - k + 1));
    for y in radius..r.rows - radius {
        for x in radius..r.cols - radius {
            let (y0, y1, x0, x1) = (y - radius, y + radius + 1, x - radius, x + radius + 1);
            let sum = sat[y1 * w + x1] - sat[y0 * w + x1] - sat[y1 * w + x0] + sat[y0 * w + x0];
            out.push((r.at(y, x) as f64 - sum / area) as f32);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn planes_have_no_relative_relief_and_a_spike_stands_out() {
        let plane = Raster::from_fn(12, 12, 1.0, |y, x| 3.0 * x as f32 - 2.0 * y as f32 + 100.0);
        let rel = relative_elevation(&plane, 2);
        assert_eq!(rel.len(), 8 * 8);
        assert!(rel.iter().all(|v| v.abs() < 1e-4), "{rel:?}");
        let spike = Raster::from_fn(5, 5, 1.0, |y, x| if (y, x) == (2, 2) { 25.0 } else { 0.0 });
        assert_eq!(relative_elevation(&spike, 2), vec![24.0]);
    }
}
