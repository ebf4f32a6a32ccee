//! The vertical mapping: metres of elevation ↔ block Y.
//!
//! One function decides where the ground is, so the server, the tests and every later tool
//! (pre-generation, maps) agree on it to the block.

use crate::config::WorldSettings;

/// How metres become block heights: `[world]` of the configuration, as block integers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vertical {
    /// Block Y of the sea surface: water fills every block below it down to the sea floor.
    pub sea_level_y: i32,
    /// Lowest block Y of the world (the bedrock floor).
    pub min_y: i32,
    /// Height of the world in blocks.
    pub height: i32,
    /// Metres of elevation per block above the sea.
    pub metres_per_block: f64,
    /// Metres of depth per block under the sea (a compressed sea floor).
    pub sea_metres_per_block: f64,
}

impl Vertical {
    /// The mapping of a validated `[world]` section (its values are range-checked at load, so
    /// they fit `i32`).
    pub fn from_world(world: &WorldSettings) -> Vertical {
        Vertical {
            sea_level_y: world.sea_level_y as i32,
            min_y: world.min_y as i32,
            height: world.height as i32,
            metres_per_block: world.vertical_metres_per_block,
            sea_metres_per_block: world.sea_vertical_metres_per_block,
        }
    }

    /// Block Y of the topmost ground block of a column whose surface is `elevation_m` metres
    /// above sea level:
    ///
    /// - on land (`m ≥ 0`): `sea_level_y + floor(m / metres_per_block)`;
    /// - under the sea (`m < 0`): `sea_level_y − 1 − floor(−m / sea_metres_per_block)`, but
    ///   at most `sea_level_y − 2` (one below the water top): every sea column holds water,
    ///   so the shallowest sea (−60 m < m < 0 with the defaults) is one block deep rather
    ///   than dry ground level with the sea;
    ///
    /// clamped into `[min_y + 1, min_y + height − 2]` so there is always bedrock below and
    /// one block of air above. A NaN elevation counts as sea level.
    pub fn surface_y(&self, elevation_m: f32) -> i32 {
        let m = if elevation_m.is_nan() { 0.0 } else { f64::from(elevation_m) };
        let sea = i64::from(self.sea_level_y);
        // `as i64` saturates, so even absurd elevations land on the clamp.
        let y = if m >= 0.0 {
            sea.saturating_add((m / self.metres_per_block).floor() as i64)
        } else {
            (sea - 1).saturating_sub((-m / self.sea_metres_per_block).floor() as i64).min(sea - 2)
        };
        y.clamp(i64::from(self.lowest_surface_y()), i64::from(self.highest_surface_y())) as i32
    }

    /// Elevation, metres, of the air at the bottom of block `y` above the sea (the inverse of
    /// [`surface_y`](Self::surface_y) on land). Below sea level it is 0: air there is sea.
    pub fn air_metres(&self, y: i32) -> f32 {
        (f64::from((y - self.sea_level_y).max(0)) * self.metres_per_block) as f32
    }

    /// Lowest block Y the ground surface may take.
    pub fn lowest_surface_y(&self) -> i32 {
        self.min_y + 1
    }

    /// Highest block Y the ground surface may take.
    pub fn highest_surface_y(&self) -> i32 {
        self.min_y + self.height - 2
    }

    /// Block Y of the topmost water block of the sea.
    pub fn water_top_y(&self) -> i32 {
        self.sea_level_y - 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn default() -> Vertical {
        Vertical::from_world(&WorldSettings::default())
    }

    #[test]
    fn land_rises_one_block_per_metres_per_block() {
        let v = default();
        assert_eq!(v.surface_y(0.0), 63);
        assert_eq!(v.surface_y(24.9), 63);
        assert_eq!(v.surface_y(25.0), 64);
        assert_eq!(v.surface_y(1000.0), 63 + 40);
    }

    #[test]
    fn the_sea_floor_is_compressed_and_starts_below_the_water_top() {
        let v = default();
        // The shallowest sea is one block of water, not dry ground at the water top.
        assert_eq!(v.surface_y(-0.1), 61);
        assert_eq!(v.surface_y(-59.9), 61);
        assert_eq!(v.surface_y(-60.0), 61);
        assert_eq!(v.surface_y(-119.9), 61);
        assert_eq!(v.surface_y(-120.0), 60);
        assert_eq!(v.surface_y(-600.0), 52);
        assert_eq!(v.water_top_y(), 62);
    }

    #[test]
    fn extremes_are_clamped_inside_the_world() {
        let v = default();
        assert_eq!(v.surface_y(1.0e9), 318);
        assert_eq!(v.surface_y(-1.0e9), -63);
        assert_eq!(v.surface_y(f32::INFINITY), 318);
        assert_eq!(v.surface_y(f32::NEG_INFINITY), -63);
        assert_eq!(v.surface_y(f32::NAN), 63);
    }

    #[test]
    fn air_metres_inverts_the_land_mapping() {
        let v = default();
        for y in 63..200 {
            assert_eq!(v.surface_y(v.air_metres(y)), y);
        }
        assert_eq!(v.air_metres(10), 0.0);
    }
}
