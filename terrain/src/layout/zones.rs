//! Climate zones of the sketch: a latitude-like coordinate from y and the Earth-like
//! temperature, seasonality and precipitation belts it implies.

use super::fbm::Octave;
use super::sketch;

/// Noise component tag of the latitude perturbation.
const LATITUDE: u64 = 20;
/// Typical wobble of the zone boundaries, degrees.
const LATITUDE_WOBBLE_DEG: f64 = 9.0;

/// Zonal mean precipitation by latitude, mm/yr: wet ITCZ, dry subtropics, wet mid-latitude
/// storm tracks, dry poles.
const PRECIPITATION_BY_LATITUDE: [(f64, f64); 12] = [
    (0.0, 2200.0),
    (8.0, 1900.0),
    (15.0, 1000.0),
    (20.0, 450.0),
    (25.0, 300.0),
    (32.0, 300.0),
    (38.0, 550.0),
    (45.0, 900.0),
    (60.0, 900.0),
    (68.0, 500.0),
    (75.0, 250.0),
    (90.0, 250.0),
];

/// Folds any value onto a triangle wave: 0 at even integers, 1 at odd ones.
fn triangle(t: f64) -> f64 {
    (t - 2.0 * (t / 2.0).round()).abs()
}

/// The zone layout of one seed.
#[derive(Clone, Debug)]
pub(crate) struct Zones {
    zone_m: f64,
    wobble: Octave,
}

impl Zones {
    /// Zones repeating every `2 · zone_km` along y (equator, pole, equator, …).
    pub(crate) fn new(seed: u64, zone_km: f64) -> Zones {
        let zone_m = zone_km * 1000.0;
        Zones { zone_m, wobble: Octave::new(seed, LATITUDE, 0, 0.5 * zone_m) }
    }

    /// Latitude-like coordinate in degrees, 0 (equator, y = 0) to 90 (pole, y = zone scale),
    /// with boundaries wobbling by a low-frequency noise.
    pub(crate) fn latitude(&self, y: f64, x: f64) -> f64 {
        let lat = 90.0 * triangle(y / self.zone_m) + LATITUDE_WOBBLE_DEG * self.wobble.at(y, x);
        // Reflect at the equator and the pole so the wobble stays smooth there.
        90.0 * triangle(lat / 90.0)
    }

    /// The sketch channels for a latitude (degrees) and a continentality in [0, 1].
    pub(crate) fn sketch(lat: f64, cont: f64, out: &mut [f32; sketch::CHANNELS]) {
        let l = (lat / 90.0).clamp(0.0, 1.0);
        // Interiors are colder on the annual mean away from the tropics (long cold winters).
        let temperature = 27.0 - 45.0 * l * l - cont * (1.0 + 6.0 * l);
        let seasonality = 1.0 + 14.0 * l * (0.3 + 0.7 * cont);
        let precipitation = super::hypsometry::interp(&PRECIPITATION_BY_LATITUDE, lat) * (1.0 - 0.75 * cont);
        out[sketch::SEA_LEVEL_TEMPERATURE] = temperature as f32;
        out[sketch::SEASONALITY] = seasonality as f32;
        out[sketch::BASE_PRECIPITATION] = precipitation as f32;
        out[sketch::CONTINENTALITY] = cont as f32;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn latitude_runs_equator_pole_equator() {
        assert_eq!(triangle(0.0), 0.0);
        assert_eq!(triangle(1.0), 1.0);
        assert_eq!(triangle(2.0), 0.0);
        assert_eq!(triangle(-1.0), 1.0);
        assert!((triangle(0.25) - 0.25).abs() < 1e-12 && (triangle(-0.25) - 0.25).abs() < 1e-12);
        let z = Zones::new(1, 3000.0);
        for i in -50..50 {
            let lat = z.latitude(i as f64 * 1.3e5, i as f64 * 7e4);
            assert!((0.0..=90.0).contains(&lat), "{lat}");
        }
    }

    #[test]
    fn tropics_are_warm_and_wet_and_poles_cold_and_seasonal() {
        let (mut eq, mut pole) = ([0.0; sketch::CHANNELS], [0.0; sketch::CHANNELS]);
        Zones::sketch(0.0, 0.0, &mut eq);
        Zones::sketch(90.0, 1.0, &mut pole);
        assert_eq!(eq[sketch::SEA_LEVEL_TEMPERATURE], 27.0);
        assert!(pole[sketch::SEA_LEVEL_TEMPERATURE] < -20.0);
        assert!(pole[sketch::SEASONALITY] > 10.0 * eq[sketch::SEASONALITY]);
        assert!(eq[sketch::BASE_PRECIPITATION] > 2000.0 && pole[sketch::BASE_PRECIPITATION] < 100.0);
    }
}
