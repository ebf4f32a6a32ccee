//! Chunk → Anvil NBT bytes, written directly in one pass over the blocks (see the module
//! documentation of [`codec`](super)).

use valence::prelude::{BiomeId, BlockState, Chunk, UnloadedChunk};
use valence::registry::RegistryIdx;

use super::nbt::{bit_width, tag, Writer};
use super::{BLOCKS, CELLS, DATA_VERSION};
use crate::chunkgen::{Light, States};

/// Marks a block state that has no palette entry in the section being encoded.
const NO_SLOT: u16 = u16::MAX;

/// Turns chunks into Anvil NBT. One per worker thread: it keeps the serialised palette entry
/// of every block state it has met and its scratch buffers across chunks.
pub struct Encoder {
    min_y: i32,
    biome_names: Vec<String>,
    /// Serialised body (fields and closing end tag) of each block state's palette compound,
    /// by raw id, filled the first time the state is met.
    entries: Vec<Option<Box<[u8]>>>,
    /// Raw id → position in the palette of the section being encoded, or [`NO_SLOT`]. Reset
    /// after each section for the palette's states only, so a section costs O(blocks).
    slots: Vec<u16>,
    /// Raw ids of the section's block palette, in order of first appearance.
    palette: Vec<u16>,
    /// Palette index of every block of the section (order y-z-x).
    indices: Vec<u16>,
    biome_palette: Vec<BiomeId>,
    biome_indices: Vec<u16>,
    /// Bytes of the previous chunk, to size the next buffer in one allocation.
    last_len: usize,
}

impl Encoder {
    /// An encoder for a world whose lowest block is `min_y` (a multiple of 16), naming biome
    /// id `i` `biome_names[i]` (the server's registry order, as `BiomePalette::names` gives).
    pub fn new(min_y: i32, biome_names: Vec<String>) -> Encoder {
        let states = usize::from(BlockState::max_raw()) + 1;
        Encoder {
            min_y,
            biome_names,
            entries: vec![None; states],
            slots: vec![NO_SLOT; states],
            palette: Vec::with_capacity(64),
            indices: vec![0; BLOCKS],
            biome_palette: Vec::with_capacity(8),
            biome_indices: vec![0; CELLS],
            last_len: 16 * 1024,
        }
    }

    /// Uncompressed NBT bytes of the chunk at (`chunk_x`, `chunk_z`), as Minecraft 1.20.1
    /// writes a finished chunk: `DataVersion`, `xPos`, `zPos`, `yPos`, `Status`
    /// `"minecraft:full"`, `LastUpdate` and `InhabitedTime` 0 (nothing time-varying: the same
    /// chunk always encodes to the same bytes), `isLightOn`, `sections` (block states, biomes
    /// and sky and block light; plus the light-only sections just below and above the world
    /// when they have any light, as vanilla writes them), empty `block_entities` and
    /// `structures`. `Heightmaps` are left out: Minecraft computes missing ones when it loads
    /// the chunk.
    ///
    /// `light` is the chunk's light when it is right to the last block — joined with its
    /// neighbours' ([`Light::joined`]) — and is written with `isLightOn` 1. `None` writes no
    /// light and `isLightOn` 0, which makes Minecraft light the chunk itself when it loads it,
    /// as it does every chunk it generates: a chunk lit alone is darker than it should be
    /// wherever light crosses its borders, and Minecraft would keep that light as it is.
    ///
    /// Panics when `light` is not the light of a chunk as high as `chunk`.
    pub fn encode(&mut self, chunk_x: i32, chunk_z: i32, chunk: &UnloadedChunk, light: Option<&Light>) -> Vec<u8> {
        self.encode_states(chunk_x, chunk_z, chunk, &States::of(chunk), light)
    }

    /// [`Encoder::encode`] with the chunk's blocks read already (`states`, of `chunk`).
    pub fn encode_states(
        &mut self,
        chunk_x: i32,
        chunk_z: i32,
        chunk: &impl Chunk,
        states: &States,
        light: Option<&Light>,
    ) -> Vec<u8> {
        let sections = (chunk.height() / 16) as usize;
        if let Some(light) = light {
            assert_eq!(light.section_count(), sections + 2, "light of a chunk of another height");
        }
        let min_section = self.min_y.div_euclid(16);
        let mut w = Writer(Vec::with_capacity(self.last_len + self.last_len / 8));
        w.tag(tag::COMPOUND, "");
        w.int("DataVersion", DATA_VERSION);
        w.int("xPos", chunk_x);
        w.int("zPos", chunk_z);
        w.int("yPos", min_section);
        w.string("Status", "minecraft:full");
        w.long("LastUpdate", 0);
        w.long("InhabitedTime", 0);
        w.byte("isLightOn", i8::from(light.is_some()));

        // Light-only sections are written only when they carry light, so count first.
        // (Nothing glows outside the world, so those two carry sky light only.)
        let below = light.and_then(|l| l.sky_bytes(0));
        let above = light.and_then(|l| l.sky_bytes(sections + 1));
        let count = sections + usize::from(below.is_some()) + usize::from(above.is_some());
        w.list("sections", tag::COMPOUND, count);
        if let Some(bytes) = below {
            w.byte("Y", (min_section - 1) as i8);
            w.byte_array("SkyLight", bytes);
            w.end();
        }
        for s in 0..sections {
            w.byte("Y", (min_section + s as i32) as i8);
            self.block_states(&mut w, states.section(s as u32));
            self.biomes(&mut w, chunk, s as u32);
            if let Some(bytes) = light.and_then(|l| l.sky_bytes(s + 1)) {
                w.byte_array("SkyLight", bytes);
            }
            if let Some(bytes) = light.and_then(|l| l.block_bytes(s + 1)) {
                w.byte_array("BlockLight", bytes);
            }
            w.end();
        }
        if let Some(bytes) = above {
            w.byte("Y", (min_section + sections as i32) as i8);
            w.byte_array("SkyLight", bytes);
            w.end();
        }

        w.list("block_entities", tag::END, 0);
        w.tag(tag::COMPOUND, "structures");
        w.tag(tag::COMPOUND, "References");
        w.end();
        w.tag(tag::COMPOUND, "starts");
        w.end();
        w.end();
        w.end();
        self.last_len = w.0.len();
        w.0
    }

    /// Writes the `block_states` compound of section `s`.
    fn block_states(&mut self, w: &mut Writer, section: &[u16]) {
        self.palette.clear();
        // A section of one block (the air above the ground, solid rock) has a palette of one
        // and no data: a comparison per block finds that faster than the table below.
        if let Some(&first) = section.first().filter(|&&first| section.iter().all(|&raw| raw == first)) {
            w.tag(tag::COMPOUND, "block_states");
            w.list("palette", tag::COMPOUND, 1);
            w.0.extend_from_slice(self.entries[usize::from(first)].get_or_insert_with(|| palette_entry(first)));
            w.end();
            return;
        }
        for (index, &raw) in self.indices.iter_mut().zip(section) {
            // A table lookup for every block, and a branch only for a block new to the
            // section (a handful a section): comparing with the previous block first was a
            // misprediction at every change of block among ores, caves and ground.
            let mut slot = self.slots[usize::from(raw)];
            if slot == NO_SLOT {
                slot = self.palette.len() as u16;
                self.slots[usize::from(raw)] = slot;
                self.palette.push(raw);
            }
            *index = slot;
        }

        w.tag(tag::COMPOUND, "block_states");
        w.list("palette", tag::COMPOUND, self.palette.len());
        for &raw in &self.palette {
            self.slots[usize::from(raw)] = NO_SLOT;
            let entry = self.entries[usize::from(raw)].get_or_insert_with(|| palette_entry(raw));
            w.0.extend_from_slice(entry);
        }
        if self.palette.len() > 1 {
            let bits = bit_width(self.palette.len() - 1).max(4);
            w.packed("data", &self.indices, bits);
        }
        w.end();
    }

    /// Writes the `biomes` compound of section `s`.
    fn biomes(&mut self, w: &mut Writer, chunk: &impl Chunk, s: u32) {
        self.biome_palette.clear();
        let mut i = 0;
        for y in s * 4..s * 4 + 4 {
            for z in 0..4 {
                for x in 0..4 {
                    let biome = chunk.biome(x, y, z);
                    let slot = match self.biome_palette.iter().position(|&b| b == biome) {
                        Some(slot) => slot,
                        None => {
                            self.biome_palette.push(biome);
                            self.biome_palette.len() - 1
                        }
                    };
                    self.biome_indices[i] = slot as u16;
                    i += 1;
                }
            }
        }

        w.tag(tag::COMPOUND, "biomes");
        w.list("palette", tag::STRING, self.biome_palette.len());
        for &biome in &self.biome_palette {
            // An id outside the names given is a caller's bug; plains keeps the file loadable.
            let name = self.biome_names.get(biome.to_index()).map_or("minecraft:plains", String::as_str);
            w.str_payload(name);
        }
        if self.biome_palette.len() > 1 {
            w.packed("data", &self.biome_indices, bit_width(self.biome_palette.len() - 1));
        }
        w.end();
    }
}

/// The body of block state `raw`'s palette compound: `Name` and, when the block has any,
/// `Properties`, then the closing end tag.
fn palette_entry(raw: u16) -> Box<[u8]> {
    let state = BlockState::from_raw(raw).unwrap_or(BlockState::AIR);
    let kind = state.to_kind();
    let mut w = Writer(Vec::with_capacity(64));
    w.tag(tag::STRING, "Name");
    let name = kind.to_str();
    w.0.extend_from_slice(&((name.len() + 10) as u16).to_be_bytes());
    w.0.extend_from_slice(b"minecraft:");
    w.0.extend_from_slice(name.as_bytes());
    if !kind.props().is_empty() {
        w.tag(tag::COMPOUND, "Properties");
        for &prop in kind.props() {
            if let Some(value) = state.get(prop) {
                w.string(prop.to_str(), value.to_str());
            }
        }
        w.end();
    }
    w.end();
    w.0.into_boxed_slice()
}
