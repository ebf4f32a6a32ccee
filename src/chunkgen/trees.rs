//! Trees: where they grow and what they look like, as pure functions of global position.
//!
//! The ground is cut into 5×5 tree cells; each cell may hold one tree, rooted at a hashed
//! spot inside it, if its biome is wooded enough (a hashed chance against the biome's
//! density) and the ground there can hold one. A chunk places every tree rooted within
//! [`REACH`] blocks of it, so crowns cross chunk borders without seams. Trunks are placed
//! before any leaves, and leaves only fill air, in one global order: the result does not
//! depend on which chunk is built first.

use valence::prelude::{BlockState, Chunk, PropName, PropValue, UnloadedChunk};

use super::hash::{hash3, unit3};

/// How far a tree reaches from its trunk, blocks (the widest crown's radius plus a margin).
pub const REACH: i64 = 4;
/// Edge of a tree cell, blocks: neighbouring trunks are at least 3 blocks apart.
const CELL: i64 = 5;
const SALT_SPOT: u64 = 0x7472_6565;
const SALT_CHANCE: u64 = 0x6368_616e;
const SALT_SHAPE: u64 = 0x7368_6170;

/// The kinds of tree.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A round crown on a short trunk (oak, birch, jungle, acacia, mangrove, cherry, dark oak).
    Round { log: BlockState, leaves: BlockState, min_height: i32 },
    /// A narrow cone of spruce.
    Spruce,
    /// Acacia: a trunk whose top bends off diagonally, under a flat canopy.
    Acacia,
    /// Dark oak: a 2×2 trunk under a broad, low crown.
    DarkOak,
}

/// One tree.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tree {
    /// Column of the trunk.
    pub x: i64,
    /// Column of the trunk.
    pub z: i64,
    /// Y of the ground block it stands on.
    pub ground_y: i32,
    /// Its kind.
    pub kind: Kind,
    /// Trunk height, blocks.
    pub height: i32,
    /// Which way an acacia's top bends (a diagonal, each part −1 or 1).
    pub lean: (i64, i64),
}

/// The tree cells whose possible root lies within `REACH` of the chunk at block `(x0, z0)`:
/// each as (root x, root z, chance draw in `[0, 1)`), in global order.
pub fn candidate_roots(seed: u64, x0: i64, z0: i64, size: i64) -> Vec<(i64, i64, f32)> {
    let (lo_x, hi_x) = (x0 - REACH, x0 + size - 1 + REACH);
    let (lo_z, hi_z) = (z0 - REACH, z0 + size - 1 + REACH);
    let mut roots = Vec::new();
    for gz in lo_z.div_euclid(CELL)..=hi_z.div_euclid(CELL) {
        for gx in lo_x.div_euclid(CELL)..=hi_x.div_euclid(CELL) {
            let h = hash3(seed, SALT_SPOT, gx, 0, gz);
            // Inside the cell's inner 3×3, so trunks of neighbouring cells never touch.
            let (x, z) = (gx * CELL + 1 + (h % 3) as i64, gz * CELL + 1 + ((h >> 8) % 3) as i64);
            if (lo_x..=hi_x).contains(&x) && (lo_z..=hi_z).contains(&z) {
                roots.push((x, z, unit3(seed, SALT_CHANCE, gx, 0, gz)));
            }
        }
    }
    roots
}

/// How wooded a biome is (the chance a tree cell holds a tree) and with what kind of tree.
pub fn woodland(biome: &str) -> Option<(f32, Kind)> {
    let b = biome.strip_prefix("minecraft:").unwrap_or(biome);
    let round = |log, leaves, min_height| Kind::Round { log, leaves, min_height };
    let oak = round(BlockState::OAK_LOG, BlockState::OAK_LEAVES, 4);
    let birch = round(BlockState::BIRCH_LOG, BlockState::BIRCH_LEAVES, 5);
    Some(match b {
        "forest" | "flower_forest" => (0.7, oak),
        "birch_forest" | "old_growth_birch_forest" => (0.75, birch),
        "dark_forest" => (0.8, Kind::DarkOak),
        "taiga" | "snowy_taiga" | "old_growth_pine_taiga" | "old_growth_spruce_taiga" => (0.7, Kind::Spruce),
        "grove" => (0.45, Kind::Spruce),
        "windswept_forest" => (0.4, Kind::Spruce),
        "jungle" => (0.9, round(BlockState::JUNGLE_LOG, BlockState::JUNGLE_LEAVES, 6)),
        "sparse_jungle" | "bamboo_jungle" => (0.3, round(BlockState::JUNGLE_LOG, BlockState::JUNGLE_LEAVES, 5)),
        "savanna" | "savanna_plateau" | "windswept_savanna" => (0.12, Kind::Acacia),
        "swamp" => (0.3, oak),
        "mangrove_swamp" => (0.45, round(BlockState::MANGROVE_LOG, BlockState::MANGROVE_LEAVES, 5)),
        "cherry_grove" => (0.5, round(BlockState::CHERRY_LOG, BlockState::CHERRY_LEAVES, 4)),
        "plains" | "sunflower_plains" | "meadow" | "windswept_hills" => (0.04, oak),
        "snowy_plains" => (0.03, Kind::Spruce),
        _ => return None,
    })
}

/// True when a tree can stand on `top` (the ground block).
pub fn holds_tree(top: BlockState) -> bool {
    matches!(
        top,
        BlockState::GRASS_BLOCK | BlockState::PODZOL | BlockState::DIRT | BlockState::COARSE_DIRT | BlockState::MUD
    ) || top == BlockState::SNOW_BLOCK
}

impl Tree {
    /// A tree of `kind` at a root, its height drawn from the root's hash.
    pub fn new(seed: u64, x: i64, z: i64, ground_y: i32, kind: Kind) -> Tree {
        let h = hash3(seed, SALT_SHAPE, x, 0, z);
        let draw = (h % 3) as i32;
        let height = match kind {
            Kind::Round { min_height, .. } => min_height + draw,
            Kind::Spruce => 6 + draw * 2,
            Kind::Acacia => 5 + draw,
            Kind::DarkOak => 6 + draw,
        };
        let lean = (if h >> 8 & 1 == 0 { -1 } else { 1 }, if h >> 9 & 1 == 0 { -1 } else { 1 });
        Tree { x, z, ground_y, kind, height, lean }
    }

    /// The round dark oak that stands where a 2×2 one cannot (uneven or wet ground).
    pub fn small_dark_oak() -> Kind {
        Kind::Round { log: BlockState::DARK_OAK_LOG, leaves: BlockState::DARK_OAK_LEAVES, min_height: 4 }
    }

    /// Columns besides the root the trunk stands on (offsets).
    pub fn extra_trunk_columns(kind: Kind) -> &'static [(i64, i64)] {
        match kind {
            Kind::DarkOak => &[(1, 0), (0, 1), (1, 1)],
            _ => &[],
        }
    }

    /// Every log position, relative to the root column and the ground (dx, dy ≥ 1, dz).
    fn logs(&self) -> Vec<(i64, i32, i64)> {
        let h = self.height;
        match self.kind {
            Kind::Round { .. } | Kind::Spruce => (1..=h).map(|y| (0, y, 0)).collect(),
            // Straight, then the top two logs a diagonal step aside.
            Kind::Acacia => {
                let (lx, lz) = self.lean;
                (1..=h).map(|y| if y < h - 1 { (0, y, 0) } else { (lx, y, lz) }).collect()
            }
            Kind::DarkOak => (1..=h).flat_map(|y| [(0, y, 0), (1, y, 0), (0, y, 1), (1, y, 1)]).collect(),
        }
    }

    /// Highest block Y the tree occupies.
    pub fn top_y(&self) -> i32 {
        self.ground_y + self.height + 1
    }

    /// Every leaf position, relative to the root column and the ground (dx, dy, dz). Logs
    /// are placed first and leaves only into air, so leaves listed over a log are harmless.
    fn crown(&self) -> Vec<(i64, i32, i64)> {
        let top = self.height;
        let mut leaves = Vec::new();
        // A square ring of radius `r` around (cx, cz) at `dy` above the trunk's top; `wide`
        // squares span the 2×2 trunk (cx..=cx+1).
        let mut square = |(cx, cz): (i64, i64), dy: i32, r: i64, corners: bool, wide: bool| {
            let hi = if wide { r + 1 } else { r };
            let lo = if wide && r == 0 { 0 } else { -r };
            for dz in lo..=hi {
                for dx in lo..=hi {
                    let corner = r > 0 && (dx == lo || dx == hi) && (dz == lo || dz == hi);
                    if corners || !corner {
                        leaves.push((cx + dx, top + dy, cz + dz));
                    }
                }
            }
        };
        match self.kind {
            Kind::Round { .. } => {
                square((0, 0), -2, 2, false, false);
                square((0, 0), -1, 2, false, false);
                square((0, 0), 0, 1, true, false);
                square((0, 0), 1, 1, false, false);
            }
            Kind::Spruce => {
                square((0, 0), 1, 0, true, false);
                square((0, 0), 0, 1, false, false);
                // Alternating rings down the trunk, wider lower down.
                for dy in (3 - self.height..0).rev() {
                    let r = if (dy - self.height).rem_euclid(2) == 0 { 1 } else { 2 };
                    square((0, 0), dy, r, r == 1, false);
                }
            }
            // Flat: a broad layer at the bent top and a small one over it.
            Kind::Acacia => {
                square(self.lean, 0, 2, false, false);
                square(self.lean, 1, 1, false, false);
            }
            // Low and broad over the 2×2 trunk: 6×6, 4×4 and 2×2 layers.
            Kind::DarkOak => {
                square((0, 0), -1, 2, false, true);
                square((0, 0), 0, 1, true, true);
                square((0, 0), 1, 0, true, true);
            }
        }
        leaves
    }

    fn blocks(&self) -> (BlockState, BlockState) {
        match self.kind {
            Kind::Round { log, leaves, .. } => (log, leaves),
            Kind::Spruce => (BlockState::SPRUCE_LOG, BlockState::SPRUCE_LEAVES),
            Kind::Acacia => (BlockState::ACACIA_LOG, BlockState::ACACIA_LEAVES),
            Kind::DarkOak => (BlockState::DARK_OAK_LOG, BlockState::DARK_OAK_LEAVES),
        }
    }
}

/// Places `trees` (in the order given, which must be global) into the chunk whose first
/// column is (`x0`, `z0`) and whose floor is `min_y`: trunks first, then leaves into air.
pub fn place(chunk: &mut UnloadedChunk, trees: &[Tree], x0: i64, z0: i64, min_y: i32) {
    let height = chunk.height() as i32;
    let mut put = |x: i64, y: i32, z: i64, block: BlockState, only_air: bool| {
        let (lx, lz, ly) = (x - x0, z - z0, y - min_y);
        if (0..16).contains(&lx) && (0..16).contains(&lz) && (0..height).contains(&ly) {
            let (lx, ly, lz) = (lx as u32, ly as u32, lz as u32);
            if !only_air || chunk.block_state(lx, ly, lz).is_air() {
                chunk.set_block_state(lx, ly, lz, block);
            }
        }
    };
    for t in trees {
        let (log, _) = t.blocks();
        for (dx, dy, dz) in t.logs() {
            put(t.x + dx, t.ground_y + dy, t.z + dz, log, false);
        }
    }
    for t in trees {
        let (_, leaves) = t.blocks();
        // Generated leaves must not decay if a client ever ticks them.
        let leaves = leaves.set(PropName::Persistent, PropValue::True);
        for (dx, dy, dz) in t.crown() {
            put(t.x + dx, t.ground_y + dy, t.z + dz, leaves, true);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roots_cover_the_reach_around_a_chunk_and_are_spaced() {
        let roots = candidate_roots(9, 0, 0, 16);
        assert!(roots.iter().all(|&(x, z, _)| (-REACH..16 + REACH).contains(&x) && (-REACH..16 + REACH).contains(&z)));
        assert!(roots.len() >= 16, "{} roots", roots.len());
        for (i, a) in roots.iter().enumerate() {
            for b in &roots[i + 1..] {
                assert!((a.0 - b.0).abs().max((a.1 - b.1).abs()) >= 3, "{a:?} {b:?}");
            }
        }
        // Roots near the shared border are seen, identically, from both chunks.
        let right = candidate_roots(9, 16, 0, 16);
        let near = |r: &&(i64, i64, f32)| (16 - REACH..16 + REACH).contains(&r.0);
        let from_left: Vec<_> = roots.iter().filter(near).collect();
        let from_right: Vec<_> = right.iter().filter(near).collect();
        assert!(!from_left.is_empty());
        assert_eq!(from_left, from_right);
    }

    #[test]
    fn crowns_stay_within_reach_and_trunks_stay_clear() {
        let forest = woodland("minecraft:forest").map_or(Kind::Spruce, |w| w.1);
        for kind in [Kind::Spruce, forest, Kind::Acacia, Kind::DarkOak, Tree::small_dark_oak()] {
            for draw in 0..20 {
                let t = Tree::new(draw, 0, 0, 70, kind);
                let (crown, logs) = (t.crown(), t.logs());
                assert!(crown.iter().chain(&logs).all(|&(dx, _, dz)| dx.abs() < REACH && dz.abs() < REACH), "{kind:?}");
                assert_eq!(logs.len() as i32, t.height * (1 + Tree::extra_trunk_columns(kind).len() as i32));
                assert!(logs.iter().all(|&(_, dy, _)| (1..=t.height).contains(&dy)));
                // Every leaf hangs over the ground the trunk stands on, and the crown tops it.
                assert!(crown.iter().all(|&(_, dy, _)| dy > 1 && dy <= t.height + 1), "{kind:?}");
                assert_eq!(crown.iter().map(|l| l.1).max(), Some(t.top_y() - t.ground_y), "{kind:?}");
            }
        }
        // An acacia's top bends a diagonal step off its trunk; a dark oak stands on 2×2.
        let acacia = Tree::new(1, 0, 0, 70, Kind::Acacia);
        let top = acacia.logs().into_iter().max_by_key(|l| l.1).expect("logs");
        assert_eq!((top.0.abs(), top.2.abs()), (1, 1));
        let oak = Tree::new(1, 0, 0, 70, Kind::DarkOak);
        assert!(oak.logs().contains(&(1, 1, 1)) && oak.logs().contains(&(0, 1, 0)));
    }

    #[test]
    fn a_tree_split_across_chunks_matches_the_tree_placed_whole() {
        let tree = Tree::new(3, 15, 8, 60, Kind::Spruce);
        let mut left = UnloadedChunk::with_height(128);
        let mut right = UnloadedChunk::with_height(128);
        place(&mut left, &[tree], 0, 0, 0);
        place(&mut right, &[tree], 16, 0, 0);
        let at = |x: i64, y: u32, z: u32| {
            if x < 16 {
                left.block_state(x as u32, y, z)
            } else {
                right.block_state((x - 16) as u32, y, z)
            }
        };
        let top = (60 + tree.height) as u32;
        assert_eq!(at(15, 61, 8), BlockState::SPRUCE_LOG);
        assert_eq!(at(15, top, 8), BlockState::SPRUCE_LOG);
        assert_eq!(at(16, top, 8).to_kind(), BlockState::SPRUCE_LEAVES.to_kind(), "crown crosses the border");
        assert_eq!(at(14, top, 8).to_kind(), BlockState::SPRUCE_LEAVES.to_kind());
        assert!((0..128).all(|y| right.block_state(0, y, 0).is_air()));
    }
}

/// The species side by side, seen from the south (`docs/trees.png`): run with
/// `cargo test -p infiniterra --lib -- --ignored draw_the_species`.
#[cfg(test)]
mod picture {
    use super::*;
    use image::{Rgb, RgbImage};

    const PX: u32 = 8;

    fn colour(b: BlockState) -> Option<Rgb<u8>> {
        let name = b.to_kind().to_str();
        let c = match name {
            _ if name.ends_with("_log") => match name {
                "birch_log" => [220, 217, 200],
                "dark_oak_log" => [60, 46, 26],
                "acacia_log" => [103, 96, 86],
                "cherry_log" => [54, 33, 44],
                "jungle_log" => [85, 67, 25],
                "spruce_log" => [58, 37, 16],
                "mangrove_log" => [84, 66, 40],
                _ => [109, 85, 50],
            },
            "cherry_leaves" => [232, 170, 200],
            "birch_leaves" => [128, 167, 85],
            "spruce_leaves" => [97, 153, 97],
            "acacia_leaves" => [110, 140, 40],
            "dark_oak_leaves" => [50, 110, 30],
            "jungle_leaves" => [48, 170, 30],
            "mangrove_leaves" => [100, 160, 50],
            _ if name.ends_with("_leaves") => [72, 140, 40],
            _ => return None,
        };
        Some(Rgb(c))
    }

    #[test]
    #[ignore = "writes docs/trees.png"]
    fn draw_the_species_side_by_side() {
        let kinds: Vec<Kind> =
            ["forest", "birch_forest", "taiga", "savanna", "dark_forest", "jungle", "cherry_grove", "mangrove_swamp"]
                .iter()
                .filter_map(|b| woodland(b).map(|w| w.1))
                .collect();
        let (slot, ground) = (16i64, 2i32);
        let width = (kinds.len() as i64 * slot) as u32;
        let height = 16u32;
        let mut img = RgbImage::from_pixel(width * PX, height * PX, Rgb([200, 222, 240]));
        for (i, &kind) in kinds.iter().enumerate() {
            // One tree a chunk, trunk in the middle.
            let tree = Tree::new(7 + i as u64, i as i64 * slot + 7, 8, ground, kind);
            let mut chunk = UnloadedChunk::with_height(32);
            let x0 = tree.x.div_euclid(16) * 16;
            place(&mut chunk, &[tree], x0, 0, 0);
            for lx in 0..16u32 {
                let x = x0 + i64::from(lx);
                if x < i as i64 * slot || x >= (i as i64 + 1) * slot {
                    continue;
                }
                for y in 0..height {
                    // The nearest block seen from the south (the largest z first).
                    let seen = (0..16u32).rev().map(|z| chunk.block_state(lx, y, z)).find(|b| !b.is_air());
                    let c = if y <= ground as u32 { Some(Rgb([104, 160, 72])) } else { seen.and_then(colour) };
                    if let Some(c) = c {
                        let (px, py) = (x as u32 * PX, (height - 1 - y) * PX);
                        for d in 0..PX * PX {
                            img.put_pixel(px + d % PX, py + d / PX, c);
                        }
                    }
                }
            }
        }
        let out = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/trees.png");
        img.save(&out).expect("write docs/trees.png");
    }
}
