//! What grows in each biome, as the owner writes it beside the rules: a
//! `[vegetation."minecraft:forest"]` table says how wooded the biome is, which tree species
//! grow there in what proportion, the chance of each ground plant per column and of each
//! plant of the water.
//!
//! This module owns the vocabulary (species and plant names, checked at load with "did you
//! mean") and the parse of one table (`per_biome` gathers them); the shapes, sites and blocks
//! they stand for live with chunk generation (`chunkgen::trees`, `chunkgen::plants`, the
//! aquatic pass).

use toml::Value;

use super::error::Problem;
use super::names::suggest_key;
use super::per_biome::{in_order, number, Body, Mistake};

/// A tree species: each has its own vanilla-like shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Species {
    /// A round crown on a short trunk.
    Oak,
    /// A tall oak with branches and several leaf clusters.
    FancyOak,
    /// A slim white trunk under a round crown.
    Birch,
    /// The old-growth birch: a much taller trunk.
    TallBirch,
    /// A narrow cone of spruce.
    Spruce,
    /// A tall bare spruce trunk with a small crown at the top (old-growth pine taiga).
    Pine,
    /// A giant spruce on a 2×2 trunk.
    MegaSpruce,
    /// A jungle tree with vines and cocoa.
    Jungle,
    /// A giant jungle tree on a 2×2 trunk, with vines, cocoa and branch clusters.
    MegaJungle,
    /// A one-log jungle bush under a mound of leaves.
    JungleBush,
    /// A trunk whose top bends off diagonally, under a flat canopy.
    Acacia,
    /// A 2×2 trunk under a broad, low crown.
    DarkOak,
    /// A trunk raised on arching prop roots.
    Mangrove,
    /// A trunk that forks into two branches under a wide pink canopy.
    Cherry,
    /// An oak-log trunk under azalea and flowering azalea leaves.
    Azalea,
    /// An oak with vines hanging from its crown (swamps).
    SwampOak,
    /// A huge red mushroom: a stem under a domed cap.
    HugeRedMushroom,
    /// A huge brown mushroom: a stem under a flat, wide cap.
    HugeBrownMushroom,
}

impl Species {
    /// Every species, in the order their names are listed.
    pub const ALL: [Species; 18] = [
        Species::Oak,
        Species::FancyOak,
        Species::Birch,
        Species::TallBirch,
        Species::Spruce,
        Species::Pine,
        Species::MegaSpruce,
        Species::Jungle,
        Species::MegaJungle,
        Species::JungleBush,
        Species::Acacia,
        Species::DarkOak,
        Species::Mangrove,
        Species::Cherry,
        Species::Azalea,
        Species::SwampOak,
        Species::HugeRedMushroom,
        Species::HugeBrownMushroom,
    ];

    /// How a vegetation table names it.
    pub fn key(self) -> &'static str {
        match self {
            Species::Oak => "oak",
            Species::FancyOak => "fancy_oak",
            Species::Birch => "birch",
            Species::TallBirch => "tall_birch",
            Species::Spruce => "spruce",
            Species::Pine => "pine",
            Species::MegaSpruce => "mega_spruce",
            Species::Jungle => "jungle",
            Species::MegaJungle => "mega_jungle",
            Species::JungleBush => "jungle_bush",
            Species::Acacia => "acacia",
            Species::DarkOak => "dark_oak",
            Species::Mangrove => "mangrove",
            Species::Cherry => "cherry",
            Species::Azalea => "azalea",
            Species::SwampOak => "swamp_oak",
            Species::HugeRedMushroom => "huge_red_mushroom",
            Species::HugeBrownMushroom => "huge_brown_mushroom",
        }
    }

    fn from_key(key: &str) -> Option<Species> {
        Species::ALL.into_iter().find(|s| s.key() == key)
    }
}

/// Every ground plant a vegetation table may name: Minecraft 1.20.1 block ids without the
/// namespace (a two-block flower names its block once; bamboo names the whole stalk).
pub const PLANTS: &[&str] = &[
    "grass",
    "tall_grass",
    "fern",
    "large_fern",
    "dandelion",
    "poppy",
    "blue_orchid",
    "allium",
    "azure_bluet",
    "red_tulip",
    "orange_tulip",
    "white_tulip",
    "pink_tulip",
    "oxeye_daisy",
    "cornflower",
    "lily_of_the_valley",
    "sunflower",
    "lilac",
    "rose_bush",
    "peony",
    "pink_petals",
    "dead_bush",
    "cactus",
    "sweet_berry_bush",
    "brown_mushroom",
    "red_mushroom",
    "bamboo",
    "azalea",
    "flowering_azalea",
];

/// Every key a vegetation table understands.
const KEYS: &[&str] = &["trees", "species", "plants", "water_plants"];

/// Every plant of the water a vegetation table may name, with where it grows (chunk
/// generation's aquatic pass decides the exact sites).
pub const WATER_PLANTS: &[&str] = &[
    // Sea floors 2–12 blocks deep.
    "seagrass",
    // Sea floors at least 5 blocks deep.
    "kelp",
    // Reefs in patches of sea floor 3–16 blocks deep: the chance a reef column bears a
    // coral or a coral fan (the reef blocks stand wherever the biome has coral).
    "coral",
    // The surface of lakes and slow rivers.
    "lily_pad",
    // Banks: ground beside water at its own height.
    "sugar_cane",
    // Water up to 3 blocks deep: a clump from the bed to above the surface.
    "mangrove_roots",
];

/// What grows in one biome.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Vegetation {
    /// Chance that a 5×5 tree cell of the biome holds a tree, in `[0, 1]`.
    pub trees: f32,
    /// The species with their cumulative shares, the last exactly 1.
    species: Vec<(Species, f32)>,
    /// Ground plants (names from [`PLANTS`]) with their chance per column; the chances sum
    /// to at most 1, and each column draws one number against them in this order.
    pub plants: Vec<(&'static str, f32)>,
    /// Plants of the water (names from [`WATER_PLANTS`]) with their chance per column where
    /// they can grow.
    pub water_plants: Vec<(&'static str, f32)>,
}

impl Vegetation {
    /// The species for a draw in `[0, 1)`: each gets the share of draws its weight says.
    pub fn species(&self, draw: f32) -> Option<Species> {
        self.species.iter().find(|&&(_, upto)| draw < upto).or(self.species.last()).map(|&(s, _)| s)
    }

    /// The chance per column of the water plant `name` (0 where the table has none).
    pub fn water_plant(&self, name: &str) -> f32 {
        self.water_plants.iter().find(|(n, _)| *n == name).map_or(0.0, |&(_, chance)| chance)
    }

    /// The species this biome can grow.
    pub fn all_species(&self) -> impl Iterator<Item = Species> + '_ {
        self.species.iter().map(|&(s, _)| s)
    }
}

/// One biome's table, key by key.
pub(crate) fn parse(body: &Body) -> Result<Vegetation, Mistake> {
    let mut vegetation = Vegetation::default();
    let mut trees_at = None;
    for (key, value) in in_order(body) {
        let wrong =
            |expected: &'static str| (value.span(), Problem::WrongType { key: key.get_ref().clone(), expected });
        match key.get_ref().as_str() {
            "trees" => {
                let chance = number(value.get_ref()).ok_or_else(|| wrong("a number from 0 to 1"))?;
                vegetation.trees = share("trees", chance).map_err(|p| (value.span(), p))?;
                trees_at = Some(value.span());
            }
            "species" => {
                let Value::Table(table) = value.get_ref() else {
                    return Err(wrong("a table of species and weights, such as { oak = 4, birch = 1 }"));
                };
                let mut weights = Vec::new();
                for (name, weight) in table {
                    let species = Species::from_key(name).ok_or_else(|| {
                        let names: Vec<&'static str> = Species::ALL.iter().map(|s| s.key()).collect();
                        let suggestion = suggest_key(name, &names);
                        (value.span(), Problem::UnknownName { what: "species", name: name.clone(), suggestion })
                    })?;
                    let weight = number(weight)
                        .filter(|w| w.is_finite() && *w > 0.0)
                        .ok_or_else(|| wrong("a table of positive weights, such as { oak = 4, birch = 1 }"))?;
                    weights.push((species, weight));
                }
                let total: f64 = weights.iter().map(|w| w.1).sum();
                let mut upto = 0.0;
                vegetation.species = weights
                    .into_iter()
                    .map(|(s, w)| {
                        upto += w / total;
                        (s, upto as f32)
                    })
                    .collect();
                if let Some(last) = vegetation.species.last_mut() {
                    last.1 = 1.0;
                }
            }
            "plants" => {
                let shape = "a table of plants and chances per column, such as { grass = 0.2 }";
                vegetation.plants = chances(value.get_ref(), PLANTS, "plant")
                    .ok_or_else(|| wrong(shape))?
                    .map_err(|p| (value.span(), p))?;
                let total: f64 = vegetation.plants.iter().map(|&(_, c)| f64::from(c)).sum();
                if total > 1.0 + 1e-6 {
                    return Err((value.span(), Problem::PlantsOverOne { total }));
                }
            }
            "water_plants" => {
                let shape = "a table of water plants and chances, such as { seagrass = 0.3 }";
                vegetation.water_plants = chances(value.get_ref(), WATER_PLANTS, "water plant")
                    .ok_or_else(|| wrong(shape))?
                    .map_err(|p| (value.span(), p))?;
                // Seagrass and kelp share a column's draw.
                let floor: f32 = ["seagrass", "kelp"].iter().map(|&n| vegetation.water_plant(n)).sum();
                if floor > 1.0 + 1e-6 {
                    return Err((value.span(), Problem::PlantsOverOne { total: f64::from(floor) }));
                }
            }
            other => {
                let problem = Problem::UnknownKey { key: other.to_string(), suggestion: suggest_key(other, KEYS) };
                return Err((key.span(), problem));
            }
        }
    }
    if let (Some(span), true) = (trees_at, vegetation.trees > 0.0 && vegetation.species.is_empty()) {
        return Err((span, Problem::TreesWithoutSpecies));
    }
    Ok(vegetation)
}

/// A table of names from `known` (a `what`) and their chances, in the table's order: `None`
/// when it is not a table of numbers, a problem for an unknown name or a chance outside 0 … 1.
fn chances(
    value: &Value,
    known: &[&'static str],
    what: &'static str,
) -> Option<Result<Vec<(&'static str, f32)>, Problem>> {
    let Value::Table(table) = value else { return None };
    let mut out = Vec::with_capacity(table.len());
    for (name, chance) in table {
        let chance = number(chance)?;
        let Some(&known_name) = known.iter().find(|&&p| p == name) else {
            let suggestion = suggest_key(name, known);
            return Some(Err(Problem::UnknownName { what, name: name.clone(), suggestion }));
        };
        match share(known_name, chance) {
            Ok(c) => out.push((known_name, c)),
            Err(p) => return Some(Err(p)),
        }
    }
    Some(Ok(out))
}

/// A chance, checked to lie in `[0, 1]`.
fn share(key: &str, chance: f64) -> Result<f32, Problem> {
    if (0.0..=1.0).contains(&chance) {
        Ok(chance as f32)
    } else {
        Err(Problem::BadChance { key: key.to_string(), value: chance })
    }
}

#[cfg(test)]
mod tests {
    use std::path::PathBuf;

    use super::super::per_biome::load_beside_a_fallback as load;
    use super::super::BiomeRules;
    use super::*;

    const RULES: &str = "fallback = \"minecraft:plains\"\n";

    fn error(vegetation: &str) -> String {
        load(vegetation).expect_err("must be rejected")
    }

    #[test]
    fn a_table_gives_trees_species_by_weight_and_plants() {
        let rules = load(
            "[vegetation.\"minecraft:forest\"]\ntrees = 0.5\nspecies = { oak = 3, birch = 1 }\n\
             plants = { grass = 0.25, poppy = 0.01 }\n",
        )
        .expect("loads");
        let forest = rules.vegetation("minecraft:forest").expect("forest has vegetation");
        assert_eq!(forest.trees, 0.5);
        let share = |s: Species| (0..1000).filter(|&i| forest.species(i as f32 / 1000.0) == Some(s)).count();
        assert_eq!((share(Species::Oak), share(Species::Birch)), (750, 250));
        assert!(forest.species(0.999_999_9).is_some(), "every draw below 1 has a species");
        assert_eq!(forest.plants, vec![("grass", 0.25), ("poppy", 0.01)]);
        assert_eq!(forest.water_plant("sugar_cane"), 0.0, "none unless the table says");
        assert!(rules.vegetation("minecraft:desert").is_none(), "no table: nothing grows");
    }

    #[test]
    fn mistakes_name_the_file_line_biome_and_what_is_wrong() {
        let e = error("\n[vegetation.\"minecraft:forset\"]\ntrees = 0.5\n");
        assert!(e.starts_with("b.toml:2: vegetation for \"minecraft:forset\": unknown biome"), "{e}");
        assert!(e.contains("did you mean \"minecraft:forest\""), "{e}");
        let e = error("[vegetation.\"minecraft:forest\"]\ntrees = 0.5\nspecies = { oak = 1, burch = 1 }\n");
        assert!(e.starts_with("b.toml:3: vegetation for \"minecraft:forest\": unknown species \"burch\""), "{e}");
        assert!(e.contains("did you mean \"birch\""), "{e}");
        let e = error("[vegetation.\"minecraft:forest\"]\nplants = { grass = 0.5, dandelon = 0.1 }\n");
        assert!(
            e.contains("b.toml:2:") && e.contains("unknown plant \"dandelon\" (did you mean \"dandelion\"?)"),
            "{e}"
        );
        let e = error("[vegetation.\"minecraft:forest\"]\nplants = { grass = 0.7, fern = 0.6 }\n");
        assert!(e.contains("sum to 1.3"), "{e}");
        let e = error("[vegetation.\"minecraft:forest\"]\n\ntrees = 1.5\n");
        assert!(e.starts_with("b.toml:3:") && e.contains("`trees` must be from 0 to 1, not 1.5"), "{e}");
        let e = error("[vegetation.\"minecraft:forest\"]\ntrees = 0.5\n");
        assert!(e.contains("needs `species`"), "{e}");
        let e = error("[vegetation.\"minecraft:forest\"]\ntres = 0.5\n");
        assert!(e.contains("unknown key `tres` (did you mean `trees`?)"), "{e}");
        let e = error("[vegetation.\"minecraft:ocean\"]\nwater_plants = { seagras = 0.3 }\n");
        assert!(e.contains("unknown water plant \"seagras\" (did you mean \"seagrass\"?)"), "{e}");
        let e = error("[vegetation.\"minecraft:ocean\"]\nwater_plants = { seagrass = 0.7, kelp = 0.6 }\n");
        assert!(e.contains("sum to 1.3"), "{e}");
        let e = error("[vegetation.\"minecraft:forest\"]\nspecies = { oak = 0 }\n");
        assert!(e.contains("positive weights"), "{e}");
        // A biome given twice, in two files, names the first.
        let twice = BiomeRules::from_sources(&[
            (PathBuf::from("a.toml"), format!("{RULES}[vegetation.\"minecraft:forest\"]\ntrees = 0\n")),
            (PathBuf::from("b.toml"), "\n[vegetation.\"minecraft:forest\"]\ntrees = 0\n".to_string()),
        ]);
        let e = twice.expect_err("twice").to_string();
        assert!(e.starts_with("b.toml:2:") && e.contains("already given at a.toml:2"), "{e}");
    }
}
