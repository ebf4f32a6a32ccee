//! The ground each biome shows on dry, gentle land, as the owner writes it beside the rules:
//! `[surface."minecraft:desert"]` gives the top block, the block under it and how deep that
//! lies before stone. Where a table is missing, grass over three blocks of dirt.
//!
//! Only the choice of blocks is data: when the ground is steep (bare stone), snowy, under
//! water, a dry lake bed or badlands' banded terracotta is decided by chunk generation
//! (`chunkgen::surface`), which reads these tables for everything else.

use toml::Value;
use valence::prelude::BlockState;

use super::error::Problem;
use super::names::suggest_key;
use super::per_biome::{in_order, number, solid_block, Body, Mistake};

/// The ground of a biome's dry land, top down.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Surface {
    /// The surface block (`grass_block`).
    pub top: BlockState,
    /// The blocks under it (`dirt`).
    pub filler: BlockState,
    /// How many filler blocks lie between the top and the stone.
    pub depth: i32,
}

impl Surface {
    /// Grass over three blocks of dirt: the ground of a biome without a table.
    pub const DEFAULT: Surface = Surface { top: BlockState::GRASS_BLOCK, filler: BlockState::DIRT, depth: 3 };
}

/// Every key a surface table understands.
const KEYS: &[&str] = &["top", "filler", "depth"];

/// The deepest filler a table may ask for, blocks.
pub const MAX_DEPTH: i32 = 16;

/// One biome's table, key by key; a key left out keeps [`Surface::DEFAULT`]'s.
pub(crate) fn parse(body: &Body) -> Result<Surface, Mistake> {
    let mut surface = Surface::DEFAULT;
    for (key, value) in in_order(body) {
        let wrong =
            |expected: &'static str| (value.span(), Problem::WrongType { key: key.get_ref().clone(), expected });
        match key.get_ref().as_str() {
            "top" | "filler" => {
                let Value::String(name) = value.get_ref() else {
                    return Err(wrong("a block id such as \"grass_block\""));
                };
                let block = solid_block(name).map_err(|p| (value.span(), p))?;
                if key.get_ref() == "top" {
                    surface.top = block;
                } else {
                    surface.filler = block;
                }
            }
            "depth" => {
                let depth = number(value.get_ref())
                    .filter(|d| d.fract() == 0.0 && (0.0..=f64::from(MAX_DEPTH)).contains(d))
                    .ok_or_else(|| wrong("a whole number of blocks from 0 to 16"))?;
                surface.depth = depth as i32;
            }
            other => {
                let problem = Problem::UnknownKey { key: other.to_string(), suggestion: suggest_key(other, KEYS) };
                return Err((key.span(), problem));
            }
        }
    }
    Ok(surface)
}

#[cfg(test)]
mod tests {
    use super::super::per_biome::load_beside_a_fallback as load;
    use super::*;

    #[test]
    fn a_table_sets_the_ground_and_a_biome_without_one_is_grass_over_dirt() {
        let rules = load(
            "[surface.\"minecraft:desert\"]\ntop = \"sand\"\nfiller = \"minecraft:sandstone\"\ndepth = 4\n\n\
                          [surface.\"minecraft:meadow\"]\ntop = \"podzol\"\n",
        )
        .expect("loads");
        let desert = Surface { top: BlockState::SAND, filler: BlockState::SANDSTONE, depth: 4 };
        assert_eq!(rules.surface("minecraft:desert"), desert);
        assert_eq!(rules.surface("minecraft:meadow"), Surface { top: BlockState::PODZOL, ..Surface::DEFAULT });
        assert_eq!(rules.surface("minecraft:plains"), Surface::DEFAULT);
    }

    #[test]
    fn mistakes_name_the_file_line_biome_and_what_is_wrong() {
        let error = |text: &str| load(text).expect_err("must be rejected");
        let e = error("[surface.\"minecraft:desert\"]\n\ntop = \"sandd\"\n");
        assert!(e.starts_with("b.toml:3: surface for \"minecraft:desert\": unknown block \"sandd\""), "{e}");
        let e = error("[surface.\"minecraft:desert\"]\ntop = \"water\"\n");
        assert!(e.contains("\"water\" is not a whole, solid block"), "{e}");
        let e = error("[surface.\"minecraft:desert\"]\nfiller = \"torch\"\n");
        assert!(e.contains("\"torch\" is not a whole, solid block"), "{e}");
        let e = error("[surface.\"minecraft:desert\"]\ndepth = 40\n");
        assert!(e.contains("`depth` must be a whole number of blocks from 0 to 16"), "{e}");
        let e = error("[surface.\"minecraft:desert\"]\ntopp = \"sand\"\n");
        assert!(e.contains("unknown key `topp` (did you mean `top`?)"), "{e}");
        let e = error("[surface.\"minecraft:desrt\"]\ntop = \"sand\"\n");
        assert!(e.contains("did you mean \"minecraft:desert\""), "{e}");
    }
}
