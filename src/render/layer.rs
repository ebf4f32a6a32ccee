//! Map layers: their names on the command line and, per layer, the pipeline channel it shows,
//! its colours and legend, and how strongly the hillshade applies.

use std::fmt;
use std::str::FromStr;

use super::panel::Legend;
use super::ramp;
use crate::terrain::pipeline::channel;

/// What a map shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Layer {
    /// Elevation: hypsometric tint under a hillshade.
    Elevation,
    /// Annual mean temperature, °C.
    Temperature,
    /// Annual precipitation, mm/yr.
    Precipitation,
    /// Temperature seasonality (standard deviation of monthly means), °C.
    Seasonality,
    /// Precipitation variability (coefficient of variation), %.
    Variability,
    /// Minecraft biomes, from the biome rules (see [`render_biomes`](super::render_biomes)).
    Biome,
    /// Rivers by discharge, lakes, dry lake beds and the sea (see
    /// [`render_water`](super::render_water)).
    Water,
}

impl Layer {
    /// Every layer, in the order the help text lists them.
    pub const ALL: [Layer; 7] = [
        Layer::Elevation,
        Layer::Temperature,
        Layer::Precipitation,
        Layer::Seasonality,
        Layer::Variability,
        Layer::Biome,
        Layer::Water,
    ];

    /// The name used on the command line and in titles.
    pub fn name(self) -> &'static str {
        match self {
            Layer::Elevation => "elevation",
            Layer::Temperature => "temperature",
            Layer::Precipitation => "precipitation",
            Layer::Seasonality => "seasonality",
            Layer::Variability => "variability",
            Layer::Biome => "biome",
            Layer::Water => "water",
        }
    }
}

impl fmt::Display for Layer {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A layer name that is not one of [`Layer::ALL`].
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "unknown layer `{given}` (allowed: elevation, temperature, precipitation, seasonality, variability, biome, water)"
)]
pub struct UnknownLayer {
    /// The name as given.
    pub given: String,
}

impl FromStr for Layer {
    type Err = UnknownLayer;

    fn from_str(s: &str) -> Result<Layer, UnknownLayer> {
        let wanted = s.trim().to_ascii_lowercase();
        Layer::ALL.into_iter().find(|l| l.name() == wanted).ok_or_else(|| UnknownLayer { given: s.to_string() })
    }
}

/// How one layer is drawn.
pub(crate) struct Style {
    /// Pipeline channel shown.
    pub channel: usize,
    /// Colours and legend.
    pub legend: Legend,
    /// Hillshade strength on land and at sea (0 = none, 1 = full).
    pub land_shading: f32,
    /// See `land_shading`.
    pub sea_shading: f32,
    /// Draw the coastline: climate colours alone do not show where the sea is.
    pub coastline: bool,
}

/// Legend position → elevation: piecewise linear so the lowlands, where land colours change
/// fastest, get a quarter of the bar instead of a twelfth.
const ELEVATION_LEGEND: [(f32, f32); 4] = [(0.0, -6000.0), (0.3, 0.0), (0.55, 1000.0), (1.0, 6000.0)];

fn piecewise(anchors: &[(f32, f32)], t: f32) -> f32 {
    let i = anchors.iter().position(|a| a.0 >= t).unwrap_or(anchors.len() - 1).max(1);
    let (a, b) = (anchors[i - 1], anchors[i]);
    a.1 + (t - a.0) / (b.0 - a.0) * (b.1 - a.1)
}

fn inverse(anchors: &[(f32, f32)], v: f32) -> f32 {
    let swapped: Vec<(f32, f32)> = anchors.iter().map(|&(t, v)| (v, t)).collect();
    piecewise(&swapped, v)
}

fn linear(range: (f32, f32), t: f32) -> f32 {
    range.0 + t * (range.1 - range.0)
}

fn fraction(range: (f32, f32), v: f32) -> f32 {
    (v - range.0) / (range.1 - range.0)
}

/// The style of a layer, or `None` for the biome and water layers (drawn by their own
/// renderers).
pub(crate) fn style(layer: Layer) -> Option<Style> {
    use ramp::{SEASONALITY_RANGE as S, TEMPERATURE_RANGE as T, VARIABILITY_RANGE as V};
    let climate = |channel: usize, legend: Legend| Style {
        channel,
        legend,
        land_shading: 0.35,
        sea_shading: 0.1,
        coastline: true,
    };
    Some(match layer {
        Layer::Elevation => Style {
            channel: channel::ELEVATION,
            legend: Legend {
                caption: "elevation (m)",
                value_at: |t| piecewise(&ELEVATION_LEGEND, t),
                position_of: |v| inverse(&ELEVATION_LEGEND, v),
                colour: ramp::elevation,
                ticks: &[-6000.0, -4000.0, -2000.0, 0.0, 500.0, 1000.0, 2000.0, 3000.0, 4000.0, 5000.0, 6000.0],
            },
            land_shading: 1.0,
            sea_shading: 0.35,
            coastline: false,
        },
        Layer::Temperature => climate(
            channel::TEMPERATURE,
            Legend {
                caption: "annual mean temperature (°C)",
                value_at: |t| linear(T, t),
                position_of: |v| fraction(T, v),
                colour: ramp::temperature,
                ticks: &[-30.0, -20.0, -10.0, 0.0, 10.0, 20.0, 30.0],
            },
        ),
        Layer::Precipitation => climate(
            channel::PRECIPITATION,
            Legend {
                caption: "annual precipitation (mm/yr)",
                value_at: ramp::precipitation_at_fraction,
                position_of: ramp::precipitation_fraction,
                colour: ramp::precipitation,
                ticks: &[0.0, 100.0, 250.0, 500.0, 1000.0, 2000.0, 3000.0],
            },
        ),
        Layer::Seasonality => climate(
            channel::SEASONALITY,
            Legend {
                caption: "temperature seasonality (°C, sd of monthly means)",
                value_at: |t| linear(S, t),
                position_of: |v| fraction(S, v),
                colour: |v| ramp::viridis(v, S.0, S.1),
                ticks: &[0.0, 5.0, 10.0, 15.0, 20.0],
            },
        ),
        Layer::Variability => climate(
            channel::VARIABILITY,
            Legend {
                caption: "precipitation variability (%, coefficient of variation)",
                value_at: |t| linear(V, t),
                position_of: |v| fraction(V, v),
                colour: |v| ramp::viridis(v, V.0, V.1),
                ticks: &[0.0, 20.0, 40.0, 60.0, 80.0],
            },
        ),
        Layer::Biome | Layer::Water => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layer_names_round_trip() {
        for l in Layer::ALL {
            assert_eq!(l.name().parse::<Layer>(), Ok(l));
            assert_eq!(l.to_string(), l.name());
        }
        assert_eq!(" Elevation ".parse::<Layer>(), Ok(Layer::Elevation));
    }

    #[test]
    fn unknown_layer_lists_the_allowed_names() {
        let err = "height".parse::<Layer>().unwrap_err().to_string();
        assert!(err.contains("`height`"), "{err}");
        for l in Layer::ALL {
            assert!(err.contains(l.name()), "{err} should list {l}");
        }
    }

    #[test]
    fn legend_positions_invert_values() {
        for l in Layer::ALL {
            let Some(style) = style(l) else { continue };
            let lg = &style.legend;
            for &v in lg.ticks {
                let back = (lg.value_at)((lg.position_of)(v));
                assert!((back - v).abs() <= 0.01 * v.abs().max(1.0), "{l}: tick {v} → {back}");
            }
            let positions: Vec<f32> = lg.ticks.iter().map(|&v| (lg.position_of)(v)).collect();
            assert!(positions.windows(2).all(|w| w[0] < w[1]), "{l}: ticks out of order");
            assert!(positions.iter().all(|p| (-1e-4..=1.0001).contains(p)), "{l}: tick off the bar");
        }
    }

    #[test]
    fn only_the_biome_and_water_layers_lack_a_style() {
        for l in Layer::ALL {
            assert_eq!(style(l).is_none(), matches!(l, Layer::Biome | Layer::Water), "{l}");
        }
    }
}
