//! Trees: where they grow and what they look like, as pure functions of global position.
//!
//! The ground is cut into 5×5 tree cells; each cell may hold one tree, rooted at a hashed
//! spot inside it, if its biome is wooded enough (a hashed chance against the biome's
//! `trees` share, see `biomes/vegetation.toml`) and the ground there can hold one. The species
//! is a second hashed draw against the biome's species shares.
//!
//! Each species has its own shape, modelled on vanilla 1.20.1's tree features (its trunk and
//! foliage placers and decorators: acacia's bent trunk, the 2×2 trunks of dark oak, giant
//! spruce and giant jungle trees, mangrove prop roots, cherry's forked canopy with hanging
//! leaves, jungle vines and cocoa), drawn to fit within [`REACH`] of the trunk. Written here
//! rather than taken from a crate: no Rust crate generates Minecraft trees, and the shapes
//! must be pure functions of (seed, position) to stay seamless, which vanilla's own random
//! streams are not.
//!
//! A chunk places every tree rooted within [`REACH`] blocks of it, so crowns cross chunk
//! borders without seams. Blocks go in by layer over all trees, in one global order — wood
//! (replacing anything), then roots (into air or water, waterlogged there), then leaves (into
//! air), then what hangs from them (vines, cocoa, hanging leaves, into air) — so the result
//! does not depend on which chunk is built first.

use valence::prelude::{BlockState, Chunk, PropName, PropValue};

use crate::chunkgen::Blocks;

use crate::biome::Species;

use super::hash::{hash3, unit3};

/// How far a tree reaches from its trunk's root column, blocks: no block of a tree lies more
/// than this many columns away along x or z.
pub const REACH: i64 = 4;
/// Edge of a tree cell, blocks: neighbouring trunks are at least 3 blocks apart.
const CELL: i64 = 5;
const SALT_SPOT: u64 = 0x7472_6565;
const SALT_CHANCE: u64 = 0x6368_616e;
const SALT_SPECIES: u64 = 0x7370_6563;
const SALT_SHAPE: u64 = 0x7368_6170;
const SALT_LEAF: u64 = 0x6c65_6166;
const SALT_HANG: u64 = 0x6861_6e67;
const SALT_PICK: u64 = 0x7069_636b;

/// The tallest tree, blocks above its ground (for the bitmap a shape is drawn in).
const MAX_DY: i32 = 32;
const SIDE: usize = (2 * REACH + 1) as usize;

/// The order blocks are placed in, over all trees of a chunk.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Layer {
    /// Logs: replace whatever is there.
    Wood,
    /// Mangrove roots: into air, or into water (waterlogged).
    Roots,
    /// Leaves: into air only.
    Leaves,
    /// Vines, cocoa and hanging leaves: into air only, after every leaf.
    Hanging,
}

/// One block of a tree, relative to its root column and the ground block (dy ≥ 1).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Part {
    dx: i64,
    dy: i32,
    dz: i64,
    block: BlockState,
    layer: Layer,
}

/// One tree.
#[derive(Clone, Debug, PartialEq)]
pub struct Tree {
    /// Column of the trunk (the north-west one of a 2×2 trunk).
    pub x: i64,
    /// Column of the trunk.
    pub z: i64,
    /// Y of the ground block it stands on.
    pub ground_y: i32,
    /// Its species.
    pub species: Species,
    /// True when a 2×2 species stands on its 2×2 trunk; false where the ground could only
    /// hold its one-column form (and for every other species).
    pub wide: bool,
    /// Trunk height, blocks.
    pub height: i32,
    /// The hash every random choice of its shape comes from.
    shape: u64,
    /// Highest block above the ground it occupies.
    top: i32,
    /// Its blocks, drawn once: every chunk it reaches places them from here.
    parts: Vec<Part>,
}

/// The tree cells whose possible root lies within `REACH` of the chunk at block `(x0, z0)`:
/// each as (root x, root z, chance draw in `[0, 1)`, species draw in `[0, 1)`), in global
/// order.
pub fn candidate_roots(seed: u64, x0: i64, z0: i64, size: i64) -> Vec<(i64, i64, f32, f32)> {
    let (lo_x, hi_x) = (x0 - REACH, x0 + size - 1 + REACH);
    let (lo_z, hi_z) = (z0 - REACH, z0 + size - 1 + REACH);
    let mut roots = Vec::new();
    for gz in lo_z.div_euclid(CELL)..=hi_z.div_euclid(CELL) {
        for gx in lo_x.div_euclid(CELL)..=hi_x.div_euclid(CELL) {
            let h = hash3(seed, SALT_SPOT, gx, 0, gz);
            // Inside the cell's inner 3×3, so trunks of neighbouring cells never touch.
            let (x, z) = (gx * CELL + 1 + (h % 3) as i64, gz * CELL + 1 + ((h >> 8) % 3) as i64);
            if (lo_x..=hi_x).contains(&x) && (lo_z..=hi_z).contains(&z) {
                let chance = unit3(seed, SALT_CHANCE, gx, 0, gz);
                roots.push((x, z, chance, unit3(seed, SALT_SPECIES, gx, 0, gz)));
            }
        }
    }
    roots
}

/// True when a tree can stand on `top` (the ground block).
pub fn holds_tree(top: BlockState) -> bool {
    matches!(
        top,
        BlockState::GRASS_BLOCK
            | BlockState::PODZOL
            | BlockState::DIRT
            | BlockState::COARSE_DIRT
            | BlockState::MUD
            | BlockState::MYCELIUM
            | BlockState::SNOW_BLOCK
    )
}

/// True for the species that stand on a 2×2 trunk where the ground allows.
pub fn is_wide(species: Species) -> bool {
    matches!(species, Species::DarkOak | Species::MegaSpruce | Species::MegaJungle)
}

/// The columns of a 2×2 trunk (offsets from its root, the north-west one).
const TRUNK_2X2: [(i64, i64); 4] = [(0, 0), (1, 0), (0, 1), (1, 1)];

/// The columns a 2×2 trunk stands on besides its root (offsets).
pub const WIDE_TRUNK: [(i64, i64); 3] = [TRUNK_2X2[1], TRUNK_2X2[2], TRUNK_2X2[3]];

/// True for the blocks trees are made of (logs, leaves, mangrove roots, vines, cocoa, huge
/// mushrooms' stems and caps): what tests skip to find the ground.
#[cfg(test)]
pub fn is_tree_part(block: BlockState) -> bool {
    let name = block.to_kind().to_str();
    name.ends_with("_log")
        || name.ends_with("_leaves")
        || name.ends_with("_mushroom_block")
        || matches!(name, "mangrove_roots" | "vine" | "cocoa" | "mushroom_stem")
}

impl Tree {
    /// A tree of `species` at a root, its height and shape drawn from the root's hash;
    /// `wide` asks for the 2×2 form of a species that has one.
    pub fn new(seed: u64, x: i64, z: i64, ground_y: i32, species: Species, wide: bool) -> Tree {
        let shape = hash3(seed, SALT_SHAPE, x, 0, z);
        let wide = wide && is_wide(species);
        // Two independent small draws for the height.
        let (a, b) = ((shape % 5) as i32, ((shape >> 3) % 7) as i32);
        let height = match species {
            Species::Oak | Species::Azalea => 4 + a % 3,
            Species::Birch => 5 + a % 3,
            Species::TallBirch => 9 + a,
            Species::FancyOak => 6 + a % 4,
            Species::SwampOak => 5 + a % 3,
            Species::Spruce => 6 + 2 * (a % 3),
            Species::Pine => 8 + a,
            Species::MegaSpruce if wide => 14 + b,
            Species::MegaSpruce => 6 + 2 * (a % 3),
            Species::Jungle => 6 + a,
            Species::MegaJungle if wide => 12 + b,
            Species::MegaJungle => 6 + a,
            Species::JungleBush => 1,
            Species::Acacia => 5 + a % 3,
            Species::DarkOak if wide => 6 + a % 3,
            Species::DarkOak => 4 + a % 3,
            Species::Mangrove => 4 + a % 3,
            Species::Cherry => 5 + a % 3,
            Species::HugeRedMushroom | Species::HugeBrownMushroom => 5 + a % 3,
        };
        let mut tree = Tree { x, z, ground_y, species, wide, height, shape, top: 0, parts: Vec::new() };
        tree.parts = tree.draw();
        tree.top = tree.parts.iter().map(|p| p.dy).max().unwrap_or(0);
        tree
    }

    /// Highest block Y the tree occupies.
    pub fn top_y(&self) -> i32 {
        self.ground_y + self.top
    }

    /// The columns its trunk stands on (offsets from the root).
    #[cfg(test)]
    fn trunk_columns(&self) -> &'static [(i64, i64)] {
        if self.wide {
            &TRUNK_2X2
        } else {
            &[(0, 0)]
        }
    }

    /// Every block of the tree (a copy, for tests).
    #[cfg(test)]
    fn parts(&self) -> Vec<Part> {
        self.parts.clone()
    }

    /// Draws every block of the tree from its species, height and shape hash.
    fn draw(&self) -> Vec<Part> {
        let mut d = Draw::new(self.shape);
        let h = self.height;
        match (self.species, self.wide) {
            (Species::MegaSpruce, true) => d.mega_spruce(h),
            (Species::MegaJungle, true) => d.mega_jungle(h),
            (Species::DarkOak, true) => d.dark_oak(h),
            (Species::DarkOak, false) => d.blob(BlockState::DARK_OAK_LOG, BlockState::DARK_OAK_LEAVES, h, 2),
            (Species::Oak, _) => d.blob(BlockState::OAK_LOG, BlockState::OAK_LEAVES, h, 2),
            (Species::Birch | Species::TallBirch, _) => d.blob(BlockState::BIRCH_LOG, BlockState::BIRCH_LEAVES, h, 2),
            (Species::Azalea, _) => {
                d.blob(BlockState::OAK_LOG, BlockState::AZALEA_LEAVES, h, 2);
                d.flower_azalea();
            }
            (Species::SwampOak, _) => {
                d.blob(BlockState::OAK_LOG, BlockState::OAK_LEAVES, h, 3);
                d.leaf_vines(0.35, 4);
            }
            (Species::Jungle | Species::MegaJungle, _) => {
                d.blob(BlockState::JUNGLE_LOG, BlockState::JUNGLE_LEAVES, h, 2);
                d.cocoa();
                d.trunk_vines(0.25);
                d.leaf_vines(0.25, 3);
            }
            (Species::FancyOak, _) => d.fancy_oak(h),
            (Species::Spruce | Species::MegaSpruce, _) => d.spruce(h),
            (Species::Pine, _) => d.pine(h),
            (Species::JungleBush, _) => d.jungle_bush(),
            (Species::Acacia, _) => d.acacia(h),
            (Species::Mangrove, _) => d.mangrove(h),
            (Species::Cherry, _) => d.cherry(h),
            (Species::HugeRedMushroom, _) => d.huge_mushroom(h, BlockState::RED_MUSHROOM_BLOCK, false),
            (Species::HugeBrownMushroom, _) => d.huge_mushroom(h, BlockState::BROWN_MUSHROOM_BLOCK, true),
        }
        d.parts
    }
}

/// How a square layer of leaves treats its corners.
#[derive(Clone, Copy, PartialEq)]
enum Corners {
    Keep,
    Drop,
    /// Each corner kept or dropped by the shape's hash (vanilla's blob foliage).
    Random,
    /// A disc: cells farther than the radius (plus a half) from the trunk dropped.
    Round,
}

/// A tree's shape as it is drawn: its parts, and which cells they already take.
struct Draw {
    parts: Vec<Part>,
    taken: Vec<bool>,
    shape: u64,
}

impl Draw {
    fn new(shape: u64) -> Draw {
        Draw { parts: Vec::with_capacity(128), taken: vec![false; SIDE * SIDE * (MAX_DY as usize + 1)], shape }
    }

    fn cell(dx: i64, dy: i32, dz: i64) -> Option<usize> {
        let inside = dx.abs() <= REACH && dz.abs() <= REACH && (1..=MAX_DY).contains(&dy);
        inside.then(|| ((dy as usize * SIDE) + (dz + REACH) as usize) * SIDE + (dx + REACH) as usize)
    }

    fn is_taken(&self, dx: i64, dy: i32, dz: i64) -> bool {
        Draw::cell(dx, dy, dz).is_some_and(|i| self.taken[i])
    }

    /// A draw in `[0, 1)` for one choice at one place of the shape.
    fn roll(&self, salt: u64, dx: i64, dy: i32, dz: i64) -> f32 {
        unit3(self.shape, salt, dx, i64::from(dy), dz)
    }

    /// A whole number below `n` for the shape's choice number `which`.
    fn pick(&self, which: u32, n: u64) -> u64 {
        hash3(self.shape, SALT_PICK, i64::from(which), 0, 0) % n
    }

    /// Adds a block where the shape has none yet (a block outside the reach is dropped: no
    /// shape asks for one, and the tests check that).
    fn put(&mut self, dx: i64, dy: i32, dz: i64, block: BlockState, layer: Layer) {
        if let Some(i) = Draw::cell(dx, dy, dz) {
            if !self.taken[i] || layer == Layer::Wood {
                self.taken[i] = true;
                self.parts.push(Part { dx, dy, dz, block, layer });
            }
        }
    }

    fn log(&mut self, dx: i64, dy: i32, dz: i64, log: BlockState, axis: PropValue) {
        self.put(dx, dy, dz, log.set(PropName::Axis, axis), Layer::Wood);
    }

    /// A straight trunk of `height` logs on each of `columns`, from `base + 1` up.
    fn trunk(&mut self, log: BlockState, columns: &[(i64, i64)], base: i32, height: i32) {
        for dy in base + 1..=base + height {
            for &(dx, dz) in columns {
                self.log(dx, dy, dz, log, PropValue::Y);
            }
        }
    }

    /// A square layer of leaves of radius `r` around column `(cx, cz)` at `dy`; a `wide`
    /// layer is centred on a 2×2 trunk (columns cx..=cx+1).
    fn layer(&mut self, leaves: BlockState, (cx, cz): (i64, i64), dy: i32, r: i64, wide: bool, corners: Corners) {
        let leaves = leaves.set(PropName::Persistent, PropValue::True);
        let (lo, hi) = (-r, if wide { r + 1 } else { r });
        for dz in lo..=hi {
            for dx in lo..=hi {
                // Distance from the trunk's span along each axis.
                let off = |d: i64| {
                    if d < 0 {
                        -d
                    } else if wide {
                        (d - 1).max(0)
                    } else {
                        d
                    }
                };
                let (ex, ez) = (off(dx), off(dz));
                let corner = r > 0 && ex == r && ez == r;
                let keep = match corners {
                    Corners::Keep => true,
                    Corners::Drop => !corner,
                    Corners::Random => !corner || self.roll(SALT_LEAF, cx + dx, dy, cz + dz) < 0.5,
                    Corners::Round => (ex * ex + ez * ez) as f32 <= (r as f32 + 0.5).powi(2),
                };
                if keep {
                    self.put(cx + dx, dy, cz + dz, leaves, Layer::Leaves);
                }
            }
        }
    }

    /// Vanilla's blob tree (oak, birch, jungle, swamp oak, azalea): a trunk under a crown
    /// of two layers of radius `r` and two of `r − 1`, corners dropped at random.
    fn blob(&mut self, log: BlockState, leaves: BlockState, h: i32, r: i64) {
        self.trunk(log, &[(0, 0)], 0, h);
        self.layer(leaves, (0, 0), h + 1, r - 1, false, Corners::Drop);
        self.layer(leaves, (0, 0), h, r - 1, false, Corners::Random);
        self.layer(leaves, (0, 0), h - 1, r, false, Corners::Random);
        self.layer(leaves, (0, 0), h - 2, r, false, Corners::Random);
    }

    /// A quarter of an azalea's leaves flower.
    fn flower_azalea(&mut self) {
        let flowering = BlockState::FLOWERING_AZALEA_LEAVES.set(PropName::Persistent, PropValue::True);
        for i in 0..self.parts.len() {
            let p = self.parts[i];
            if p.layer == Layer::Leaves && self.roll(SALT_LEAF ^ 1, p.dx, p.dy, p.dz) < 0.25 {
                self.parts[i].block = flowering;
            }
        }
    }

    /// Vines hanging from the outer leaves: on each leaf with open air beside it, with
    /// `chance`, a vine of 1..=`longest` blocks down its outer face.
    fn leaf_vines(&mut self, chance: f32, longest: i32) {
        let leaves: Vec<Part> = self.parts.iter().copied().filter(|p| p.layer == Layer::Leaves).collect();
        for p in leaves {
            for (ox, oz) in [(1, 0), (-1, 0), (0, 1), (0, -1)] {
                let (vx, vz) = (p.dx + ox, p.dz + oz);
                if self.is_taken(vx, p.dy, vz) || self.roll(SALT_HANG, vx, p.dy, vz) >= chance {
                    continue;
                }
                let length = 1 + (self.roll(SALT_HANG ^ 1, vx, p.dy, vz) * longest as f32) as i32;
                let vine = vine_facing(-ox, -oz);
                for dy in (p.dy - length + 1..=p.dy).rev() {
                    if dy < 1 || self.is_taken(vx, dy, vz) {
                        break;
                    }
                    self.put(vx, dy, vz, vine, Layer::Hanging);
                }
            }
        }
    }

    /// Vines up the sides of the trunk logs, each face of each log with `chance`.
    fn trunk_vines(&mut self, chance: f32) {
        let logs: Vec<Part> =
            self.parts.iter().copied().filter(|p| p.layer == Layer::Wood && p.dx.abs() + p.dz.abs() <= 1).collect();
        for p in logs {
            for (ox, oz) in [(1, 0), (-1, 0), (0, 1), (0, -1)] {
                let (vx, vz) = (p.dx + ox, p.dz + oz);
                if !self.is_taken(vx, p.dy, vz) && self.roll(SALT_HANG ^ 2, vx, p.dy, vz) < chance {
                    self.put(vx, p.dy, vz, vine_facing(-ox, -oz), Layer::Hanging);
                }
            }
        }
    }

    /// Cocoa pods on the lowest three logs of a jungle trunk (one tree in five has them,
    /// as in vanilla), facing the log they hang on.
    fn cocoa(&mut self) {
        if self.pick(40, 5) != 0 {
            return;
        }
        for dy in 1..=3 {
            for (ox, oz) in [(1, 0), (-1, 0), (0, 1), (0, -1)] {
                if !self.is_taken(0, dy, 0) || self.is_taken(ox, dy, oz) || self.roll(SALT_HANG ^ 3, ox, dy, oz) >= 0.25
                {
                    continue;
                }
                let age = PropValue::from_u16((self.roll(SALT_HANG ^ 4, ox, dy, oz) * 3.0) as u16);
                let pod = BlockState::COCOA.set(PropName::Facing, facing(-ox, -oz));
                let pod = age.map_or(pod, |age| pod.set(PropName::Age, age));
                self.put(ox, dy, oz, pod, Layer::Hanging);
            }
        }
    }

    /// Vanilla's fancy (large) oak: a tall trunk with branches rising out of its upper half,
    /// each ending in a cluster of leaves, and a cluster on top.
    fn fancy_oak(&mut self, h: i32) {
        let (log, leaves) = (BlockState::OAK_LOG, BlockState::OAK_LEAVES);
        self.trunk(log, &[(0, 0)], 0, h);
        self.cluster(leaves, (0, 0), h);
        let branches = 2 + self.pick(20, 2) as i32;
        for i in 0..branches {
            let (ox, oz) = DIRECTIONS[((self.pick(24, 8) as i32 + i * 3) % 8) as usize];
            let base = h / 2 + (i * (h / 2 - 1)) / branches.max(1);
            let axis = if ox != 0 && oz == 0 {
                PropValue::X
            } else if ox == 0 {
                PropValue::Z
            } else {
                PropValue::Y
            };
            self.log(ox, base + 1, oz, log, axis);
            self.log(2 * ox, base + 2, 2 * oz, log, axis);
            self.cluster(leaves, (2 * ox, 2 * oz), base + 2);
        }
    }

    /// A fancy oak's leaf cluster: four layers around a branch end at `dy`.
    fn cluster(&mut self, leaves: BlockState, c: (i64, i64), dy: i32) {
        self.layer(leaves, c, dy - 1, 1, false, Corners::Drop);
        self.layer(leaves, c, dy, 2, false, Corners::Drop);
        self.layer(leaves, c, dy + 1, 2, false, Corners::Round);
        self.layer(leaves, c, dy + 2, 1, false, Corners::Drop);
    }

    /// Spruce: a narrow cone of alternating rings down the trunk.
    fn spruce(&mut self, h: i32) {
        let leaves = BlockState::SPRUCE_LEAVES;
        self.trunk(BlockState::SPRUCE_LOG, &[(0, 0)], 0, h);
        self.layer(leaves, (0, 0), h + 1, 0, false, Corners::Keep);
        self.layer(leaves, (0, 0), h, 1, false, Corners::Drop);
        for dy in (3..h).rev() {
            let r = if (h - dy) % 2 == 0 { 1 } else { 2 };
            self.layer(leaves, (0, 0), dy, r, false, if r == 1 { Corners::Keep } else { Corners::Drop });
        }
    }

    /// Pine (old-growth pine taiga): a tall bare trunk under a small crown at its top.
    fn pine(&mut self, h: i32) {
        let leaves = BlockState::SPRUCE_LEAVES;
        self.trunk(BlockState::SPRUCE_LOG, &[(0, 0)], 0, h);
        self.layer(leaves, (0, 0), h + 1, 0, false, Corners::Keep);
        self.layer(leaves, (0, 0), h, 1, false, Corners::Drop);
        self.layer(leaves, (0, 0), h - 1, 1, false, Corners::Keep);
        self.layer(leaves, (0, 0), h - 2, 2, false, Corners::Drop);
        self.layer(leaves, (0, 0), h - 3, 1, false, Corners::Drop);
    }

    /// Giant spruce: a 2×2 trunk under a long cone, widening down in alternating skirts.
    fn mega_spruce(&mut self, h: i32) {
        let leaves = BlockState::SPRUCE_LEAVES;
        self.trunk(BlockState::SPRUCE_LOG, &TRUNK_2X2, 0, h);
        let crown = h / 2 + 2;
        for i in 0..crown {
            // A cap over the trunk, then skirts of at least radius 1 around it.
            let mut r = if i == 0 { 0 } else { (1 + i64::from(i) * 3 / i64::from(crown)).min(3) };
            if i % 2 == 0 && r > 1 {
                r -= 1;
            }
            self.layer(leaves, (0, 0), h + 1 - i, r, true, if r >= 2 { Corners::Round } else { Corners::Drop });
        }
    }

    /// Giant jungle tree: a 2×2 trunk with vines, two branches with leaf clusters, and a
    /// broad crown.
    fn mega_jungle(&mut self, h: i32) {
        let (log, leaves) = (BlockState::JUNGLE_LOG, BlockState::JUNGLE_LEAVES);
        self.trunk(log, &TRUNK_2X2, 0, h);
        self.layer(leaves, (0, 0), h + 1, 1, true, Corners::Drop);
        self.layer(leaves, (0, 0), h, 2, true, Corners::Round);
        self.layer(leaves, (0, 0), h - 1, 3, true, Corners::Round);
        for i in 0..2 {
            let (ox, oz) = [(1, 0), (0, 1), (-1, 0), (0, -1)][((self.pick(28, 4) + i * 2) % 4) as usize];
            // From the trunk's face on that side.
            let (ex, ez) = (if ox > 0 { 1 } else { 0 }, if oz > 0 { 1 } else { 0 });
            let base = h / 2 + (i as i32) * (h / 4);
            let axis = if ox != 0 { PropValue::X } else { PropValue::Z };
            self.log(ex + ox, base + 1, ez + oz, log, axis);
            self.log(ex + 2 * ox, base + 2, ez + 2 * oz, log, axis);
            self.layer(leaves, (ex + 2 * ox, ez + 2 * oz), base + 3, 1, false, Corners::Keep);
            self.layer(leaves, (ex + 2 * ox, ez + 2 * oz), base + 2, 1, false, Corners::Drop);
        }
        self.trunk_vines(0.3);
        self.leaf_vines(0.25, 4);
    }

    /// Jungle bush: one log under a low mound of leaves.
    fn jungle_bush(&mut self) {
        self.log(0, 1, 0, BlockState::JUNGLE_LOG, PropValue::Y);
        self.layer(BlockState::OAK_LEAVES, (0, 0), 1, 2, false, Corners::Random);
        self.layer(BlockState::OAK_LEAVES, (0, 0), 2, 1, false, Corners::Drop);
    }

    /// Acacia: a straight trunk whose top two logs bend off diagonally under a flat canopy,
    /// and, on the taller ones, a second, lower branch the other way.
    fn acacia(&mut self, h: i32) {
        let (log, leaves) = (BlockState::ACACIA_LOG, BlockState::ACACIA_LEAVES);
        let (lx, lz) = (if self.pick(8, 2) == 0 { -1 } else { 1 }, if self.pick(9, 2) == 0 { -1 } else { 1 });
        let straight = h - 2;
        self.trunk(log, &[(0, 0)], 0, straight);
        self.log(lx, straight + 1, lz, log, PropValue::Y);
        self.log(2 * lx, h, 2 * lz, log, PropValue::Y);
        self.layer(leaves, (2 * lx, 2 * lz), h, 2, false, Corners::Drop);
        self.layer(leaves, (2 * lx, 2 * lz), h + 1, 1, false, Corners::Drop);
        if straight >= 4 && self.pick(12, 2) == 0 {
            let s = straight - 2;
            self.log(-lx, s + 1, -lz, log, PropValue::Y);
            self.log(-lx, s + 2, -lz, log, PropValue::Y);
            self.layer(leaves, (-lx, -lz), s + 2, 2, false, Corners::Drop);
            self.layer(leaves, (-lx, -lz), s + 3, 1, false, Corners::Drop);
        }
    }

    /// Dark oak: a 2×2 trunk under a broad, low, irregular crown.
    fn dark_oak(&mut self, h: i32) {
        let leaves = BlockState::DARK_OAK_LEAVES;
        self.trunk(BlockState::DARK_OAK_LOG, &TRUNK_2X2, 0, h);
        self.layer(leaves, (0, 0), h - 2, 2, true, Corners::Random);
        self.layer(leaves, (0, 0), h - 1, 3, true, Corners::Round);
        self.layer(leaves, (0, 0), h, 2, true, Corners::Round);
        self.layer(leaves, (0, 0), h + 1, 1, true, Corners::Drop);
    }

    /// Mangrove: a trunk raised two or three blocks on prop roots that arch out and down to
    /// the ground (waterlogged where they stand in water), under a ragged crown with vines.
    fn mangrove(&mut self, h: i32) {
        let (log, leaves) = (BlockState::MANGROVE_LOG, BlockState::MANGROVE_LEAVES);
        let lift = 2 + self.pick(16, 2) as i32;
        let roots = BlockState::MANGROVE_ROOTS;
        for dy in 1..=lift {
            self.put(0, dy, 0, roots, Layer::Roots);
        }
        for (i, (ox, oz)) in [(1, 0), (-1, 0), (0, 1), (0, -1)].into_iter().enumerate() {
            if self.pick(32 + i as u32, 4) == 0 {
                continue;
            }
            self.put(ox, lift, oz, roots, Layer::Roots);
            for dy in 1..lift {
                self.put(2 * ox, dy, 2 * oz, roots, Layer::Roots);
            }
        }
        self.trunk(log, &[(0, 0)], lift, h);
        let top = lift + h;
        self.layer(leaves, (0, 0), top + 1, 1, false, Corners::Drop);
        self.layer(leaves, (0, 0), top, 2, false, Corners::Random);
        self.layer(leaves, (0, 0), top - 1, 2, false, Corners::Round);
        self.layer(leaves, (0, 0), top - 2, 2, false, Corners::Random);
        self.leaf_vines(0.15, 3);
    }

    /// Cherry: a trunk forking into one or two branches under a wide, flat canopy of pink
    /// leaves, some hanging below its rim.
    fn cherry(&mut self, h: i32) {
        let (log, leaves) = (BlockState::CHERRY_LOG, BlockState::CHERRY_LEAVES);
        self.trunk(log, &[(0, 0)], 0, h);
        let along_x = self.pick(14, 2) == 0;
        let (axis, step) = if along_x { (PropValue::X, (1, 0)) } else { (PropValue::Z, (0, 1)) };
        let sides: &[i64] = if self.pick(15, 3) == 0 { &[1] } else { &[1, -1] };
        for &s in sides {
            let (ox, oz) = (step.0 * s, step.1 * s);
            self.log(ox, h, oz, log, axis);
            self.log(2 * ox, h + 1, 2 * oz, log, PropValue::Y);
            self.layer(leaves, (2 * ox, 2 * oz), h + 1, 2, false, Corners::Round);
            self.layer(leaves, (2 * ox, 2 * oz), h + 2, 2, false, Corners::Random);
            self.layer(leaves, (2 * ox, 2 * oz), h + 3, 1, false, Corners::Drop);
        }
        self.layer(leaves, (0, 0), h + 1, 2, false, Corners::Drop);
        self.layer(leaves, (0, 0), h + 2, 1, false, Corners::Keep);
        // Leaves hanging one block under the lowest layer's rim.
        let hanging = leaves.set(PropName::Persistent, PropValue::True);
        let rim: Vec<Part> = self
            .parts
            .iter()
            .copied()
            .filter(|p| p.layer == Layer::Leaves && p.dy == h + 1 && !self.is_taken(p.dx, p.dy - 1, p.dz))
            .collect();
        for p in rim {
            if self.roll(SALT_HANG ^ 5, p.dx, p.dy, p.dz) < 0.3 {
                self.put(p.dx, p.dy - 1, p.dz, hanging, Layer::Hanging);
            }
        }
    }
}

impl Draw {
    /// A huge mushroom: a stem of `h` blocks under a cap of `cap` blocks — flat and seven
    /// wide (brown) or a dome with three-block walls (red), as vanilla's.
    fn huge_mushroom(&mut self, h: i32, cap: BlockState, flat: bool) {
        for dy in 1..=h {
            self.put(0, dy, 0, BlockState::MUSHROOM_STEM, Layer::Wood);
        }
        if flat {
            self.layer(cap, (0, 0), h + 1, 3, false, Corners::Drop);
            return;
        }
        self.layer(cap, (0, 0), h + 1, 1, false, Corners::Keep);
        for dy in h - 2..=h {
            for d in -1..=1 {
                for (dx, dz) in [(d, 2), (d, -2), (2, d), (-2, d)] {
                    self.put(dx, dy, dz, cap, Layer::Leaves);
                }
            }
        }
    }
}

/// The eight directions around a trunk.
const DIRECTIONS: [(i64, i64); 8] = [(1, 0), (1, 1), (0, 1), (-1, 1), (-1, 0), (-1, -1), (0, -1), (1, -1)];

/// A vine on the face towards `(ox, oz)` (the block it clings to): +x is east, +z south.
fn vine_facing(ox: i64, oz: i64) -> BlockState {
    let none = BlockState::VINE
        .set(PropName::East, PropValue::False)
        .set(PropName::West, PropValue::False)
        .set(PropName::North, PropValue::False)
        .set(PropName::South, PropValue::False)
        .set(PropName::Up, PropValue::False);
    let face = match (ox, oz) {
        (1, _) => PropName::East,
        (-1, _) => PropName::West,
        (_, 1) => PropName::South,
        _ => PropName::North,
    };
    none.set(face, PropValue::True)
}

/// The horizontal facing towards `(ox, oz)`.
fn facing(ox: i64, oz: i64) -> PropValue {
    match (ox, oz) {
        (1, _) => PropValue::East,
        (-1, _) => PropValue::West,
        (_, 1) => PropValue::South,
        _ => PropValue::North,
    }
}

/// Places `trees` (in the order given, which must be global) into the chunk whose first
/// column is (`x0`, `z0`) and whose floor is `min_y`, layer by layer over all trees.
pub fn place(chunk: &mut Blocks, trees: &[Tree], x0: i64, z0: i64, min_y: i32) {
    let height = chunk.height() as i32;
    for layer in [Layer::Wood, Layer::Roots, Layer::Leaves, Layer::Hanging] {
        for t in trees {
            for p in t.parts.iter().filter(|p| p.layer == layer) {
                let (lx, lz, ly) = (t.x + p.dx - x0, t.z + p.dz - z0, t.ground_y + p.dy - min_y);
                if !((0..16).contains(&lx) && (0..16).contains(&lz) && (0..height).contains(&ly)) {
                    continue;
                }
                let (lx, ly, lz) = (lx as u32, ly as u32, lz as u32);
                let there = chunk.block_state(lx, ly, lz);
                let block = match layer {
                    Layer::Wood => Some(p.block),
                    Layer::Roots if there == BlockState::WATER => {
                        Some(p.block.set(PropName::Waterlogged, PropValue::True))
                    }
                    _ => there.is_air().then_some(p.block),
                };
                if let Some(block) = block {
                    chunk.set_block_state(lx, ly, lz, block);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grown(species: Species, wide: bool) -> impl Iterator<Item = Tree> {
        (0..40u64).map(move |seed| Tree::new(seed, 0, 0, 70, species, wide))
    }

    #[test]
    fn roots_cover_the_reach_around_a_chunk_and_are_spaced() {
        let roots = candidate_roots(9, 0, 0, 16);
        assert!(roots.iter().all(|r| (-REACH..16 + REACH).contains(&r.0) && (-REACH..16 + REACH).contains(&r.1)));
        assert!(roots.len() >= 16, "{} roots", roots.len());
        for (i, a) in roots.iter().enumerate() {
            for b in &roots[i + 1..] {
                assert!((a.0 - b.0).abs().max((a.1 - b.1).abs()) >= 3, "{a:?} {b:?}");
            }
        }
        // Roots near the shared border are seen, identically, from both chunks.
        let right = candidate_roots(9, 16, 0, 16);
        let near = |r: &&(i64, i64, f32, f32)| (16 - REACH..16 + REACH).contains(&r.0);
        let from_left: Vec<_> = roots.iter().filter(near).collect();
        let from_right: Vec<_> = right.iter().filter(near).collect();
        assert!(!from_left.is_empty());
        assert_eq!(from_left, from_right);
    }

    #[test]
    fn every_species_stays_within_reach_above_its_ground_with_its_trunk_whole() {
        for species in Species::ALL {
            for wide in [false, true] {
                for t in grown(species, wide) {
                    let parts = t.parts();
                    let what = format!("{species:?} wide={wide} seed-shape {:x}", t.shape);
                    assert!(parts.iter().all(|p| p.dx.abs() <= REACH && p.dz.abs() <= REACH), "{what}");
                    assert!(parts.iter().all(|p| p.dy >= 1 && p.dy <= MAX_DY), "{what}");
                    assert_eq!(parts.iter().map(|p| p.dy).max(), Some(t.top), "{what}");
                    // Leaves over the crown: the top block is a leaf (or, for a bush, too).
                    let leaves = parts.iter().filter(|p| p.layer == Layer::Leaves).count();
                    assert!(leaves >= 10, "{what}: {leaves} leaves");
                    // The trunk stands on every trunk column, right above the ground (a
                    // mangrove's on its roots).
                    for &(dx, dz) in t.trunk_columns() {
                        let first = parts.iter().find(|p| p.dx == dx && p.dz == dz && p.dy == 1).map(|p| p.layer);
                        assert!(matches!(first, Some(Layer::Wood | Layer::Roots)), "{what}: ({dx}, {dz})");
                    }
                    assert_eq!(t.wide, wide && is_wide(species));
                }
            }
        }
    }

    #[test]
    fn what_hangs_clings_to_the_tree() {
        let mut vines = 0;
        let mut pods = 0;
        for species in [Species::Jungle, Species::MegaJungle, Species::SwampOak, Species::Mangrove] {
            for t in grown(species, true) {
                let parts = t.parts();
                let at = |dx: i64, dy: i32, dz: i64| parts.iter().find(|p| (p.dx, p.dy, p.dz) == (dx, dy, dz));
                for p in parts.iter().filter(|p| p.layer == Layer::Hanging) {
                    let name = p.block.to_kind().to_str();
                    let towards = |face: PropName| p.block.get(face) == Some(PropValue::True);
                    let (ox, oz) = match name {
                        "vine" if towards(PropName::East) => (1, 0),
                        "vine" if towards(PropName::West) => (-1, 0),
                        "vine" if towards(PropName::South) => (0, 1),
                        "vine" => (0, -1),
                        "cocoa" => match p.block.get(PropName::Facing) {
                            Some(PropValue::East) => (1, 0),
                            Some(PropValue::West) => (-1, 0),
                            Some(PropValue::South) => (0, 1),
                            _ => (0, -1),
                        },
                        other => panic!("{other} hangs from a {species:?}"),
                    };
                    if name == "cocoa" {
                        pods += 1;
                        let log = at(p.dx + ox, p.dy, p.dz + oz).map(|l| l.block.to_kind().to_str());
                        assert_eq!(log, Some("jungle_log"), "a pod on {log:?}");
                    } else {
                        vines += 1;
                        // Clings to a block of the tree, or hangs under a vine on the same face.
                        let beside = at(p.dx + ox, p.dy, p.dz + oz).is_some_and(|b| b.layer != Layer::Hanging);
                        let above = at(p.dx, p.dy + 1, p.dz).is_some_and(|b| b.block == p.block);
                        assert!(beside || above, "{species:?}: a vine hangs free at {:?}", (p.dx, p.dy, p.dz));
                    }
                }
            }
        }
        assert!(vines > 100 && pods > 0, "{vines} vines, {pods} pods");
    }

    #[test]
    fn shapes_tell_the_species_apart() {
        let logs = |t: &Tree| -> Vec<(i64, i32, i64)> {
            t.parts().iter().filter(|p| p.layer == Layer::Wood).map(|p| (p.dx, p.dy, p.dz)).collect()
        };
        // An acacia's top bends two diagonal steps off its trunk.
        let acacia = Tree::new(1, 0, 0, 70, Species::Acacia, false);
        let top = logs(&acacia).into_iter().max_by_key(|l| l.1).expect("logs");
        assert_eq!((top.0.abs(), top.2.abs()), (2, 2));
        // 2×2 trunks where the ground allows, one column where it does not.
        for species in [Species::DarkOak, Species::MegaSpruce, Species::MegaJungle] {
            let wide = logs(&Tree::new(1, 0, 0, 70, species, true));
            assert!(WIDE_TRUNK.iter().all(|&(dx, dz)| wide.contains(&(dx, 1, dz))), "{species:?}");
            let small = logs(&Tree::new(1, 0, 0, 70, species, false));
            assert!(!small.contains(&(1, 1, 0)), "{species:?}");
        }
        // Giants are taller than their small forms; tall birches than birches.
        let tallest = |s: Species, wide: bool| grown(s, wide).map(|t| t.height).max().unwrap_or(0);
        assert!(tallest(Species::MegaSpruce, true) > tallest(Species::Spruce, false) + 4);
        assert!(tallest(Species::TallBirch, false) > tallest(Species::Birch, false) + 4);
        // A mangrove's trunk starts above its roots; roots arch out from it.
        for t in grown(Species::Mangrove, false) {
            let parts = t.parts();
            let roots: Vec<_> = parts.iter().filter(|p| p.layer == Layer::Roots).collect();
            assert!(roots.iter().any(|p| (p.dx, p.dy, p.dz) == (0, 1, 0)));
            assert!(roots.iter().any(|p| p.dx.abs() == 2 || p.dz.abs() == 2));
            assert!(logs(&t).iter().all(|l| l.1 >= 3));
        }
        // A cherry's canopy spreads wider than an oak's, and some of it hangs.
        let spread = |t: &Tree| t.parts().iter().map(|p| p.dx.abs().max(p.dz.abs())).max().unwrap_or(0);
        assert!(grown(Species::Cherry, false).all(|t| spread(&t) == 4));
        assert!(grown(Species::Oak, false).all(|t| spread(&t) == 2));
        assert!(grown(Species::Cherry, false).any(|t| t.parts().iter().any(|p| p.layer == Layer::Hanging)));
        // A brown mushroom's cap is flat and seven wide; a red one's walls hang three blocks
        // down around its stem.
        for t in grown(Species::HugeBrownMushroom, false) {
            let caps: Vec<Part> = t.parts().into_iter().filter(|p| p.layer == Layer::Leaves).collect();
            assert!(caps.iter().all(|p| p.dy == t.height + 1) && spread(&t) == 3);
        }
        for t in grown(Species::HugeRedMushroom, false) {
            let walls =
                t.parts().iter().filter(|p| p.layer == Layer::Leaves && p.dx.abs().max(p.dz.abs()) == 2).count();
            assert_eq!(walls, 36, "twelve a layer, three layers");
        }
    }

    #[test]
    fn a_tree_split_across_chunks_matches_the_tree_placed_whole() {
        for species in Species::ALL {
            let tree = Tree::new(3, 15, 8, 60, species, true);
            let mut left = Blocks::with_height(128);
            let mut right = Blocks::with_height(128);
            let mut whole = Blocks::with_height(128);
            place(&mut left, std::slice::from_ref(&tree), 0, 0, 0);
            place(&mut right, std::slice::from_ref(&tree), 16, 0, 0);
            // The same tree 8 blocks further west, whole in one chunk.
            let moved = Tree::new(3, 15, 8, 60, species, true);
            let moved = Tree { x: 7, ..moved };
            place(&mut whole, &[moved], 0, 0, 0);
            let split = |x: i64, y: u32, z: u32| {
                if x < 16 {
                    left.block_state(x as u32, y, z)
                } else {
                    right.block_state((x - 16) as u32, y, z)
                }
            };
            for x in 15 - REACH..=15 + REACH {
                for z in 0..16 {
                    for y in 60..100 {
                        assert_eq!(
                            split(x, y, z),
                            whole.block_state((x - 8) as u32, y, z),
                            "{species:?} at {x} {y} {z}"
                        );
                    }
                }
            }
            assert!(is_tree_part(split(15, 61, 8)), "{species:?}: no trunk over its root");
        }
    }

    #[test]
    fn roots_in_water_are_waterlogged_and_leaves_never_replace_ground() {
        let tree = Tree::new(5, 8, 8, 60, Species::Mangrove, false);
        let mut chunk = Blocks::with_height(128);
        // Water two blocks deep over the ground, and a stone block where a leaf would go.
        for x in 0..16 {
            for z in 0..16 {
                chunk.set_block_state(x, 61, z, BlockState::WATER);
                chunk.set_block_state(x, 62, z, BlockState::WATER);
            }
        }
        let leaf = tree.parts().into_iter().find(|p| p.layer == Layer::Leaves).expect("leaves");
        let (sx, sy, sz) = ((8 + leaf.dx) as u32, (60 + leaf.dy) as u32, (8 + leaf.dz) as u32);
        chunk.set_block_state(sx, sy, sz, BlockState::STONE);
        place(&mut chunk, std::slice::from_ref(&tree), 0, 0, 0);
        let root = chunk.block_state(8, 61, 8);
        assert_eq!(root.to_kind().to_str(), "mangrove_roots");
        assert_eq!(root.get(PropName::Waterlogged), Some(PropValue::True));
        assert_eq!(chunk.block_state(sx, sy, sz), BlockState::STONE);
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
            "mangrove_roots" => [74, 59, 38],
            "vine" => [40, 110, 20],
            "cocoa" => [150, 90, 40],
            "cherry_leaves" => [232, 170, 200],
            "birch_leaves" => [128, 167, 85],
            "spruce_leaves" => [97, 153, 97],
            "acacia_leaves" => [110, 140, 40],
            "dark_oak_leaves" => [50, 110, 30],
            "jungle_leaves" => [48, 170, 30],
            "mangrove_leaves" => [100, 160, 50],
            "azalea_leaves" => [90, 125, 40],
            "mushroom_stem" => [203, 196, 185],
            "red_mushroom_block" => [200, 46, 45],
            "brown_mushroom_block" => [149, 111, 81],
            "flowering_azalea_leaves" => [190, 110, 190],
            _ if name.ends_with("_leaves") => [72, 140, 40],
            _ => return None,
        };
        Some(Rgb(c))
    }

    #[test]
    #[ignore = "writes docs/trees.png"]
    fn draw_the_species_side_by_side() {
        // Two rows of nine, each tree in a slot of its own.
        let (slot, ground, height, per_row) = (12i64, 2i32, 26u32, 9usize);
        let species = Species::ALL;
        let rows = species.len().div_ceil(per_row) as u32;
        let width = (per_row as i64 * slot) as u32;
        let mut img = RgbImage::from_pixel(width * PX, rows * height * PX, Rgb([200, 222, 240]));
        for (i, &s) in species.iter().enumerate() {
            let (column, row) = ((i % per_row) as i64, (i / per_row) as u32);
            let x = column * slot + slot / 2;
            let tree = Tree::new(11 + i as u64, x, 8, ground, s, true);
            let mut chunk = Blocks::with_height(height + 8);
            let x0 = x - 8;
            place(&mut chunk, &[tree], x0, 0, 0);
            for lx in 0..16u32 {
                let x = x0 + i64::from(lx);
                if x < column * slot || x >= (column + 1) * slot {
                    continue;
                }
                for y in 0..height {
                    // The nearest block seen from the south (the largest z first).
                    let seen = (0..16u32).rev().map(|z| chunk.block_state(lx, y, z)).find(|b| !b.is_air());
                    let c = if y <= ground as u32 { Some(Rgb([104, 160, 72])) } else { seen.and_then(colour) };
                    if let Some(c) = c {
                        let (px, py) = (x as u32 * PX, (row * height + height - 1 - y) * PX);
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
