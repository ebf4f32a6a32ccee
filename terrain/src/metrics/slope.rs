//! Slope in degrees from central differences.

use super::Raster;

/// Slope angle, degrees, of every interior pixel (edges have no central difference and are
/// left out): `atan(√((∂z/∂x)² + (∂z/∂y)²))` with central differences over 2 pixels.
/// A plane `z = g·x` gives exactly `atan(g)` everywhere.
pub fn slope_degrees(r: &Raster) -> Vec<f32> {
    if r.rows < 3 || r.cols < 3 {
        return Vec::new();
    }
    let d = 2.0 * r.metres;
    let mut out = Vec::with_capacity((r.rows - 2) * (r.cols - 2));
    for y in 1..r.rows - 1 {
        for x in 1..r.cols - 1 {
            let gx = (r.at(y, x + 1) as f64 - r.at(y, x - 1) as f64) / d;
            let gy = (r.at(y + 1, x) as f64 - r.at(y - 1, x) as f64) / d;
            out.push(gx.hypot(gy).atan().to_degrees() as f32);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plane_has_slope_atan_of_its_gradient() {
        // 30 m per 100 m pixel east, 40 m per pixel south: gradient 0.5, slope atan(0.5).
        let plane = Raster::from_fn(16, 20, 100.0, |y, x| 30.0 * x as f32 + 40.0 * y as f32 - 500.0);
        let s = slope_degrees(&plane);
        assert_eq!(s.len(), 14 * 18);
        let expected = 0.5f64.atan().to_degrees() as f32;
        for v in s {
            assert!((v - expected).abs() < 1e-4, "{v} vs {expected}");
        }
        let flat = Raster::from_fn(5, 5, 30.0, |_, _| 7.0);
        assert!(slope_degrees(&flat).iter().all(|&v| v == 0.0));
    }
}
