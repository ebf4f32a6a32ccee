use super::*;
use crate::infinite::{Engine, EngineConfig, Windowed};
use crate::layout::sketch;
use crate::tile::Rect;

/// Coarse cell size of the synthetic tests, metres.
const PIXEL_M: f64 = 5_000.0;

/// A north–south Gaussian ridge 2000 m high (σ = 30 km) at x = 0 on a 100 m plain.
struct Ridge;

impl Source for Ridge {
    fn channels(&self) -> usize {
        1
    }
    fn query(&self, rect: Rect) -> Tile {
        let row: Vec<f32> = (rect.x0..rect.x1())
            .map(|x| {
                let d = (x as f64 + 0.5) * PIXEL_M / 30_000.0;
                (100.0 + 2000.0 * (-0.5 * d * d).exp()) as f32
            })
            .collect();
        Tile::from_data(1, rect, row.repeat(rect.h as usize))
    }
}

/// A flat climate sketch: 1000 mm/yr everywhere, no continentality.
struct FlatSketch;

impl Source for FlatSketch {
    fn channels(&self) -> usize {
        sketch::CHANNELS
    }
    fn query(&self, rect: Rect) -> Tile {
        let n = rect.area();
        let mut data = vec![0.0; sketch::CHANNELS * n];
        data[sketch::SEA_LEVEL_TEMPERATURE * n..][..n].fill(15.0);
        data[sketch::SEASONALITY * n..][..n].fill(5.0);
        data[sketch::BASE_PRECIPITATION * n..][..n].fill(1000.0);
        Tile::from_data(sketch::CHANNELS, rect, data)
    }
}

/// Hills and sea basins varying along both axes, for checks any wind direction exercises.
struct Bumps;

impl Source for Bumps {
    fn channels(&self) -> usize {
        1
    }
    fn query(&self, rect: Rect) -> Tile {
        let mut data = Vec::with_capacity(rect.area());
        for y in rect.y0..rect.y1() {
            for x in rect.x0..rect.x1() {
                data.push((300.0 + 1500.0 * (x as f64 / 7.0).sin() * (y as f64 / 5.0).cos()) as f32);
            }
        }
        Tile::from_data(1, rect, data)
    }
}

fn orographic(elevation: Arc<dyn Source>, wind_from_deg: f64) -> Orographic {
    Orographic {
        elevation,
        sketch: Arc::new(FlatSketch),
        settings: ClimateSettings { wind_from_deg, ..Default::default() },
        pixel_metres: PIXEL_M,
        layout: WindowLayout::square(32, 16, 0),
        margin: 64,
    }
}

fn precipitation_across_ridge(wind_from_deg: f64) -> Vec<f32> {
    let engine = Engine::new(EngineConfig { cache_bytes: 64 << 20, threads: 1 });
    let tensor = Windowed::new(&engine, orographic(Arc::new(Ridge), wind_from_deg));
    let t = tensor.query(Rect::new(-3, -60, 4, 120));
    assert!(t.data.iter().all(|v| v.is_finite()));
    // One row, west to east (x = −60 … 59); rows are identical for a north–south ridge.
    (0..120).map(|k| t.get(precipitation::ANNUAL_MM, 0, k - 60)).collect()
}

fn mean(v: &[f32]) -> f32 {
    v.iter().sum::<f32>() / v.len() as f32
}

/// Mean precipitation over cells `x0..x1` of the row returned by `precipitation_across_ridge`.
fn band(p: &[f32], x0: i64, x1: i64) -> f32 {
    mean(&p[(x0 + 60) as usize..(x1 + 60) as usize])
}

#[test]
fn westerly_wind_wets_the_west_slope_and_dries_the_east() {
    let p = precipitation_across_ridge(270.0);
    let (plain, windward, lee) = (band(&p, -60, -50), band(&p, -8, -2), band(&p, 2, 8));
    println!("westerly: upwind plain {plain:.0}, windward slope {windward:.0}, lee {lee:.0} mm/yr");
    assert!(windward > 2.0 * lee, "windward {windward} vs lee {lee} mm");
    assert!(windward > 1.3 * plain, "windward {windward} vs upwind plain {plain} mm");
    assert!(lee < 0.8 * plain, "lee {lee} vs upwind plain {plain} mm");
}

#[test]
fn easterly_wind_flips_the_rain_shadow() {
    let p = precipitation_across_ridge(90.0);
    let (plain, windward, lee) = (band(&p, 50, 60), band(&p, 2, 8), band(&p, -8, -2));
    assert!(windward > 2.0 * lee, "windward {windward} vs lee {lee} mm");
    assert!(lee < 0.8 * plain, "lee {lee} vs upwind plain {plain} mm");
}

#[test]
fn diagonal_wind_still_casts_a_shadow_and_variability_tracks_dryness() {
    let p = precipitation_across_ridge(225.0);
    assert!(band(&p, -8, -2) > 1.5 * band(&p, 2, 8));
    assert!(variability_pct(100.0) > variability_pct(500.0) && variability_pct(500.0) > variability_pct(2000.0));
    assert!((5.0..=80.0).contains(&variability_pct(0.0)) && variability_pct(1e6) >= 5.0);
}

#[test]
fn wind_vector_points_downwind() {
    let close = |a: (f64, f64), b: (f64, f64)| (a.0 - b.0).abs() < 1e-12 && (a.1 - b.1).abs() < 1e-12;
    assert!(close(wind_vector(270.0), (1.0, 0.0)), "westerly blows east");
    assert!(close(wind_vector(0.0), (0.0, 1.0)), "northerly blows south (+y)");
    assert!(close(wind_vector(90.0), (-1.0, 0.0)));
    assert!(close(wind_vector(180.0), (0.0, -1.0)));
}

#[test]
fn temperature_follows_the_lapse_rate_above_sea_level_only() {
    let s = ClimateSettings::default();
    let lapse = s.lapse_rate_c_per_km as f32;
    for h in [10.0f32, 250.0, 1000.0, 2500.0, 4800.0, 8000.0] {
        let rate = (temperature_at(20.0, 0.0, lapse) - temperature_at(20.0, h, lapse)) / h * 1000.0;
        assert!((rate - lapse).abs() < 1e-3, "{rate} °C/km at {h} m");
    }
    for h in [-1.0f32, -200.0, -5000.0] {
        assert_eq!(temperature_at(20.0, h, lapse), 20.0, "no lapse below sea level ({h} m)");
    }
}

#[test]
fn upwind_padding_gives_the_same_window_as_padding_every_side() {
    for wind in [0.0, 30.0, 90.0, 123.0, 180.0, 225.0, 270.0, 315.0] {
        let f = orographic(Arc::new(Bumps), wind);
        let core = f.layout.rect(WindowIndex { iy: -3, ix: 5 });
        let full = f.solve_over(core.pad(f.margin), core);
        assert_eq!(f.solve_over(upwind_pad(core, f.margin, wind), core), full, "wind from {wind}°");
        assert!(full.data.iter().all(|v| v.is_finite() && *v >= 0.0));
    }
}

#[test]
fn precipitation_is_a_function_of_the_region_only() {
    let region = Rect::new(-40, 70, 48, 56);
    let whole = {
        let engine = Engine::new(EngineConfig { cache_bytes: 64 << 20, threads: 2 });
        Windowed::new(&engine, orographic(Arc::new(Bumps), 250.0)).query(region)
    };
    let engine = Engine::new(EngineConfig { cache_bytes: 1 << 20, threads: 1 });
    let tensor = Windowed::new(&engine, orographic(Arc::new(Bumps), 250.0));
    for part in [Rect::new(-10, 100, 9, 20), Rect::new(-40, 70, 13, 11), Rect::new(0, 120, 8, 6)] {
        assert_eq!(tensor.query(part), whole.crop(part));
    }
}
