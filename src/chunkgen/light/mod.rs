//! Light of a chunk, sky and block: valence computes and sends no light at all.
//!
//! Sky light falls straight down from the open sky: 15 in the open air, one level less per
//! block of water, ice or leaves, and 0 from the first opaque block down. From there it
//! spreads, one level less per block (and per block of water or leaves on the way), sideways,
//! down and up into what the sky does not reach: a tunnel dug into a hillside, a cave's
//! mouth, the space under an overhang — vanilla's flood fill. Block light spreads the same
//! way from what glows: lava, at 15.
//!
//! [`Light::of`] lights a chunk alone, as if walled in at its borders. [`Light::joined`]
//! then lets the light of its eight neighbours in (a neighbour's lava, an open cave mouth or
//! an overhang across the border), exactly as a flood fill over all nine would: the server
//! sends a chunk's joined light once its neighbours are loaded (see `joined.rs`).

use std::collections::VecDeque;
use std::sync::OnceLock;

use valence::prelude::{BlockState, ChunkPos, UnloadedChunk};

mod joined;

use super::states::{index, States};
use valence::protocol::packets::play::LightUpdateS2c;
use valence::protocol::{LengthPrefixedArray, VarInt};

/// Bytes of one section's light: 4096 values, 4 bits each.
const SECTION_BYTES: usize = 2048;

/// Light of one 16×16×16 section.
#[derive(Clone, Debug, PartialEq)]
enum Section {
    /// Every value 0.
    Dark,
    /// Every value 15.
    Full,
    /// Anything else, as the client stores it (index `y·256 + z·16 + x`, low nibble first).
    Mixed(Box<[u8; SECTION_BYTES]>),
}

/// Light of one chunk, sky and block: one entry per section, plus one below the world and
/// one above it, as the protocol counts them. It keeps the chunk's opacity (each block's
/// dampening) beside the light, which is what its neighbours' [`Light::joined`] reads.
#[derive(Clone, Debug, PartialEq)]
pub struct Light {
    sky: Vec<Section>,
    block: Vec<Section>,
    opacity: Vec<Section>,
}

impl Light {
    /// Computes the light of `chunk` from its blocks.
    pub fn of(chunk: &UnloadedChunk) -> Light {
        Light::of_states(&States::of(chunk))
    }

    /// [`Light::of`] a chunk whose blocks were read already.
    pub fn of_states(states: &States) -> Light {
        let height = states.height();
        let n = height as usize * 256;
        // Every block once: what it takes away and what it gives off.
        let table = properties();
        let mut damp = vec![0u8; n];
        let mut block = vec![0u8; n];
        let mut glowing = VecDeque::new();
        for (i, &id) in states.ids().iter().enumerate() {
            let p = table[usize::from(id)];
            damp[i] = p & 0xF;
            if p >> 4 > 0 {
                block[i] = p >> 4;
                let i = i as u32;
                glowing.push_back((i % 16, i / 256, i / 16 % 16));
            }
        }

        // Sky light straight down; `lit[c]` is the lowest lit block of each column and
        // `open[c]` the lowest from which it is 15 all the way up.
        let mut sky = vec![0u8; n];
        let (mut lit, mut open) = ([0u32; 256], [0u32; 256]);
        for c in 0..256usize {
            let (x, z) = ((c % 16) as u32, (c / 16) as u32);
            let mut light = 15u8;
            let (mut low, mut full) = (height, height);
            for y in (0..height).rev() {
                light = light.saturating_sub(damp[index(x, y, z)]);
                if light == 0 {
                    break; // Below stays 0 unless light spreads in.
                }
                sky[index(x, y, z)] = light;
                low = y;
                if light == 15 && full == y + 1 {
                    full = y;
                }
            }
            (lit[c], open[c]) = (low, full);
        }
        // Seeds of the spread: lit blocks beside a darker one light can enter. Only between
        // a column's lowest lit block and the height from which it and its neighbours are
        // all open sky can there be one.
        let mut queue = VecDeque::new();
        for c in 0..256usize {
            let (x, z) = ((c % 16) as u32, (c / 16) as u32);
            let mut top = open[c];
            for (a, _, b) in neighbours(x, 0, z, 1) {
                top = top.max(open[(b * 16 + a) as usize]);
            }
            for y in lit[c]..top.min(height) {
                let l = sky[index(x, y, z)];
                if l >= 2 && neighbours(x, y, z, height).any(|(a, b, c)| enters(&sky, &damp, l, index(a, b, c))) {
                    queue.push_back((x, y, z));
                }
            }
        }
        spread(&mut sky, &damp, &mut queue, height);
        spread(&mut block, &damp, &mut glowing, height);
        Light {
            sky: sections(&sky, height, Section::Full),
            block: sections(&block, height, Section::Dark),
            // Below the world is as opaque as bedrock, above it open air.
            opacity: sections_between(Section::Full, &damp, height, Section::Dark),
        }
    }

    /// Sky light at chunk-local block (`x`, `y`, `z`) with `y` counted from the world's floor.
    pub fn sky(&self, x: u32, y: u32, z: u32) -> u8 {
        self.sky[(y / 16) as usize + 1].get(x, y, z)
    }

    /// Block light at chunk-local block (`x`, `y`, `z`) with `y` counted from the world's
    /// floor.
    pub fn block(&self, x: u32, y: u32, z: u32) -> u8 {
        self.block[(y / 16) as usize + 1].get(x, y, z)
    }

    /// Number of light sections: the world's sections plus one below and one above it.
    pub fn section_count(&self) -> usize {
        self.sky.len()
    }

    /// Sky light bytes of section `index` (0 is the one below the world) in the client's and
    /// Anvil's layout (index `y·256 + z·16 + x`, low nibble first), or `None` when every
    /// value is 0 (Anvil then omits the array). Panics when `index` is out of range.
    pub fn sky_bytes(&self, index: usize) -> Option<&[u8; SECTION_BYTES]> {
        self.sky[index].bytes()
    }

    /// Block light bytes of section `index`, as [`Light::sky_bytes`].
    pub fn block_bytes(&self, index: usize) -> Option<&[u8; SECTION_BYTES]> {
        self.block[index].bytes()
    }

    /// The packet that gives a client this light for the chunk at `pos`.
    pub fn packet(&self, pos: ChunkPos) -> LightUpdateS2c {
        let (sky_light_mask, empty_sky_light_mask, sky_light_arrays) = masks(&self.sky);
        let (block_light_mask, empty_block_light_mask, block_light_arrays) = masks(&self.block);
        LightUpdateS2c {
            chunk_x: VarInt(pos.x),
            chunk_z: VarInt(pos.z),
            sky_light_mask,
            block_light_mask,
            empty_sky_light_mask,
            empty_block_light_mask,
            sky_light_arrays,
            block_light_arrays,
        }
    }
}

/// The sections of a chunk's `levels`, with one below the world (dark: bedrock above it) and
/// one above it (`above`: the open sky's, or no block light).
fn sections(levels: &[u8], height: u32, above: Section) -> Vec<Section> {
    sections_between(Section::Dark, levels, height, above)
}

/// The sections of a chunk's `levels`, with `below` and `above` the world.
fn sections_between(below: Section, levels: &[u8], height: u32, above: Section) -> Vec<Section> {
    let world_sections = (height / 16) as usize;
    let mut out = Vec::with_capacity(world_sections + 2);
    out.push(below);
    out.extend((0..world_sections).map(|s| Section::from_levels(&levels[s * 4096..(s + 1) * 4096])));
    out.push(above);
    out
}

/// The protocol's masks and arrays of one kind of light: sections sent, sections empty, and
/// the arrays of those sent.
fn masks(sections: &[Section]) -> (Vec<u64>, Vec<u64>, Vec<LengthPrefixedArray<u8, SECTION_BYTES>>) {
    let n = sections.len();
    let (mut sent, mut empty, mut arrays) = (vec![0u64; n.div_ceil(64)], vec![0u64; n.div_ceil(64)], Vec::new());
    for (i, section) in sections.iter().enumerate() {
        let bit = 1u64 << (i % 64);
        match section.bytes() {
            None => empty[i / 64] |= bit,
            Some(bytes) => {
                sent[i / 64] |= bit;
                arrays.push(LengthPrefixedArray(*bytes));
            }
        }
    }
    (sent, empty, arrays)
}

/// The in-chunk neighbours of (`x`, `y`, `z`) in a chunk `height` blocks high.
fn neighbours(x: u32, y: u32, z: u32, height: u32) -> impl Iterator<Item = (u32, u32, u32)> {
    const STEPS: [(i32, i32, i32); 6] = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)];
    STEPS.iter().filter_map(move |&(dx, dy, dz)| {
        let (a, b, c) = (x as i32 + dx, y as i32 + dy, z as i32 + dz);
        ((0..16).contains(&a) && (0..height as i32).contains(&b) && (0..16).contains(&c))
            .then_some((a as u32, b as u32, c as u32))
    })
}

/// Vanilla's flood fill: from each queued cell, every neighbour light can enter gets one
/// level less (or its dampening, if more) when that is more than it has.
fn spread(levels: &mut [u8], damp: &[u8], queue: &mut VecDeque<(u32, u32, u32)>, height: u32) {
    while let Some((x, y, z)) = queue.pop_front() {
        let l = levels[index(x, y, z)];
        for (a, b, c) in neighbours(x, y, z, height) {
            let i = index(a, b, c);
            if enters(levels, damp, l, i) {
                levels[i] = l - damp[i].max(1);
                queue.push_back((a, b, c));
            }
        }
    }
}

/// Whether light `l` coming from a neighbour raises block `i`'s level.
#[inline]
fn enters(levels: &[u8], damp: &[u8], l: u8, i: usize) -> bool {
    let d = damp[i].max(1);
    l > d && levels[i] < l - d
}

impl Section {
    fn from_levels(levels: &[u8]) -> Section {
        if levels.iter().all(|&l| l == 0) {
            Section::Dark
        } else if levels.iter().all(|&l| l == 15) {
            Section::Full
        } else {
            let mut bytes = Box::new([0u8; SECTION_BYTES]);
            for (i, pair) in levels.chunks_exact(2).enumerate() {
                bytes[i] = pair[0] | (pair[1] << 4);
            }
            Section::Mixed(bytes)
        }
    }

    fn get(&self, x: u32, y: u32, z: u32) -> u8 {
        match self {
            Section::Dark => 0,
            Section::Full => 15,
            Section::Mixed(bytes) => {
                let i = index(x, y % 16, z);
                (bytes[i / 2] >> ((i % 2) * 4)) & 0xF
            }
        }
    }

    /// Sets the value at (`x`, `y % 16`, `z`) to `level`.
    fn set(&mut self, x: u32, y: u32, z: u32, level: u8) {
        if let Section::Dark | Section::Full = self {
            let fill = if *self == Section::Full { 0xFF } else { 0 };
            *self = Section::Mixed(Box::new([fill; SECTION_BYTES]));
        }
        if let Section::Mixed(bytes) = self {
            let i = index(x, y % 16, z);
            let shift = (i % 2) * 4;
            bytes[i / 2] = (bytes[i / 2] & !(0xF << shift)) | (level << shift);
        }
    }

    fn bytes(&self) -> Option<&[u8; SECTION_BYTES]> {
        static FULL: [u8; SECTION_BYTES] = [0xFF; SECTION_BYTES];
        match self {
            Section::Dark => None,
            Section::Full => Some(&FULL),
            Section::Mixed(bytes) => Some(bytes),
        }
    }
}

/// How much light a block takes away: all of it for opaque blocks, one level for water,
/// ice and leaves, nothing for air and small plants.
fn dampening(block: BlockState) -> u8 {
    if block.is_air() || super::plants::is_plant(block) {
        0
    } else if block.is_opaque() {
        15
    } else if block.is_liquid() || !block.is_replaceable() || block == BlockState::SEAGRASS {
        1
    } else {
        0
    }
}

/// Per block state (by raw id): its [`dampening`] in the low nibble and the block light it
/// gives off (vanilla's luminance: lava 15, and what players place — torches, glowstone) in
/// the high one. Built once: `dampening` compares names, too slow for every block.
fn properties() -> &'static [u8] {
    static TABLE: OnceLock<Vec<u8>> = OnceLock::new();
    TABLE.get_or_init(|| {
        (0..=BlockState::max_raw())
            .map(|raw| BlockState::from_raw(raw).map_or(15, |b| dampening(b) | (b.luminance().min(15) << 4)))
            .collect()
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use valence::prelude::Chunk;

    fn column_chunk(blocks: &[(u32, BlockState)]) -> UnloadedChunk {
        let mut chunk = UnloadedChunk::with_height(64);
        for &(y, b) in blocks {
            chunk.set_block_state(3, y, 5, b);
        }
        chunk
    }

    /// A chunk of stone up to Y 39 (chunk-local), open sky above.
    fn hill() -> UnloadedChunk {
        let mut chunk = UnloadedChunk::with_height(64);
        for y in 0..40 {
            for z in 0..16 {
                for x in 0..16 {
                    chunk.set_block_state(x, y, z, BlockState::STONE);
                }
            }
        }
        chunk
    }

    #[test]
    fn open_air_is_full_and_ground_is_dark() {
        let chunk = column_chunk(&[(0, BlockState::BEDROCK), (1, BlockState::STONE), (2, BlockState::GRASS_BLOCK)]);
        let light = Light::of(&chunk);
        assert_eq!(light.sky(3, 3, 5), 15);
        assert_eq!(light.sky(3, 2, 5), 0);
        assert_eq!(light.sky(3, 0, 5), 0);
        assert_eq!(light.sky(4, 0, 5), 15, "a column of air is lit to the floor");
        assert_eq!(light.sky(3, 63, 5), 15);
        assert_eq!(light.block(3, 3, 5), 0, "nothing glows");
    }

    #[test]
    fn water_and_leaves_dim_light_one_level_per_block() {
        let mut layers = vec![(10, BlockState::SAND)];
        layers.extend((11..=20).map(|y| (y, BlockState::WATER)));
        layers.push((21, BlockState::ICE));
        layers.push((30, BlockState::OAK_LEAVES));
        // The same layers in every column (a lake under a canopy), so no light comes from the side.
        let mut chunk = UnloadedChunk::with_height(64);
        for &(y, b) in &layers {
            for z in 0..16 {
                for x in 0..16 {
                    chunk.set_block_state(x, y, z, b);
                }
            }
        }
        let light = Light::of(&chunk);
        assert_eq!(light.sky(3, 31, 5), 15);
        assert_eq!(light.sky(3, 30, 5), 14);
        assert_eq!(light.sky(3, 22, 5), 14);
        assert_eq!(light.sky(3, 21, 5), 13);
        assert_eq!(light.sky(3, 20, 5), 12);
        assert_eq!(light.sky(3, 11, 5), 3);
        assert_eq!(light.sky(3, 10, 5), 0);
        // A lone column of the same among open air is lit from its sides too, one level less
        // than the air beside it.
        let light = Light::of(&column_chunk(&layers));
        assert_eq!((light.sky(3, 20, 5), light.sky(3, 11, 5), light.sky(3, 10, 5)), (14, 14, 0));
    }

    #[test]
    fn sky_light_spreads_into_a_tunnel_one_level_a_block() {
        // Open the hill's west face (air at x 0 from Y 30 up) and dig a tunnel east from it
        // along Y 30.
        let mut chunk = hill();
        for y in 30..40 {
            for z in 0..16 {
                chunk.set_block_state(0, y, z, BlockState::AIR);
            }
        }
        for x in 1..12 {
            chunk.set_block_state(x, 30, 8, BlockState::AIR);
        }
        let light = Light::of(&chunk);
        assert_eq!(light.sky(0, 30, 8), 15, "the open face's air column");
        let tunnel: Vec<u8> = (1..12).map(|x| light.sky(x, 30, 8)).collect();
        assert_eq!(tunnel, (4..=14).rev().collect::<Vec<u8>>());
        assert_eq!(light.sky(5, 31, 8), 0, "rock stays dark");
        // Under an overhang: one block of rock over air beside the open column.
        let mut ledge = hill();
        for y in 35..40 {
            for z in 0..16 {
                ledge.set_block_state(0, y, z, BlockState::AIR);
                ledge.set_block_state(1, y, z, BlockState::AIR);
            }
        }
        ledge.set_block_state(1, 39, 4, BlockState::STONE);
        let light = Light::of(&ledge);
        assert_eq!((light.sky(1, 38, 4), light.sky(1, 35, 4)), (14, 14), "lit from the open side");
    }

    #[test]
    fn lava_lights_the_air_around_it_and_not_through_rock() {
        let mut chunk = hill();
        // A cave of air at Y 5…9, x 2…13, z 2…13, with a lava pool on its floor at x 2…4.
        for y in 5..10 {
            for z in 2..14 {
                for x in 2..14 {
                    chunk.set_block_state(x, y, z, if y == 5 && x < 5 { BlockState::LAVA } else { BlockState::AIR });
                }
            }
        }
        let light = Light::of(&chunk);
        assert_eq!(light.block(3, 5, 7), 15, "lava glows");
        assert_eq!(light.block(3, 6, 7), 14);
        assert_eq!(light.block(5, 5, 7), 14);
        assert_eq!(light.block(10, 5, 7), 9, "one level less a block across the cave");
        assert_eq!(light.block(3, 11, 7), 0, "rock over the cave stays dark");
        assert_eq!(light.sky(3, 6, 7), 0, "a closed cave has no sky light");
        let packet = light.packet(ChunkPos::new(0, 0));
        assert_eq!(packet.block_light_mask[0], 0b10, "the section holding the cave sends block light");
        assert_eq!(packet.block_light_arrays.len(), 1);
        assert!(light.block_bytes(1).is_some() && light.block_bytes(2).is_none());
    }

    #[test]
    fn the_packet_lists_every_section_once() {
        let light = Light::of(&column_chunk(&[(20, BlockState::STONE)]));
        let packet = light.packet(ChunkPos::new(2, -3));
        let sections = 64 / 16 + 2;
        let (sky, empty) = (packet.sky_light_mask[0], packet.empty_sky_light_mask[0]);
        assert_eq!(sky & empty, 0, "a section is either sent or empty");
        assert_eq!((sky | empty).count_ones() as usize, sections);
        assert_eq!(empty & 1, 1, "below the world is dark");
        assert_eq!(sky.count_ones() as usize, packet.sky_light_arrays.len());
        assert_eq!(packet.empty_block_light_mask[0].count_ones() as usize, sections);
        assert_eq!(packet.block_light_mask[0], 0);
        assert_eq!((packet.chunk_x.0, packet.chunk_z.0), (2, -3));
    }
}
