//! A chunk's blocks and biomes while it is being generated: plain arrays, one entry per block
//! and per 4×4×4 biome cell, behind valence's [`Chunk`] trait so the passes read and write
//! them as they would a valence chunk.
//!
//! valence's [`UnloadedChunk`] keeps every section paletted: each read unpacks a few bits,
//! each write searches (and grows) the section's palette. The passes touch every block of a
//! chunk several times over (rock, caves, ores, surface, trees), and light and the
//! region-file encoder read them all back. Here a read or a write is one array access; the
//! paletted chunk is built once at the end, for the server ([`Blocks::to_chunk`]), and not at
//! all for pre-generation, which encodes from the arrays ([`Blocks::states`]).

use valence::nbt::Compound;
use valence::prelude::{BiomeId, BlockState, Chunk, UnloadedChunk};

use super::states::{index, States, SECTION_BLOCKS};

/// Biome cells in a section (4 × 4 × 4).
const SECTION_CELLS: usize = 64;

/// Every block state and biome of one chunk, in section order (index `(y·16 + z)·16 + x` for
/// blocks, `(y·4 + z)·4 + x` for biome cells).
#[derive(Clone, Debug, PartialEq)]
pub struct Blocks {
    height: u32,
    states: Vec<BlockState>,
    biomes: Vec<BiomeId>,
}

impl Blocks {
    /// An empty chunk (all air, the default biome) `height` blocks tall (a multiple of 16).
    pub fn with_height(height: u32) -> Blocks {
        assert!(height % 16 == 0, "a chunk's height is whole sections, not {height}");
        Blocks {
            height,
            states: vec![BlockState::AIR; height as usize * 256],
            biomes: vec![BiomeId::default(); height as usize / 4 * 16],
        }
    }

    #[inline]
    fn cell(x: u32, y: u32, z: u32) -> usize {
        debug_assert!(x < 4 && z < 4, "biome cell {x}, {y}, {z} is outside the chunk");
        ((y * 4 + z) * 4 + x) as usize
    }

    /// The raw block-state ids, for light and the region-file encoder.
    pub fn states(&self) -> States {
        States::from_ids(self.height, self.states.iter().map(|s| s.to_raw()).collect())
    }

    /// The same chunk as valence keeps it (paletted), for the server: a uniform section is
    /// filled whole, the others block by block (air, what a new chunk holds, is skipped).
    pub fn to_chunk(&self) -> UnloadedChunk {
        let mut chunk = UnloadedChunk::with_height(self.height);
        for s in 0..self.height / 16 {
            let blocks = &self.states[s as usize * SECTION_BLOCKS..(s as usize + 1) * SECTION_BLOCKS];
            if let Some(&only) = uniform(blocks) {
                if only != BlockState::AIR {
                    chunk.fill_block_state_section(s, only);
                }
            } else {
                for (i, &state) in blocks.iter().enumerate().filter(|(_, &b)| b != BlockState::AIR) {
                    let i = i as u32;
                    chunk.set_block_state(i % 16, s * 16 + i / 256, i / 16 % 16, state);
                }
            }
            let cells = &self.biomes[s as usize * SECTION_CELLS..(s as usize + 1) * SECTION_CELLS];
            if let Some(&only) = uniform(cells) {
                chunk.fill_biome_section(s, only);
            } else {
                for (i, &biome) in cells.iter().enumerate() {
                    let i = i as u32;
                    chunk.set_biome(i % 4, s * 4 + i / 16, i / 4 % 4, biome);
                }
            }
        }
        chunk
    }
}

impl Blocks {
    /// The 256 blocks at height `y` (counted from the chunk's floor), index `z·16 + x`: for
    /// passes that fill layers rather than columns.
    pub fn layer_mut(&mut self, y: u32) -> &mut [BlockState] {
        let start = index(0, y, 0);
        &mut self.states[start..start + 256]
    }
}

/// The one value every entry of `values` holds, if they all hold the same.
fn uniform<T: PartialEq>(values: &[T]) -> Option<&T> {
    let first = values.first()?;
    values.iter().all(|v| v == first).then_some(first)
}

impl Chunk for Blocks {
    fn height(&self) -> u32 {
        self.height
    }

    #[inline]
    fn block_state(&self, x: u32, y: u32, z: u32) -> BlockState {
        self.states[index(x, y, z)]
    }

    #[inline]
    fn set_block_state(&mut self, x: u32, y: u32, z: u32, block: BlockState) -> BlockState {
        std::mem::replace(&mut self.states[index(x, y, z)], block)
    }

    fn fill_block_state_section(&mut self, sect_y: u32, block: BlockState) {
        let start = sect_y as usize * SECTION_BLOCKS;
        self.states[start..start + SECTION_BLOCKS].fill(block);
    }

    // Generation places no block entities (chests, signs): there are none to keep.
    fn block_entity(&self, _x: u32, _y: u32, _z: u32) -> Option<&Compound> {
        None
    }

    fn block_entity_mut(&mut self, _x: u32, _y: u32, _z: u32) -> Option<&mut Compound> {
        None
    }

    fn set_block_entity(&mut self, _x: u32, _y: u32, _z: u32, _block_entity: Option<Compound>) -> Option<Compound> {
        None
    }

    fn clear_block_entities(&mut self) {}

    #[inline]
    fn biome(&self, x: u32, y: u32, z: u32) -> BiomeId {
        self.biomes[Blocks::cell(x, y, z)]
    }

    fn set_biome(&mut self, x: u32, y: u32, z: u32, biome: BiomeId) -> BiomeId {
        std::mem::replace(&mut self.biomes[Blocks::cell(x, y, z)], biome)
    }

    fn fill_biome_section(&mut self, sect_y: u32, biome: BiomeId) {
        let start = sect_y as usize * SECTION_CELLS;
        self.biomes[start..start + SECTION_CELLS].fill(biome);
    }

    fn shrink_to_fit(&mut self) {}
}

/// Test support: panics, naming the first difference, unless `a` and `b` hold the same
/// blocks and biomes (whatever their representation).
#[cfg(test)]
pub(crate) fn assert_same(a: &impl Chunk, b: &impl Chunk) {
    assert_eq!(a.height(), b.height());
    for y in 0..a.height() {
        for z in 0..16 {
            for x in 0..16 {
                assert_eq!(a.block_state(x, y, z), b.block_state(x, y, z), "block {x} {y} {z}");
            }
        }
    }
    for y in 0..a.height() / 4 {
        for z in 0..4 {
            for x in 0..4 {
                assert_eq!(a.biome(x, y, z), b.biome(x, y, z), "biome cell {x} {y} {z}");
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use valence::registry::RegistryIdx;

    /// A chunk with a bit of everything: a filled section, scattered blocks, biomes per cell.
    fn sample() -> Blocks {
        let mut b = Blocks::with_height(64);
        b.fill_block_state_section(0, BlockState::DEEPSLATE);
        for i in 0..300u32 {
            let state = if i % 3 == 0 { BlockState::STONE } else { BlockState::GRASS_BLOCK };
            b.set_block_state(i * 7 % 16, 16 + i * 13 % 40, i * 5 % 16, state);
        }
        b.set_block_state(2, 5, 9, BlockState::LAVA);
        b.fill_biome_section(2, BiomeId::from_index(3));
        b.set_biome(1, 13, 2, BiomeId::from_index(5));
        b
    }

    #[test]
    fn reads_give_back_what_was_written() {
        let mut b = Blocks::with_height(32);
        assert_eq!(b.set_block_state(3, 17, 5, BlockState::STONE), BlockState::AIR);
        assert_eq!(b.set_block_state(3, 17, 5, BlockState::DIRT), BlockState::STONE);
        assert_eq!(b.block_state(3, 17, 5), BlockState::DIRT);
        assert_eq!(b.block_state(5, 17, 3), BlockState::AIR);
        assert_eq!(b.set_biome(1, 6, 3, BiomeId::from_index(4)), BiomeId::default());
        assert_eq!(b.biome(1, 6, 3), BiomeId::from_index(4));
        assert_eq!(b.biome(3, 6, 1), BiomeId::default());
    }

    #[test]
    fn the_paletted_chunk_holds_every_block_and_biome() {
        let b = sample();
        assert_same(&b.to_chunk(), &b);
    }

    #[test]
    fn states_are_read_in_section_order_as_from_the_paletted_chunk() {
        let b = sample();
        assert_eq!(b.states().ids(), States::of(&b.to_chunk()).ids());
        assert_eq!(b.states().ids()[(5 * 16 + 9) * 16 + 2], BlockState::LAVA.to_raw());
    }
}
