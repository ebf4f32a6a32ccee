//! The climate model: temperature, seasonality, precipitation and its variability per cell,
//! computed physically over the generated terrain (no land climatology ships in the
//! registries). Temperature is the layout's sea-level field with a lapse rate on the final
//! elevation (pointwise); precipitation is orographic, with a prevailing wind over the coarse
//! elevation, so it needs upwind context and is a windowed infinite tensor itself.
//!
//! Owns: `[climate]` settings, the orographic window function, the lapse-rate formula.
//! Must not touch: Minecraft, biomes, learned models.

mod orographic;

use std::sync::Arc;

use serde::Deserialize;

use crate::infinite::{Source, WindowFn, WindowIndex, WindowLayout};
use crate::range::{check_range, RangeError};
use crate::tile::{Rect, Tile};

pub use orographic::{upwind_pad, variability_pct, wind_vector};

/// Owner knobs of the climate model (`[climate]` in `config/server.toml`).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ClimateSettings {
    /// Temperature drop with height, °C per km (Earth's standard atmosphere: 6.5).
    pub lapse_rate_c_per_km: f64,
    /// Where the prevailing wind blows from, degrees clockwise from north (270 = westerly).
    pub wind_from_deg: f64,
    /// Strength of orographic lift: extra precipitation per unit of upwind slope.
    pub orographic_strength: f64,
    /// Added to every sea-level temperature, °C (warmer or colder worlds).
    pub temperature_offset_c: f64,
    /// Multiplies every precipitation value (wetter or drier worlds).
    pub precipitation_scale: f64,
}

impl Default for ClimateSettings {
    fn default() -> Self {
        ClimateSettings {
            lapse_rate_c_per_km: 6.5,
            wind_from_deg: 270.0,
            orographic_strength: 1.0,
            temperature_offset_c: 0.0,
            precipitation_scale: 1.0,
        }
    }
}

impl ClimateSettings {
    /// Checks every value against its range.
    pub fn validate(&self) -> Result<(), RangeError> {
        check_range("climate.lapse_rate_c_per_km", self.lapse_rate_c_per_km, 0.0, 15.0)?;
        check_range("climate.wind_from_deg", self.wind_from_deg, 0.0, 360.0)?;
        check_range("climate.orographic_strength", self.orographic_strength, 0.0, 10.0)?;
        check_range("climate.temperature_offset_c", self.temperature_offset_c, -40.0, 40.0)?;
        check_range("climate.precipitation_scale", self.precipitation_scale, 0.0, 10.0)
    }
}

/// Air temperature at `elevation_m` given the sea-level temperature: the lapse rate applies
/// above sea level only (the sea surface is at 0 m).
pub fn temperature_at(sea_level_c: f32, elevation_m: f32, lapse_c_per_km: f32) -> f32 {
    sea_level_c - lapse_c_per_km * elevation_m.max(0.0) / 1000.0
}

/// Channels of the [`Orographic`] tensor.
pub mod precipitation {
    /// Annual precipitation, mm.
    pub const ANNUAL_MM: usize = 0;
    /// Inter-annual variability (coefficient of variation), %.
    pub const VARIABILITY_PCT: usize = 1;
    /// Number of channels.
    pub const CHANNELS: usize = 2;
}

/// Orographic precipitation as a window function on the coarse grid: moisture is carried
/// along the prevailing wind from the upwind edge of a padded window, rains out where the
/// air rises over terrain, recharges over the sea, and leaves rain shadows behind ridges.
pub struct Orographic {
    /// Coarse elevation, metres (one channel).
    pub elevation: Arc<dyn Source>,
    /// The layout's climate sketch on the same grid.
    pub sketch: Arc<dyn Source>,
    /// Climate settings.
    pub settings: ClimateSettings,
    /// Coarse cell size, metres (slopes are per metre).
    pub pixel_metres: f64,
    /// The window layout.
    pub layout: WindowLayout,
    /// Upwind context, cells.
    pub margin: i64,
}

impl WindowFn for Orographic {
    fn name(&self) -> &str {
        "climate.orographic"
    }
    fn channels(&self) -> usize {
        precipitation::CHANNELS
    }
    fn layout(&self) -> WindowLayout {
        self.layout
    }
    fn eval(&self, windows: &[WindowIndex]) -> Vec<Tile> {
        windows.iter().map(|&w| self.window(w)).collect()
    }
}

impl Orographic {
    /// Precipitation over one window: solved on the window padded by `margin` cells on its
    /// upwind sides (see [`upwind_pad`]), so air arriving at the window already carries its
    /// upwind history, then cropped. Depends on the window and the (pure) inputs only.
    fn window(&self, w: WindowIndex) -> Tile {
        let core = self.layout.rect(w);
        self.solve_over(upwind_pad(core, self.margin, self.settings.wind_from_deg), core)
    }

    /// Solves the sweep over `padded` and returns the part over `core` (inside it).
    fn solve_over(&self, padded: Rect, core: Rect) -> Tile {
        let elevation = self.elevation.query(padded);
        let sketch = self.sketch.query(padded);
        let base = sketch.channel(crate::layout::sketch::BASE_PRECIPITATION);
        let (h, w) = (padded.h as usize, padded.w as usize);
        let annual = orographic::solve(elevation.channel(0), base, h, w, &self.settings, self.pixel_metres);
        orographic::to_tile(annual, self.settings.precipitation_scale, padded).crop(core)
    }
}

/// [`Orographic`] precipitation of any rectangle solved in one sweep over it, padded by the
/// margin on its upwind sides: no windows, no cache. The continent's drainage asks for the
/// rain over 2,560 km at once; the windowed tensor answered that with about 440 overlapping
/// windows, 2.7 of a continental tile's 3.2 s (measured, cold). One sweep gives each cell at
/// least the windows' upwind history, so it differs from them only where air has crossed
/// more than the margin's 400 km of land, past which rain shadows have faded.
pub struct OrographicSweep(pub Orographic);

impl Source for OrographicSweep {
    fn channels(&self) -> usize {
        precipitation::CHANNELS
    }

    fn query(&self, rect: Rect) -> Tile {
        self.0.solve_over(upwind_pad(rect, self.0.margin, self.0.settings.wind_from_deg), rect)
    }
}

#[cfg(test)]
mod tests;
