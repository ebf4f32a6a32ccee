//! The shipped `biomes/default.toml`: it loads, covers every realistic cell, reaches the
//! biomes the issue asks for, and puts them where climate and terrain say they belong.

use std::collections::BTreeSet;
use std::path::Path;

use super::*;
use crate::terrain::climate::variability_pct;

/// Lapse rate of the default climate settings, °C per m.
const LAPSE_C_PER_M: f32 = 6.5 / 1000.0;

fn shipped() -> BiomeRules {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("biomes");
    BiomeRules::load_dir(&dir).unwrap_or_else(|e| panic!("the shipped rules must load: {e}"))
}

/// A surface cell: elevation is the ground's, variability follows precipitation as in the
/// climate model.
fn ground(temperature_c: f32, precipitation_mm: f32, surface_m: f32, slope_deg: f32) -> Conditions {
    Conditions {
        temperature_c,
        seasonality_c: 5.0,
        precipitation_mm,
        variability_pct: variability_pct(f64::from(precipitation_mm)) as f32,
        elevation_m: surface_m,
        surface_m,
        slope_deg,
        water: if surface_m < 0.0 { WaterBody::Sea } else { WaterBody::None },
        river_distance_m: 640.0,
    }
}

/// Every biome the issue names for the default rules.
const REQUIRED: &[&str] = &[
    "ocean",
    "deep_ocean",
    "frozen_ocean",
    "deep_frozen_ocean",
    "cold_ocean",
    "deep_cold_ocean",
    "lukewarm_ocean",
    "deep_lukewarm_ocean",
    "warm_ocean",
    "beach",
    "snowy_beach",
    "stony_shore",
    "desert",
    "badlands",
    "eroded_badlands",
    "wooded_badlands",
    "savanna",
    "savanna_plateau",
    "windswept_savanna",
    "jungle",
    "sparse_jungle",
    "bamboo_jungle",
    "swamp",
    "mangrove_swamp",
    "forest",
    "flower_forest",
    "birch_forest",
    "old_growth_birch_forest",
    "dark_forest",
    "taiga",
    "old_growth_pine_taiga",
    "old_growth_spruce_taiga",
    "snowy_taiga",
    "windswept_forest",
    "windswept_hills",
    "windswept_gravelly_hills",
    "plains",
    "sunflower_plains",
    "snowy_plains",
    "ice_spikes",
    "cherry_grove",
    "meadow",
    "grove",
    "snowy_slopes",
    "jagged_peaks",
    "frozen_peaks",
    "stony_peaks",
    "river",
    "frozen_river",
];

#[test]
fn the_shipped_rules_cover_every_realistic_cell_and_reach_every_required_biome() {
    let rules = shipped();
    let surfaces = [
        -5000.0, -2500.0, -1500.0, -500.0, -50.0, -15.0, -5.0, 0.0, 5.0, 15.0, 30.0, 50.0, 100.0, 150.0, 300.0, 500.0,
        800.0, 1200.0, 1600.0, 2200.0, 3000.0, 4000.0,
    ];
    let slopes = [0.0, 0.5, 1.2, 2.0, 4.0, 8.0, 14.0, 20.0];
    let seasonalities = [1.0, 3.0, 5.0, 8.0, 12.0, 15.0];
    let mut reached = BTreeSet::new();
    let mut cells = 0u64;
    for &surface_m in &surfaces {
        for &slope_deg in &slopes {
            for &seasonality_c in &seasonalities {
                for t in -30..=32 {
                    for p in 0..=70 {
                        let c = Conditions { seasonality_c, ..ground(t as f32, p as f32 * 50.0, surface_m, slope_deg) };
                        assert!(
                            rules.matching_rule(&c).is_some(),
                            "no rule for {c:?}: the fallback should be a last resort"
                        );
                        reached.insert(rules.biome(&c));
                        cells += 1;
                    }
                }
            }
        }
    }
    // Inland water, through the climates.
    for water in WaterBody::ALL {
        for t in -30..=32 {
            for p in [100.0, 800.0, 2500.0] {
                let c = Conditions { water, ..ground(t as f32, p, 200.0, 2.0) };
                assert!(rules.matching_rule(&c).is_some(), "no rule for {c:?}");
                reached.insert(rules.biome(&c));
            }
        }
    }
    assert!(cells > 4_000_000);
    assert!(reached.len() >= 40, "only {} biomes: {reached:?}", reached.len());
    let missing: Vec<_> = REQUIRED.iter().filter(|b| !reached.contains(format!("minecraft:{b}").as_str())).collect();
    assert!(missing.is_empty(), "never produced: {missing:?}");
    assert!(reached.iter().all(|b| OVERWORLD_BIOMES.contains(b)));
    assert_eq!(rules.biome_names().len(), reached.len(), "every biome in the rules is reachable");
}

#[test]
fn dry_land_has_gallery_forests_along_its_rivers() {
    let rules = shipped();
    let at = |t: f32, p: f32, river_distance_m: f32| {
        rules.biome(&Conditions { river_distance_m, ..ground(t, p, 200.0, 1.0) })
    };
    // Temperate steppe: forest within 160 m of a river's bank, grassland beyond.
    assert_eq!((at(12.0, 300.0, 80.0), at(12.0, 300.0, 640.0)), ("minecraft:forest", "minecraft:plains"));
    // Hot and dry: acacia woodland along the river through the desert.
    assert_eq!((at(24.0, 200.0, 0.0), at(24.0, 200.0, 640.0)), ("minecraft:savanna", "minecraft:desert"));
    // Wet land is forest anyway; the river itself and the hyper-arid desert are untouched.
    assert_eq!(at(12.0, 900.0, 80.0), at(12.0, 900.0, 640.0));
    assert_eq!(at(24.0, 50.0, 80.0), "minecraft:desert");
    assert_eq!(
        rules.biome(&Conditions { water: WaterBody::River, river_distance_m: 0.0, ..ground(12.0, 300.0, 200.0, 1.0) }),
        "minecraft:river"
    );
}

#[test]
fn biomes_change_with_height_on_a_mountain() {
    let rules = shipped();
    // A 1500 m plateau at 6 °C: the biome of the air cells above it follows their altitude.
    let (surface_m, surface_c) = (1500.0, 6.0);
    let at = |elevation_m: f32| Conditions {
        temperature_c: surface_c - LAPSE_C_PER_M * (elevation_m - surface_m),
        elevation_m,
        ..ground(surface_c, 800.0, surface_m, 3.0)
    };
    assert_eq!(rules.biome(&at(1500.0)), "minecraft:meadow");
    assert_eq!(rules.biome(&at(2300.0)), "minecraft:grove", "just below the tree line");
    assert_eq!(rules.biome(&at(3000.0)), "minecraft:snowy_slopes", "above the tree line");
    // Summits by temperature and steepness.
    assert_eq!(rules.biome(&ground(-6.0, 800.0, 3500.0, 15.0)), "minecraft:jagged_peaks");
    assert_eq!(rules.biome(&ground(-15.0, 800.0, 4500.0, 5.0)), "minecraft:frozen_peaks");
    assert_eq!(rules.biome(&ground(4.0, 800.0, 2500.0, 15.0)), "minecraft:stony_peaks");
    assert_eq!(rules.biome(&ground(9.0, 1600.0, 1400.0, 3.0)), "minecraft:cherry_grove");
}

#[test]
fn coasts_and_seas_follow_height_slope_depth_and_temperature() {
    let rules = shipped();
    assert_eq!(rules.biome(&ground(15.0, 800.0, 5.0, 1.0)), "minecraft:beach");
    assert_eq!(rules.biome(&ground(15.0, 800.0, -10.0, 1.0)), "minecraft:beach", "the shallows in front");
    assert_eq!(rules.biome(&ground(15.0, 800.0, 30.0, 10.0)), "minecraft:stony_shore", "a cliff coast");
    assert_eq!(rules.biome(&ground(-8.0, 300.0, 5.0, 1.0)), "minecraft:snowy_beach");
    assert_eq!(rules.biome(&ground(26.0, 2500.0, 5.0, 0.5)), "minecraft:mangrove_swamp");
    assert_eq!(rules.biome(&ground(26.0, 2500.0, -500.0, 0.5)), "minecraft:warm_ocean");
    assert_eq!(rules.biome(&ground(26.0, 2500.0, -4000.0, 0.5)), "minecraft:deep_lukewarm_ocean");
    assert_eq!(rules.biome(&ground(12.0, 900.0, -4000.0, 0.5)), "minecraft:deep_ocean");
    assert_eq!(rules.biome(&ground(-10.0, 200.0, -300.0, 0.5)), "minecraft:frozen_ocean");
    // The water column above a sea floor keeps the ocean biome.
    let water = Conditions { elevation_m: -100.0, ..ground(12.0, 900.0, -4000.0, 0.5) };
    assert_eq!(rules.biome(&water), "minecraft:deep_ocean");
}

#[test]
fn rivers_are_river_biomes_frozen_where_cold_and_lakes_keep_the_land_biome() {
    let rules = shipped();
    let at = |t: f32, surface_m: f32, water| rules.biome(&Conditions { water, ..ground(t, 900.0, surface_m, 2.0) });
    assert_eq!(at(12.0, 200.0, WaterBody::River), "minecraft:river");
    assert_eq!(at(12.0, 1500.0, WaterBody::River), "minecraft:river", "mountain rivers too");
    assert_eq!(at(-5.0, 200.0, WaterBody::River), "minecraft:frozen_river");
    assert_eq!(at(12.0, 200.0, WaterBody::Lake), at(12.0, 200.0, WaterBody::None));
}

#[test]
fn lowlands_follow_temperature_and_precipitation() {
    let rules = shipped();
    let low = |t: f32, p: f32| rules.biome(&ground(t, p, 200.0, 2.0));
    assert_eq!(low(26.0, 2800.0), "minecraft:jungle");
    assert_eq!(low(20.0, 2800.0), "minecraft:bamboo_jungle");
    assert_eq!(low(26.0, 1700.0), "minecraft:sparse_jungle");
    assert_eq!(low(26.0, 900.0), "minecraft:savanna");
    assert_eq!(low(26.0, 150.0), "minecraft:desert");
    assert_eq!(rules.biome(&ground(26.0, 150.0, 200.0, 5.0)), "minecraft:badlands");
    assert_eq!(rules.biome(&ground(26.0, 150.0, 200.0, 9.0)), "minecraft:eroded_badlands");
    assert_eq!(low(12.0, 300.0), "minecraft:plains");
    assert_eq!(low(13.0, 500.0), "minecraft:sunflower_plains");
    assert_eq!(low(12.0, 700.0), "minecraft:forest");
    assert_eq!(low(13.0, 900.0), "minecraft:flower_forest");
    assert_eq!(low(12.0, 1400.0), "minecraft:dark_forest");
    assert_eq!(low(7.0, 800.0), "minecraft:birch_forest");
    assert_eq!(low(2.0, 500.0), "minecraft:taiga");
    assert_eq!(low(-8.0, 300.0), "minecraft:snowy_plains");
    assert_eq!(rules.biome(&ground(-25.0, 150.0, 200.0, 0.2)), "minecraft:ice_spikes");
    assert_eq!(
        rules.biome(&Conditions { seasonality_c: 12.0, ..ground(-8.0, 300.0, 200.0, 2.0) }),
        "minecraft:snowy_taiga"
    );
    assert_eq!(rules.biome(&ground(12.0, 1000.0, 50.0, 0.5)), "minecraft:swamp");
    assert_eq!(rules.biome(&ground(12.0, 1000.0, 400.0, 9.0)), "minecraft:windswept_forest");
}

#[test]
fn the_header_documents_every_key() {
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("biomes/default.toml"))
        .unwrap_or_else(|e| panic!("{e}"));
    let header: String = text.lines().take_while(|l| l.starts_with('#') || l.is_empty()).collect::<Vec<_>>().join("\n");
    for key in super::load::RULE_KEYS {
        assert!(header.contains(key), "`{key}` is not explained at the top of default.toml");
    }
}
