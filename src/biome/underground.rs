//! Veins of ore and blobs of other rock, as the owner writes them beside the rules: each
//! `[[vein]]` is one of vanilla 1.20.1's ore placements (`worldgen/placed_feature/ore_*.json`)
//! — which block, how many attempts per chunk, the vein's size and the heights it starts at.
//! The shipped `biomes/underground.toml` holds vanilla's own list; a folder without veins has
//! none. Their order matters: each vein's random draws are keyed by its place in the list.

use std::ops::Range;

use toml::Value;
use valence::prelude::BlockState;

use super::error::Problem;
use super::names::suggest_key;
use super::per_biome::{in_order, number, solid_block, Body, Mistake};

/// How a vein's start heights spread.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum VeinHeight {
    /// Uniform between the two Y (inclusive).
    Uniform(i32, i32),
    /// Triangular between the two Y, densest in the middle (vanilla's "trapezoid" with no
    /// plateau); parts outside the world are simply never drawn.
    Triangle(i32, i32),
}

/// One placement of ore or rock.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vein {
    /// The block it places in stone.
    pub block: BlockState,
    /// The block it places in deepslate (the same block for rock blobs).
    pub deepslate: BlockState,
    /// Attempts per chunk (vanilla's `count`); a fraction is the chance of one more.
    pub per_chunk: f32,
    /// Blocks a vein tries to place (vanilla's `size`, 1 … 64).
    pub size: u32,
    /// Where its attempts start.
    pub height: VeinHeight,
    /// Only under ground at least this many metres high (emerald: mountains).
    pub min_elevation_m: f32,
}

/// Every key a vein understands.
const KEYS: &[&str] = &["block", "deepslate", "per_chunk", "size", "uniform", "triangle", "min_elevation_m"];

/// The largest vein size (vanilla's largest, granite's 64).
pub const MAX_SIZE: u32 = 64;

/// The most attempts per chunk a vein may ask for.
const MAX_PER_CHUNK: f64 = 256.0;

/// One `[[vein]]` (whose header is at `header`), key by key.
pub(crate) fn parse(body: &Body, header: Range<usize>) -> Result<Vein, Mistake> {
    let (mut block, mut deepslate, mut per_chunk, mut size, mut height) = (None, None, None, None, None);
    let mut min_elevation_m = f32::NEG_INFINITY;
    for (key, value) in in_order(body) {
        let k = key.get_ref().as_str();
        let wrong = |expected: &'static str| (value.span(), Problem::WrongType { key: k.to_string(), expected });
        match k {
            "block" | "deepslate" => {
                let Value::String(name) = value.get_ref() else {
                    return Err(wrong("a block id such as \"iron_ore\""));
                };
                let found = solid_block(name).map_err(|p| (value.span(), p))?;
                *(if k == "block" { &mut block } else { &mut deepslate }) = Some(found);
            }
            "per_chunk" => {
                let n = number(value.get_ref()).filter(|n| (0.0..=MAX_PER_CHUNK).contains(n));
                per_chunk = Some(n.ok_or_else(|| wrong("a number of attempts from 0 to 256"))? as f32);
            }
            "size" => {
                let n = number(value.get_ref()).filter(|n| n.fract() == 0.0 && (1.0..=f64::from(MAX_SIZE)).contains(n));
                size = Some(n.ok_or_else(|| wrong("a whole number from 1 to 64"))? as u32);
            }
            "uniform" | "triangle" => {
                let shape = "[lowest, highest]: two whole Y, the lowest first";
                let Value::Array(items) = value.get_ref() else { return Err(wrong(shape)) };
                let ys: Vec<i32> = items
                    .iter()
                    .filter_map(|v| number(v).filter(|y| y.fract() == 0.0 && y.abs() <= 4096.0).map(|y| y as i32))
                    .collect();
                let [lo, hi] = ys[..] else { return Err(wrong(shape)) };
                if lo > hi || items.len() != 2 {
                    return Err(wrong(shape));
                }
                if height.is_some() {
                    return Err((key.span(), Problem::TwoHeights));
                }
                height = Some(if k == "uniform" { VeinHeight::Uniform(lo, hi) } else { VeinHeight::Triangle(lo, hi) });
            }
            "min_elevation_m" => {
                let n = number(value.get_ref()).filter(|n| n.is_finite());
                min_elevation_m = n.ok_or_else(|| wrong("a number of metres"))? as f32;
            }
            other => {
                let problem = Problem::UnknownKey { key: other.to_string(), suggestion: suggest_key(other, KEYS) };
                return Err((key.span(), problem));
            }
        }
    }
    let missing = |key: &'static str| (header.clone(), Problem::MissingKey { key });
    let block = block.ok_or_else(|| missing("block"))?;
    Ok(Vein {
        block,
        deepslate: deepslate.unwrap_or(block),
        per_chunk: per_chunk.ok_or_else(|| missing("per_chunk"))?,
        size: size.ok_or_else(|| missing("size"))?,
        height: height.ok_or_else(|| missing("uniform` or `triangle"))?,
        min_elevation_m,
    })
}

#[cfg(test)]
mod tests {
    use super::super::per_biome::load_beside_a_fallback as load;
    use super::*;

    #[test]
    fn veins_load_in_order_with_their_deepslate_forms() {
        let rules = load(
            "[[vein]]\nblock = \"iron_ore\"\ndeepslate = \"deepslate_iron_ore\"\nper_chunk = 10\nsize = 9\n\
             triangle = [-24, 56]\n\n[[vein]]\nblock = \"granite\"\nper_chunk = 0.5\nsize = 64\nuniform = [0, 60]\n\
             min_elevation_m = 100\n",
        )
        .expect("loads");
        let veins = rules.veins();
        assert_eq!(veins.len(), 2);
        assert_eq!((veins[0].block, veins[0].deepslate), (BlockState::IRON_ORE, BlockState::DEEPSLATE_IRON_ORE));
        assert_eq!(veins[0].height, VeinHeight::Triangle(-24, 56));
        assert_eq!(
            (veins[1].deepslate, veins[1].per_chunk, veins[1].min_elevation_m),
            (BlockState::GRANITE, 0.5, 100.0)
        );
        assert!(load("").expect("loads").veins().is_empty(), "no [[vein]]: no veins");
    }

    #[test]
    fn mistakes_name_the_file_line_vein_and_what_is_wrong() {
        let error = |text: &str| load(text).expect_err("must be rejected");
        let base = "[[vein]]\nblock = \"coal_ore\"\nper_chunk = 20\nsize = 17\n";
        let e = error(&format!("{base}uniform = [10, 0]\n"));
        assert!(e.starts_with("b.toml:5: vein #1 (coal_ore): `uniform` must be [lowest, highest]"), "{e}");
        let e = error(&format!("{base}uniform = [0, 10]\ntriangle = [0, 10]\n"));
        assert!(e.contains("b.toml:6:") && e.contains("give `uniform` or `triangle`, not both"), "{e}");
        let e = error(&format!("\n\n{base}"));
        assert!(e.contains("vein #1 (coal_ore): missing `uniform` or `triangle`"), "{e}");
        let e = error("[[vein]]\nblock = \"coal_ore\"\nper_chunk = 20\nsize = 100\nuniform = [0, 1]\n");
        assert!(e.contains("b.toml:4:") && e.contains("`size` must be a whole number from 1 to 64"), "{e}");
        let e = error("[[vein]]\nblock = \"cole_ore\"\n");
        assert!(e.contains("b.toml:2: vein #1: unknown block \"cole_ore\""), "{e}");
        let e = error("[[vein]]\nblock = \"torch\"\n");
        assert!(e.contains("\"torch\" is not a whole, solid block"), "{e}");
        let e = error(&format!("{base}uniform = [0, 10]\n[[vein]]\nblock = \"dirt\"\nsise = 3\n"));
        assert!(e.contains("b.toml:8: vein #2 (dirt): unknown key `sise` (did you mean `size`?)"), "{e}");
    }
}
