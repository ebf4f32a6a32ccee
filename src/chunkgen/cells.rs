//! Biomes per 4×4×4 cell: the physical conditions of a cell, for the biome rules.
//!
//! A cell takes its climate from one sample column (its centre column, `4·c + 2`), so a cell
//! means the same thing whichever chunk or query computes it. Cells at or below the ground
//! (or the sea surface) share the column's conditions; cells in the air above it are colder
//! by the lapse rate, so high air over a warm valley can still be a snowy biome.

use crate::biome::{Conditions, WaterBody};
use crate::terrain::pipeline::channel;

use super::columns::{Columns, Water};
use super::Vertical;

/// Edge of a biome cell, blocks.
pub const CELL: i64 = 4;

/// The column whose climate stands for the cell at horizontal cell index (`cell_x`, `cell_z`).
pub fn sample_column(cell_x: i64, cell_z: i64) -> (i64, i64) {
    (cell_x * CELL + CELL / 2, cell_z * CELL + CELL / 2)
}

/// Block Y that stands for the vertical extent of the cell holding block `y`.
pub fn cell_centre_y(y: i32) -> i32 {
    y.div_euclid(CELL as i32) * CELL as i32 + CELL as i32 / 2
}

/// Conditions of the cell whose sample column is (`x`, `z`) (which with its four neighbours
/// and the rest of its cell must lie in `columns`) and whose centre is block `centre_y`.
pub fn conditions(
    columns: &Columns,
    vertical: &Vertical,
    lapse_c_per_km: f32,
    x: i64,
    z: i64,
    centre_y: i32,
) -> Conditions {
    let ground_top = columns.water_top_y(x, z).unwrap_or(columns.surface_y(x, z));
    at_height(&ground_conditions(columns, x, z), ground_top, vertical, lapse_c_per_km, centre_y)
}

/// Conditions of the cells at or below the ground (or water) of the cell column whose sample
/// column is (`x`, `z`): what every cell of that column starts from (see [`at_height`]).
pub fn ground_conditions(columns: &Columns, x: i64, z: i64) -> Conditions {
    let surface_m = columns.elevation(x, z);
    Conditions {
        temperature_c: columns.get(channel::TEMPERATURE, x, z),
        seasonality_c: columns.get(channel::SEASONALITY, x, z),
        precipitation_mm: columns.get(channel::PRECIPITATION, x, z),
        variability_pct: columns.get(channel::VARIABILITY, x, z),
        elevation_m: surface_m,
        surface_m,
        slope_deg: columns.slope_deg(x, z),
        water: water_body(columns, x, z),
        river_distance_m: columns.get(channel::RIVER_DISTANCE, x, z),
    }
}

/// The conditions of the cell centred at block `centre_y` of a cell column whose ground (or
/// water) top is `ground_top` and whose ground cells have `ground`: the same at or below it,
/// colder by the lapse rate with height above it.
pub fn at_height(
    ground: &Conditions,
    ground_top: i32,
    vertical: &Vertical,
    lapse_c_per_km: f32,
    centre_y: i32,
) -> Conditions {
    if centre_y <= ground_top {
        return *ground;
    }
    // The column's temperature is at its surface, or at the sea surface over the sea.
    let base_m = ground.surface_m.max(0.0);
    let cell_m = vertical.air_metres(centre_y).max(base_m);
    Conditions {
        elevation_m: cell_m,
        temperature_c: ground.temperature_c - lapse_c_per_km * (cell_m - base_m) / 1000.0,
        ..*ground
    }
}

/// The water of the cell whose sample column is (`x`, `z`): a river or lake if any of its
/// 4×4 columns holds one (rivers are a few blocks wide, narrower than a cell, and a river
/// biome along the banks is what vanilla does too), else the sample column's own.
fn water_body(columns: &Columns, x: i64, z: i64) -> WaterBody {
    let cell = (z - CELL / 2..z + CELL / 2).flat_map(|cz| (x - CELL / 2..x + CELL / 2).map(move |cx| (cx, cz)));
    let mut lake = false;
    for (cx, cz) in cell {
        match columns.water(cx, cz) {
            Water::River => return WaterBody::River,
            Water::Lake => lake = true,
            _ => {}
        }
    }
    if lake {
        WaterBody::Lake
    } else if columns.water(x, z) == Water::Sea {
        WaterBody::Sea
    } else if columns.is_dry_bed(x, z) {
        WaterBody::DryLake
    } else {
        WaterBody::None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::terrain::{Rect, Tile};

    fn flat(elevation: f32, temperature: f32) -> Columns {
        let rect = Rect::new(0, 0, 8, 8);
        let mut tile = Tile::zeros(channel::COUNT, rect);
        tile.channel_mut(channel::ELEVATION).fill(elevation);
        tile.channel_mut(channel::TEMPERATURE).fill(temperature);
        Columns::from_tile(tile, &Vertical::from_world(&crate::config::WorldSettings::default()))
    }

    #[test]
    fn cells_map_to_their_centres() {
        assert_eq!(sample_column(0, 0), (2, 2));
        assert_eq!(sample_column(-1, 3), (-2, 14));
        assert_eq!(cell_centre_y(-64), -62);
        assert_eq!(cell_centre_y(-61), -62);
        assert_eq!(cell_centre_y(63), 62);
        assert_eq!(cell_centre_y(64), 66);
    }

    #[test]
    fn ground_cells_share_the_surface_and_air_cells_cool_with_height() {
        let v = Vertical::from_world(&crate::config::WorldSettings::default());
        let cols = flat(100.0, 10.0); // surface Y = 63 + 4 = 67
        let ground = conditions(&cols, &v, 6.5, 2, 2, 66);
        assert_eq!((ground.elevation_m, ground.temperature_c, ground.surface_m), (100.0, 10.0, 100.0));
        let air = conditions(&cols, &v, 6.5, 2, 2, 63 + 400);
        assert_eq!(air.elevation_m, 10_000.0);
        assert!((air.temperature_c - (10.0 - 6.5 * 9.9)).abs() < 1e-3, "{}", air.temperature_c);
    }

    #[test]
    fn water_cells_are_sea_and_air_over_the_sea_cools_from_sea_level() {
        let v = Vertical::from_world(&crate::config::WorldSettings::default());
        let cols = flat(-3000.0, 20.0);
        let water = conditions(&cols, &v, 6.5, 2, 2, 62);
        assert_eq!((water.elevation_m, water.temperature_c), (-3000.0, 20.0));
        let air = conditions(&cols, &v, 6.5, 2, 2, 63 + 40);
        assert_eq!(air.elevation_m, 1000.0);
        assert!((air.temperature_c - 13.5).abs() < 1e-4);
    }
}
