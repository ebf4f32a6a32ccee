//! Sky light of a chunk, per column: valence computes and sends no light at all.
//!
//! Terrain here is a height field (no caves, no overhangs except tree crowns), so light from
//! straight above is the whole story: 15 in the open air, one level less per block of water,
//! ice or leaves, and 0 from the first opaque block down. The open side of a cliff is lit by
//! the air column next to it, which is exactly what the client looks at for that face.

use valence::prelude::{BlockState, Chunk, ChunkPos, UnloadedChunk};
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

/// Sky light of one chunk: one entry per section, plus one below the world and one above
/// it, as the protocol counts them.
#[derive(Clone, Debug, PartialEq)]
pub struct SkyLight {
    sections: Vec<Section>,
}

impl SkyLight {
    /// Computes the sky light of `chunk` from its blocks.
    pub fn of(chunk: &UnloadedChunk) -> SkyLight {
        let height = chunk.height();
        let world_sections = (height / 16) as usize;
        let mut levels = vec![0u8; (height as usize) * 256];
        for z in 0..16u32 {
            for x in 0..16u32 {
                let mut light = 15u8;
                for y in (0..height).rev() {
                    light = light.saturating_sub(dampening(chunk.block_state(x, y, z)));
                    levels[((y * 16 + z) * 16 + x) as usize] = light;
                    if light == 0 {
                        break; // Everything below stays 0.
                    }
                }
            }
        }
        let mut sections = Vec::with_capacity(world_sections + 2);
        sections.push(Section::Dark); // Below the world: bedrock above it.
        for s in 0..world_sections {
            sections.push(Section::from_levels(&levels[s * 4096..(s + 1) * 4096]));
        }
        sections.push(Section::Full); // Above the world: open sky.
        SkyLight { sections }
    }

    /// Sky light at chunk-local block (`x`, `y`, `z`) with `y` counted from the world's floor.
    pub fn get(&self, x: u32, y: u32, z: u32) -> u8 {
        match &self.sections[(y / 16) as usize + 1] {
            Section::Dark => 0,
            Section::Full => 15,
            Section::Mixed(bytes) => {
                let i = (((y % 16) * 16 + z) * 16 + x) as usize;
                (bytes[i / 2] >> ((i % 2) * 4)) & 0xF
            }
        }
    }

    /// Number of light sections: the world's sections plus one below and one above it.
    pub fn section_count(&self) -> usize {
        self.sections.len()
    }

    /// Light bytes of section `index` (0 is the one below the world) in the client's and
    /// Anvil's layout (index `y·256 + z·16 + x`, low nibble first), or `None` when every
    /// value is 0 (Anvil then omits the array). Panics when `index` is out of range.
    pub fn section_bytes(&self, index: usize) -> Option<&[u8; SECTION_BYTES]> {
        static FULL: [u8; SECTION_BYTES] = [0xFF; SECTION_BYTES];
        match &self.sections[index] {
            Section::Dark => None,
            Section::Full => Some(&FULL),
            Section::Mixed(bytes) => Some(bytes),
        }
    }

    /// The packet that gives a client this light for the chunk at `pos` (no block light:
    /// nothing in generated terrain glows).
    pub fn packet(&self, pos: ChunkPos) -> LightUpdateS2c {
        let n = self.sections.len();
        let mut sky_mask = vec![0u64; n.div_ceil(64)];
        let mut empty_sky_mask = vec![0u64; n.div_ceil(64)];
        let mut empty_block_mask = vec![0u64; n.div_ceil(64)];
        let mut arrays = Vec::new();
        for (i, section) in self.sections.iter().enumerate() {
            let bit = 1u64 << (i % 64);
            empty_block_mask[i / 64] |= bit;
            match section {
                Section::Dark => empty_sky_mask[i / 64] |= bit,
                Section::Full => {
                    sky_mask[i / 64] |= bit;
                    arrays.push(LengthPrefixedArray([0xFF; SECTION_BYTES]));
                }
                Section::Mixed(bytes) => {
                    sky_mask[i / 64] |= bit;
                    arrays.push(LengthPrefixedArray(**bytes));
                }
            }
        }
        LightUpdateS2c {
            chunk_x: VarInt(pos.x),
            chunk_z: VarInt(pos.z),
            sky_light_mask: sky_mask,
            block_light_mask: vec![0; n.div_ceil(64)],
            empty_sky_light_mask: empty_sky_mask,
            empty_block_light_mask: empty_block_mask,
            sky_light_arrays: arrays,
            block_light_arrays: Vec::new(),
        }
    }
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
}

/// How much sky light a block takes away: all of it for opaque blocks, one level for water,
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

#[cfg(test)]
mod tests {
    use super::*;

    fn column_chunk(blocks: &[(u32, BlockState)]) -> UnloadedChunk {
        let mut chunk = UnloadedChunk::with_height(64);
        for &(y, b) in blocks {
            chunk.set_block_state(3, y, 5, b);
        }
        chunk
    }

    #[test]
    fn open_air_is_full_and_ground_is_dark() {
        let chunk = column_chunk(&[(0, BlockState::BEDROCK), (1, BlockState::STONE), (2, BlockState::GRASS_BLOCK)]);
        let light = SkyLight::of(&chunk);
        assert_eq!(light.get(3, 3, 5), 15);
        assert_eq!(light.get(3, 2, 5), 0);
        assert_eq!(light.get(3, 0, 5), 0);
        assert_eq!(light.get(4, 0, 5), 15, "a column of air is lit to the floor");
        assert_eq!(light.get(3, 63, 5), 15);
    }

    #[test]
    fn water_and_leaves_dim_light_one_level_per_block() {
        let mut blocks = vec![(10, BlockState::SAND)];
        blocks.extend((11..=20).map(|y| (y, BlockState::WATER)));
        blocks.push((21, BlockState::ICE));
        blocks.push((30, BlockState::OAK_LEAVES));
        let light = SkyLight::of(&column_chunk(&blocks));
        assert_eq!(light.get(3, 31, 5), 15);
        assert_eq!(light.get(3, 30, 5), 14);
        assert_eq!(light.get(3, 22, 5), 14);
        assert_eq!(light.get(3, 21, 5), 13);
        assert_eq!(light.get(3, 20, 5), 12);
        assert_eq!(light.get(3, 11, 5), 3);
        assert_eq!(light.get(3, 10, 5), 0);
    }

    #[test]
    fn the_packet_lists_every_section_once() {
        let light = SkyLight::of(&column_chunk(&[(20, BlockState::STONE)]));
        let packet = light.packet(ChunkPos::new(2, -3));
        let sections = 64 / 16 + 2;
        let (sky, empty) = (packet.sky_light_mask[0], packet.empty_sky_light_mask[0]);
        assert_eq!(sky & empty, 0, "a section is either sent or empty");
        assert_eq!((sky | empty).count_ones() as usize, sections);
        assert_eq!(empty & 1, 1, "below the world is dark");
        assert_eq!(sky.count_ones() as usize, packet.sky_light_arrays.len());
        assert_eq!(packet.empty_block_light_mask[0].count_ones() as usize, sections);
        assert_eq!((packet.chunk_x.0, packet.chunk_z.0), (2, -3));
    }
}
