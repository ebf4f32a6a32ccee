//! The compiled rule table: what a rule constrains, as boxes of half-open ranges, and the
//! first-match lookup on the hot path.

use super::{Conditions, WaterBody};

/// Lanes of a compiled box: the nine axes, so a box is two short rows the compiler can
/// compare with a few vector instructions and no branch per axis.
pub(crate) const LANES: usize = 9;

/// One physical quantity a rule can constrain.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Axis {
    Temperature,
    Seasonality,
    Precipitation,
    Variability,
    Elevation,
    Surface,
    Slope,
    /// The column's water body, as its [`WaterBody`] code (a rule names kinds, never codes).
    Water,
    /// Distance to the nearest river's bank, metres.
    RiverDistance,
}

impl Axis {
    /// Every axis, in lane order.
    pub(crate) const ALL: [Axis; LANES] = [
        Axis::Temperature,
        Axis::Seasonality,
        Axis::Precipitation,
        Axis::Variability,
        Axis::Elevation,
        Axis::Surface,
        Axis::Slope,
        Axis::Water,
        Axis::RiverDistance,
    ];

    /// The lane this axis occupies in a compiled box.
    pub(crate) fn lane(self) -> usize {
        self as usize
    }

    /// The key that sets this axis in a rule file.
    pub(crate) fn key(self) -> &'static str {
        match self {
            Axis::Temperature => "temperature_c",
            Axis::Seasonality => "seasonality_c",
            Axis::Precipitation => "precipitation_mm",
            Axis::Variability => "variability_pct",
            Axis::Elevation => "elevation_m",
            Axis::Surface => "surface_m",
            Axis::Slope => "slope_deg",
            Axis::Water => "water",
            Axis::RiverDistance => "river_distance_m",
        }
    }

    /// The physically possible values (finite bounds must lie inside): a bound outside is a
    /// typo (a missing minus, an extra zero), not a deliberate choice; open ends use ±inf.
    pub(crate) fn limits(self) -> (f32, f32) {
        match self {
            Axis::Temperature => (-100.0, 100.0),
            Axis::Seasonality => (0.0, 60.0),
            Axis::Precipitation => (0.0, 30_000.0),
            Axis::Variability => (0.0, 1_000.0),
            Axis::Elevation | Axis::Surface => (-12_000.0, 12_000.0),
            Axis::Slope => (0.0, 90.0),
            Axis::Water => (0.0, WaterBody::ALL.len() as f32),
            Axis::RiverDistance => (0.0, 100_000.0),
        }
    }
}

impl Conditions {
    /// The conditions in lane order.
    #[inline]
    pub(crate) fn lanes(&self) -> [f32; LANES] {
        [
            self.temperature_c,
            self.seasonality_c,
            self.precipitation_mm,
            self.variability_pct,
            self.elevation_m,
            self.surface_m,
            self.slope_deg,
            self.water as u8 as f32,
            self.river_distance_m,
        ]
    }
}

/// A rule's box: per lane, `lo <= value < hi`. Unconstrained lanes are (−inf, inf).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub(crate) struct Bounds {
    pub(crate) lo: [f32; LANES],
    pub(crate) hi: [f32; LANES],
}

impl Bounds {
    /// The box that contains everything.
    pub(crate) const ANY: Bounds = Bounds { lo: [f32::NEG_INFINITY; LANES], hi: [f32::INFINITY; LANES] };

    /// Whether `v` lies in the box. NaN lies in no box, so bad input reaches the fallback.
    #[inline]
    pub(crate) fn contains(&self, v: &[f32; LANES]) -> bool {
        // `&` rather than `&&`: no early exit, so the loop stays branch-free and vectorises.
        let mut inside = true;
        for ((&lo, &hi), &x) in self.lo.iter().zip(&self.hi).zip(v) {
            inside &= (lo <= x) & (x < hi);
        }
        inside
    }

    /// Whether every point of `inner` lies in `self`.
    pub(crate) fn covers(&self, inner: &Bounds) -> bool {
        (0..LANES).all(|i| self.lo[i] <= inner.lo[i] && inner.hi[i] <= self.hi[i])
    }

    /// The common part of two boxes, if it is not empty (half-open: touching is not overlap).
    pub(crate) fn intersection(&self, other: &Bounds) -> Option<Bounds> {
        let mut out = Bounds::ANY;
        for i in 0..LANES {
            out.lo[i] = self.lo[i].max(other.lo[i]);
            out.hi[i] = self.hi[i].min(other.hi[i]);
            if out.lo[i] >= out.hi[i] {
                return None;
            }
        }
        Some(out)
    }

    /// The constrained lanes as `key in [lo, hi)`, for error messages. Surface ranges are
    /// shown as depth when the rule was written with `depth_m`.
    pub(crate) fn describe(&self, as_depth: bool) -> String {
        let parts: Vec<String> = Axis::ALL
            .iter()
            .filter(|a| self.lo[a.lane()] > f32::NEG_INFINITY || self.hi[a.lane()] < f32::INFINITY)
            .map(|&a| {
                let (lo, hi) = (self.lo[a.lane()], self.hi[a.lane()]);
                if a == Axis::Water {
                    let kinds: Vec<&str> = WaterBody::ALL
                        .iter()
                        .filter(|w| (lo..hi).contains(&(**w as u8 as f32)))
                        .map(|w| w.key())
                        .collect();
                    format!("water in [{}]", kinds.join(", "))
                } else if a == Axis::Surface && as_depth {
                    // `0.0 - x` rather than `-x`: no "-0" in messages.
                    format!("depth_m in ({}, {}]", 0.0 - hi, 0.0 - lo)
                } else {
                    format!("{} in [{lo}, {hi})", a.key())
                }
            })
            .collect();
        if parts.is_empty() {
            "everywhere".to_string()
        } else {
            parts.join(", ")
        }
    }
}

/// The rules in match order, compiled for lookup.
#[derive(Clone, Debug)]
pub(crate) struct Table {
    /// One box per rule, in match order.
    pub(crate) bounds: Vec<Bounds>,
    /// The biome of each rule, parallel to `bounds`.
    pub(crate) biomes: Vec<&'static str>,
    /// Where no rule matches.
    pub(crate) fallback: &'static str,
}

impl Table {
    /// The index of the first rule whose box holds `c`.
    #[inline]
    pub(crate) fn first_match(&self, c: &Conditions) -> Option<usize> {
        let v = c.lanes();
        self.bounds.iter().position(|b| b.contains(&v))
    }

    /// The rules that can match conditions equal to `c` on every lane but temperature and
    /// elevation, in order: those whose box holds `c` on all the other lanes.
    pub(crate) fn candidates_varying_height(&self, c: &Conditions) -> Vec<usize> {
        let v = c.lanes();
        let fixed = |b: &Bounds| {
            (0..LANES)
                .filter(|&i| i != Axis::Temperature.lane() && i != Axis::Elevation.lane())
                .all(|i| b.lo[i] <= v[i] && v[i] < b.hi[i])
        };
        (0..self.bounds.len()).filter(|&i| fixed(&self.bounds[i])).collect()
    }

    /// [`biome`](Self::biome) of `c` among `candidates` only (see
    /// [`candidates_varying_height`](Self::candidates_varying_height)): a rule left out
    /// fails on a lane `c` shares, so the first match among the rest is the first of all.
    #[inline]
    pub(crate) fn biome_among(&self, candidates: &[usize], c: &Conditions) -> &'static str {
        let v = c.lanes();
        match candidates.iter().find(|&&i| self.bounds[i].contains(&v)) {
            Some(&i) => self.biomes[i],
            None => self.fallback,
        }
    }

    /// The biome of the first matching rule, or the fallback.
    #[inline]
    pub(crate) fn biome(&self, c: &Conditions) -> &'static str {
        match self.first_match(c) {
            Some(i) => self.biomes[i],
            None => self.fallback,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ranged(axis: Axis, lo: f32, hi: f32) -> Bounds {
        let mut b = Bounds::ANY;
        b.lo[axis.lane()] = lo;
        b.hi[axis.lane()] = hi;
        b
    }

    fn at(temperature_c: f32) -> Conditions {
        Conditions {
            temperature_c,
            seasonality_c: 5.0,
            precipitation_mm: 800.0,
            variability_pct: 15.0,
            elevation_m: 100.0,
            surface_m: 100.0,
            slope_deg: 1.0,
            water: WaterBody::None,
            river_distance_m: 640.0,
        }
    }

    #[test]
    fn ranges_are_half_open_and_nan_matches_nothing() {
        let b = ranged(Axis::Temperature, 0.0, 10.0);
        assert!(b.contains(&at(0.0).lanes()));
        assert!(b.contains(&at(9.99).lanes()));
        assert!(!b.contains(&at(10.0).lanes()));
        assert!(!b.contains(&at(-0.01).lanes()));
        assert!(!b.contains(&at(f32::NAN).lanes()));
        assert!(Bounds::ANY.contains(&at(-1e30).lanes()));
    }

    #[test]
    fn covering_and_intersecting_boxes() {
        let wide = ranged(Axis::Temperature, 0.0, 10.0);
        let narrow = ranged(Axis::Temperature, 2.0, 5.0);
        assert!(wide.covers(&narrow) && !narrow.covers(&wide));
        assert!(Bounds::ANY.covers(&wide));
        let touching = ranged(Axis::Temperature, 10.0, 20.0);
        assert_eq!(wide.intersection(&touching), None, "[0,10) and [10,20) share no point");
        let common = wide.intersection(&ranged(Axis::Slope, 5.0, 8.0)).expect("overlap");
        assert_eq!(common.describe(false), "temperature_c in [0, 10), slope_deg in [5, 8)");
        assert_eq!(ranged(Axis::Surface, -2000.0, -20.0).describe(true), "depth_m in (20, 2000]");
    }

    #[test]
    fn the_first_matching_rule_wins_and_the_fallback_catches_the_rest() {
        let table = Table {
            bounds: vec![ranged(Axis::Temperature, 0.0, 10.0), ranged(Axis::Temperature, 5.0, 20.0)],
            biomes: vec!["minecraft:taiga", "minecraft:forest"],
            fallback: "minecraft:plains",
        };
        assert_eq!(table.biome(&at(7.0)), "minecraft:taiga");
        assert_eq!(table.biome(&at(12.0)), "minecraft:forest");
        assert_eq!(table.biome(&at(25.0)), "minecraft:plains");
        assert_eq!(table.biome(&at(f32::NAN)), "minecraft:plains");
    }
}
