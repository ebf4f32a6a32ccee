//! Ground vegetation: one plant at most per column, chosen from a hash of (seed, x, z) against
//! the chances the biome's vegetation table gives (`biomes/vegetation.toml`).
//!
//! A pure function of global coordinates (plus the column's biome and ground), so chunks meet
//! without seams. Cacti also look at their four neighbours' candidates and ground, so that no
//! cactus ever touches a block sideways (in 1.20.1 such a cactus would break).

use valence::prelude::{BlockState, PropName, PropValue};

use crate::biome::Vegetation;

use super::hash::{hash3, unit3};

const SALT_PLANT: u64 = 0x706c_616e;
const SALT_PICK: u64 = 0x7069_636b;

/// One plant, standing on a ground block.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Plant {
    /// A one-block plant (grass, fern, flower, dead bush, berry bush, mushroom).
    Single(BlockState),
    /// A two-block plant (tall grass, large fern, sunflower): the lower half's block.
    Tall(BlockState),
    /// A cactus this many blocks tall (1–3).
    Cactus(i32),
    /// A bamboo stalk this many blocks tall.
    Bamboo(i32),
}

impl Plant {
    /// The blocks of the plant from the one above the ground upwards.
    pub fn blocks(self) -> Vec<BlockState> {
        match self {
            Plant::Single(b) => vec![b],
            Plant::Tall(b) => vec![b.set(PropName::Half, PropValue::Lower), b.set(PropName::Half, PropValue::Upper)],
            Plant::Cactus(h) => vec![BlockState::CACTUS; h.max(0) as usize],
            // A grown stalk: thick (age 1), leafless below, small then large leaves on top.
            Plant::Bamboo(h) => (0..h)
                .map(|i| {
                    let leaves = match h - i {
                        1 | 2 => PropValue::Large,
                        3 => PropValue::Small,
                        _ => PropValue::None,
                    };
                    BlockState::BAMBOO.set(PropName::Age, PropValue::_1).set(PropName::Leaves, leaves)
                })
                .collect(),
        }
    }
}

/// True for the blocks this module and the aquatic pass place (they let sky light through
/// and are not ground).
pub fn is_plant(block: BlockState) -> bool {
    matches!(
        block.to_kind().to_str(),
        "grass"
            | "tall_grass"
            | "fern"
            | "large_fern"
            | "dead_bush"
            | "cactus"
            | "sunflower"
            | "lilac"
            | "rose_bush"
            | "peony"
            | "dandelion"
            | "poppy"
            | "blue_orchid"
            | "allium"
            | "azure_bluet"
            | "red_tulip"
            | "orange_tulip"
            | "white_tulip"
            | "pink_tulip"
            | "oxeye_daisy"
            | "cornflower"
            | "lily_of_the_valley"
            | "pink_petals"
            | "sweet_berry_bush"
            | "brown_mushroom"
            | "red_mushroom"
            | "bamboo"
            | "azalea"
            | "flowering_azalea"
            | "sugar_cane"
            | "lily_pad"
    )
}

/// What ground a plant needs.
#[derive(Clone, Copy, PartialEq)]
enum Needs {
    /// Grass, dirt, podzol or mud.
    Soil,
    /// Soil, or mycelium.
    Mushroom,
    /// Soil, sand, red sand or terracotta.
    Dry,
    /// Sand or red sand.
    Sand,
    /// Soil, sand or gravel.
    Bamboo,
}

/// The plant a vegetation table's name stands for at one column (`pick` varies a flower's
/// facing, a cactus' or stalk's height, a bush's age), and the ground it needs.
fn plant(name: &str, pick: u64) -> Option<(Plant, Needs)> {
    let single = |b: BlockState| Some((Plant::Single(b), Needs::Soil));
    let tall = |b: BlockState| Some((Plant::Tall(b), Needs::Soil));
    match name {
        "grass" => single(BlockState::GRASS),
        "tall_grass" => tall(BlockState::TALL_GRASS),
        "fern" => single(BlockState::FERN),
        "large_fern" => tall(BlockState::LARGE_FERN),
        "dandelion" => single(BlockState::DANDELION),
        "poppy" => single(BlockState::POPPY),
        "blue_orchid" => single(BlockState::BLUE_ORCHID),
        "allium" => single(BlockState::ALLIUM),
        "azure_bluet" => single(BlockState::AZURE_BLUET),
        "red_tulip" => single(BlockState::RED_TULIP),
        "orange_tulip" => single(BlockState::ORANGE_TULIP),
        "white_tulip" => single(BlockState::WHITE_TULIP),
        "pink_tulip" => single(BlockState::PINK_TULIP),
        "oxeye_daisy" => single(BlockState::OXEYE_DAISY),
        "cornflower" => single(BlockState::CORNFLOWER),
        "lily_of_the_valley" => single(BlockState::LILY_OF_THE_VALLEY),
        "sunflower" => tall(BlockState::SUNFLOWER),
        "lilac" => tall(BlockState::LILAC),
        "rose_bush" => tall(BlockState::ROSE_BUSH),
        "peony" => tall(BlockState::PEONY),
        "pink_petals" => {
            let facing = [PropValue::North, PropValue::East, PropValue::South, PropValue::West][(pick % 4) as usize];
            let amount = [PropValue::_1, PropValue::_2, PropValue::_3, PropValue::_4][(pick / 4 % 4) as usize];
            single(BlockState::PINK_PETALS.set(PropName::Facing, facing).set(PropName::FlowerAmount, amount))
        }
        "sweet_berry_bush" => {
            let age = if pick % 2 == 0 { PropValue::_2 } else { PropValue::_3 };
            single(BlockState::SWEET_BERRY_BUSH.set(PropName::Age, age))
        }
        "azalea" => single(BlockState::AZALEA),
        "flowering_azalea" => single(BlockState::FLOWERING_AZALEA),
        "dead_bush" => Some((Plant::Single(BlockState::DEAD_BUSH), Needs::Dry)),
        "cactus" => Some((Plant::Cactus(1 + (pick % 3) as i32), Needs::Sand)),
        "brown_mushroom" => Some((Plant::Single(BlockState::BROWN_MUSHROOM), Needs::Mushroom)),
        "red_mushroom" => Some((Plant::Single(BlockState::RED_MUSHROOM), Needs::Mushroom)),
        "bamboo" => Some((Plant::Bamboo(5 + (pick % 8) as i32), Needs::Bamboo)),
        _ => None,
    }
}

/// The plant column (`x`, `z`) would grow with `vegetation` (its biome's table) on dry,
/// gentle ground topped by `top`, before any look at its neighbours or trees; `None` for
/// bare ground.
pub fn candidate(seed: u64, vegetation: Option<&Vegetation>, top: BlockState, x: i64, z: i64) -> Option<Plant> {
    let vegetation = vegetation?;
    let soil = matches!(
        top,
        BlockState::GRASS_BLOCK | BlockState::PODZOL | BlockState::DIRT | BlockState::COARSE_DIRT | BlockState::MUD
    );
    let sand = matches!(top, BlockState::SAND | BlockState::RED_SAND);
    let mut r = unit3(seed, SALT_PLANT, x, 0, z);
    let &(name, _) = vegetation.plants.iter().find(|&&(_, chance)| {
        let hit = r < chance;
        r -= chance;
        hit
    })?;
    let (plant, needs) = plant(name, hash3(seed, SALT_PICK, x, 0, z))?;
    let grows = match needs {
        Needs::Soil => soil,
        Needs::Mushroom => soil || top == BlockState::MYCELIUM,
        Needs::Dry => soil || sand || top.to_kind().to_str().ends_with("terracotta"),
        Needs::Sand => sand,
        Needs::Bamboo => soil || sand || top == BlockState::GRAVEL,
    };
    grows.then_some(plant)
}

#[cfg(test)]
mod tests {
    use std::path::PathBuf;

    use super::*;
    use crate::biome::{BiomeRules, PLANTS};

    fn shipped() -> BiomeRules {
        let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("biomes");
        BiomeRules::load_dir(&dir).expect("the shipped rules load")
    }

    fn count(rules: &BiomeRules, biome: &str, top: BlockState, want: impl Fn(Plant) -> bool) -> usize {
        let vegetation = rules.vegetation(biome);
        (0..64i64)
            .flat_map(|x| (0..64i64).map(move |z| (x, z)))
            .filter_map(|(x, z)| candidate(7, vegetation, top, x, z))
            .filter(|&p| want(p))
            .count()
    }

    #[test]
    fn every_plant_name_stands_for_a_plant() {
        for name in PLANTS {
            let (plant, _) = plant(name, 5).unwrap_or_else(|| panic!("{name} has no plant"));
            let blocks = plant.blocks();
            assert!(blocks.iter().all(|&b| is_plant(b)), "{name}: {blocks:?}");
            assert_eq!(blocks[0].to_kind().to_str(), *name, "{name}");
        }
    }

    #[test]
    fn deserts_grow_cacti_and_dead_bushes_but_never_grass() {
        let rules = shipped();
        let desert = "minecraft:desert";
        assert!(count(&rules, desert, BlockState::SAND, |p| matches!(p, Plant::Cactus(1..=3))) > 10);
        assert!(count(&rules, desert, BlockState::SAND, |p| p == Plant::Single(BlockState::DEAD_BUSH)) > 10);
        let green = |p| matches!(p, Plant::Single(BlockState::GRASS) | Plant::Tall(_));
        assert_eq!(count(&rules, desert, BlockState::SAND, green), 0);
        let badlands = "minecraft:badlands";
        assert!(count(&rules, badlands, BlockState::RED_SAND, |p| p == Plant::Single(BlockState::DEAD_BUSH)) > 10);
        assert_eq!(count(&rules, badlands, BlockState::RED_SAND, |p| matches!(p, Plant::Cactus(_))), 0);
    }

    #[test]
    fn plains_grow_grass_and_flowers_and_nothing_grows_on_snow_or_stone() {
        let rules = shipped();
        let plains = "minecraft:plains";
        assert!(count(&rules, plains, BlockState::GRASS_BLOCK, |p| p == Plant::Single(BlockState::GRASS)) > 500);
        let flower = |p| matches!(p, Plant::Single(b) if b != BlockState::GRASS);
        assert!(count(&rules, plains, BlockState::GRASS_BLOCK, flower) > 20);
        assert_eq!(count(&rules, plains, BlockState::SNOW_BLOCK, |_| true), 0);
        assert_eq!(count(&rules, plains, BlockState::STONE, |_| true), 0);
        assert_eq!(count(&rules, "minecraft:snowy_plains", BlockState::SNOW_BLOCK, |_| true), 0);
        let forest = "minecraft:flower_forest";
        assert!(count(&rules, forest, BlockState::GRASS_BLOCK, |p| p == Plant::Single(BlockState::ALLIUM)) > 10);
        assert!(count(&rules, "minecraft:taiga", BlockState::PODZOL, |p| p == Plant::Single(BlockState::FERN)) > 50);
        // Bamboo jungles grow bamboo, mushroom fields mushrooms on their mycelium.
        let bamboo =
            count(&rules, "minecraft:bamboo_jungle", BlockState::GRASS_BLOCK, |p| matches!(p, Plant::Bamboo(_)));
        assert!(bamboo > 200, "{bamboo} stalks");
        let mushroom = |p| matches!(p, Plant::Single(BlockState::RED_MUSHROOM | BlockState::BROWN_MUSHROOM));
        assert!(count(&rules, "minecraft:mushroom_fields", BlockState::MYCELIUM, mushroom) > 20);
        // A biome without a table grows nothing.
        assert_eq!(count(&rules, "minecraft:stony_peaks", BlockState::GRASS_BLOCK, |_| true), 0);
    }

    #[test]
    fn candidates_are_deterministic_and_tall_plants_have_both_halves() {
        let rules = shipped();
        let v = rules.vegetation("minecraft:plains");
        for x in -20..20 {
            for z in -20..20 {
                assert_eq!(
                    candidate(3, v, BlockState::GRASS_BLOCK, x, z),
                    candidate(3, v, BlockState::GRASS_BLOCK, x, z)
                );
            }
        }
        assert_eq!(Plant::Tall(BlockState::SUNFLOWER).blocks()[1].get(PropName::Half), Some(PropValue::Upper));
        let stalk = Plant::Bamboo(6).blocks();
        assert_eq!(
            (stalk[0].get(PropName::Leaves), stalk[5].get(PropName::Leaves)),
            (Some(PropValue::None), Some(PropValue::Large))
        );
        assert!(!is_plant(BlockState::GRASS_BLOCK) && !is_plant(BlockState::SAND) && !is_plant(BlockState::AIR));
    }
}
