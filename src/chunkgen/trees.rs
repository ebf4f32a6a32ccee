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
pub const REACH: i64 = 3;
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
        "dark_forest" => (0.95, round(BlockState::DARK_OAK_LOG, BlockState::DARK_OAK_LEAVES, 4)),
        "taiga" | "snowy_taiga" | "old_growth_pine_taiga" | "old_growth_spruce_taiga" => (0.7, Kind::Spruce),
        "grove" => (0.45, Kind::Spruce),
        "windswept_forest" => (0.4, Kind::Spruce),
        "jungle" => (0.9, round(BlockState::JUNGLE_LOG, BlockState::JUNGLE_LEAVES, 6)),
        "sparse_jungle" | "bamboo_jungle" => (0.3, round(BlockState::JUNGLE_LOG, BlockState::JUNGLE_LEAVES, 5)),
        "savanna" | "savanna_plateau" | "windswept_savanna" => {
            (0.12, round(BlockState::ACACIA_LOG, BlockState::ACACIA_LEAVES, 4))
        }
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
        let draw = (hash3(seed, SALT_SHAPE, x, 0, z) % 3) as i32;
        let height = match kind {
            Kind::Round { min_height, .. } => min_height + draw,
            Kind::Spruce => 6 + draw * 2,
        };
        Tree { x, z, ground_y, kind, height }
    }

    /// Highest block Y the tree occupies.
    pub fn top_y(&self) -> i32 {
        self.ground_y + self.height + 1
    }

    /// Every leaf position, relative to the trunk's top block (dx, dy, dz).
    fn crown(&self) -> Vec<(i64, i32, i64)> {
        let mut leaves = Vec::new();
        let mut layer = |dy: i32, r: i64, corners: bool| {
            for dz in -r..=r {
                for dx in -r..=r {
                    let trunk = (dx, dz) == (0, 0) && dy <= 0;
                    let corner = r > 0 && dx.abs() == r && dz.abs() == r;
                    if !trunk && (corners || !corner) {
                        leaves.push((dx, dy, dz));
                    }
                }
            }
        };
        match self.kind {
            Kind::Round { .. } => {
                layer(-2, 2, false);
                layer(-1, 2, false);
                layer(0, 1, true);
                layer(1, 1, false);
            }
            Kind::Spruce => {
                layer(1, 0, true);
                layer(0, 1, false);
                // Alternating rings down the trunk, wider lower down.
                for dy in (3 - self.height..0).rev() {
                    let r = if (dy - self.height).rem_euclid(2) == 0 { 1 } else { 2 };
                    layer(dy, r, r == 1);
                }
            }
        }
        leaves
    }

    fn blocks(&self) -> (BlockState, BlockState) {
        match self.kind {
            Kind::Round { log, leaves, .. } => (log, leaves),
            Kind::Spruce => (BlockState::SPRUCE_LOG, BlockState::SPRUCE_LEAVES),
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
        for y in t.ground_y + 1..=t.ground_y + t.height {
            put(t.x, y, t.z, log, false);
        }
    }
    for t in trees {
        let (_, leaves) = t.blocks();
        // Generated leaves must not decay if a client ever ticks them.
        let leaves = leaves.set(PropName::Persistent, PropValue::True);
        let top = t.ground_y + t.height;
        for (dx, dy, dz) in t.crown() {
            put(t.x + dx, top + dy, t.z + dz, leaves, true);
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
        for kind in [Kind::Spruce, woodland("minecraft:forest").map(|w| w.1).unwrap_or(Kind::Spruce)] {
            for draw in 0..20 {
                let t = Tree::new(draw, 0, 0, 70, kind);
                let crown = t.crown();
                assert!(crown.iter().all(|&(dx, _, dz)| dx.abs() < REACH && dz.abs() < REACH));
                assert!(!crown.iter().any(|&(dx, dy, dz)| dx == 0 && dz == 0 && dy <= 0), "leaves inside the trunk");
            }
        }
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
