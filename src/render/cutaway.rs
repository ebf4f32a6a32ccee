//! The cut-away: a vertical slice through the world along one row of blocks, from the bedrock
//! to the sky — caves, ores, rock blobs, the deepslate transition, lava and water as chunk
//! generation builds them (the server's own chunks, every pass run).
//!
//! Each block is a square of pixels; air under a column's ground (the highest block that is
//! not air or a plant) is a cave and drawn dark, air above it is sky. The legend counts the
//! blocks of each kind in the slice.

use std::collections::HashMap;

use image::{Rgb, RgbImage};
use valence::prelude::{BlockState, Chunk};

use super::biomes::frame;
use super::RenderError;
use crate::biome::BiomeRules;
use crate::chunkgen::{is_plant, BiomePalette, Generator, CHUNK};

/// Widest slice, blocks.
pub const MAX_CUTAWAY_WIDTH: i64 = 1024;
/// Pixels per block side.
const BLOCK_PIXELS: u32 = 3;
/// Blocks of sky kept above the highest ground of the slice.
const SKY_BLOCKS: i32 = 24;

/// One slice to draw: blocks `x0 .. x0 + width` of row `z` (block coordinates).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CutawayRequest {
    /// Block x of the slice's west end.
    pub x0: i64,
    /// Block z of the row sliced.
    pub z: i64,
    /// Width in blocks (1 ..= [`MAX_CUTAWAY_WIDTH`]).
    pub width: i64,
}

/// Draws the slice `req` asks for; `progress(done, total)` counts chunks built.
pub fn render_cutaway(
    generator: &Generator,
    rules: &BiomeRules,
    req: &CutawayRequest,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<RgbImage, RenderError> {
    let (img, counts, top) = slice(generator, rules, req, progress)?;
    let v = generator.vertical();
    let title = [
        format!("cut-away - seed {} - blocks as chunk generation builds them", generator.pipeline().seed()),
        format!(
            "row z {}, x {}..{}; Y {}..{} (deepslate below Y 0, ragged to Y 8); {} px per block",
            req.z,
            req.x0,
            req.x0 + req.width,
            v.min_y,
            v.min_y + top as i32,
            BLOCK_PIXELS
        ),
    ];
    Ok(frame(img, &title, counts, colour))
}

/// The slice's picture (without its legend), the blocks counted by legend entry, and the
/// highest row drawn (counted from the world's floor).
fn slice(
    generator: &Generator,
    rules: &BiomeRules,
    req: &CutawayRequest,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<(RgbImage, HashMap<String, u64>, usize), RenderError> {
    if req.width <= 0 || req.width > MAX_CUTAWAY_WIDTH {
        return Err(RenderError::ViewTooLarge { width: req.width, height: 1, max: MAX_CUTAWAY_WIDTH });
    }
    let palette = BiomePalette::vanilla();
    let v = *generator.vertical();
    let height = v.height as usize;
    let (cz, lz) = (req.z.div_euclid(CHUNK) as i32, req.z.rem_euclid(CHUNK) as u32);
    let (c0, c1) = (req.x0.div_euclid(CHUNK), (req.x0 + req.width - 1).div_euclid(CHUNK));
    // Block names of the slice, column by column, from the floor up.
    let mut names: Vec<Vec<BlockState>> = Vec::with_capacity(req.width as usize);
    for cx in c0..=c1 {
        let chunk = generator.chunk(rules, &palette, cx as i32, cz);
        for lx in 0..CHUNK {
            let x = cx * CHUNK + lx;
            if x < req.x0 || x >= req.x0 + req.width {
                continue;
            }
            names.push((0..height as u32).map(|y| chunk.block_state(lx as u32, y, lz)).collect());
        }
        progress((cx - c0 + 1) as u64, (c1 - c0 + 1) as u64);
    }
    // Each column's ground: its highest block that is neither air nor a plant.
    let solid = |b: &BlockState| !b.is_air() && !is_plant(*b);
    let grounds: Vec<usize> = names.iter().map(|col| col.iter().rposition(solid).unwrap_or(0)).collect();
    let top = (grounds.iter().max().copied().unwrap_or(0) + SKY_BLOCKS as usize).min(height - 1);
    let rows = top + 1;
    let mut img = RgbImage::new(req.width as u32 * BLOCK_PIXELS, rows as u32 * BLOCK_PIXELS);
    let mut counts: HashMap<String, u64> = HashMap::new();
    for (i, col) in names.iter().enumerate() {
        for (y, &block) in col.iter().enumerate().take(rows) {
            let shown = match (block.is_air(), y < grounds[i]) {
                (true, true) => "cave",
                (true, false) => "sky",
                (false, _) => legend_name(block),
            };
            if shown != "sky" {
                *counts.entry(shown.to_string()).or_default() += 1;
            }
            let colour = colour(shown);
            let (px, py) = (i as u32 * BLOCK_PIXELS, (top - y) as u32 * BLOCK_PIXELS);
            for dy in 0..BLOCK_PIXELS {
                for dx in 0..BLOCK_PIXELS {
                    img.put_pixel(px + dx, py + dy, colour);
                }
            }
        }
    }
    Ok((img, counts, top))
}

/// The legend entry a block is counted under: deepslate ores with their ore, logs and leaves
/// as trees, the rest by name.
fn legend_name(block: BlockState) -> &'static str {
    let name = block.to_kind().to_str();
    let ore = name.strip_prefix("deepslate_").filter(|o| o.ends_with("_ore")).unwrap_or(name);
    if ore.ends_with("_log") || ore.ends_with("_leaves") {
        "tree"
    } else if is_plant(block) {
        "plant"
    } else {
        ore
    }
}

/// Colour of a legend entry.
fn colour(name: &str) -> Rgb<u8> {
    Rgb(match name {
        "sky" => [200, 222, 240],
        "cave" => [24, 22, 28],
        "stone" => [125, 125, 125],
        "deepslate" => [72, 72, 78],
        "bedrock" => [20, 20, 20],
        "granite" => [170, 112, 92],
        "diorite" => [205, 205, 205],
        "andesite" => [140, 142, 140],
        "tuff" => [108, 109, 92],
        "gravel" => [136, 126, 125],
        "dirt" | "coarse_dirt" => [134, 96, 67],
        "grass_block" => [104, 160, 72],
        "sand" | "sandstone" => [219, 207, 163],
        "mud" => [60, 57, 60],
        "water" => [63, 118, 228],
        "lava" => [255, 120, 0],
        "coal_ore" => [0, 0, 0],
        "iron_ore" => [216, 175, 147],
        "copper_ore" => [64, 190, 160],
        "gold_ore" => [252, 222, 40],
        "redstone_ore" => [230, 20, 20],
        "lapis_ore" => [30, 60, 220],
        "diamond_ore" => [90, 240, 240],
        "emerald_ore" => [20, 220, 80],
        "tree" => [60, 110, 40],
        "plant" => [120, 190, 90],
        _ => [200, 100, 200],
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::chunkgen::passes::testing;

    #[test]
    fn a_slice_runs_from_bedrock_through_deepslate_and_stone_to_the_sky() {
        let (g, rules) = (testing::generator(), testing::single_biome("minecraft:plains"));
        let req = CutawayRequest { x0: -8, z: 5, width: 20 };
        let (img, counts, top) = slice(&g, &rules, &req, &mut |_, _| {}).expect("a slice");
        assert_eq!(img.width(), 20 * BLOCK_PIXELS);
        assert_eq!(img.height(), (top as u32 + 1) * BLOCK_PIXELS);
        for name in ["bedrock", "deepslate", "stone"] {
            assert!(counts.get(name).is_some_and(|&n| n > 20), "{name}: {counts:?}");
        }
        assert!(!counts.contains_key("sky"), "sky is not counted");
        // The floor is bedrock; the top row is sky.
        let bottom = img.get_pixel(0, img.height() - 1);
        assert_eq!(*bottom, colour("bedrock"));
        assert_eq!(*img.get_pixel(0, 0), colour("sky"));
    }

    #[test]
    fn too_wide_a_slice_is_refused() {
        let (g, rules) = (testing::generator(), testing::single_biome("minecraft:plains"));
        let req = CutawayRequest { x0: 0, z: 0, width: MAX_CUTAWAY_WIDTH + 1 };
        assert!(matches!(slice(&g, &rules, &req, &mut |_, _| {}), Err(RenderError::ViewTooLarge { .. })));
    }

    #[test]
    fn ores_are_counted_with_their_deepslate_variants_and_trees_as_one() {
        assert_eq!(legend_name(BlockState::DEEPSLATE_DIAMOND_ORE), "diamond_ore");
        assert_eq!(legend_name(BlockState::DEEPSLATE), "deepslate");
        assert_eq!(legend_name(BlockState::OAK_LEAVES), "tree");
        assert_ne!(colour("diamond_ore"), colour("lapis_ore"));
        assert_ne!(colour("cave"), colour("sky"));
    }
}
