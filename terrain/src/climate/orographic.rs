//! The orographic precipitation scheme on one padded window: moisture advected by a
//! first-order upwind sweep, rained out by uplift, recharged over the sea.

use super::{precipitation, ClimateSettings};
use crate::tile::{Rect, Tile};

/// Extra precipitation per unit of uplift slope at strength 1: a 1000 m rise over 20 km
/// (slope 0.05) triples precipitation (1 + 40 · 0.05 = 3).
const UPLIFT_GAIN: f64 = 40.0;
/// Rise (m) over which orographic rain-out removes 1 − 1/e of the moisture at strength 1:
/// air crossing a 2000 m ridge keeps ~60 %, so the lee gets about a third of the windward
/// slope's rain and half of the upwind plain's.
const RAINOUT_RISE_M: f64 = 4_000.0;
/// Moisture that air settles to over flat land, far from the sea: evaporation from the
/// land recycles some rain, so it dries (from 1) or recovers (from a rain shadow) toward it.
const LAND_EQUILIBRIUM: f64 = 0.8;
/// Distance over which air over land moves 1 − 1/e of the way to [`LAND_EQUILIBRIUM`]: rain
/// shadows fade over several hundred km, so a window margin of that order sees them.
const LAND_RELAX_M: f64 = 500_000.0;
/// Distance over which air over the sea recovers 1 − 1/e of its missing moisture.
const SEA_RECHARGE_M: f64 = 400_000.0;

/// The wind's unit vector `(dx, dy)` pointing where it blows TO, for a wind blowing FROM
/// `from_deg` clockwise from north (north = −y, east = +x).
pub fn wind_vector(from_deg: f64) -> (f64, f64) {
    let a = from_deg.to_radians();
    // Snap round-off (e.g. cos 90° ≈ 6e-17) so axis-aligned winds stay exactly 1-D.
    let snap = |v: f64| if v.abs() < 1e-9 { 0.0 } else { v };
    (snap(-a.sin()), snap(a.cos()))
}

/// `core` grown by `margin` cells on its upwind sides only. Moisture flows downwind, so no
/// cell of `core` depends on anything downwind or beside this rectangle: the result is
/// identical to padding every side, at a fraction of the cost.
pub fn upwind_pad(core: Rect, margin: i64, from_deg: f64) -> Rect {
    let (dx, dy) = wind_vector(from_deg);
    let m = margin.max(0);
    let side = |upwind: bool| if upwind { m } else { 0 };
    core.pad_sides(side(dy > 0.0), side(dy < 0.0), side(dx > 0.0), side(dx < 0.0))
}

/// Inter-annual variability (%) for an annual precipitation (mm): drier climates vary more
/// (≈ 60 % at 100 mm, 40 % at 250 mm, 12 % at 1000 mm, as in Earth's observed relation).
pub fn variability_pct(annual_mm: f64) -> f64 {
    (10.0 + 70.0 * (-annual_mm / 300.0).exp()).clamp(5.0, 80.0)
}

/// The per-cell constants of one sweep.
struct Sweep {
    /// |dx|, |dy| of the wind: weights of the upwind x and y neighbours.
    ax: f64,
    ay: f64,
    pixel_m: f64,
    strength: f64,
    /// Fraction of the land-equilibrium gap kept per cell, and of the sea gap recharged.
    land_keep: f64,
    sea_recharge: f64,
}

impl Sweep {
    /// One cell given the moisture arriving (`q_in`), the rise along the wind over the cell
    /// (m), its base precipitation and whether it is sea: (precipitation, moisture leaving).
    fn cell(&self, q_in: f64, rise: f64, base: f64, sea: bool) -> (f64, f64) {
        if sea {
            return (base * q_in, q_in + (1.0 - q_in) * self.sea_recharge);
        }
        let uplift = (rise / self.pixel_m).max(0.0);
        let rain = base * q_in * (1.0 + self.strength * UPLIFT_GAIN * uplift);
        // Rain-out is proportional to the extra orographic rain (∝ the rise climbed).
        let q_out = q_in * (-self.strength * rise.max(0.0) / RAINOUT_RISE_M).exp();
        (rain, LAND_EQUILIBRIUM + (q_out - LAND_EQUILIBRIUM) * self.land_keep)
    }
}

/// Annual precipitation (mm, before the owner's scale) over a padded window, given its
/// elevation (m) and base precipitation (mm/yr) planes, `h × w` row-major.
pub(crate) fn solve(
    elevation: &[f32],
    base: &[f32],
    h: usize,
    w: usize,
    s: &ClimateSettings,
    pixel_m: f64,
) -> Vec<f32> {
    let (dx, dy) = wind_vector(s.wind_from_deg);
    let sweep = Sweep {
        ax: dx.abs(),
        ay: dy.abs(),
        pixel_m,
        strength: s.orographic_strength,
        land_keep: (-pixel_m / LAND_RELAX_M).exp(),
        sea_recharge: 1.0 - (-pixel_m / SEA_RECHARGE_M).exp(),
    };
    // Visit rows and columns in the wind's direction so upwind neighbours come first.
    let order = |n: usize, reverse: bool| (0..n).map(move |k| if reverse { n - 1 - k } else { k });
    let upwind = |i: usize, reverse: bool| if reverse { i + 1 } else { i.wrapping_sub(1) };
    let ground = |i: usize| f64::from(elevation[i]).max(0.0); // the sea surface is flat
    let mut q = vec![1.0f64; h * w];
    let mut annual = vec![0.0f32; h * w];
    for y in order(h, dy < 0.0) {
        let up_y = upwind(y, dy < 0.0);
        for x in order(w, dx < 0.0) {
            let (i, up_x) = (y * w + x, upwind(x, dx < 0.0));
            // Outside the padded window the air is saturated (q = 1) and the ground level.
            let ux = if up_x < w { y * w + up_x } else { i };
            let uy = if up_y < h { up_y * w + x } else { i };
            let q_at = |j: usize| if j == i { 1.0 } else { q[j] };
            let q_in = (sweep.ax * q_at(ux) + sweep.ay * q_at(uy)) / (sweep.ax + sweep.ay);
            // Rise along the wind over one cell: upwind differences weighted by the wind.
            let rise = sweep.ax * (ground(i) - ground(ux)) + sweep.ay * (ground(i) - ground(uy));
            let (rain, q_out) = sweep.cell(q_in, rise, f64::from(base[i]).max(0.0), elevation[i] <= 0.0);
            annual[i] = rain as f32;
            q[i] = q_out;
        }
    }
    annual
}

/// Applies the owner's scale, derives the variability channel and stacks both into a tile
/// over `rect` (channel order of [`precipitation`]).
pub(crate) fn to_tile(mut annual: Vec<f32>, scale: f64, rect: Rect) -> Tile {
    for v in &mut annual {
        *v = (f64::from(*v) * scale).max(0.0) as f32;
    }
    let variability: Vec<f32> = annual.iter().map(|&p| variability_pct(f64::from(p)) as f32).collect();
    annual.extend_from_slice(&variability);
    Tile::from_data(precipitation::CHANNELS, rect, annual)
}
