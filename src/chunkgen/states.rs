//! A chunk's block states read once into a flat array, for the consumers that visit every
//! block: light and the region-file encoder.
//!
//! valence's chunk answers one block at a time through its paletted sections (a bounds check,
//! a section lookup and a nibble unpacking each); reading every block twice, once for light
//! and once for the encoder, was a tenth of pre-generation's time.

use valence::prelude::Chunk;

/// Blocks in a section.
pub const SECTION_BLOCKS: usize = 4096;

/// Index of chunk-local block (`x`, `y`, `z`) in a chunk's flat arrays, section order
/// (`(y·16 + z)·16 + x`): [`States`], light levels and the generator's `Blocks`.
#[inline]
pub fn index(x: u32, y: u32, z: u32) -> usize {
    debug_assert!(x < 16 && z < 16, "block {x}, {y}, {z} is outside the chunk");
    ((y * 16 + z) * 16 + x) as usize
}

/// Raw block-state ids of every block of a chunk, index `(y·16 + z)·16 + x` (the order of a
/// section's blocks in the protocol and in region files).
pub struct States {
    height: u32,
    ids: Vec<u16>,
}

impl States {
    /// Reads every block of `chunk`.
    pub fn of(chunk: &impl Chunk) -> States {
        let height = chunk.height();
        let mut ids = Vec::with_capacity(height as usize * 256);
        for y in 0..height {
            for z in 0..16 {
                for x in 0..16 {
                    ids.push(chunk.block_state(x, y, z).to_raw());
                }
            }
        }
        States { height, ids }
    }

    /// States from raw ids already in section order (`height · 256` of them).
    pub(crate) fn from_ids(height: u32, ids: Vec<u16>) -> States {
        assert_eq!(ids.len(), height as usize * 256, "a chunk {height} blocks tall");
        States { height, ids }
    }

    /// Height of the chunk, blocks.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Every id, index `(y·16 + z)·16 + x`.
    pub fn ids(&self) -> &[u16] {
        &self.ids
    }

    /// The ids of section `s` (counted from the world's floor).
    pub fn section(&self, s: u32) -> &[u16] {
        let start = s as usize * SECTION_BLOCKS;
        &self.ids[start..start + SECTION_BLOCKS]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use valence::prelude::{BlockState, UnloadedChunk};

    #[test]
    fn every_block_is_read_in_section_order() {
        let mut chunk = UnloadedChunk::with_height(32);
        chunk.set_block_state(3, 17, 5, BlockState::STONE);
        chunk.set_block_state(0, 0, 0, BlockState::LAVA);
        let states = States::of(&chunk);
        assert_eq!(states.height(), 32);
        assert_eq!(states.ids().len(), 32 * 256);
        // Y 17 is the second section's local Y 1.
        assert_eq!(states.section(1)[(16 + 5) * 16 + 3], BlockState::STONE.to_raw());
        assert_eq!(states.ids()[0], BlockState::LAVA.to_raw());
        assert_eq!(states.ids().iter().filter(|&&id| id != BlockState::AIR.to_raw()).count(), 2);
    }
}
