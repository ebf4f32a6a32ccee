//! Ground vegetation: grass, ferns, flowers, dead bushes and cacti, one plant at most per
//! column, chosen from a hash of (seed, x, z) against the biome's densities.
//!
//! A pure function of global coordinates (plus the column's biome and ground), so chunks meet
//! without seams. Cacti also look at their four neighbours' candidates and ground, so that no
//! cactus ever touches a block sideways (in 1.20.1 such a cactus would break).

use valence::prelude::{BlockState, PropName, PropValue};

use super::hash::{hash3, unit3};

const SALT_PLANT: u64 = 0x706c_616e;
const SALT_PICK: u64 = 0x7069_636b;

/// One plant, standing on a ground block.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Plant {
    /// A one-block plant (grass, fern, flower, dead bush).
    Single(BlockState),
    /// A two-block plant (tall grass, large fern, sunflower): the lower half's block.
    Tall(BlockState),
    /// A cactus this many blocks tall (1–3).
    Cactus(i32),
}

impl Plant {
    /// The blocks of the plant from the one above the ground upwards.
    pub fn blocks(self) -> Vec<BlockState> {
        match self {
            Plant::Single(b) => vec![b],
            Plant::Tall(b) => vec![b.set(PropName::Half, PropValue::Lower), b.set(PropName::Half, PropValue::Upper)],
            Plant::Cactus(h) => vec![BlockState::CACTUS; h.max(0) as usize],
        }
    }
}

/// True for the blocks this module places (they let sky light through and are not ground).
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
            | "dandelion"
            | "poppy"
            | "cornflower"
            | "oxeye_daisy"
            | "azure_bluet"
            | "allium"
            | "pink_petals"
            | "sugar_cane"
            | "lily_pad"
    )
}

/// What grows in a biome, as chances per column (summing to less than 1).
#[derive(Clone, Copy, Debug, Default)]
struct Flora {
    grass: f32,
    tall_grass: f32,
    fern: f32,
    flowers: f32,
    petals: f32,
    sunflowers: f32,
    dead_bush: f32,
    cactus: f32,
}

fn flora(biome: &str) -> Flora {
    let b = biome.strip_prefix("minecraft:").unwrap_or(biome);
    let f = Flora::default();
    match b {
        "plains" => Flora { grass: 0.3, tall_grass: 0.03, flowers: 0.03, ..f },
        "sunflower_plains" => Flora { grass: 0.3, tall_grass: 0.03, flowers: 0.03, sunflowers: 0.04, ..f },
        "meadow" => Flora { grass: 0.35, tall_grass: 0.05, flowers: 0.1, ..f },
        "forest" | "birch_forest" | "old_growth_birch_forest" | "dark_forest" => {
            Flora { grass: 0.2, tall_grass: 0.02, flowers: 0.02, ..f }
        }
        "flower_forest" => Flora { grass: 0.12, flowers: 0.3, ..f },
        "cherry_grove" => Flora { grass: 0.15, flowers: 0.03, petals: 0.2, ..f },
        "taiga" | "old_growth_pine_taiga" | "old_growth_spruce_taiga" => {
            Flora { grass: 0.1, fern: 0.15, tall_grass: 0.02, ..f }
        }
        "jungle" | "sparse_jungle" | "bamboo_jungle" => Flora { grass: 0.25, fern: 0.15, tall_grass: 0.05, ..f },
        "savanna" | "savanna_plateau" | "windswept_savanna" => Flora { grass: 0.3, tall_grass: 0.06, ..f },
        "swamp" | "windswept_hills" | "windswept_forest" => Flora { grass: 0.1, ..f },
        "desert" => Flora { dead_bush: 0.02, cactus: 0.015, ..f },
        _ if b.contains("badlands") => Flora { dead_bush: 0.02, ..f },
        _ => f,
    }
}

/// The plant column (`x`, `z`) would grow in `biome` on dry, gentle ground topped by `top`,
/// before any look at its neighbours or trees; `None` for bare ground.
pub fn candidate(seed: u64, biome: &str, top: BlockState, x: i64, z: i64) -> Option<Plant> {
    let soil = matches!(
        top,
        BlockState::GRASS_BLOCK | BlockState::PODZOL | BlockState::DIRT | BlockState::COARSE_DIRT | BlockState::MUD
    );
    let sand = matches!(top, BlockState::SAND | BlockState::RED_SAND);
    let dry_ground = sand || top.to_kind().to_str().ends_with("terracotta") || soil;
    let f = flora(biome);
    let pick = hash3(seed, SALT_PICK, x, 0, z);
    let mut r = unit3(seed, SALT_PLANT, x, 0, z);
    let mut take = |chance: f32| {
        let hit = r < chance;
        r -= chance;
        hit
    };
    if take(f.grass) {
        return soil.then_some(Plant::Single(BlockState::GRASS));
    }
    if take(f.tall_grass) {
        return soil.then_some(Plant::Tall(BlockState::TALL_GRASS));
    }
    if take(f.fern) {
        let fern = if pick % 5 == 0 { Plant::Tall(BlockState::LARGE_FERN) } else { Plant::Single(BlockState::FERN) };
        return soil.then_some(fern);
    }
    if take(f.flowers) {
        let b = biome.strip_prefix("minecraft:").unwrap_or(biome);
        let flowers: &[BlockState] = if b == "flower_forest" {
            &[
                BlockState::DANDELION,
                BlockState::POPPY,
                BlockState::CORNFLOWER,
                BlockState::OXEYE_DAISY,
                BlockState::AZURE_BLUET,
                BlockState::ALLIUM,
            ]
        } else {
            &[BlockState::DANDELION, BlockState::POPPY, BlockState::CORNFLOWER, BlockState::OXEYE_DAISY]
        };
        return soil.then_some(Plant::Single(flowers[(pick % flowers.len() as u64) as usize]));
    }
    if take(f.petals) {
        return soil.then_some(Plant::Single(BlockState::PINK_PETALS));
    }
    if take(f.sunflowers) {
        return soil.then_some(Plant::Tall(BlockState::SUNFLOWER));
    }
    if take(f.dead_bush) {
        return dry_ground.then_some(Plant::Single(BlockState::DEAD_BUSH));
    }
    if take(f.cactus) {
        return (top == BlockState::SAND).then_some(Plant::Cactus(1 + (pick % 3) as i32));
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn count(biome: &str, top: BlockState, want: impl Fn(Plant) -> bool) -> usize {
        (0..64i64)
            .flat_map(|x| (0..64i64).map(move |z| (x, z)))
            .filter_map(|(x, z)| candidate(7, biome, top, x, z))
            .filter(|&p| want(p))
            .count()
    }

    #[test]
    fn candidates_are_deterministic() {
        for x in -20..20 {
            for z in -20..20 {
                assert_eq!(
                    candidate(3, "minecraft:plains", BlockState::GRASS_BLOCK, x, z),
                    candidate(3, "minecraft:plains", BlockState::GRASS_BLOCK, x, z)
                );
            }
        }
    }

    #[test]
    fn deserts_grow_cacti_and_dead_bushes_but_never_grass() {
        let desert = "minecraft:desert";
        assert!(count(desert, BlockState::SAND, |p| matches!(p, Plant::Cactus(1..=3))) > 10);
        assert!(count(desert, BlockState::SAND, |p| p == Plant::Single(BlockState::DEAD_BUSH)) > 10);
        assert_eq!(
            count(desert, BlockState::SAND, |p| matches!(p, Plant::Single(BlockState::GRASS) | Plant::Tall(_))),
            0
        );
        assert!(count("minecraft:badlands", BlockState::RED_SAND, |p| p == Plant::Single(BlockState::DEAD_BUSH)) > 10);
        assert_eq!(count("minecraft:badlands", BlockState::RED_SAND, |p| matches!(p, Plant::Cactus(_))), 0);
    }

    #[test]
    fn plains_grow_grass_and_flowers_and_nothing_grows_on_snow_or_stone() {
        let plains = "minecraft:plains";
        assert!(count(plains, BlockState::GRASS_BLOCK, |p| p == Plant::Single(BlockState::GRASS)) > 500);
        assert!(
            count(plains, BlockState::GRASS_BLOCK, |p| matches!(p, Plant::Single(b) if b != BlockState::GRASS)) > 20
        );
        assert_eq!(count(plains, BlockState::SNOW_BLOCK, |_| true), 0);
        assert_eq!(count(plains, BlockState::STONE, |_| true), 0);
        assert_eq!(count("minecraft:snowy_plains", BlockState::SNOW_BLOCK, |_| true), 0);
        let alliums =
            count("minecraft:flower_forest", BlockState::GRASS_BLOCK, |p| p == Plant::Single(BlockState::ALLIUM));
        assert!(alliums > 10);
        assert!(count("minecraft:taiga", BlockState::PODZOL, |p| p == Plant::Single(BlockState::FERN)) > 50);
    }

    #[test]
    fn plants_are_plants() {
        for p in [Plant::Tall(BlockState::TALL_GRASS), Plant::Cactus(3), Plant::Single(BlockState::PINK_PETALS)] {
            assert!(p.blocks().iter().all(|&b| is_plant(b)));
        }
        assert_eq!(Plant::Tall(BlockState::SUNFLOWER).blocks()[1].get(PropName::Half), Some(PropValue::Upper));
        assert!(!is_plant(BlockState::GRASS_BLOCK) && !is_plant(BlockState::SAND) && !is_plant(BlockState::AIR));
    }
}
