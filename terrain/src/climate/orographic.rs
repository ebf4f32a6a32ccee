//! The orographic precipitation scheme on one padded window: moisture advected by a
//! first-order upwind sweep, rained out by uplift, recharged over the sea.

use super::{precipitation, ClimateSettings};
use crate::tile::Tile;

/// Extra precipitation per unit of uplift slope at strength 1: a 1000 m rise over 20 km
/// (slope 0.05) triples precipitation (1 + 40 · 0.05 = 3).
const UPLIFT_GAIN: f64 = 40.0;
/// Rise (m) over which orographic rain-out removes 1 − 1/e of the moisture at strength 1:
/// air crossing a 2000 m ridge keeps ~60 %, so the lee gets about a third of the windward
/// slope's rain and half of the upwind plain's.
const RAINOUT_RISE_M: f64 = 4_000.0;
/// Distance over which air loses 1 − 1/e of its moisture over land without uplift
/// (continental interiors are drier).
const LAND_DRYING_M: f64 = 2_000_000.0;
/// Distance over which air over the sea recovers 1 − 1/e of its missing moisture.
const SEA_RECHARGE_M: f64 = 400_000.0;

/// The wind's unit vector `(dx, dy)` pointing where it blows TO, for a wind blowing FROM
/// `from_deg` clockwise from north (north = −y, east = +x).
pub fn wind_vector(from_deg: f64) -> (f64, f64) {
    let a = from_deg.to_radians();
    let (dx, dy) = (-a.sin(), a.cos());
    // Snap round-off (e.g. cos 90° ≈ 6e-17) so axis-aligned winds stay exactly 1-D.
    let snap = |v: f64| if v.abs() < 1e-9 { 0.0 } else { v };
    (snap(dx), snap(dy))
}

/// Inter-annual variability (%) for an annual precipitation (mm): drier climates vary more
/// (≈ 60 % at 100 mm, 40 % at 250 mm, 12 % at 1000 mm, as in Earth's observed relation).
pub fn variability_pct(annual_mm: f64) -> f64 {
    (10.0 + 70.0 * (-annual_mm / 300.0).exp()).clamp(5.0, 80.0)
}

/// Precipitation and variability over a padded window, given its elevation (m) and base
/// precipitation (mm/yr) planes, `h × w` row-major.
pub(crate) fn solve(elevation: &[f32], base: &[f32], h: usize, w: usize, s: &ClimateSettings, pixel_m: f64) -> [Vec<f32>; 2] {
    let (dx, dy) = wind_vector(s.wind_from_deg);
    let (ax, ay) = (dx.abs(), dy.abs());
    let (sx, sy) = (dx < 0.0, dy < 0.0);
    let strength = s.orographic_strength;
    let land_keep = (-pixel_m / LAND_DRYING_M).exp();
    let sea_recharge = 1.0 - (-pixel_m / SEA_RECHARGE_M).exp();
    let mut q = vec![1.0f64; h * w];
    let mut annual = vec![0.0f32; h * w];
    // Visit rows and columns in the wind's direction so upwind neighbours come first.
    for ky in 0..h {
        let y = if sy { h - 1 - ky } else { ky };
        let up_y = if sy { y + 1 } else { y.wrapping_sub(1) };
        for kx in 0..w {
            let x = if sx { w - 1 - kx } else { kx };
            let up_x = if sx { x + 1 } else { x.wrapping_sub(1) };
            let i = y * w + x;
            // Outside the padded window the air is saturated (q = 1) and the ground flat.
            let ux = (up_x < w).then(|| y * w + up_x);
            let uy = (up_y < h).then(|| up_y * w + x);
            let upwind_q = |j: Option<usize>| j.map_or(1.0, |j| q[j]);
            let ground = |j: Option<usize>| surface(elevation[j.unwrap_or(i)]);
            let q_in = (ax * upwind_q(ux) + ay * upwind_q(uy)) / (ax + ay);
            let here = ground(None);
            // Rise along the wind over one cell: the upwind difference of the wind-weighted slope.
            let rise = ax * (here - ground(ux)) + ay * (here - ground(uy));
            let b = f64::from(base[i]).max(0.0);
            if elevation[i] <= 0.0 {
                q[i] = q_in + (1.0 - q_in) * sea_recharge;
                annual[i] = (b * q_in) as f32;
            } else {
                let uplift = (rise / pixel_m).max(0.0);
                annual[i] = (b * q_in * (1.0 + strength * UPLIFT_GAIN * uplift)) as f32;
                // Rain-out is proportional to the extra orographic rain (∝ the rise climbed).
                q[i] = q_in * (-strength * rise.max(0.0) / RAINOUT_RISE_M).exp() * land_keep;
            }
        }
    }
    finish(annual, s.precipitation_scale)
}

/// The sea surface is flat: air rises over land only.
fn surface(e: f32) -> f64 {
    f64::from(e).max(0.0)
}

/// Applies the owner's scale and derives the variability channel.
fn finish(mut annual: Vec<f32>, scale: f64) -> [Vec<f32>; 2] {
    for v in &mut annual {
        *v = (f64::from(*v) * scale).max(0.0) as f32;
    }
    let variability = annual.iter().map(|&p| variability_pct(f64::from(p)) as f32).collect();
    [annual, variability]
}

/// Stacks the two output planes into a tile over `rect` (channel order of
/// [`precipitation`]).
pub(crate) fn to_tile(planes: [Vec<f32>; 2], rect: crate::tile::Rect) -> Tile {
    let [annual, variability] = planes;
    let mut data = Vec::with_capacity(precipitation::CHANNELS * rect.area());
    data.extend_from_slice(&annual);
    data.extend_from_slice(&variability);
    Tile::from_data(precipitation::CHANNELS, rect, data)
}
