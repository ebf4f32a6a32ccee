//! The biome layer: each pixel coloured by the biome of the ground cell the server would
//! build there (the same `Generator::surface` the end-to-end tests check against a live
//! server), with a legend of the biomes on the map.

use std::collections::HashMap;

use image::{Rgb, RgbImage};

use super::{check, panel, title_lines, RenderError, RenderRequest};
use crate::biome::BiomeRules;
use crate::chunkgen::Generator;
use crate::draw;

/// Map colours of the biomes, close to the ones players know from biome-map tools.
const COLOURS: &[(&str, [u8; 3])] = &[
    ("badlands", [217, 69, 21]),
    ("bamboo_jungle", [118, 142, 20]),
    ("beach", [250, 222, 85]),
    ("birch_forest", [48, 116, 68]),
    ("cherry_grove", [255, 183, 214]),
    ("cold_ocean", [32, 32, 112]),
    ("dark_forest", [64, 81, 26]),
    ("deep_cold_ocean", [32, 32, 56]),
    ("deep_frozen_ocean", [64, 64, 144]),
    ("deep_lukewarm_ocean", [0, 0, 64]),
    ("deep_ocean", [0, 0, 48]),
    ("desert", [250, 148, 24]),
    ("eroded_badlands", [255, 109, 61]),
    ("flower_forest", [45, 142, 73]),
    ("forest", [5, 102, 33]),
    ("frozen_ocean", [112, 112, 214]),
    ("frozen_peaks", [160, 200, 255]),
    ("frozen_river", [160, 160, 255]),
    ("grove", [150, 190, 170]),
    ("ice_spikes", [180, 220, 220]),
    ("jagged_peaks", [220, 220, 240]),
    ("jungle", [83, 123, 9]),
    ("lukewarm_ocean", [0, 0, 144]),
    ("mangrove_swamp", [44, 204, 142]),
    ("meadow", [131, 187, 109]),
    ("ocean", [0, 0, 112]),
    ("old_growth_birch_forest", [88, 156, 108]),
    ("old_growth_pine_taiga", [89, 102, 81]),
    ("old_growth_spruce_taiga", [129, 142, 121]),
    ("plains", [141, 179, 96]),
    ("river", [0, 0, 255]),
    ("savanna", [189, 178, 95]),
    ("savanna_plateau", [167, 157, 100]),
    ("snowy_beach", [250, 240, 192]),
    ("snowy_plains", [255, 255, 255]),
    ("snowy_slopes", [196, 196, 196]),
    ("snowy_taiga", [49, 85, 74]),
    ("sparse_jungle", [98, 139, 23]),
    ("stony_peaks", [123, 143, 116]),
    ("stony_shore", [162, 162, 132]),
    ("sunflower_plains", [181, 219, 136]),
    ("swamp", [7, 249, 178]),
    ("taiga", [11, 102, 89]),
    ("warm_ocean", [0, 0, 172]),
    ("windswept_forest", [34, 85, 28]),
    ("windswept_gravelly_hills", [136, 136, 136]),
    ("windswept_hills", [96, 96, 96]),
    ("windswept_savanna", [229, 218, 135]),
    ("wooded_badlands", [176, 151, 101]),
];

/// The colour of a biome (`"minecraft:plains"`); biomes without a listed colour get a
/// stable colour from their name, so owners' own rules still draw distinguishably.
pub(crate) fn colour(name: &str) -> Rgb<u8> {
    let short = name.strip_prefix("minecraft:").unwrap_or(name);
    match COLOURS.binary_search_by(|(n, _)| n.cmp(&short)) {
        Ok(i) => Rgb(COLOURS[i].1),
        Err(_) => {
            let h = short.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| (h ^ b as u64).wrapping_mul(0x100_0000_01b3));
            Rgb([(h >> 8) as u8 | 0x40, (h >> 24) as u8 | 0x40, (h >> 40) as u8 | 0x40])
        }
    }
}

/// Draws the biome map `req` asks for; `progress(done, total)` counts image rows.
pub fn render_biomes(
    generator: &Generator,
    rules: &BiomeRules,
    req: &RenderRequest,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<RgbImage, RenderError> {
    let (width, height) = check(req)?;
    let mut map = RgbImage::new(width, height);
    let mut counts: HashMap<String, u64> = HashMap::new();
    for py in 0..height {
        let z = req.z0 + py as i64 * req.zoom + req.zoom / 2;
        for px in 0..width {
            let x = req.x0 + px as i64 * req.zoom + req.zoom / 2;
            let biome = generator.surface(rules, x, z).biome;
            map.put_pixel(px, py, colour(&biome));
            *counts.entry(biome).or_default() += 1;
        }
        progress(py as u64 + 1, height as u64);
    }
    let pipeline = generator.pipeline();
    let title = title_lines(req, pipeline.seed(), &pipeline.active_stages(), pipeline.block_metres());
    Ok(frame(map, &title, counts, colour))
}

/// The map above a panel with the title and one swatch per named thing (biome, block),
/// most common first, coloured by `colour`.
pub(crate) fn frame(
    map: RgbImage,
    title: &[String],
    counts: HashMap<String, u64>,
    colour: impl Fn(&str) -> Rgb<u8>,
) -> RgbImage {
    let mut biomes: Vec<(String, u64)> = counts.into_iter().collect();
    biomes.sort_by(|a, b| b.1.cmp(&a.1).then_with(|| a.0.cmp(&b.0)));
    let frame_width = map.width().max(panel::MIN_FRAME_WIDTH);
    let scale = panel::text_scale(frame_width);
    let line = (draw::GLYPH + 4) * scale;
    let column = 34 * draw::GLYPH * scale;
    let per_row = (frame_width / column).max(1) as usize;
    let rows = biomes.len().div_ceil(per_row) as u32;
    let margin = 8 * scale;
    let panel_height = margin + title.len() as u32 * line + margin + rows * line + margin;
    let mut img = RgbImage::from_pixel(frame_width, map.height() + panel_height, panel::BACKGROUND);
    image::imageops::replace(&mut img, &map, 0, 0);
    let ink = Rgb([20, 20, 20]);
    let mut y = (map.height() + margin) as i64;
    for t in title {
        draw::text(&mut img, margin as i64, y, t, scale, ink);
        y += line as i64;
    }
    y += margin as i64;
    let total: u64 = biomes.iter().map(|b| b.1).sum::<u64>().max(1);
    for (i, (name, n)) in biomes.iter().enumerate() {
        let x = (margin + (i % per_row) as u32 * column) as i64;
        let row_y = y + (i / per_row) as i64 * line as i64;
        draw::fill(&mut img, x, row_y, draw::GLYPH * scale, draw::GLYPH * scale, colour(name));
        let label =
            format!("{} {:.1}%", name.strip_prefix("minecraft:").unwrap_or(name), 100.0 * *n as f64 / total as f64);
        draw::text(&mut img, x + (draw::GLYPH * scale + 4 * scale) as i64, row_y, &label, scale, ink);
    }
    img
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_colour_table_is_sorted_and_every_listed_biome_is_distinct() {
        assert!(COLOURS.windows(2).all(|w| w[0].0 < w[1].0), "binary search needs a sorted table");
        assert_eq!(colour("minecraft:plains"), Rgb([141, 179, 96]));
        assert_eq!(colour("minecraft:made_up"), colour("minecraft:made_up"));
        let mut seen: Vec<[u8; 3]> = COLOURS.iter().map(|c| c.1).collect();
        seen.sort();
        seen.dedup();
        assert_eq!(seen.len(), COLOURS.len());
    }

    #[test]
    fn every_biome_the_default_rules_produce_has_a_listed_colour() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("biomes");
        let rules = BiomeRules::load_dir(&dir).expect("shipped rules load");
        for name in rules.biome_names() {
            let short = name.strip_prefix("minecraft:").unwrap_or(name);
            assert!(COLOURS.iter().any(|c| c.0 == short), "{name} has no map colour");
        }
    }

    #[test]
    fn a_biome_map_shows_what_the_server_builds() {
        let config = crate::config::Config::default();
        let pipeline = std::sync::Arc::new(crate::terrain::Pipeline::new(4, &config.terrain()));
        let generator = Generator::new(pipeline, &config);
        let rules = BiomeRules::load_dir(&std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("biomes")).unwrap();
        let req = RenderRequest { x0: -64, z0: 32, width: 64, height: 48, zoom: 8, layer: super::super::Layer::Biome };
        let mut rows = 0;
        let img = render_biomes(&generator, &rules, &req, &mut |d, _| rows = d).unwrap();
        assert_eq!(rows, 6);
        assert!(img.width() >= 8 && img.height() > 6);
        for (px, py) in [(0u32, 0u32), (7, 5), (3, 2)] {
            let (x, z) = (req.x0 + px as i64 * 8 + 4, req.z0 + py as i64 * 8 + 4);
            assert_eq!(*img.get_pixel(px, py), colour(&generator.surface(&rules, x, z).biome));
        }
    }
}
