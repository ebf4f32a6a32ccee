//! The oblique view: a rectangle of the world as a player sees it from above at an angle —
//! every block column a stack of voxels up to its ground (and the sea up to the water top),
//! in a 2:1 dimetric projection from the south-west, painted back to front.
//!
//! The columns are the server's own: [`Generator::surfaces`] gives each column's ground Y and
//! top block exactly as chunk generation builds them, so the picture shows the blocks players
//! walk on (without trees, plants or sea ice). One block up is as long on screen as one block
//! across, as in the game, so the relief reads at the world's own vertical scale.

use std::collections::HashMap;

use image::{Rgb, RgbImage};

use super::biomes::frame;
use super::{ramp, shade, RenderError};
use crate::biome::BiomeRules;
use crate::chunkgen::{Generator, SurfaceSample};
use crate::terrain::Rect;

/// Largest side of an oblique view, blocks: 2048 + 2048 columns already make an image 8192
/// pixels wide at one pixel per half block.
pub const MAX_OBLIQUE_SIDE: i64 = 2048;

/// Rows of columns fetched per query at most; also how often `progress` is called.
const STRIP_ROWS: i64 = 64;

/// Blocks of rock shown under the lowest ground, so every column of the cut-away edges has a
/// visible foot.
const FOOT_BLOCKS: i32 = 4;

/// Target image width, pixels: the block size on screen is chosen to come near it.
const TARGET_WIDTH: i64 = 2048;

/// One oblique view to draw. Coordinates are block coordinates (x east, z south).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ObliqueRequest {
    /// Block x of the rectangle's west edge.
    pub x0: i64,
    /// Block z of the rectangle's north edge.
    pub z0: i64,
    /// Width in blocks (> 0).
    pub width: i64,
    /// Height (north to south) in blocks (> 0).
    pub height: i64,
}

/// What the view needs of one column.
#[derive(Clone, Copy, Debug)]
struct Column {
    /// Block Y of the ground's top block.
    ground: i32,
    /// The top block's colour.
    top: [f32; 3],
    /// The colour of the few blocks under it.
    filler: [f32; 3],
    /// Block Y of the water's top over it (sea, river or lake), or `i32::MIN` where dry.
    water: i32,
}

/// Where the columns land on screen: half a block is `k` pixels, so a block's top is a
/// `4k`×`2k` rhombus and one block up is `2k` pixels.
#[derive(Clone, Copy, Debug)]
struct Projection {
    k: i64,
    /// Block Y drawn as the base of the cut-away edges.
    floor: i32,
    /// Screen y of the centre of column (0, 0)'s top at Y `floor`.
    origin_y: i64,
    width: i64,
    height: i64,
}

impl Projection {
    /// Screen (x of the left corner, y of the centre) of column (`i`, `j`) (offsets east and
    /// south of the north-west corner) whose top is block `y`.
    fn anchor(&self, i: i64, j: i64, y: i32) -> (i64, i64) {
        ((i + j) * 2 * self.k, self.origin_y + (j - i) * self.k - (y - self.floor) as i64 * 2 * self.k)
    }
}

/// Draws the oblique view `req` asks for; `progress(done, total)` counts rows of columns
/// fetched.
pub fn render_oblique(
    generator: &Generator,
    rules: &BiomeRules,
    req: &ObliqueRequest,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<RgbImage, RenderError> {
    check(req)?;
    let mut columns = Vec::with_capacity((req.width * req.height) as usize);
    let mut counts: HashMap<String, u64> = HashMap::new();
    let mut top = 0;
    while top < req.height {
        let rows = STRIP_ROWS.min(req.height - top);
        for s in generator.surfaces(rules, Rect::new(req.z0 + top, req.x0, rows, req.width)) {
            let name = if s.water_y.is_some() { "water" } else { s.top };
            *counts.entry(name.to_string()).or_default() += 1;
            columns.push(column(&s));
        }
        top += rows;
        progress(top as u64, req.height as u64);
    }
    let view = paint(&columns, (req.width, req.height));
    let pipeline = generator.pipeline();
    let v = generator.vertical();
    let title = [
        format!(
            "oblique view from the south-west - seed {} - ground blocks as chunk generation builds them",
            pipeline.seed()
        ),
        format!(
            "x {}..{}, z {}..{} ({}×{} blocks); east runs up-right, south down-right",
            req.x0,
            req.x0 + req.width,
            req.z0,
            req.z0 + req.height,
            req.width,
            req.height
        ),
        format!(
            "1 block up = 1 block across (as in game): {} m per block across, {} m per block up",
            pipeline.block_metres(),
            v.metres_per_block
        ),
    ];
    Ok(frame(view, &title, counts, |name| ramp::to_rgb(block_colour(name))))
}

/// Validates the request.
fn check(req: &ObliqueRequest) -> Result<(), RenderError> {
    if req.width <= 0 || req.height <= 0 {
        return Err(RenderError::BadSize { width: req.width, height: req.height });
    }
    if req.width > MAX_OBLIQUE_SIDE || req.height > MAX_OBLIQUE_SIDE {
        return Err(RenderError::ViewTooLarge { width: req.width, height: req.height, max: MAX_OBLIQUE_SIDE });
    }
    // Columns are queried with a biome cell and a block of border.
    let fits = |start: i64, len: i64| start.checked_sub(8).is_some() && start.checked_add(len + 8).is_some();
    if !(fits(req.x0, req.width) && fits(req.z0, req.height)) {
        return Err(RenderError::OutOfRange { x0: req.x0, z0: req.z0, width: req.width, height: req.height });
    }
    Ok(())
}

fn column(s: &SurfaceSample) -> Column {
    let top = match s.top {
        // Grass and leaves take the biome's tint in game; the plain green stands for it except
        // where the tint differs most.
        "grass_block" => grass(&s.biome),
        name => block_colour(name),
    };
    Column { ground: s.y, top, filler: block_colour(filler(s.top)), water: s.water_y.unwrap_or(i32::MIN) }
}

/// The blocks under a top block, for the cut-away faces.
fn filler(top: &str) -> &'static str {
    match top {
        "grass_block" | "podzol" | "mycelium" | "snow_block" | "coarse_dirt" => "dirt",
        "sand" => "sandstone",
        "red_sand" => "terracotta",
        "powder_snow" => "powder_snow",
        "gravel" => "gravel",
        "mud" => "mud",
        "terracotta" => "terracotta",
        _ => "stone",
    }
}

/// Colours of blocks seen from afar (the average of their textures).
pub(crate) fn block_colour(name: &str) -> [f32; 3] {
    match name.strip_prefix("minecraft:").unwrap_or(name) {
        "grass_block" => [104.0, 160.0, 72.0],
        "dirt" => [134.0, 96.0, 67.0],
        "coarse_dirt" => [119.0, 85.0, 59.0],
        "podzol" => [91.0, 63.0, 24.0],
        "mycelium" => [111.0, 99.0, 105.0],
        "sand" => [219.0, 207.0, 163.0],
        "sandstone" => [216.0, 203.0, 155.0],
        "red_sand" => [190.0, 102.0, 33.0],
        "terracotta" => [152.0, 94.0, 67.0],
        "stone" => [125.0, 125.0, 125.0],
        "gravel" => [136.0, 126.0, 125.0],
        "snow_block" => [240.0, 248.0, 248.0],
        "powder_snow" => [248.0, 253.0, 253.0],
        "mud" => [60.0, 57.0, 60.0],
        "ice" => [145.0, 183.0, 253.0],
        "water" => [63.0, 118.0, 228.0],
        _ => [160.0, 160.0, 160.0],
    }
}

/// Grass colour by biome, as the game tints it (roughly).
fn grass(biome: &str) -> [f32; 3] {
    let b = biome.strip_prefix("minecraft:").unwrap_or(biome);
    if b.contains("savanna") || b.contains("badlands") || b == "desert" {
        [174.0, 164.0, 74.0]
    } else if b.contains("jungle") {
        [89.0, 171.0, 48.0]
    } else if b.contains("swamp") {
        [106.0, 112.0, 57.0]
    } else if b.contains("taiga") || b.contains("snowy") || b == "grove" || b.contains("windswept") {
        [118.0, 160.0, 125.0]
    } else {
        block_colour("grass_block")
    }
}

const WATER_SHALLOW: [f32; 3] = [63.0, 118.0, 228.0];
const WATER_DEEP: [f32; 3] = [28.0, 52.0, 140.0];
const BACKGROUND: Rgb<u8> = Rgb([236, 240, 244]);

/// How much darker the faces turned from the north-west sun are than the tops.
const WEST_FACE: f32 = 0.78;
const SOUTH_FACE: f32 = 0.6;
/// The bottom pixel row of every block on a side face, so single steps read as blocks.
const BLOCK_EDGE: f32 = 0.85;

/// Paints `columns` (`width`×`height`, row-major from the north-west corner) back to front.
fn paint(columns: &[Column], (width, height): (i64, i64)) -> RgbImage {
    let at = |i: i64, j: i64| &columns[(j * width + i) as usize];
    // What hides the ground behind: the ground, or the water surface over it.
    let surface = |i: i64, j: i64| at(i, j).ground.max(at(i, j).water);
    let low = columns.iter().map(|c| c.ground).min().unwrap_or(0) - FOOT_BLOCKS;
    let high = columns.iter().map(|c| c.ground.max(c.water)).max().unwrap_or(0);
    let k = (TARGET_WIDTH / (2 * (width + height))).clamp(1, 4);
    let origin_y = width * k + (high - low) as i64 * 2 * k;
    let p = Projection { k, floor: low, origin_y, width: (width + height) * 2 * k, height: origin_y + height * k + k };
    let mut img = RgbImage::from_pixel(p.width as u32, p.height as u32, BACKGROUND);

    // Far to near: the diagonals of constant j − i, from the north-east corner to the
    // south-west one. Columns on one diagonal do not overlap.
    for d in -(width - 1)..height {
        for i in 0..width {
            let j = i + d;
            if !(0..height).contains(&j) {
                continue;
            }
            let c = at(i, j);
            let clamp = |i: i64, j: i64| surface(i.clamp(0, width - 1), j.clamp(0, height - 1));
            // A face shows down to the top of the column in front of it; at the edges of the
            // rectangle it runs down to the floor (a cut-away, like a block diagram).
            let west_below = if i > 0 { surface(i - 1, j) } else { low };
            let south_below = if j + 1 < height { surface(i, j + 1) } else { low };
            if c.ground >= c.water {
                let light = shade::illumination(
                    clamp(i - 1, j) as f32,
                    clamp(i + 1, j) as f32,
                    clamp(i, j - 1) as f32,
                    clamp(i, j + 1) as f32,
                    1.0,
                    1.0,
                );
                let top = shade::apply(c.top, light, 0.6);
                draw_column(&mut img, &p, (i, j), c, top, (west_below, south_below));
            } else {
                // The sea floor first (seen only through the cut-away faces), then the water.
                let floor_faces = (west_below.min(c.ground), south_below.min(c.ground));
                draw_column(&mut img, &p, (i, j), c, c.top, floor_faces);
                let depth = (c.water - c.ground) as f32;
                let blue = mix(WATER_DEEP, WATER_SHALLOW, (-depth / 24.0).exp());
                // Shallow water shows its floor, as clear water does in game.
                let top = mix(c.top, blue, 1.0 - 0.55 * (-depth / 3.0).exp());
                draw_water(&mut img, &p, (i, j), c.water, top, c.ground, (west_below, south_below));
            }
        }
    }
    img
}

fn mix(a: [f32; 3], b: [f32; 3], t: f32) -> [f32; 3] {
    [0, 1, 2].map(|n| a[n] * (1.0 - t) + b[n] * t)
}

/// Rows of the top rhombus at screen column `col` (0..4k) of a tile: half its height there.
fn half_height(k: i64, col: i64) -> i64 {
    let d = if col < 2 * k { 2 * k - 1 - col } else { col - 2 * k };
    k - d / 2
}

fn put(img: &mut RgbImage, x: i64, y: i64, colour: [f32; 3]) {
    if x >= 0 && y >= 0 && (x as u32) < img.width() && (y as u32) < img.height() {
        img.put_pixel(x as u32, y as u32, ramp::to_rgb(colour));
    }
}

/// Draws a ground column: its top rhombus and its west and south faces down to the tops of
/// the columns in front (`below`: west, south).
fn draw_column(
    img: &mut RgbImage,
    p: &Projection,
    (i, j): (i64, i64),
    c: &Column,
    top: [f32; 3],
    (west_below, south_below): (i32, i32),
) {
    let (left, cy) = p.anchor(i, j, c.ground);
    let block_px = 2 * p.k;
    for col in 0..4 * p.k {
        let hh = half_height(p.k, col);
        let x = left + col;
        for y in cy - hh..cy + hh {
            put(img, x, y, top);
        }
        let (below, face) = if col < 2 * p.k { (west_below, WEST_FACE) } else { (south_below, SOUTH_FACE) };
        let blocks = (c.ground - below).max(0) as i64;
        for n in 0..blocks * block_px {
            // Block 0 is the top block itself, then a few blocks of filler, then stone.
            let b = n / block_px;
            let base = match b {
                0 => c.top,
                1..=3 => c.filler,
                _ => block_colour("stone"),
            };
            let edge = if p.k > 1 && n % block_px == block_px - 1 { BLOCK_EDGE } else { 1.0 };
            put(img, x, cy + hh + n, base.map(|v| v * face * edge));
        }
    }
}

/// Draws the sea over a column whose ground is at `ground`: its surface at `water_top` and,
/// where nothing stands in front, its faces down to the ground, translucent over what is
/// behind.
fn draw_water(
    img: &mut RgbImage,
    p: &Projection,
    (i, j): (i64, i64),
    water_top: i32,
    top: [f32; 3],
    ground: i32,
    (west_below, south_below): (i32, i32),
) {
    let (left, cy) = p.anchor(i, j, water_top);
    for col in 0..4 * p.k {
        let hh = half_height(p.k, col);
        let x = left + col;
        for y in cy - hh..cy + hh {
            put(img, x, y, top);
        }
        let (below, face) = if col < 2 * p.k { (west_below, WEST_FACE) } else { (south_below, SOUTH_FACE) };
        let blocks = (water_top - below.max(ground)).max(0) as i64;
        for n in 0..blocks * 2 * p.k {
            let y = cy + hh + n;
            if x >= 0 && y >= 0 && (x as u32) < img.width() && (y as u32) < img.height() {
                let behind = img.get_pixel(x as u32, y as u32).0.map(f32::from);
                put(img, x, y, mix(behind, WATER_SHALLOW.map(|v| v * face), 0.7));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn land(ground: i32, name: &str) -> Column {
        // The sea's water top at the default vertical scale, over ground below it.
        let water = if ground < 62 { 62 } else { i32::MIN };
        Column { ground, top: block_colour(name), filler: block_colour(filler(name)), water }
    }

    #[test]
    fn a_flat_square_fills_its_rhombus_without_gaps() {
        let cols = vec![land(70, "grass_block"); 16 * 16];
        let img = paint(&cols, (16, 16));
        let k = (TARGET_WIDTH / 64).clamp(1, 4);
        assert_eq!(img.width() as i64, 32 * 2 * k);
        // The row through the west and east corners of the square's top crosses the tops of
        // the columns on the north-west / south-east diagonal: grass all the way across.
        let p = Projection {
            k,
            floor: 70 - FOOT_BLOCKS,
            origin_y: 16 * k + FOOT_BLOCKS as i64 * 2 * k,
            width: 0,
            height: 0,
        };
        let (_, y) = p.anchor(0, 0, 70);
        let grass = ramp::to_rgb(block_colour("grass_block"));
        assert!((0..img.width()).all(|x| *img.get_pixel(x, y as u32) == grass), "a gap in the top");
    }

    #[test]
    fn a_tall_column_hides_what_is_behind_it_and_faces_are_darker_than_tops() {
        // 8×8 flat stone with one snow pillar 20 blocks higher in the middle.
        let mut cols = vec![land(64, "stone"); 64];
        cols[4 * 8 + 4] = land(84, "snow_block");
        let img = paint(&cols, (8, 8));
        let flat = paint(&[land(64, "stone"); 64], (8, 8));
        assert_eq!(img.dimensions().0, flat.dimensions().0);
        let snow = ramp::to_rgb(block_colour("snow_block"));
        let whiteish = |p: &Rgb<u8>| p[0] > 200 && p[1] > 200 && p[2] > 200;
        assert!(img.pixels().any(|p| p == &snow || whiteish(p)), "the pillar's top shows");
        // The pillar's south face is snow (its top block) darkened.
        let dark_snow = ramp::to_rgb(block_colour("snow_block").map(|v| v * SOUTH_FACE));
        assert!(img.pixels().any(|p| *p == dark_snow), "the pillar's south face shows, darker");
        // The column behind it (north-east, drawn earlier) is covered where the pillar stands:
        // fewer stone-top pixels than the flat square shows.
        let stone_tops = |im: &RgbImage| im.pixels().filter(|p| **p == ramp::to_rgb(block_colour("stone"))).count();
        assert!(stone_tops(&img) < stone_tops(&flat), "the pillar hides the tops behind it");
    }

    #[test]
    fn a_river_above_the_sea_is_drawn_as_water() {
        let mut cols = vec![land(70, "grass_block"); 8 * 8];
        for c in cols.iter_mut().skip(3 * 8).take(8) {
            *c = Column { water: 70, ..land(68, "gravel") };
        }
        let img = paint(&cols, (8, 8));
        let blue = img.pixels().filter(|p| p[2] as i32 > p[0] as i32 + 60 && p[2] as i32 > p[1] as i32 + 30).count();
        assert!(blue > 20, "only {blue} blue pixels for a river");
    }

    #[test]
    fn sea_columns_are_blue_and_deep_water_is_darker() {
        let mut cols = vec![land(40, "gravel"); 8 * 8];
        for c in cols.iter_mut().take(8) {
            *c = land(61, "sand"); // a shallow northern row
        }
        let img = paint(&cols, (8, 8));
        let blue = img.pixels().filter(|p| p[2] as i32 > p[0] as i32 + 60 && p[2] as i32 > p[1] as i32 + 30).count();
        assert!(blue > img.pixels().count() / 10, "only {blue} blue pixels");
    }

    #[test]
    fn a_view_of_the_generated_world_is_deterministic_and_drawn() {
        let config = crate::config::Config::default();
        let pipeline = std::sync::Arc::new(crate::terrain::Pipeline::new(4, &config.terrain()));
        let generator = Generator::new(pipeline, &config);
        let rules = BiomeRules::load_dir(&std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("biomes")).unwrap();
        let req = ObliqueRequest { x0: -20, z0: 9, width: 24, height: 40 };
        let mut rows = 0;
        let a = render_oblique(&generator, &rules, &req, &mut |d, _| rows = d).unwrap();
        let b = render_oblique(&generator, &rules, &req, &mut |_, _| {}).unwrap();
        assert_eq!(rows, 40);
        assert!(a == b, "two renders differ");
        let drawn = a.pixels().filter(|p| **p != BACKGROUND && **p != super::super::panel::BACKGROUND).count();
        assert!(drawn > 64 * 64, "only {drawn} pixels drawn");
        let err = render_oblique(&generator, &rules, &ObliqueRequest { width: 0, ..req }, &mut |_, _| {});
        assert!(matches!(err, Err(RenderError::BadSize { .. })));
    }

    #[test]
    fn block_colours_are_distinct_for_the_common_tops() {
        let names = ["grass_block", "sand", "stone", "snow_block", "water", "gravel", "red_sand", "terracotta"];
        for (a, na) in names.iter().enumerate() {
            for nb in &names[a + 1..] {
                assert_ne!(block_colour(na), block_colour(nb), "{na} vs {nb}");
            }
        }
    }
}
