//! The aquatic pass: what grows by and in water, once the ground, the water and the land's
//! plants are in place — seagrass, kelp and coral reefs on sea floors that are not frozen, lily
//! pads on lakes and slow rivers, sugar cane on the banks where ground meets water, mangrove
//! roots in shallow water — each with the chance its biome's vegetation table gives
//! (`water_plants` in `biomes/vegetation.toml`); this pass decides only where each can stand.
//!
//! Like every pass, a pure function of global coordinates: each choice hashes (seed, x, z)
//! and reads only the column and its four neighbours, which the columns pass provides.

use valence::prelude::{BlockState, Chunk, PropName, PropValue};

use crate::chunkgen::Blocks;

use crate::chunkgen::cells::{self, CELL};
use crate::chunkgen::columns::Water;
use crate::chunkgen::hash::{hash3, unit3, value_noise};
use crate::chunkgen::surface::SEA_ICE_C;
use crate::chunkgen::ChunkContext;
use crate::terrain::pipeline::channel;

const SALT_AQUATIC: u64 = 0x6171_7561;
const SALT_HEIGHT: u64 = 0x6865_6967;
const SALT_REEF: u64 = 0x7265_6566;
const SALT_CORAL: u64 = 0x636f_7261;

/// The sea floor depths seagrass grows at, blocks.
pub const SEAGRASS_DEPTHS: std::ops::RangeInclusive<i32> = 2..=12;
/// The shallowest water kelp grows in, blocks.
pub const KELP_MIN_DEPTH: i32 = 5;
/// The deepest water reefs grow in, blocks.
pub const CORAL_MAX_DEPTH: i32 = 16;
/// Width of reef patches, blocks, and the share of the warm shallow floor they cover (about).
const REEF_SCALE: i64 = 12;
const REEF_THRESHOLD: f32 = 0.55;
/// The corals, by their block ids' first word.
const CORALS: [(BlockState, BlockState, BlockState); 5] = [
    (BlockState::TUBE_CORAL_BLOCK, BlockState::TUBE_CORAL, BlockState::TUBE_CORAL_FAN),
    (BlockState::BRAIN_CORAL_BLOCK, BlockState::BRAIN_CORAL, BlockState::BRAIN_CORAL_FAN),
    (BlockState::BUBBLE_CORAL_BLOCK, BlockState::BUBBLE_CORAL, BlockState::BUBBLE_CORAL_FAN),
    (BlockState::FIRE_CORAL_BLOCK, BlockState::FIRE_CORAL, BlockState::FIRE_CORAL_FAN),
    (BlockState::HORN_CORAL_BLOCK, BlockState::HORN_CORAL, BlockState::HORN_CORAL_FAN),
];

/// True for what the sea floor grows (seagrass, kelp, coral): under water, not the ground.
pub fn is_sea_growth(block: BlockState) -> bool {
    let name = block.to_kind().to_str();
    block == BlockState::SEAGRASS || name.starts_with("kelp") || name.contains("coral")
}

/// The fastest river lily pads float on, m³/s.
pub const LILY_PAD_MAX_M3S: f32 = 20.0;
/// The deepest water mangrove roots stand in, blocks.
pub const MANGROVE_MAX_DEPTH: i32 = 3;

/// Places the aquatic plants of every column of the chunk.
pub fn run(ctx: &mut ChunkContext, chunk: &mut Blocks) {
    let (v, seed, columns, cells_y) = (*ctx.vertical(), ctx.seed(), ctx.columns(), ctx.cells_y());
    for (lx, lz, x, z) in ctx.each_column() {
        let ground = columns.surface_y(x, z);
        let temperature = columns.get(channel::TEMPERATURE, x, z);
        let roll = unit3(seed, SALT_AQUATIC, x, 0, z);
        let ly = |y: i32| (y - v.min_y) as u32;
        let top = chunk.block_state(lx, ly(ground), lz);
        let cell = ((lz as i64 / CELL) * 4 + lx as i64 / CELL) as usize;
        let cell_y = ((cells::cell_centre_y(ground) - v.min_y) / CELL as i32) as usize;
        let biome = ctx.biomes[cell * cells_y + cell_y.min(cells_y - 1)];
        let Some(vegetation) = ctx.rules.vegetation(biome) else { continue };
        let chance = |name: &str| vegetation.water_plant(name);
        if let Some(water_top) = columns.water_top_y(x, z) {
            let depth = water_top - ground;
            let rooted = chunk.block_state(lx, ly(ground + 1), lz) == BlockState::WATER;
            if rooted && depth <= MANGROVE_MAX_DEPTH && roll < chance("mangrove_roots") {
                // Roots from the mud to one block over the water, as a mangrove stands on them.
                let wet = BlockState::MANGROVE_ROOTS.set(PropName::Waterlogged, PropValue::True);
                for y in ground + 1..=water_top {
                    chunk.set_block_state(lx, ly(y), lz, wet);
                }
                if ((water_top + 1) as u32) < (v.min_y + v.height) as u32
                    && chunk.block_state(lx, ly(water_top + 1), lz).is_air()
                {
                    chunk.set_block_state(lx, ly(water_top + 1), lz, BlockState::MANGROVE_ROOTS);
                }
                continue;
            }
        }
        match (columns.water(x, z), columns.water_top_y(x, z)) {
            (Water::Sea, Some(water_top)) if temperature >= SEA_ICE_C => {
                let depth = water_top - ground;
                let floor = matches!(top, BlockState::SAND | BlockState::GRAVEL | BlockState::CLAY);
                if !floor || chunk.block_state(lx, ly(ground + 1), lz) != BlockState::WATER {
                    continue;
                }
                let reef = chance("coral") > 0.0
                    && (3..=CORAL_MAX_DEPTH).contains(&depth)
                    && value_noise(seed, SALT_REEF, x, z, REEF_SCALE) > REEF_THRESHOLD;
                if reef {
                    // One or two coral blocks, and on most a coral or a fan, at least two
                    // blocks under the surface; the colours mix as in vanilla's reefs.
                    let h = hash3(seed, SALT_CORAL, x, 0, z);
                    let block = CORALS[(h % 5) as usize].0;
                    let (top_y, tall) = (water_top - 2, 1 + (h >> 8) as i32 % 2);
                    let mound = (ground + tall).min(top_y - 1);
                    for y in ground + 1..=mound {
                        chunk.set_block_state(lx, ly(y), lz, block);
                    }
                    if roll < chance("coral") && mound < top_y {
                        let (coral, fan) = (CORALS[(h >> 16) as usize % 5].1, CORALS[(h >> 24) as usize % 5].2);
                        let grows = if (h >> 32) % 3 == 0 { fan } else { coral };
                        chunk.set_block_state(lx, ly(mound + 1), lz, grows);
                    }
                } else if depth >= KELP_MIN_DEPTH && roll < chance("kelp") {
                    // A stalk that stops at least two blocks under the surface.
                    let tall = 1 + (hash3(seed, SALT_HEIGHT, x, 0, z) % (depth - 2).clamp(1, 12) as u64) as i32;
                    for y in ground + 1..ground + tall {
                        chunk.set_block_state(lx, ly(y), lz, BlockState::KELP_PLANT);
                    }
                    chunk.set_block_state(lx, ly(ground + tall), lz, BlockState::KELP);
                } else if SEAGRASS_DEPTHS.contains(&depth) && roll < chance("kelp") + chance("seagrass") {
                    chunk.set_block_state(lx, ly(ground + 1), lz, BlockState::SEAGRASS);
                }
            }
            (Water::Lake | Water::River, Some(water_top)) => {
                let slow = columns.get(channel::DISCHARGE, x, z) <= LILY_PAD_MAX_M3S;
                let open = chunk.block_state(lx, ly(water_top), lz) == BlockState::WATER
                    && chunk.block_state(lx, ly(water_top + 1), lz).is_air()
                    // Level water all round: not on a step of a river.
                    && [(1, 0), (-1, 0), (0, 1), (0, -1)]
                        .iter()
                        .all(|&(dx, dz)| columns.water_top_y(x + dx, z + dz).is_none_or(|t| t == water_top));
                if slow && open && roll < chance("lily_pad") {
                    chunk.set_block_state(lx, ly(water_top + 1), lz, BlockState::LILY_PAD);
                }
            }
            (Water::Dry, None) => {
                // Sugar cane needs water beside the block it stands on.
                let soil = matches!(
                    top,
                    BlockState::GRASS_BLOCK
                        | BlockState::DIRT
                        | BlockState::SAND
                        | BlockState::RED_SAND
                        | BlockState::MUD
                );
                let bank = [(1, 0), (-1, 0), (0, 1), (0, -1)]
                    .iter()
                    .any(|&(dx, dz)| columns.water_top_y(x + dx, z + dz) == Some(ground));
                if !(soil && bank && roll < chance("sugar_cane")) {
                    continue;
                }
                let tall = 1 + (hash3(seed, SALT_HEIGHT, x, 0, z) % 3) as i32;
                let ys = (ground + 1..=ground + tall).map(ly);
                if ys.clone().all(|y| y < v.height as u32 && chunk.block_state(lx, y, lz).is_air()) {
                    for y in ys {
                        chunk.set_block_state(lx, y, lz, BlockState::SUGAR_CANE);
                    }
                }
            }
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::testing;
    use super::*;
    use crate::terrain::Rect;

    /// Runs the rock-less passes that aquatic plants need (water, surface) over synthetic
    /// columns, then this pass.
    fn grow(f: impl Fn(i64, i64) -> (f32, f32), biome: &str) -> (Blocks, crate::chunkgen::Vertical) {
        grow_at((0, 0), f, biome)
    }

    /// [`grow`] for chunk (`cx`, `cz`).
    fn grow_at(
        (cx, cz): (i32, i32),
        f: impl Fn(i64, i64) -> (f32, f32),
        biome: &str,
    ) -> (Blocks, crate::chunkgen::Vertical) {
        let (g, palette, rules) = (testing::generator(), testing::palette(), testing::single_biome(biome));
        let v = *g.vertical();
        let mut ctx = ChunkContext::new(&g, &rules, &palette, cx, cz);
        let (x0, z0) = (i64::from(cx) * 16, i64::from(cz) * 16);
        ctx.columns = Some(testing::columns(&g, Rect::new(z0 - 5, x0 - 5, 26, 26), f));
        ctx.biomes = vec![biome; 16 * ctx.cells_y()];
        let mut chunk = Blocks::with_height(v.height as u32);
        super::super::water::run(&mut ctx, &mut chunk);
        super::super::surface::run(&mut ctx, &mut chunk);
        run(&mut ctx, &mut chunk);
        (chunk, v)
    }

    fn count(chunk: &Blocks, v: &crate::chunkgen::Vertical, block: BlockState) -> usize {
        (0..16u32)
            .flat_map(|x| (0..16u32).map(move |z| (x, z)))
            .flat_map(|(x, z)| (0..v.height as u32).map(move |y| (x, y, z)))
            .filter(|&(x, y, z)| chunk.block_state(x, y, z) == block)
            .count()
    }

    #[test]
    fn temperate_seas_grow_seagrass_and_kelp_and_frozen_seas_nothing() {
        let (sea, v) = grow(|_, _| (-200.0, 12.0), "minecraft:ocean");
        assert!(count(&sea, &v, BlockState::SEAGRASS) + count(&sea, &v, BlockState::KELP) > 20);
        // Every kelp top stands on kelp stalk or on the floor, and has water above.
        for (x, z) in (0..16u32).flat_map(|x| (0..16u32).map(move |z| (x, z))) {
            for y in 1..v.height as u32 - 1 {
                if sea.block_state(x, y, z) == BlockState::KELP {
                    assert_eq!(sea.block_state(x, y + 1, z), BlockState::WATER, "kelp at the surface");
                    assert!(sea.block_state(x, y - 1, z) != BlockState::WATER, "floating kelp");
                }
            }
        }
        let (frozen, v) = grow(|_, _| (-200.0, -5.0), "minecraft:frozen_ocean");
        assert_eq!(count(&frozen, &v, BlockState::SEAGRASS) + count(&frozen, &v, BlockState::KELP), 0);
    }

    #[test]
    fn warm_seas_grow_coral_reefs_under_the_water_and_cooler_seas_none() {
        let (mut blocks, mut plants) = (0, 0);
        for chunk in [(0, 0), (1, 0), (0, 1), (-1, -1)] {
            let (reef, v) = grow_at(chunk, |_, _| (-500.0, 27.0), "minecraft:warm_ocean");
            for (x, z) in (0..16u32).flat_map(|x| (0..16u32).map(move |z| (x, z))) {
                for y in 1..v.height as u32 - 2 {
                    let b = reef.block_state(x, y, z);
                    let name = b.to_kind().to_str();
                    if !name.contains("coral") {
                        continue;
                    }
                    if name.ends_with("_block") {
                        blocks += 1;
                    } else {
                        plants += 1;
                        // A coral or fan stands on its reef or the floor, waterlogged.
                        assert_eq!(b.get(PropName::Waterlogged), Some(PropValue::True), "{name}");
                        assert_ne!(reef.block_state(x, y - 1, z), BlockState::WATER, "a floating {name}");
                    }
                    // At least two blocks of water over every reef.
                    let above = [reef.block_state(x, y + 1, z), reef.block_state(x, y + 2, z)];
                    assert!(above.iter().all(|&a| a == BlockState::WATER || is_sea_growth(a)), "{name}: {above:?}");
                }
            }
        }
        assert!(blocks > 20 && plants > 20, "{blocks} coral blocks, {plants} corals");
        let (cool, v) = grow(|_, _| (-200.0, 15.0), "minecraft:ocean");
        let corals = (0..16u32)
            .flat_map(|x| (0..16u32).map(move |z| (x, z)))
            .flat_map(|(x, z)| (0..v.height as u32).map(move |y| (x, y, z)));
        assert_eq!(
            corals.filter(|&(x, y, z)| cool.block_state(x, y, z).to_kind().to_str().contains("coral")).count(),
            0
        );
    }

    #[test]
    fn mangrove_swamps_grow_roots_in_shallow_water_from_the_bed_to_over_the_surface() {
        let (swamp, v) = grow(|_, _| (-30.0, 26.0), "minecraft:mangrove_swamp");
        let roots = count(&swamp, &v, BlockState::MANGROVE_ROOTS);
        let wet = count(&swamp, &v, BlockState::MANGROVE_ROOTS.set(PropName::Waterlogged, PropValue::True));
        assert!(wet > 20 && roots > 10, "{wet} waterlogged, {roots} over the water");
        // Every clump stands on the bed, waterlogged up to the surface, and no water is left
        // open to air beside an unwaterlogged root.
        for (x, z) in (0..16u32).flat_map(|x| (0..16u32).map(move |z| (x, z))) {
            for y in 1..v.height as u32 - 1 {
                if swamp.block_state(x, y, z) == BlockState::MANGROVE_ROOTS {
                    assert!(swamp.block_state(x, y + 1, z).is_air(), "root under something at ({x}, {y}, {z})");
                    assert!(swamp.block_state(x, y - 1, z).get(PropName::Waterlogged) == Some(PropValue::True));
                }
            }
        }
        // Deep water and other biomes grow none.
        let (deep, v) = grow(|_, _| (-1000.0, 26.0), "minecraft:mangrove_swamp");
        assert_eq!(count(&deep, &v, BlockState::MANGROVE_ROOTS.set(PropName::Waterlogged, PropValue::True)), 0);
        let (ocean, v) = grow(|_, _| (-30.0, 26.0), "minecraft:warm_ocean");
        assert_eq!(count(&ocean, &v, BlockState::MANGROVE_ROOTS.set(PropName::Waterlogged, PropValue::True)), 0);
    }

    #[test]
    fn sugar_cane_grows_on_banks_and_lily_pads_on_the_river() {
        // A river along z 6..10 whose water stands at the land's height (Y 67), 4 blocks deep.
        let (g, palette, rules) = (testing::generator(), testing::palette(), testing::single_biome("minecraft:plains"));
        let v = *g.vertical();
        let mut ctx = ChunkContext::new(&g, &rules, &palette, 0, 0);
        ctx.columns = Some(testing::river_columns(&g, Rect::new(-5, -5, 26, 26), |_, z| {
            if (6..10).contains(&z) {
                (0.0, 20.0, Some(100.0))
            } else {
                (100.0, 20.0, None)
            }
        }));
        ctx.biomes = vec!["minecraft:plains"; 16 * ctx.cells_y()];
        let mut chunk = Blocks::with_height(v.height as u32);
        super::super::water::run(&mut ctx, &mut chunk);
        super::super::surface::run(&mut ctx, &mut chunk);
        run(&mut ctx, &mut chunk);
        let ground = (67 - v.min_y) as u32;
        let cane: Vec<(u32, u32)> = (0..16u32)
            .flat_map(|x| (0..16u32).map(move |z| (x, z)))
            .filter(|&(x, z)| chunk.block_state(x, ground + 1, z) == BlockState::SUGAR_CANE)
            .collect();
        assert!(cane.iter().all(|&(_, z)| z == 5 || z == 10), "sugar cane away from the banks: {cane:?}");
        assert!(cane.len() >= 2, "{cane:?}");
        let pads = (0..16u32).flat_map(|x| (6..10u32).map(move |z| (x, z)));
        let pads = pads.filter(|&(x, z)| chunk.block_state(x, ground + 1, z) == BlockState::LILY_PAD).count();
        assert!(pads >= 1, "no lily pad on a slow warm river");
    }
}
