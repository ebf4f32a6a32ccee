//! Whole-chunk tests: chunks agree with the per-column surface function (which queries the
//! pipeline over different rectangles, so this is also the seam test), are deterministic,
//! and are layered as documented.

use std::sync::Arc;

use valence::prelude::{Biome, BiomeRegistry, BlockState, Chunk, Ident, UnloadedChunk};

use super::passes::testing;
use super::*;
use crate::biome::BiomeRules;
use crate::terrain::pipeline::channel;
use crate::terrain::Rect;

fn rules() -> BiomeRules {
    testing::rules()
}

fn palette() -> BiomePalette {
    let mut registry = BiomeRegistry::default();
    for name in vanilla_biome_names() {
        if let Ok(ident) = Ident::new(name) {
            registry.insert(ident, Biome::default());
        }
    }
    BiomePalette::from_registry(&registry)
}

fn generator(seed: u64) -> Generator {
    let mut config = Config::default();
    config.world.seed = seed;
    Generator::new(Arc::new(Pipeline::new(seed, &config.terrain())), &config)
}

fn is_tree(b: BlockState) -> bool {
    super::trees::is_tree_part(b)
}

/// Highest ground block of a chunk column (not air, not tree, not plant): (world Y, block).
fn top(chunk: &UnloadedChunk, v: &Vertical, lx: u32, lz: u32) -> (i32, BlockState) {
    (0..chunk.height())
        .rev()
        .map(|y| (y, chunk.block_state(lx, y, lz)))
        .find(|(_, b)| !b.is_air() && !is_tree(*b) && !is_plant(*b))
        .map_or((v.min_y, BlockState::AIR), |(y, b)| (y as i32 + v.min_y, b))
}

/// Highest ground block of a chunk column under any water and what grows in it: (world Y,
/// block).
fn ground(chunk: &UnloadedChunk, v: &Vertical, lx: u32, lz: u32) -> (i32, BlockState) {
    let wet = |b: BlockState| b.is_liquid() || b == BlockState::ICE || super::passes::is_sea_growth(b);
    (0..chunk.height())
        .rev()
        .map(|y| (y, chunk.block_state(lx, y, lz)))
        .find(|(_, b)| !b.is_air() && !is_tree(*b) && !is_plant(*b) && !wet(*b))
        .map_or((v.min_y, BlockState::AIR), |(y, b)| (y as i32 + v.min_y, b))
}

#[test]
fn chunks_agree_with_the_surface_function_across_chunk_borders() {
    let (g, rules, palette) = (generator(11), rules(), palette());
    let v = *g.vertical();
    for (cx, cz) in [(0, 0), (1, 0), (-1, -1)] {
        let chunk = g.chunk(&rules, &palette, cx, cz);
        for lz in 0..16u32 {
            for lx in 0..16u32 {
                let (x, z) = (i64::from(cx) * 16 + i64::from(lx), i64::from(cz) * 16 + i64::from(lz));
                let s = g.surface(&rules, x, z);
                let (top_y, top_block) = top(&chunk, &v, lx, lz);
                let (ground_y, ground_block) = ground(&chunk, &v, lx, lz);
                assert_eq!(ground_y, s.y, "column ({x}, {z})");
                assert_eq!(ground_block.to_kind().to_str(), s.top, "column ({x}, {z})");
                if s.y < v.water_top_y() {
                    assert_eq!(top_y, v.water_top_y(), "sea column ({x}, {z})");
                    assert!(matches!(top_block, BlockState::WATER | BlockState::ICE));
                }
                let cell_y = ((s.y - v.min_y) / 4) as u32;
                assert_eq!(chunk.biome(lx / 4, cell_y, lz / 4), palette.id(&s.biome), "biome at ({x}, {}, {z})", s.y);
            }
        }
    }
}

#[test]
fn chunks_are_deterministic() {
    let (rules, palette) = (rules(), palette());
    let a = generator(5).chunk(&rules, &palette, 3, -2);
    let b = generator(5).chunk(&rules, &palette, 3, -2);
    for y in 0..a.height() {
        for z in 0..16 {
            for x in 0..16 {
                assert_eq!(a.block_state(x, y, z), b.block_state(x, y, z));
            }
        }
    }
    for y in 0..a.height() / 4 {
        for z in 0..4 {
            for x in 0..4 {
                assert_eq!(a.biome(x, y, z), b.biome(x, y, z));
            }
        }
    }
}

#[test]
fn columns_are_bedrock_then_deepslate_then_stone_under_the_ground() {
    let g = generator(3);
    let v = *g.vertical();
    let chunk = g.chunk(&rules(), &palette(), 0, 0);
    for (lx, lz) in [(0, 0), (7, 9), (15, 15)] {
        let at = |y: i32| chunk.block_state(lx, (y - v.min_y) as u32, lz);
        assert_eq!(at(v.min_y), BlockState::BEDROCK);
        assert!(matches!(at(v.min_y + 1), BlockState::BEDROCK | BlockState::DEEPSLATE));
        assert_eq!(at(v.min_y + 5), BlockState::DEEPSLATE);
        assert_eq!(at(-1), BlockState::DEEPSLATE);
        assert_eq!(at(0), BlockState::DEEPSLATE);
        assert_eq!(at(8), BlockState::STONE);
    }
}

#[test]
fn biomes_vary_with_height_as_the_air_cools() {
    let (g, rules, palette) = (generator(2), rules(), palette());
    let chunk = g.chunk(&rules, &palette, 0, 0);
    let top_cell = chunk.height() / 4 - 1;
    let snowy = palette.id("minecraft:snowy_plains");
    // 6.5 °C/km over the 6 km of air above the sea: the highest cells are always cold.
    for z in 0..4 {
        for x in 0..4 {
            assert_eq!(chunk.biome(x, top_cell, z), snowy, "cell ({x}, {z})");
        }
    }
    let distinct: std::collections::HashSet<_> = (0..=top_cell).map(|y| chunk.biome(1, y, 1)).collect();
    assert!(distinct.len() >= 2, "one biome from bedrock to sky: {distinct:?}");
}

/// Checks the column at chunk-local (`lx`, `lz`) of the chunk at (`cx`, `cz`), whose
/// pipeline values `columns` holds: a sea column (elevation below 0 m) has its ground under
/// the water top, then water up to the water top, which is ice exactly where the column is
/// colder than [`surface::SEA_ICE_C`], then air; a land column has dry ground above the sea.
/// Returns whether the sea column froze (`None` for land).
fn check_sea_column(
    chunk: &UnloadedChunk,
    columns: &Columns,
    v: &Vertical,
    (cx, cz): (i32, i32),
    (lx, lz): (u32, u32),
) -> Option<bool> {
    let (x, z) = (i64::from(cx) * 16 + i64::from(lx), i64::from(cz) * 16 + i64::from(lz));
    let at = |y: i32| chunk.block_state(lx, (y - v.min_y) as u32, lz);
    let (ground_y, ground) = top(chunk, v, lx, lz);
    let elevation = columns.elevation(x, z);
    if elevation >= 0.0 {
        if columns.is_wet(x, z) {
            return None; // a river or lake (tests in water_tests.rs)
        }
        assert!(ground_y >= v.sea_level_y && !ground.is_liquid(), "land ({x}, {z}) at {elevation} m: {ground:?}");
        return None;
    }
    let floor_y = columns.surface_y(x, z);
    assert!(floor_y < v.water_top_y(), "sea ({x}, {z}) at {elevation} m has its ground at Y {floor_y}");
    assert!(!at(floor_y).is_air() && !at(floor_y).is_liquid(), "sea floor ({x}, {z}): {:?}", at(floor_y));
    for y in floor_y + 1..v.water_top_y() {
        let b = at(y);
        let growing = super::passes::is_sea_growth(b);
        assert!(b == BlockState::WATER || growing, "sea ({x}, {y}, {z}) at {elevation} m: {b:?}");
    }
    let frozen = columns.get(channel::TEMPERATURE, x, z) < surface::SEA_ICE_C;
    let want = if frozen { BlockState::ICE } else { BlockState::WATER };
    assert_eq!(at(v.water_top_y()), want, "sea surface ({x}, {z}) at {elevation} m");
    assert_eq!(ground_y, v.water_top_y(), "({x}, {z}): something stands on the sea");
    assert!(at(v.sea_level_y).is_air(), "({x}, {z}): {:?} above the sea", at(v.sea_level_y));
    Some(frozen)
}

/// Checks every column of the `n`×`n` chunks from (`cx0`, `cz0`) with [`check_sea_column`];
/// returns how many were (land, open sea, frozen sea).
fn check_sea(g: &Generator, rules: &BiomeRules, (cx0, cz0): (i32, i32), n: i32) -> (usize, usize, usize) {
    let (v, palette) = (*g.vertical(), palette());
    let (mut land, mut open, mut frozen) = (0, 0, 0);
    for cz in cz0..cz0 + n {
        for cx in cx0..cx0 + n {
            let chunk = g.chunk(rules, &palette, cx, cz);
            let rect = Rect::new(i64::from(cz) * 16, i64::from(cx) * 16, 16, 16);
            let columns = Columns::query(g.pipeline(), &v, rect);
            for lz in 0..16 {
                for lx in 0..16 {
                    match check_sea_column(&chunk, &columns, &v, (cx, cz), (lx, lz)) {
                        None => land += 1,
                        Some(false) => open += 1,
                        Some(true) => frozen += 1,
                    }
                }
            }
        }
    }
    (land, open, frozen)
}

#[test]
fn the_sea_is_water_up_to_the_water_top_and_frozen_where_cold() {
    // A deep-sea chunk of seed 1 that the 0 °C line of the sea surface crosses: some of its
    // columns freeze, the others stay open. Searched for near the place where it lay at
    // 125 m/block (the layout and climate live in metres, so it moves with the scale).
    let g = generator(1);
    let v = *g.vertical();
    let guess = at_scale(&g, (0, -1192));
    let chunk = find_chunks(guess, 200, 1, |rect| {
        let columns = Columns::query(g.pipeline(), &v, rect);
        let (mut open, mut frozen) = (0, 0);
        for (x, z) in rect_columns(rect) {
            if columns.elevation(x, z) > -200.0 {
                return false;
            }
            let cold = columns.get(channel::TEMPERATURE, x, z) < surface::SEA_ICE_C;
            (frozen, open) = (frozen + usize::from(cold), open + usize::from(!cold));
        }
        open > 0 && frozen > 0
    })
    .expect("no deep-sea chunk on the 0 °C line near the old one");
    let (land, open, frozen) = check_sea(&g, &rules(), chunk, 1);
    assert_eq!(land, 0);
    assert!(open > 0 && frozen > 0, "{open} open and {frozen} frozen sea columns: pick a chunk on the 0 °C line");
}

#[test]
fn every_sea_column_is_under_water_even_the_shallowest() {
    // 3×3 chunks of seed 1's coast: shallows, beach and land (before the sea fix, ground at
    // −60 m .. 0 m lay dry at the water top), searched for near where they lay at 125 m/block.
    let g = generator(1);
    let v = *g.vertical();
    // (land, sea, shallow sea) columns of a rectangle, by the pipeline's elevation.
    let kinds = |rect: Rect| {
        let columns = Columns::query(g.pipeline(), &v, rect);
        let e: Vec<f32> = rect_columns(rect).map(|(x, z)| columns.elevation(x, z)).collect();
        let count = |f: fn(f32) -> bool| e.iter().filter(|&&e| f(e)).count();
        (count(|e| e >= 0.0), count(|e| e < 0.0), count(|e| e > -60.0 && e < 0.0))
    };
    let corner = find_chunks(at_scale(&g, (13, 2)), 60, 3, |rect| {
        let (land, sea, shallow) = kinds(rect);
        land > 300 && sea > 300 && shallow > 200
    })
    .expect("no coast with shallows near the old one");
    let shallow = kinds(chunk_rect(corner, 3)).2;
    let (land, open, _) = check_sea(&g, &rules(), corner, 3);
    assert!(land > 100 && open > 100 && shallow > 100, "{land} land, {open} sea, {shallow} shallow columns");
}

#[test]
fn woodland_grows_trees_that_stand_on_the_ground() {
    let rules = single_biome("forest");
    let (g, palette) = (generator(4), palette());
    let v = *g.vertical();
    let land = land_chunks(&g, &rules, 8);
    let mut trunks = 0;
    for &(cx, cz) in &land {
        let chunk = g.chunk(&rules, &palette, cx, cz);
        for lz in 0..16u32 {
            for lx in 0..16u32 {
                let (ground_y, ground) = top(&chunk, &v, lx, lz);
                let above = chunk.block_state(lx, (ground_y + 1 - v.min_y) as u32, lz);
                if above.to_kind().to_str().ends_with("_log") {
                    trunks += 1;
                    assert_eq!(ground, BlockState::GRASS_BLOCK, "a trunk on {ground:?}");
                }
            }
        }
    }
    // 70 % of the 5×5 cells of 8 land chunks: about 50 trees, fewer on steep or wet ground.
    assert!(trunks >= 10, "only {trunks} trees in 8 forest chunks");
}

fn single_biome(biome: &str) -> BiomeRules {
    testing::single_biome(&format!("minecraft:{biome}"))
}

/// `n` land chunks near the world's spawn (the origin may be open sea), well above the sea.
fn land_chunks(g: &Generator, rules: &BiomeRules, n: usize) -> Vec<(i32, i32)> {
    let v = *g.vertical();
    let spawn = crate::world::find_spawn(g, rules).block;
    let centre = (spawn.x.div_euclid(16), spawn.z.div_euclid(16));
    let land: Vec<(i32, i32)> = (0..30)
        .flat_map(|ring| ring_chunks(centre, ring))
        .filter(|&(cx, cz)| g.surface(rules, i64::from(cx) * 16 + 8, i64::from(cz) * 16 + 8).y > v.sea_level_y + 2)
        .take(n)
        .collect();
    assert_eq!(land.len(), n, "not enough land near the spawn {spawn:?}");
    land
}

/// The chunks on the square ring `ring` chunks from `centre`.
fn ring_chunks((cx, cz): (i32, i32), ring: i32) -> impl Iterator<Item = (i32, i32)> {
    (-ring..=ring)
        .flat_map(move |dz| (-ring..=ring).map(move |dx| (dx, dz)))
        .filter(move |&(dx, dz)| dx.abs().max(dz.abs()) == ring)
        .map(move |(dx, dz)| (cx + dx, cz + dz))
}

/// The block rectangle of the `n`×`n` chunks from chunk `corner`.
fn chunk_rect((cx, cz): (i32, i32), n: i32) -> Rect {
    Rect::new(i64::from(cz) * 16, i64::from(cx) * 16, 16 * i64::from(n), 16 * i64::from(n))
}

/// Every (x, z) column of `rect`.
fn rect_columns(rect: Rect) -> impl Iterator<Item = (i64, i64)> {
    (rect.y0..rect.y0 + rect.h).flat_map(move |z| (rect.x0..rect.x0 + rect.w).map(move |x| (x, z)))
}

/// The chunk that lay at `chunk` at the old fixed 125 m/block, at `g`'s scale (same metres).
fn at_scale(g: &Generator, (cx, cz): (i32, i32)) -> (i32, i32) {
    let k = 125.0 / g.pipeline().block_metres();
    ((f64::from(cx) * k).round() as i32, (f64::from(cz) * k).round() as i32)
}

/// The corner of the nearest `n`×`n` chunks to `centre` (within `radius` rings) whose block
/// rectangle satisfies `want`: lets a test find the sea, coast or climate it needs wherever the
/// scale puts it, instead of hard-coding a place.
fn find_chunks(centre: (i32, i32), radius: i32, n: i32, want: impl Fn(Rect) -> bool) -> Option<(i32, i32)> {
    (0..=radius).flat_map(|ring| ring_chunks(centre, ring)).find(|&c| want(chunk_rect(c, n)))
}

/// The plant blocks standing on the ground of a chunk column, bottom up.
fn plant_on(chunk: &UnloadedChunk, v: &Vertical, lx: u32, lz: u32) -> Vec<BlockState> {
    let (ground_y, _) = top(chunk, v, lx, lz);
    ((ground_y + 1 - v.min_y) as u32..chunk.height())
        .map(|y| chunk.block_state(lx, y, lz))
        .take_while(|&b| is_plant(b))
        .collect()
}

#[test]
fn vegetation_matches_the_per_column_function_across_chunk_borders() {
    for (biome, seed) in [("plains", 4), ("desert", 6)] {
        let (g, rules, palette) = (generator(seed), single_biome(biome), palette());
        let v = *g.vertical();
        let mut plants = 0;
        for (cx, cz) in land_chunks(&g, &rules, 2) {
            let chunk = g.chunk(&rules, &palette, cx, cz);
            let again = g.chunk(&rules, &palette, cx, cz);
            for lz in 0..16u32 {
                for lx in 0..16u32 {
                    let (x, z) = (i64::from(cx) * 16 + i64::from(lx), i64::from(cz) * 16 + i64::from(lz));
                    let seen = plant_on(&chunk, &v, lx, lz);
                    assert_eq!(seen, plant_on(&again, &v, lx, lz), "not deterministic at ({x}, {z})");
                    plants += usize::from(!seen.is_empty());
                    // Queried over a different rectangle of the pipeline; trees may crowd
                    // plants out, but never add any.
                    let alone = g.plant_blocks(&rules, x, z);
                    if g.clear_of_trees(&rules, x, z) {
                        assert_eq!(seen, alone, "{biome} column ({x}, {z})");
                    } else {
                        assert!(seen.is_empty() || seen == alone, "{biome} column ({x}, {z})");
                    }
                }
            }
        }
        assert!(plants > 0, "no plants in two {biome} chunks");
    }
}

#[test]
fn deserts_grow_cacti_and_dead_bushes_and_no_cactus_touches_a_block() {
    let (g, rules, palette) = (generator(6), single_biome("desert"), palette());
    let v = *g.vertical();
    let (cx, cz) = land_chunks(&g, &rules, 1)[0];
    // A 3×3 block of chunks, read as one area, so neighbours across borders are checked too.
    let chunks: Vec<Vec<UnloadedChunk>> =
        (-1..=1).map(|dz| (-1..=1).map(|dx| g.chunk(&rules, &palette, cx + dx, cz + dz)).collect()).collect();
    let (x0, z0) = (i64::from(cx - 1) * 16, i64::from(cz - 1) * 16);
    let at = |x: i64, y: i32, z: i64| {
        let (ox, oz) = (x - x0, z - z0);
        chunks[(oz / 16) as usize][(ox / 16) as usize].block_state(
            (ox % 16) as u32,
            (y - v.min_y) as u32,
            (oz % 16) as u32,
        )
    };
    let (mut cacti, mut bushes) = (0, 0);
    for x in x0 + 1..x0 + 47 {
        for z in z0 + 1..z0 + 47 {
            for y in v.min_y..v.min_y + v.height {
                let b = at(x, y, z);
                assert!(
                    !matches!(b, BlockState::GRASS | BlockState::TALL_GRASS | BlockState::FERN),
                    "grass in a desert"
                );
                if b == BlockState::DEAD_BUSH {
                    bushes += 1;
                }
                if b == BlockState::CACTUS {
                    cacti += 1;
                    for (dx, dz) in [(1, 0), (-1, 0), (0, 1), (0, -1)] {
                        let n = at(x + dx, y, z + dz);
                        assert!(n.is_air(), "cactus at ({x}, {y}, {z}) touches {n:?}");
                    }
                    let below = at(x, y - 1, z);
                    assert!(matches!(below, BlockState::SAND | BlockState::CACTUS), "cactus on {below:?}");
                }
            }
        }
    }
    assert!(cacti > 0 && bushes > 0, "{cacti} cactus blocks and {bushes} dead bushes in 9 desert chunks");
}

#[test]
fn plains_grow_grass_and_flowers_and_plants_let_the_sky_light_through() {
    let (g, rules, palette) = (generator(4), single_biome("plains"), palette());
    let v = *g.vertical();
    let (mut grass, mut flowers) = (0, 0);
    for (cx, cz) in land_chunks(&g, &rules, 2) {
        let chunk = g.chunk(&rules, &palette, cx, cz);
        let light = Light::of(&chunk);
        for lz in 0..16u32 {
            for lx in 0..16u32 {
                let seen = plant_on(&chunk, &v, lx, lz);
                match seen.first() {
                    Some(&BlockState::GRASS) => grass += 1,
                    Some(b) if matches!(b.to_kind().to_str(), "dandelion" | "poppy" | "cornflower" | "oxeye_daisy") => {
                        flowers += 1
                    }
                    _ => {}
                }
                if !seen.is_empty() {
                    let (ground_y, ground) = top(&chunk, &v, lx, lz);
                    assert!(!matches!(ground, BlockState::SNOW_BLOCK | BlockState::STONE | BlockState::WATER));
                    let above = (ground_y + 1 - v.min_y) as u32;
                    let covered = (above..chunk.height()).any(|y| is_tree(chunk.block_state(lx, y, lz)));
                    if !covered {
                        assert_eq!(light.sky(lx, above, lz), 15, "a plant shades ({lx}, {lz}) of ({cx}, {cz})");
                    }
                }
            }
        }
    }
    assert!(grass > 20 && flowers > 0, "{grass} grass and {flowers} flowers in two plains chunks");
}

#[test]
fn timed_chunks_are_the_same_chunks_and_time_every_pass_in_order() {
    let (g, rules, palette) = (generator(8), rules(), palette());
    let (timed, timings) = g.chunk_timed(&rules, &palette, -2, 5);
    let plain = g.chunk(&rules, &palette, -2, 5);
    let names: Vec<&str> = timings.iter().map(|t| t.name).collect();
    assert_eq!(names, passes::PASSES.iter().map(|p| p.name).collect::<Vec<_>>());
    let want = ["columns", "rock", "water", "caves", "ores", "surface", "vegetation", "aquatic", "icebergs", "snow"];
    assert_eq!(names, want);
    assert!(timings.iter().any(|t| t.nanos > 0));
    for y in 0..plain.height() {
        for z in 0..16 {
            for x in 0..16 {
                assert_eq!(timed.block_state(x, y, z), plain.block_state(x, y, z));
            }
        }
    }
}

/// Seed 1's generator at `metres_per_block`, with the shipped biome rules.
fn generator_at(metres_per_block: f64) -> (Generator, BiomeRules) {
    let mut config = Config::default();
    config.world.metres_per_block = metres_per_block;
    let g = Generator::new(Arc::new(Pipeline::new(config.world.seed, &config.terrain())), &config);
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("biomes");
    (g, BiomeRules::load_dir(&dir).expect("the shipped rules load"))
}

#[test]
fn at_30_40_and_125_metres_per_block_spawn_climate_rock_trees_and_biomes_still_behave() {
    for scale in [30.0, 40.0, 125.0] {
        let (g, rules) = generator_at(scale);
        let v = *g.vertical();
        // Spawn: dry land above the sea.
        let spawn = crate::world::find_spawn(&g, &rules).block;
        let at_spawn = g.surface(&rules, i64::from(spawn.x), i64::from(spawn.z));
        assert!(at_spawn.y > v.sea_level_y && at_spawn.top != "water", "{scale} m: spawn {spawn:?} {at_spawn:?}");
        // The high range of the default world (the same metres at every scale): rock on its
        // steep faces, plants on its gentler ground, colder on the heights.
        let block = |m: f64| (m / scale).round() as i64;
        let range = Rect::new(block(-271_360.0) - 64, block(291_840.0) - 64, 128, 128);
        let tops = g.surfaces(&rules, range);
        let count = |names: &[&str]| tops.iter().filter(|s| names.contains(&s.top)).count();
        let rock = count(&["stone", "andesite", "gravel", "terracotta", "snow_block", "powder_snow"]);
        let green = count(&["grass_block", "podzol", "coarse_dirt", "mud"]);
        assert!(rock > 100 && green > 100, "{scale} m: {rock} rock and {green} green tops in the range");
        let columns = Columns::query(g.pipeline(), &v, range);
        let (high, low) = rect_columns(range).fold(((f32::MIN, 0.0), (f32::MAX, 0.0)), |(hi, lo), (x, z)| {
            let (e, t) = (columns.elevation(x, z), columns.get(channel::TEMPERATURE, x, z));
            (if e > hi.0 { (e, t) } else { hi }, if e < lo.0 { (e, t) } else { lo })
        });
        assert!(high.0 - low.0 > 500.0 && high.1 < low.1 - 2.0, "{scale} m: {low:?} .. {high:?} (m, °C)");
        // Biomes vary over ~100 km around the spawn, and forests grow trees.
        let step = block(12_000.0);
        let biomes: std::collections::HashSet<String> = (-4..=4)
            .flat_map(|i| (-4..=4).map(move |j| (i, j)))
            .map(|(i, j)| g.surface(&rules, i64::from(spawn.x) + i * step, i64::from(spawn.z) + j * step).biome)
            .collect();
        assert!(biomes.len() >= 4, "{scale} m: only {biomes:?} over 100 km");
        let forest = single_biome("forest");
        let near = Rect::new(i64::from(spawn.z) - 32, i64::from(spawn.x) - 32, 64, 64);
        let trees = rect_columns(near).filter(|&(x, z)| !g.clear_of_trees(&forest, x, z)).count();
        assert!(trees > 50, "{scale} m: {trees} columns under trees by the spawn");
    }
}
