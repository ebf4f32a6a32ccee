//! Chunks ⇄ Anvil chunk NBT, as Minecraft 1.20.1 stores a finished chunk in a region file.
//!
//! Encoding writes the NBT bytes directly instead of building a [`Compound`] first: a chunk is
//! encoded every time one is generated, and this way the whole chunk costs one pass over its
//! blocks, no allocation per block or per palette entry (each block state's palette entry is
//! serialised once per [`Encoder`] and copied afterwards) and a fixed field order, so the same
//! chunk always gives the same bytes. Decoding is rarer (a chunk loaded from disk) and goes
//! through valence's NBT reader, checking everything it reads.

use std::sync::Arc;

use valence::nbt::{Compound, List, Value};
use valence::prelude::{BiomeId, BlockKind, BlockState, Chunk, PropName, PropValue, UnloadedChunk};
use valence::registry::RegistryIdx;

use crate::chunkgen::{BiomePalette, SkyLight};

/// Minecraft 1.20.1's data version.
pub const DATA_VERSION: i32 = 3465;

/// Blocks in a section.
const BLOCKS: usize = 16 * 16 * 16;
/// Biome cells (4×4×4 blocks each) in a section.
const CELLS: usize = 4 * 4 * 4;
/// Marks a block state that has no palette entry in the section being encoded.
const NO_SLOT: u16 = u16::MAX;

/// NBT tag ids.
mod tag {
    pub(super) const END: u8 = 0;
    pub(super) const BYTE: u8 = 1;
    pub(super) const INT: u8 = 3;
    pub(super) const LONG: u8 = 4;
    pub(super) const BYTE_ARRAY: u8 = 7;
    pub(super) const STRING: u8 = 8;
    pub(super) const LIST: u8 = 9;
    pub(super) const COMPOUND: u8 = 10;
    pub(super) const LONG_ARRAY: u8 = 12;
}

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
    /// id `i` `biome_names[i]` (the server's registry order, as [`BiomePalette::names`] gives).
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
    /// and sky light; plus the light-only sections just below and above the world when they
    /// have any light, as vanilla writes them), empty `block_entities` and `structures`.
    /// `Heightmaps` are left out: Minecraft computes missing ones when it loads the chunk.
    ///
    /// Panics when `light` is not the light of a chunk as high as `chunk`.
    pub fn encode(&mut self, chunk_x: i32, chunk_z: i32, chunk: &UnloadedChunk, light: &SkyLight) -> Vec<u8> {
        let sections = (chunk.height() / 16) as usize;
        assert_eq!(light.section_count(), sections + 2, "sky light of a chunk of another height");
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
        w.byte("isLightOn", 1);

        // Light-only sections are written only when they carry light, so count first.
        let below = light.section_bytes(0);
        let above = light.section_bytes(sections + 1);
        let count = sections + usize::from(below.is_some()) + usize::from(above.is_some());
        w.list("sections", tag::COMPOUND, count);
        if let Some(bytes) = below {
            w.byte("Y", (min_section - 1) as i8);
            w.byte_array("SkyLight", bytes);
            w.end();
        }
        for s in 0..sections {
            w.byte("Y", (min_section + s as i32) as i8);
            self.block_states(&mut w, chunk, s as u32);
            self.biomes(&mut w, chunk, s as u32);
            if let Some(bytes) = light.section_bytes(s + 1) {
                w.byte_array("SkyLight", bytes);
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
    fn block_states(&mut self, w: &mut Writer, chunk: &UnloadedChunk, s: u32) {
        self.palette.clear();
        let mut last_raw = NO_SLOT; // No block state has this raw id.
        let mut last_slot = 0u16;
        let mut i = 0;
        for y in s * 16..s * 16 + 16 {
            for z in 0..16 {
                for x in 0..16 {
                    let raw = chunk.block_state(x, y, z).to_raw();
                    // Neighbouring blocks are mostly the same: skip the table then.
                    if raw != last_raw {
                        last_raw = raw;
                        last_slot = self.slots[usize::from(raw)];
                        if last_slot == NO_SLOT {
                            last_slot = self.palette.len() as u16;
                            self.slots[usize::from(raw)] = last_slot;
                            self.palette.push(raw);
                        }
                    }
                    self.indices[i] = last_slot;
                    i += 1;
                }
            }
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
    fn biomes(&mut self, w: &mut Writer, chunk: &UnloadedChunk, s: u32) {
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

/// Bits needed to write `n`.
fn bit_width(n: usize) -> u32 {
    usize::BITS - n.leading_zeros()
}

/// Longs of `count` values of `bits` bits packed as Anvil does (no value spans two longs).
pub(crate) fn packed_len(count: usize, bits: u32) -> usize {
    count.div_ceil((64 / bits) as usize)
}

/// Appends big-endian NBT to a byte vector. Every name and string written is ASCII (block,
/// property and biome identifiers), whose modified UTF-8 is the bytes themselves.
struct Writer(Vec<u8>);

impl Writer {
    fn tag(&mut self, id: u8, name: &str) {
        self.0.push(id);
        self.str_payload(name);
    }

    fn str_payload(&mut self, s: &str) {
        debug_assert!(s.bytes().all(|b| b != 0 && b.is_ascii()), "not plain ASCII: {s:?}");
        self.0.extend_from_slice(&(s.len() as u16).to_be_bytes());
        self.0.extend_from_slice(s.as_bytes());
    }

    fn byte(&mut self, name: &str, v: i8) {
        self.tag(tag::BYTE, name);
        self.0.push(v as u8);
    }

    fn int(&mut self, name: &str, v: i32) {
        self.tag(tag::INT, name);
        self.0.extend_from_slice(&v.to_be_bytes());
    }

    fn long(&mut self, name: &str, v: i64) {
        self.tag(tag::LONG, name);
        self.0.extend_from_slice(&v.to_be_bytes());
    }

    fn string(&mut self, name: &str, v: &str) {
        self.tag(tag::STRING, name);
        self.str_payload(v);
    }

    fn byte_array(&mut self, name: &str, v: &[u8]) {
        self.tag(tag::BYTE_ARRAY, name);
        self.0.extend_from_slice(&(v.len() as i32).to_be_bytes());
        self.0.extend_from_slice(v);
    }

    /// A list header; the caller writes `len` element payloads after it.
    fn list(&mut self, name: &str, element: u8, len: usize) {
        self.tag(tag::LIST, name);
        self.0.push(element);
        self.0.extend_from_slice(&(len as i32).to_be_bytes());
    }

    /// Closes a compound.
    fn end(&mut self) {
        self.0.push(tag::END);
    }

    /// A long array of `values` packed `bits` bits each, first value in the lowest bits.
    fn packed(&mut self, name: &str, values: &[u16], bits: u32) {
        let per_long = (64 / bits) as usize;
        self.tag(tag::LONG_ARRAY, name);
        self.0.extend_from_slice(&(packed_len(values.len(), bits) as i32).to_be_bytes());
        for group in values.chunks(per_long) {
            let mut long = 0u64;
            for (j, &v) in group.iter().enumerate() {
                long |= u64::from(v) << (j as u32 * bits);
            }
            self.0.extend_from_slice(&long.to_be_bytes());
        }
    }
}

/// Why chunk NBT could not be read back; each names the value at fault.
#[derive(Debug, thiserror::Error)]
pub enum DecodeError {
    /// The bytes are not uncompressed NBT with a compound at the root.
    #[error("not NBT: {0}")]
    NotNbt(String),
    /// A field the chunk needs is absent.
    #[error("no {0} field")]
    Missing(&'static str),
    /// A field holds another kind of value.
    #[error("{field} is not {expected}")]
    WrongType {
        /// The field.
        field: &'static str,
        /// What it should be.
        expected: &'static str,
    },
    /// Saved by another Minecraft version.
    #[error("DataVersion {0} is not Minecraft 1.20.1's (only {DATA_VERSION} is read)")]
    DataVersion(i32),
    /// The chunk says it is at another position than the one it was read for.
    #[error("chunk says it is at xPos {found_x}, zPos {found_z}, not {x}, {z}")]
    Position {
        /// Expected chunk x.
        x: i32,
        /// Expected chunk z.
        z: i32,
        /// Its xPos.
        found_x: i32,
        /// Its zPos.
        found_z: i32,
    },
    /// The chunk's lowest section is not this world's.
    #[error("yPos {found} is not this world's lowest section {expected}")]
    YPos {
        /// This world's lowest section.
        expected: i32,
        /// The chunk's yPos.
        found: i32,
    },
    /// Not a finished chunk (vanilla saves half-generated ones too).
    #[error("Status {0:?} is not minecraft:full")]
    NotFull(String),
    /// A section with blocks lies outside this world's height.
    #[error("section Y {found} with blocks is outside this world's sections {min}..={max}")]
    SectionOutside {
        /// The section's Y.
        found: i32,
        /// Lowest section of the world.
        min: i32,
        /// Highest section of the world.
        max: i32,
    },
    /// Two sections have the same Y.
    #[error("section Y {0} appears twice")]
    DuplicateSection(i32),
    /// A palette is empty or longer than the section has values.
    #[error("section Y {y}: {what} palette has {len} entries")]
    PaletteLength {
        /// The section's Y.
        y: i32,
        /// `"block"` or `"biome"`.
        what: &'static str,
        /// Its length.
        len: usize,
    },
    /// A block name Minecraft 1.20.1 does not have.
    #[error("unknown block {0:?}")]
    UnknownBlock(String),
    /// A property name the block does not have.
    #[error("block {block:?} has no property {property:?}")]
    UnknownProperty {
        /// The block.
        block: String,
        /// The property.
        property: String,
    },
    /// A property value the block's property cannot take (or not a string).
    #[error("block {block:?} property {property:?} cannot be {value:?}")]
    BadPropertyValue {
        /// The block.
        block: String,
        /// The property.
        property: String,
        /// The value, as read.
        value: String,
    },
    /// A biome the server's registry does not have.
    #[error("unknown biome {0:?}")]
    UnknownBiome(String),
    /// A packed data array of the wrong length for its palette.
    #[error("section Y {y}: {what} data has {found} longs, not {expected} for a palette of {palette}")]
    DataLength {
        /// The section's Y.
        y: i32,
        /// `"block"` or `"biome"`.
        what: &'static str,
        /// Its length.
        found: usize,
        /// The length the palette implies.
        expected: usize,
        /// The palette's length.
        palette: usize,
    },
    /// A packed value that points past the end of its palette.
    #[error("section Y {y}: {what} palette index {index} out of range (palette of {palette})")]
    PaletteIndex {
        /// The section's Y.
        y: i32,
        /// `"block"` or `"biome"`.
        what: &'static str,
        /// The index read.
        index: u64,
        /// The palette's length.
        palette: usize,
    },
}

/// Turns Anvil chunk NBT back into chunks for one world's height and biome registry.
pub struct Decoder {
    min_y: i32,
    height: u32,
    biomes: Arc<BiomePalette>,
}

impl Decoder {
    /// A decoder for a world of `height` blocks from `min_y` (both multiples of 16) whose
    /// biome ids are those of `biomes`.
    pub fn new(min_y: i32, height: u32, biomes: Arc<BiomePalette>) -> Decoder {
        Decoder { min_y, height, biomes }
    }

    /// Parses uncompressed NBT bytes of the chunk expected at (`chunk_x`, `chunk_z`). Only
    /// finished chunks of Minecraft 1.20.1 (DataVersion 3465) are read; sections that are
    /// absent, or that have no `block_states` or `biomes`, are air and plains as in vanilla;
    /// light-only sections outside the world are ignored. Light, block entities and
    /// everything else are not read: the chunk's sky light is computed again from its blocks.
    pub fn decode(&self, chunk_x: i32, chunk_z: i32, nbt: &[u8]) -> Result<UnloadedChunk, DecodeError> {
        if let Some(&first) = nbt.first().filter(|&&b| b != tag::COMPOUND) {
            // valence's reader would take a lone end tag for an empty compound.
            return Err(DecodeError::NotNbt(format!("root tag {first} is not a compound (10)")));
        }
        let mut slice = nbt;
        let (mut root, _) = Compound::from_binary(&mut slice).map_err(|e| DecodeError::NotNbt(e.to_string()))?;

        let version = int(&root, "DataVersion")?;
        if version != DATA_VERSION {
            return Err(DecodeError::DataVersion(version));
        }
        let (x, z) = (int(&root, "xPos")?, int(&root, "zPos")?);
        if (x, z) != (chunk_x, chunk_z) {
            return Err(DecodeError::Position { x: chunk_x, z: chunk_z, found_x: x, found_z: z });
        }
        let min_section = self.min_y.div_euclid(16);
        if root.get("yPos").is_some() {
            let y = int(&root, "yPos")?;
            if y != min_section {
                return Err(DecodeError::YPos { expected: min_section, found: y });
            }
        }
        match root.get("Status") {
            None => {}
            Some(Value::String(s)) if s == "minecraft:full" || s == "full" => {}
            Some(Value::String(s)) => return Err(DecodeError::NotFull(s.clone())),
            Some(_) => return Err(DecodeError::WrongType { field: "Status", expected: "a string" }),
        }

        let sections = match root.remove("sections") {
            Some(Value::List(List::Compound(sections))) => sections,
            Some(Value::List(List::End)) => Vec::new(),
            Some(_) => return Err(DecodeError::WrongType { field: "sections", expected: "a list of compounds" }),
            None => return Err(DecodeError::Missing("sections")),
        };
        let count = (self.height / 16) as i32;
        let mut chunk = UnloadedChunk::with_height(self.height);
        let mut seen = vec![false; count as usize];
        let mut states = Vec::new();
        let mut biomes = Vec::new();
        for section in &sections {
            let y = match section.get("Y") {
                Some(Value::Byte(y)) => i32::from(*y),
                Some(_) => return Err(DecodeError::WrongType { field: "section Y", expected: "a byte" }),
                None => return Err(DecodeError::Missing("section Y")),
            };
            let block_states = compound(section, "block_states")?;
            let section_biomes = compound(section, "biomes")?;
            let s = y - min_section;
            if !(0..count).contains(&s) {
                if block_states.is_none() && section_biomes.is_none() {
                    continue; // Light only, as vanilla writes just below and above the world.
                }
                return Err(DecodeError::SectionOutside { found: y, min: min_section, max: min_section + count - 1 });
            }
            if std::mem::replace(&mut seen[s as usize], true) {
                return Err(DecodeError::DuplicateSection(y));
            }
            let s = s as u32;
            if let Some(block_states) = block_states {
                self.read_blocks(&mut chunk, &mut states, block_states, y, s)?;
            }
            if let Some(section_biomes) = section_biomes {
                self.read_biomes(&mut chunk, &mut biomes, section_biomes, y, s)?;
            }
        }
        Ok(chunk)
    }

    /// Reads section `s`'s `block_states` into `chunk` (`states` is scratch).
    fn read_blocks(
        &self,
        chunk: &mut UnloadedChunk,
        states: &mut Vec<BlockState>,
        block_states: &Compound,
        y: i32,
        s: u32,
    ) -> Result<(), DecodeError> {
        let palette = match block_states.get("palette") {
            Some(Value::List(List::Compound(palette))) => palette.as_slice(),
            Some(Value::List(List::End)) => &[],
            Some(_) => return Err(DecodeError::WrongType { field: "block palette", expected: "a list of compounds" }),
            None => return Err(DecodeError::Missing("block_states palette")),
        };
        if !(1..=BLOCKS).contains(&palette.len()) {
            return Err(DecodeError::PaletteLength { y, what: "block", len: palette.len() });
        }
        states.clear();
        for entry in palette {
            states.push(block_state(entry)?);
        }
        if let [state] = states.as_slice() {
            chunk.fill_block_state_section(s, *state);
            return Ok(());
        }
        let bits = bit_width(states.len() - 1).max(4);
        let data = long_array(block_states, "block_states data")?;
        let mut i = 0;
        unpack(data, BLOCKS, bits, |index| {
            let Some(&state) = states.get(index as usize) else {
                return Err(DecodeError::PaletteIndex { y, what: "block", index, palette: states.len() });
            };
            let (x, yy, z) = (i % 16, i / 256, i / 16 % 16);
            chunk.set_block_state(x, s * 16 + yy, z, state);
            i += 1;
            Ok(())
        })
        .map_err(|e| e.in_section(y, "block", states.len()))
    }

    /// Reads section `s`'s `biomes` into `chunk` (`biomes` is scratch).
    fn read_biomes(
        &self,
        chunk: &mut UnloadedChunk,
        biomes: &mut Vec<BiomeId>,
        section: &Compound,
        y: i32,
        s: u32,
    ) -> Result<(), DecodeError> {
        let palette = match section.get("palette") {
            Some(Value::List(List::String(palette))) => palette.as_slice(),
            Some(Value::List(List::End)) => &[],
            Some(_) => return Err(DecodeError::WrongType { field: "biome palette", expected: "a list of strings" }),
            None => return Err(DecodeError::Missing("biomes palette")),
        };
        if !(1..=CELLS).contains(&palette.len()) {
            return Err(DecodeError::PaletteLength { y, what: "biome", len: palette.len() });
        }
        biomes.clear();
        for name in palette {
            if !self.biomes.contains(name) {
                return Err(DecodeError::UnknownBiome(name.clone()));
            }
            biomes.push(self.biomes.id(name));
        }
        if let [biome] = biomes.as_slice() {
            chunk.fill_biome_section(s, *biome);
            return Ok(());
        }
        let data = long_array(section, "biomes data")?;
        let mut i = 0;
        unpack(data, CELLS, bit_width(biomes.len() - 1), |index| {
            let Some(&biome) = biomes.get(index as usize) else {
                return Err(DecodeError::PaletteIndex { y, what: "biome", index, palette: biomes.len() });
            };
            chunk.set_biome(i % 4, s * 4 + i / 16, i / 4 % 4, biome);
            i += 1;
            Ok(())
        })
        .map_err(|e| e.in_section(y, "biome", biomes.len()))
    }
}

impl DecodeError {
    /// Fills in the section and palette of a [`DecodeError::DataLength`] from [`unpack`].
    fn in_section(self, y: i32, what: &'static str, palette: usize) -> DecodeError {
        match self {
            DecodeError::DataLength { found, expected, .. } => {
                DecodeError::DataLength { y, what, found, expected, palette }
            }
            other => other,
        }
    }
}

/// Calls `each` with the `count` values of `bits` bits packed in `data`, after checking its
/// length (a wrong one is a [`DecodeError::DataLength`] whose section is filled in later).
fn unpack(
    data: &[i64],
    count: usize,
    bits: u32,
    mut each: impl FnMut(u64) -> Result<(), DecodeError>,
) -> Result<(), DecodeError> {
    let expected = packed_len(count, bits);
    if data.len() != expected {
        return Err(DecodeError::DataLength { y: 0, what: "", found: data.len(), expected, palette: 0 });
    }
    let per_long = (64 / bits) as usize;
    let mask = (1u64 << bits) - 1;
    let mut left = count;
    for &long in data {
        for j in 0..per_long.min(left) {
            each((long as u64 >> (j as u32 * bits)) & mask)?;
        }
        left = left.saturating_sub(per_long);
    }
    Ok(())
}

/// The block state a palette compound names.
fn block_state(entry: &Compound) -> Result<BlockState, DecodeError> {
    let name = match entry.get("Name") {
        Some(Value::String(name)) => name,
        Some(_) => return Err(DecodeError::WrongType { field: "block Name", expected: "a string" }),
        None => return Err(DecodeError::Missing("block Name")),
    };
    let path = name.strip_prefix("minecraft:").unwrap_or(name);
    let Some(kind) = BlockKind::from_str(path) else {
        return Err(DecodeError::UnknownBlock(name.clone()));
    };
    let mut state = kind.to_state();
    match entry.get("Properties") {
        None => {}
        Some(Value::Compound(props)) => {
            for (key, value) in props {
                let Some(prop) = PropName::from_str(key).filter(|p| kind.props().contains(p)) else {
                    return Err(DecodeError::UnknownProperty { block: name.clone(), property: key.clone() });
                };
                let bad = || DecodeError::BadPropertyValue {
                    block: name.clone(),
                    property: key.clone(),
                    value: match value {
                        Value::String(text) => text.clone(),
                        other => format!("{other:?}"),
                    },
                };
                let Value::String(text) = value else { return Err(bad()) };
                let Some(v) = PropValue::from_str(text) else { return Err(bad()) };
                // `set` ignores values the property cannot take: check it took.
                state = state.set(prop, v);
                if state.get(prop) != Some(v) {
                    return Err(bad());
                }
            }
        }
        Some(_) => return Err(DecodeError::WrongType { field: "block Properties", expected: "a compound" }),
    }
    Ok(state)
}

fn int(c: &Compound, field: &'static str) -> Result<i32, DecodeError> {
    match c.get(field) {
        Some(Value::Int(v)) => Ok(*v),
        Some(_) => Err(DecodeError::WrongType { field, expected: "an int" }),
        None => Err(DecodeError::Missing(field)),
    }
}

/// The compound `field` of `c`, if there is one.
fn compound<'a>(c: &'a Compound, field: &'static str) -> Result<Option<&'a Compound>, DecodeError> {
    match c.get(field) {
        Some(Value::Compound(v)) => Ok(Some(v)),
        Some(_) => Err(DecodeError::WrongType { field, expected: "a compound" }),
        None => Ok(None),
    }
}

/// The `data` long array of a `block_states` or `biomes` compound (`field` names it).
fn long_array<'a>(c: &'a Compound, field: &'static str) -> Result<&'a [i64], DecodeError> {
    match c.get("data") {
        Some(Value::LongArray(v)) => Ok(v),
        Some(_) => Err(DecodeError::WrongType { field, expected: "a long array" }),
        None => Err(DecodeError::Missing(field)),
    }
}

#[cfg(test)]
#[path = "codec_tests.rs"]
mod tests;
