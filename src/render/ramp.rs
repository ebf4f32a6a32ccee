//! Colour ramps: physical value → colour for every map layer.
//!
//! Colours come back as `[f32; 3]` in 0..=255 so the hillshade can scale them before the
//! single rounding to `u8`. Every ramp clamps outside its range, so an out-of-range value
//! shows as the nearest end colour rather than wrapping or panicking.

/// Shown for NaN: a colour no ramp uses, so missing data is visibly wrong, never plausible.
pub(crate) const NO_DATA: [f32; 3] = [255.0, 0.0, 255.0];

/// A piecewise-linear ramp through `(value, colour)` stops given in increasing value order.
pub(crate) struct Ramp {
    stops: &'static [(f32, [u8; 3])],
}

impl Ramp {
    /// The colour at `v`, clamped to the end stops.
    pub(crate) fn colour(&self, v: f32) -> [f32; 3] {
        if v.is_nan() {
            return NO_DATA;
        }
        let stops = self.stops;
        let (first, last) = (stops[0], stops[stops.len() - 1]);
        if v <= first.0 {
            return to_f32(first.1);
        }
        if v >= last.0 {
            return to_f32(last.1);
        }
        // A handful of stops: a linear scan is faster than anything clever.
        let i = stops.iter().position(|s| s.0 > v).unwrap_or(stops.len() - 1);
        let (a, b) = (stops[i - 1], stops[i]);
        let t = (v - a.0) / (b.0 - a.0);
        let mut out = [0.0; 3];
        for (k, o) in out.iter_mut().enumerate() {
            *o = a.1[k] as f32 + t * (b.1[k] as f32 - a.1[k] as f32);
        }
        out
    }
}

fn to_f32(c: [u8; 3]) -> [f32; 3] {
    [c[0] as f32, c[1] as f32, c[2] as f32]
}

/// Sea floor by depth (metres, negative): deep navy in the abyss to a pale shelf at the coast.
const SEA: Ramp = Ramp {
    stops: &[
        (-8000.0, [8, 18, 56]),
        (-5000.0, [16, 40, 98]),
        (-3000.0, [28, 68, 138]),
        (-1000.0, [52, 108, 184]),
        (-200.0, [98, 158, 214]),
        (0.0, [158, 206, 238]),
    ],
};

/// Land by height (metres): lowland greens, yellow and brown uplands, grey rock, white peaks.
const LAND: Ramp = Ramp {
    stops: &[
        (0.0, [76, 140, 78]),
        (300.0, [136, 180, 98]),
        (800.0, [218, 206, 128]),
        (1500.0, [190, 148, 94]),
        (2500.0, [148, 112, 88]),
        (3500.0, [150, 146, 142]),
        (4500.0, [248, 248, 248]),
    ],
};

/// Hypsometric tint of an elevation in metres (sea below 0 m, land at and above).
pub(crate) fn elevation(metres: f32) -> [f32; 3] {
    if metres < 0.0 {
        SEA.colour(metres)
    } else {
        LAND.colour(metres)
    }
}

/// Range of the temperature ramp, °C.
pub(crate) const TEMPERATURE_RANGE: (f32, f32) = (-30.0, 35.0);

/// Diverging blue → white → red with white at freezing, where biomes change most visibly.
/// Stops are chosen so "redness" (red − blue) never decreases with temperature.
const TEMPERATURE: Ramp = Ramp {
    stops: &[
        (-30.0, [20, 40, 140]),
        (-15.0, [120, 170, 235]),
        (0.0, [245, 245, 245]),
        (15.0, [240, 170, 110]),
        (35.0, [170, 20, 20]),
    ],
};

/// Annual mean temperature, °C.
pub(crate) fn temperature(celsius: f32) -> [f32; 3] {
    TEMPERATURE.colour(celsius)
}

/// Top of the precipitation ramp, mm/yr.
pub(crate) const PRECIPITATION_MAX: f32 = 3000.0;
/// The log offset (mm/yr): below it the scale is roughly linear, above it logarithmic, so
/// deserts (0–250 mm) and rain forests (2000+ mm) both get a readable share of the ramp.
const PRECIPITATION_KNEE: f32 = 100.0;

/// Position of a precipitation value on its ramp, 0..=1 (log-ish, clamped).
pub(crate) fn precipitation_fraction(mm: f32) -> f32 {
    let t = (1.0 + mm.max(0.0) / PRECIPITATION_KNEE).ln() / (1.0 + PRECIPITATION_MAX / PRECIPITATION_KNEE).ln();
    t.clamp(0.0, 1.0)
}

/// Inverse of [`precipitation_fraction`] on 0..=1.
pub(crate) fn precipitation_at_fraction(t: f32) -> f32 {
    PRECIPITATION_KNEE * ((1.0 + PRECIPITATION_MAX / PRECIPITATION_KNEE).powf(t.clamp(0.0, 1.0)) - 1.0)
}

/// Dry brown → yellow → green → blue, over the log-ish fraction. The blue share of each
/// stop rises monotonically, so wetter always reads bluer.
const PRECIPITATION: Ramp = Ramp {
    stops: &[
        (0.0, [150, 95, 45]),
        (0.3, [235, 215, 110]),
        (0.6, [90, 170, 80]),
        (0.8, [40, 130, 160]),
        (1.0, [30, 50, 150]),
    ],
};

/// Annual precipitation, mm/yr.
pub(crate) fn precipitation(mm: f32) -> [f32; 3] {
    if mm.is_nan() {
        return NO_DATA;
    }
    PRECIPITATION.colour(precipitation_fraction(mm))
}

/// Viridis (matplotlib's perceptually uniform, colour-blind-safe ramp), sampled at nine stops;
/// its lightness rises monotonically.
const VIRIDIS: Ramp = Ramp {
    stops: &[
        (0.0, [68, 1, 84]),
        (0.125, [71, 44, 122]),
        (0.25, [59, 81, 139]),
        (0.375, [44, 113, 142]),
        (0.5, [33, 144, 141]),
        (0.625, [39, 173, 129]),
        (0.75, [92, 200, 99]),
        (0.875, [170, 220, 50]),
        (1.0, [253, 231, 37]),
    ],
};

/// Viridis over `lo..=hi`.
pub(crate) fn viridis(v: f32, lo: f32, hi: f32) -> [f32; 3] {
    VIRIDIS.colour((v - lo) / (hi - lo))
}

/// Range of the seasonality ramp (standard deviation of monthly means), °C: Earth's runs from
/// ~0 on tropical coasts to ~20 deep in Siberia.
pub(crate) const SEASONALITY_RANGE: (f32, f32) = (0.0, 20.0);
/// Range of the precipitation-variability ramp (coefficient of variation), %: the climate
/// model gives 10 % in wet places up to 80 % in deserts.
pub(crate) const VARIABILITY_RANGE: (f32, f32) = (0.0, 80.0);

/// Rounds a shaded colour to pixels.
pub(crate) fn to_rgb(c: [f32; 3]) -> image::Rgb<u8> {
    image::Rgb(c.map(|v| v.round().clamp(0.0, 255.0) as u8))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn luminance(c: [f32; 3]) -> f32 {
        0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
    }

    /// `n + 1` evenly spaced samples over `lo..=hi`.
    fn samples(lo: f32, hi: f32, n: usize) -> impl Iterator<Item = f32> {
        (0..=n).map(move |i| lo + (hi - lo) * i as f32 / n as f32)
    }

    fn assert_bounded_and_continuous(f: impl Fn(f32) -> [f32; 3], lo: f32, hi: f32) {
        let mut prev: Option<[f32; 3]> = None;
        for v in samples(lo, hi, 2000) {
            let c = f(v);
            assert!(c.iter().all(|x| (0.0..=255.0).contains(x)), "{c:?} at {v}");
            if let Some(p) = prev {
                let jump = (0..3).map(|k| (c[k] - p[k]).abs()).fold(0.0, f32::max);
                assert!(jump < 8.0, "jump of {jump} at {v}");
            }
            prev = Some(c);
        }
    }

    #[test]
    fn ramps_are_bounded_and_continuous() {
        assert_bounded_and_continuous(elevation, -9000.0, -0.01);
        assert_bounded_and_continuous(elevation, 0.0, 9000.0);
        assert_bounded_and_continuous(temperature, -50.0, 50.0);
        assert_bounded_and_continuous(precipitation, 0.0, 5000.0);
        assert_bounded_and_continuous(|v| viridis(v, 0.0, 20.0), -5.0, 25.0);
    }

    #[test]
    fn ramps_clamp_outside_their_range() {
        assert_eq!(temperature(-80.0), temperature(-30.0));
        assert_eq!(temperature(90.0), temperature(35.0));
        assert_eq!(precipitation(-10.0), precipitation(0.0));
        assert_eq!(precipitation(1e6), precipitation(PRECIPITATION_MAX));
        assert_eq!(elevation(12_000.0), elevation(4500.0));
        assert_eq!(elevation(-11_000.0), elevation(-8000.0));
        assert_eq!(viridis(-1.0, 0.0, 1.0), viridis(0.0, 0.0, 1.0));
        assert_eq!(temperature(f32::NAN), NO_DATA);
        assert_eq!(precipitation(f32::NAN), NO_DATA);
    }

    #[test]
    fn sequential_ramps_are_monotone() {
        // Deeper sea is darker; viridis brightens; warmer is redder; wetter is bluer.
        let mut prev = f32::NEG_INFINITY;
        for v in samples(-8000.0, -0.01, 500) {
            let l = luminance(elevation(v));
            assert!(l >= prev - 1e-3, "sea luminance drops toward the coast at {v}");
            prev = l;
        }
        let mut prev = f32::NEG_INFINITY;
        for v in samples(0.0, 1.0, 500) {
            let l = luminance(viridis(v, 0.0, 1.0));
            assert!(l >= prev - 1e-3, "viridis luminance drops at {v}");
            prev = l;
        }
        let mut prev = f32::NEG_INFINITY;
        for v in samples(-30.0, 35.0, 500) {
            let c = temperature(v);
            assert!(c[0] - c[2] >= prev - 1e-3, "temperature redness drops at {v}");
            prev = c[0] - c[2];
        }
        let mut prev = f32::NEG_INFINITY;
        for v in samples(0.0, 3000.0, 500) {
            let c = precipitation(v);
            let blue = c[2] / (c[0] + c[1] + c[2]);
            assert!(blue >= prev - 1e-4, "precipitation blueness drops at {v}");
            prev = blue;
        }
    }

    #[test]
    fn precipitation_scale_round_trips() {
        for mm in [0.0, 50.0, 250.0, 1000.0, 3000.0] {
            let back = precipitation_at_fraction(precipitation_fraction(mm));
            assert!((back - mm).abs() < 0.01 * mm.max(1.0), "{mm} → {back}");
        }
        assert_eq!(precipitation_fraction(0.0), 0.0);
        assert!((precipitation_fraction(PRECIPITATION_MAX) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn sea_and_land_are_told_apart_at_the_coast() {
        let (sea, land) = (elevation(-0.5), elevation(0.0));
        assert!(sea[2] > sea[1] && land[1] > land[2], "sea {sea:?} should be blue, land {land:?} green");
    }
}
