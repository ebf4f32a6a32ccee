//! What the ground is made of: the top block and the layer under it, from the biome, the
//! steepness, the temperature and whether the sea covers it.
//!
//! Pure functions of their inputs; the surface pass (`passes/surface.rs`) lays the result on the rock.

use valence::prelude::BlockState;

use crate::biome::Surface;

use super::columns::Water;
use super::hash::value_noise;

/// Everything the choice depends on for one column.
#[derive(Clone, Copy, Debug)]
pub struct Site<'a> {
    /// Biome of the cell holding the surface block (`"minecraft:desert"`).
    pub biome: &'a str,
    /// The biome's dry-land ground, from its `[surface."…"]` table.
    pub soil: Surface,
    /// Blocks of water above the surface block (0 on land, at least 1 under the sea).
    pub water_depth: i32,
    /// The water over the column ([`Water::Dry`] on land).
    pub water: Water,
    /// Discharge of the river or lake over the column, m³/s (0 elsewhere).
    pub discharge_m3s: f32,
    /// The bed of a dry lake (a closed basin too arid to fill).
    pub dry_bed: bool,
    /// Annual precipitation, mm.
    pub precipitation_mm: f32,
    /// Blocks the ground falls to its lowest neighbour (see `Columns::drop_blocks`).
    pub drop_blocks: i32,
    /// Annual mean air temperature at the surface, °C.
    pub temperature_c: f32,
    /// World seed (for patch noise).
    pub seed: u64,
    /// Global block coordinates of the column.
    pub x: i64,
    /// Global block coordinates of the column.
    pub z: i64,
}

/// The ground of one column, top down: `top`, then `filler` for `filler_depth` blocks (or
/// terracotta bands where `banded`), then stone.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ground {
    /// The surface block.
    pub top: BlockState,
    /// The blocks under it.
    pub filler: BlockState,
    /// How many filler blocks.
    pub filler_depth: i32,
    /// Badlands: fill with horizontal terracotta bands (by Y) instead of `filler`.
    pub banded: bool,
}

/// A fall of this many blocks to a neighbour shows bare rock (about 37° at 25 m per block).
pub const STEEP_DROP_BLOCKS: i32 = 3;
/// Annual mean temperature below which exposed land is snow-covered, °C.
pub const SNOW_LINE_C: f32 = -4.0;
/// Below this temperature snow fields hold pockets of powder snow, °C.
pub const POWDER_SNOW_C: f32 = -12.0;
/// Below this temperature the sea surface freezes, °C.
pub const SEA_ICE_C: f32 = 0.0;

/// Discharge from which a river's bed is sand (big lowland rivers carry sand; small, steep
/// ones leave gravel), m³/s.
pub const SANDY_RIVER_M3S: f32 = 100.0;
/// Annual precipitation under which a dry lake bed is a salt flat rather than clay, mm.
pub const SALT_FLAT_MM: f32 = 250.0;

const NOISE_POWDER: u64 = 0x5057_4452;
const NOISE_BED: u64 = 0x4245_4453;
const NOISE_CLAY: u64 = 0x434C_4159;

/// Chooses the ground of one column.
pub fn ground(site: &Site) -> Ground {
    let b = site.biome.strip_prefix("minecraft:").unwrap_or(site.biome);
    let steep = site.drop_blocks >= STEEP_DROP_BLOCKS;
    let layer = |top, filler, filler_depth| Ground { top, filler, filler_depth, banded: false };

    if site.water_depth > 0 {
        if matches!(site.water, Water::River | Water::Lake) {
            return fresh_bed(site);
        }
        return underwater(b, site.water_depth, site.temperature_c);
    }
    if site.dry_bed {
        return dry_lake_bed(site);
    }
    if b.contains("badlands") {
        // Badlands show their banded terracotta on every slope; red sand only on flats.
        let top = if steep { BlockState::TERRACOTTA } else { BlockState::RED_SAND };
        return Ground { top, filler: BlockState::TERRACOTTA, filler_depth: 14, banded: true };
    }
    if steep {
        return layer(BlockState::STONE, BlockState::STONE, 0);
    }
    let snowy = b.starts_with("snowy_")
        || b.starts_with("frozen_")
        || matches!(b, "jagged_peaks" | "grove" | "ice_spikes")
        || site.temperature_c < SNOW_LINE_C;
    if snowy && !matches!(b, "desert" | "beach" | "stony_shore") {
        let powder =
            site.temperature_c < POWDER_SNOW_C && value_noise(site.seed, NOISE_POWDER, site.x, site.z, 6) > 0.72;
        let top = if powder { BlockState::POWDER_SNOW } else { BlockState::SNOW_BLOCK };
        return layer(top, if powder { BlockState::POWDER_SNOW } else { BlockState::DIRT }, if powder { 1 } else { 2 });
    }
    layer(site.soil.top, site.soil.filler, site.soil.depth)
}

fn underwater(biome: &str, depth: i32, temperature_c: f32) -> Ground {
    let cold = biome.contains("cold") || biome.contains("frozen") || temperature_c < SEA_ICE_C;
    let warm = biome.contains("warm") || biome.contains("lukewarm");
    let top = match biome {
        "mangrove_swamp" | "swamp" => BlockState::MUD,
        _ if cold => BlockState::GRAVEL,
        _ if warm => BlockState::SAND,
        // Sandy shallows, gravel in the deep.
        _ if depth <= 12 => BlockState::SAND,
        _ => BlockState::GRAVEL,
    };
    Ground { top, filler: top, filler_depth: 3, banded: false }
}

/// The bed of a river or lake: mud in warm, wet climates; gravel where cold; in rivers,
/// gravel and sand by flow (sand from [`SANDY_RIVER_M3S`]); in lakes sand, with patches of
/// clay in both (vanilla's clay disks).
fn fresh_bed(site: &Site) -> Ground {
    let patch = |key, scale| value_noise(site.seed, key, site.x, site.z, scale);
    let top = if site.temperature_c >= 18.0 && site.precipitation_mm >= 1500.0 {
        BlockState::MUD
    } else if site.temperature_c < SEA_ICE_C {
        BlockState::GRAVEL
    } else if patch(NOISE_CLAY, 5) > 0.75 {
        BlockState::CLAY
    } else if site.water == Water::Lake {
        BlockState::SAND
    } else {
        // The share of gravel falls from about three quarters in small streams to none in
        // rivers of SANDY_RIVER_M3S.
        let smallness = (SANDY_RIVER_M3S / site.discharge_m3s.max(0.5)).log10() / (SANDY_RIVER_M3S / 0.5).log10();
        let gravel = 0.75 * smallness.clamp(0.0, 1.0);
        if patch(NOISE_BED, 3) < gravel {
            BlockState::GRAVEL
        } else {
            BlockState::SAND
        }
    };
    Ground { top, filler: top, filler_depth: 2, banded: false }
}

/// The bed of a dry lake: a white salt flat (calcite) where very dry, a clay flat otherwise.
fn dry_lake_bed(site: &Site) -> Ground {
    let top = if site.precipitation_mm < SALT_FLAT_MM { BlockState::CALCITE } else { BlockState::CLAY };
    Ground { top, filler: BlockState::CLAY, filler_depth: 2, banded: false }
}

/// The terracotta of badlands band at block `y` (repeating every 16 blocks, like strata).
pub fn terracotta_band(y: i32) -> BlockState {
    const BANDS: [BlockState; 16] = [
        BlockState::TERRACOTTA,
        BlockState::ORANGE_TERRACOTTA,
        BlockState::ORANGE_TERRACOTTA,
        BlockState::TERRACOTTA,
        BlockState::YELLOW_TERRACOTTA,
        BlockState::TERRACOTTA,
        BlockState::TERRACOTTA,
        BlockState::BROWN_TERRACOTTA,
        BlockState::TERRACOTTA,
        BlockState::RED_TERRACOTTA,
        BlockState::RED_TERRACOTTA,
        BlockState::TERRACOTTA,
        BlockState::WHITE_TERRACOTTA,
        BlockState::TERRACOTTA,
        BlockState::LIGHT_GRAY_TERRACOTTA,
        BlockState::ORANGE_TERRACOTTA,
    ];
    BANDS[y.rem_euclid(16) as usize]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shipped tables, loaded once for all the tests' sites.
    static RULES: std::sync::LazyLock<crate::biome::BiomeRules> = std::sync::LazyLock::new(|| {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("biomes");
        crate::biome::BiomeRules::load_dir(&dir).expect("the shipped rules load")
    });

    fn site(biome: &str) -> Site<'_> {
        Site {
            biome,
            soil: RULES.surface(biome),
            water_depth: 0,
            water: Water::Dry,
            discharge_m3s: 0.0,
            dry_bed: false,
            precipitation_mm: 800.0,
            drop_blocks: 0,
            temperature_c: 15.0,
            seed: 1,
            x: 0,
            z: 0,
        }
    }

    #[test]
    fn biomes_choose_their_surface() {
        assert_eq!(ground(&site("minecraft:plains")).top, BlockState::GRASS_BLOCK);
        assert_eq!(ground(&site("minecraft:desert")).top, BlockState::SAND);
        assert_eq!(ground(&site("minecraft:desert")).filler, BlockState::SANDSTONE);
        assert_eq!(ground(&site("minecraft:badlands")).top, BlockState::RED_SAND);
        assert!(ground(&site("minecraft:eroded_badlands")).banded);
        assert_eq!(ground(&site("minecraft:old_growth_spruce_taiga")).top, BlockState::PODZOL);
        assert_eq!(ground(&site("minecraft:mangrove_swamp")).top, BlockState::MUD);
        assert_eq!(ground(&site("minecraft:windswept_gravelly_hills")).top, BlockState::GRAVEL);
    }

    #[test]
    fn steep_ground_is_bare_rock_except_in_badlands() {
        let steep = |b| Site { drop_blocks: STEEP_DROP_BLOCKS, ..site(b) };
        assert_eq!(ground(&steep("minecraft:plains")).top, BlockState::STONE);
        assert_eq!(
            ground(&Site { drop_blocks: STEEP_DROP_BLOCKS - 1, ..site("minecraft:plains") }).top,
            BlockState::GRASS_BLOCK
        );
        assert_eq!(ground(&steep("minecraft:badlands")).top, BlockState::TERRACOTTA);
    }

    #[test]
    fn cold_ground_is_snow_and_very_cold_ground_has_powder_snow_somewhere() {
        let cold = Site { temperature_c: SNOW_LINE_C - 1.0, ..site("minecraft:plains") };
        assert_eq!(ground(&cold).top, BlockState::SNOW_BLOCK);
        assert_eq!(ground(&site("minecraft:snowy_plains")).top, BlockState::SNOW_BLOCK);
        let tops: Vec<BlockState> = (0..64)
            .flat_map(|x| (0..64).map(move |z| (x, z)))
            .map(|(x, z)| ground(&Site { temperature_c: -20.0, x, z, ..site("minecraft:frozen_peaks") }).top)
            .collect();
        assert!(tops.contains(&BlockState::POWDER_SNOW));
        assert!(tops.contains(&BlockState::SNOW_BLOCK));
    }

    #[test]
    fn sea_floors_are_sand_shallow_and_gravel_deep_or_cold() {
        let wet = |b, depth, t| ground(&Site { water_depth: depth, temperature_c: t, ..site(b) }).top;
        assert_eq!(wet("minecraft:ocean", 3, 15.0), BlockState::SAND);
        assert_eq!(wet("minecraft:deep_ocean", 40, 15.0), BlockState::GRAVEL);
        assert_eq!(wet("minecraft:cold_ocean", 3, 15.0), BlockState::GRAVEL);
        assert_eq!(wet("minecraft:warm_ocean", 40, 25.0), BlockState::SAND);
    }

    #[test]
    fn river_beds_are_gravel_in_streams_and_sand_in_big_rivers_with_clay_patches_and_lakes_are_sandy() {
        let beds = |water, discharge_m3s, temperature_c, precipitation_mm| {
            let mut counts = std::collections::HashMap::new();
            for (x, z) in (0..64).flat_map(|x| (0..64).map(move |z| (x, z))) {
                let site = Site {
                    water,
                    discharge_m3s,
                    temperature_c,
                    precipitation_mm,
                    water_depth: 2,
                    x,
                    z,
                    ..site("minecraft:river")
                };
                *counts.entry(ground(&site).top).or_insert(0) += 1;
            }
            counts
        };
        let stream = beds(Water::River, 1.0, 12.0, 800.0);
        let big = beds(Water::River, 500.0, 12.0, 800.0);
        let share = |c: &std::collections::HashMap<BlockState, i32>, b| f64::from(*c.get(&b).unwrap_or(&0)) / 4096.0;
        assert!(share(&stream, BlockState::GRAVEL) > 0.3, "{stream:?}");
        assert_eq!(share(&big, BlockState::GRAVEL), 0.0, "{big:?}");
        assert!(share(&big, BlockState::SAND) > 0.6, "{big:?}");
        assert!(share(&big, BlockState::CLAY) > 0.0, "{big:?}");
        let lake = beds(Water::Lake, 20.0, 12.0, 800.0);
        assert!(share(&lake, BlockState::SAND) > 0.6 && !lake.contains_key(&BlockState::GRAVEL), "{lake:?}");
        assert_eq!(beds(Water::River, 5.0, -5.0, 800.0).len(), 1, "cold beds are gravel only");
        assert!(beds(Water::River, 5.0, 25.0, 2500.0).contains_key(&BlockState::MUD), "tropical rivers are muddy");
    }

    #[test]
    fn dry_lake_beds_are_salt_flats_where_arid_and_clay_otherwise() {
        let dry = |precipitation_mm| ground(&Site { dry_bed: true, precipitation_mm, ..site("minecraft:desert") }).top;
        assert_eq!(dry(100.0), BlockState::CALCITE);
        assert_eq!(dry(400.0), BlockState::CLAY);
    }

    #[test]
    fn bands_repeat_every_sixteen_blocks() {
        for y in -64..64 {
            assert_eq!(terracotta_band(y), terracotta_band(y + 16));
        }
    }
}
