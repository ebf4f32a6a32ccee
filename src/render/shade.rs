//! Hillshade: relief as light and shadow, with the sun in the north-west at 45°.
//!
//! The sun sits in the north-west because readers perceive relief correctly when light comes
//! from the top left (from the south, valleys read as ridges). Slopes flatten as the pixel
//! grows, so the vertical exaggeration grows with metres per pixel to keep relief readable
//! at every zoom.

/// Sun altitude: 45° (the cartographic convention).
const SUN_ALTITUDE: f32 = std::f32::consts::FRAC_PI_4;

/// Vertical exaggeration for pixels `metres_per_px` wide: 2× at block resolution (125 m),
/// growing with the 0.4th power of the pixel size (~18× at 32 km/px), which keeps mountain
/// ranges legible on continental maps without turning them into black-and-white streaks.
pub(crate) fn exaggeration(metres_per_px: f64) -> f32 {
    (2.0 * (metres_per_px / 125.0).powf(0.4)).clamp(1.0, 40.0) as f32
}

/// Illumination of a pixel from its four neighbours' elevations (metres), `spacing_m` apart:
/// 1.0 on flat ground, above 1 on slopes facing the sun, toward 0 on slopes facing away.
pub(crate) fn illumination(west: f32, east: f32, north: f32, south: f32, spacing_m: f32, exaggeration: f32) -> f32 {
    let dz_dx = exaggeration * (east - west) / (2.0 * spacing_m);
    let dz_dy = exaggeration * (south - north) / (2.0 * spacing_m); // y points south
    if !(dz_dx.is_finite() && dz_dy.is_finite()) {
        return 1.0;
    }
    // Unit vector toward the sun: north-west (−x, −y) and up.
    let (s, c) = SUN_ALTITUDE.sin_cos();
    let h = c * std::f32::consts::FRAC_1_SQRT_2;
    let dot = (dz_dx * h + dz_dy * h + s) / (dz_dx * dz_dx + dz_dy * dz_dy + 1.0).sqrt();
    dot.max(0.0) / s
}

/// Darkens or lightens `colour` by `illumination`, at `strength` 0 (no shading) to 1 (full).
pub(crate) fn apply(colour: [f32; 3], illumination: f32, strength: f32) -> [f32; 3] {
    let factor = (1.0 + strength * (illumination - 1.0)).clamp(0.15, 1.6);
    colour.map(|v| v * factor)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_ground_keeps_its_colour() {
        let i = illumination(100.0, 100.0, 100.0, 100.0, 125.0, 2.0);
        assert!((i - 1.0).abs() < 1e-6);
        assert_eq!(apply([10.0, 20.0, 30.0], i, 1.0), [10.0, 20.0, 30.0]);
    }

    #[test]
    fn slopes_facing_the_north_west_sun_are_lit_and_others_shaded() {
        // Rising toward the south-east faces the sun.
        let lit = illumination(0.0, 100.0, 0.0, 100.0, 125.0, 2.0);
        let dark = illumination(100.0, 0.0, 100.0, 0.0, 125.0, 2.0);
        assert!(lit > 1.0 && dark < 1.0, "lit {lit}, dark {dark}");
    }

    #[test]
    fn exaggeration_grows_with_pixel_size() {
        assert!(exaggeration(125.0) < exaggeration(2000.0));
        assert!(exaggeration(2000.0) < exaggeration(64_000.0));
        assert!(exaggeration(1.0) >= 1.0);
    }
}
