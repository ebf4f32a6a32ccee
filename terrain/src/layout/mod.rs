//! The procedural continental layout: the cheap, owner-tunable sketch the hierarchy starts
//! from. Pure per-cell functions of (seed, settings, global coordinates) — fBm with domain
//! warp, quantile-mapped to Earth-like elevation distributions, plus a climate sketch.
//!
//! Owns: the knobs `ocean_fraction`, `continent_scale_km`, `mountain_frequency`,
//! `climate_zone_scale_km`. Must not touch: windows or caches (it is cheap enough to
//! recompute), learned models, Minecraft.

mod fbm;
mod hypsometry;
mod relief;
mod zones;

use std::sync::Arc;

use serde::Deserialize;

use crate::infinite::Source;
use crate::range::{check_range, RangeError};
use crate::tile::{Rect, Tile};

/// Owner knobs of the continental layout (`[layout]` in `config/server.toml`).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LayoutSettings {
    /// Fraction of the world's area under the sea.
    pub ocean_fraction: f64,
    /// Typical size of a continent, km.
    pub continent_scale_km: f64,
    /// How common mountain ranges are: 0 none, 1 Earth-like, 3 everywhere.
    pub mountain_frequency: f64,
    /// Distance from an "equator" to a "pole" of the climate zones, km.
    pub climate_zone_scale_km: f64,
}

impl Default for LayoutSettings {
    fn default() -> Self {
        LayoutSettings {
            ocean_fraction: 0.55,
            continent_scale_km: 2000.0,
            mountain_frequency: 1.0,
            climate_zone_scale_km: 3000.0,
        }
    }
}

impl LayoutSettings {
    /// Checks every value against its range.
    pub fn validate(&self) -> Result<(), RangeError> {
        check_range("layout.ocean_fraction", self.ocean_fraction, 0.0, 0.95)?;
        check_range("layout.continent_scale_km", self.continent_scale_km, 50.0, 20_000.0)?;
        check_range("layout.mountain_frequency", self.mountain_frequency, 0.0, 3.0)?;
        check_range("layout.climate_zone_scale_km", self.climate_zone_scale_km, 100.0, 50_000.0)
    }
}

/// Channels of [`Layout::climate_sketch`].
pub mod sketch {
    /// Sea-level annual mean temperature, °C.
    pub const SEA_LEVEL_TEMPERATURE: usize = 0;
    /// Temperature seasonality: standard deviation of monthly means, °C.
    pub const SEASONALITY: usize = 1;
    /// Precipitation before orography, mm/yr.
    pub const BASE_PRECIPITATION: usize = 2;
    /// Continentality: 0 on the open sea and coasts, 1 deep inside a continent.
    pub const CONTINENTALITY: usize = 3;
    /// Number of channels.
    pub const CHANNELS: usize = 4;
}

/// The continental layout for one seed. Cheap to clone (the calibrated fields are shared).
#[derive(Clone, Debug)]
pub struct Layout {
    seed: u64,
    settings: LayoutSettings,
    relief: Arc<relief::Relief>,
    zones: zones::Zones,
}

impl Layout {
    /// The layout of `seed` with `settings` (already validated). Calibrates the relief on a
    /// fixed sample of the seed's own noise (a few milliseconds).
    pub fn new(seed: u64, settings: &LayoutSettings) -> Layout {
        Layout {
            seed,
            settings: settings.clone(),
            relief: Arc::new(relief::Relief::new(seed, settings)),
            zones: zones::Zones::new(seed, settings.climate_zone_scale_km),
        }
    }

    /// The world seed this layout was built for.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// The settings this layout was built with.
    pub fn settings(&self) -> &LayoutSettings {
        &self.settings
    }

    /// Elevation in metres (negative under the sea) on a grid of `pixel_metres` cells, as a
    /// one-channel [`Source`]. Cell `(y, x)` is centred at `((y+0.5)·pixel_metres, …)`.
    pub fn elevation(&self, pixel_metres: f64) -> LayoutField {
        LayoutField { layout: self.clone(), pixel_metres, kind: FieldKind::Elevation }
    }

    /// The climate sketch (see [`sketch`] for channels) on a grid of `pixel_metres` cells.
    pub fn climate_sketch(&self, pixel_metres: f64) -> LayoutField {
        LayoutField { layout: self.clone(), pixel_metres, kind: FieldKind::ClimateSketch }
    }

    /// Elevation in metres at a point given in metres (y south, x east): strictly positive
    /// on land, strictly negative under the sea.
    pub fn elevation_at(&self, y_m: f64, x_m: f64) -> f32 {
        self.relief.elevation(y_m, x_m) as f32
    }

    /// The climate sketch's channels (see [`sketch`]) at a point given in metres. Smooth:
    /// built from the low-frequency continental value and the latitude-like zones only.
    pub fn sketch_at(&self, y_m: f64, x_m: f64, out: &mut [f32; sketch::CHANNELS]) {
        let cont = self.relief.continentality(y_m, x_m);
        zones::Zones::sketch(self.zones.latitude(y_m, x_m), cont, out);
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum FieldKind {
    Elevation,
    ClimateSketch,
}

/// One of the layout's fields sampled on a grid: a pure per-cell [`Source`].
#[derive(Clone, Debug)]
pub struct LayoutField {
    layout: Layout,
    pixel_metres: f64,
    kind: FieldKind,
}

impl Source for LayoutField {
    fn channels(&self) -> usize {
        match self.kind {
            FieldKind::Elevation => 1,
            FieldKind::ClimateSketch => sketch::CHANNELS,
        }
    }

    fn query(&self, rect: Rect) -> Tile {
        let mut out = Tile::zeros(self.channels(), rect);
        let n = rect.area();
        let mut i = 0;
        for y in rect.y0..rect.y1() {
            for x in rect.x0..rect.x1() {
                let (ym, xm) = ((y as f64 + 0.5) * self.pixel_metres, (x as f64 + 0.5) * self.pixel_metres);
                match self.kind {
                    FieldKind::Elevation => out.data[i] = self.layout.elevation_at(ym, xm),
                    FieldKind::ClimateSketch => {
                        let mut v = [0.0; sketch::CHANNELS];
                        self.layout.sketch_at(ym, xm, &mut v);
                        for (c, v) in v.iter().enumerate() {
                            out.data[c * n + i] = *v;
                        }
                    }
                }
                i += 1;
            }
        }
        out
    }
}

#[cfg(test)]
mod tests;
