//! Chunks ⇄ Anvil chunk NBT, as Minecraft 1.20.1 stores a finished chunk in a region file.
//!
//! Encoding writes the NBT bytes directly instead of building a `Compound` first: a chunk is
//! encoded every time one is generated, and this way the whole chunk costs one pass over its
//! blocks, no allocation per block or per palette entry (each block state's palette entry is
//! serialised once per [`Encoder`] and copied afterwards) and a fixed field order, so the same
//! chunk always gives the same bytes. Decoding is rarer (a chunk loaded from disk) and goes
//! through valence's NBT reader, checking everything it reads.
//!
//! Three parts: `encode` (chunk → bytes), `decode` (bytes → chunk) and `nbt` (the tag
//! ids, the byte writer and Anvil's bit packing that both sides share).

mod decode;
mod encode;
mod nbt;

pub use decode::{DecodeError, Decoder};
pub use encode::Encoder;

/// Minecraft 1.20.1's data version.
pub const DATA_VERSION: i32 = 3465;

/// Blocks in a section.
const BLOCKS: usize = 16 * 16 * 16;
/// Biome cells (4×4×4 blocks each) in a section.
const CELLS: usize = 4 * 4 * 4;

#[cfg(test)]
mod tests;
