//! Anvil NBT bytes → chunk, through valence's NBT reader, checking everything it reads.

use std::sync::Arc;

use valence::nbt::{Compound, List, Value};
use valence::prelude::{BiomeId, BlockKind, BlockState, Chunk, PropName, PropValue, UnloadedChunk};

use super::nbt::{bit_width, packed_len, tag};
use super::{BLOCKS, CELLS, DATA_VERSION};
use crate::chunkgen::BiomePalette;

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
