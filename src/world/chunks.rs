//! Chunks as the server and the pre-generator get them: loaded from disk when saved,
//! otherwise generated and saved. A saved chunk that cannot be read is reported and
//! generated again; generation is deterministic, so it comes back identical.

use std::sync::Arc;

use valence::prelude::UnloadedChunk;

use super::codec::{Decoder, Encoder};
use super::store::{Store, StoreError};
use crate::biome::BiomeRules;
use crate::chunkgen::{BiomePalette, Generator, Light};

/// Where a chunk came from.
#[derive(Clone, Debug, PartialEq)]
pub enum Origin {
    /// Read from its region file.
    Loaded,
    /// Generated (and saved, when saving is on).
    Generated,
    /// Its saved copy was unreadable (the reason): generated again and saved over it.
    Regenerated(String),
}

/// Generator + saved world.
pub struct ChunkSource {
    generator: Arc<Generator>,
    palette: Arc<BiomePalette>,
    store: Option<Arc<Store>>,
}

/// Per-thread scratch: the codec's caches.
pub struct Scratch {
    encoder: Encoder,
    decoder: Decoder,
}

impl ChunkSource {
    /// Chunks from `generator`, saved to and loaded from `store` when there is one.
    pub fn new(generator: Arc<Generator>, palette: Arc<BiomePalette>, store: Option<Arc<Store>>) -> ChunkSource {
        ChunkSource { generator, palette, store }
    }

    /// The generator.
    pub fn generator(&self) -> &Arc<Generator> {
        &self.generator
    }

    /// The saved world, if saving is on.
    pub fn store(&self) -> Option<&Arc<Store>> {
        self.store.as_ref()
    }

    /// Fresh scratch for one thread.
    pub fn scratch(&self) -> Scratch {
        let v = self.generator.vertical();
        Scratch {
            encoder: Encoder::new(v.min_y, self.palette.names().to_vec()),
            decoder: Decoder::new(v.min_y, v.height as u32, self.palette.clone()),
        }
    }

    /// The chunk at (`x`, `z`) and its own light: from disk when saved and readable, else
    /// generated with `rules` and queued for saving (without light: a chunk lit alone is not
    /// lit right at its borders, see [`Encoder::encode_states`]). A chunk that cannot be saved
    /// (a full disk) is still returned, so players keep playing; the error is logged and
    /// recorded in the store.
    pub fn get(&self, scratch: &mut Scratch, rules: &BiomeRules, x: i32, z: i32) -> (UnloadedChunk, Light, Origin) {
        let Some(store) = &self.store else {
            let blocks = self.generator.blocks(rules, &self.palette, x, z);
            let light = Light::of_states(&blocks.states());
            return (blocks.to_chunk(), light, Origin::Generated);
        };
        let origin = match store.load(x, z) {
            Ok(None) => Origin::Generated,
            Ok(Some(nbt)) => match scratch.decoder.decode(x, z, &nbt) {
                Ok(chunk) => {
                    let light = Light::of(&chunk);
                    return (chunk, light, Origin::Loaded);
                }
                Err(e) => Origin::Regenerated(format!("chunk {x}, {z} in {}: {e}", self.region_file(x, z))),
            },
            Err(e) => Origin::Regenerated(e.to_string()),
        };
        let blocks = self.generator.blocks(rules, &self.palette, x, z);
        let states = blocks.states();
        let light = Light::of_states(&states);
        let nbt = scratch.encoder.encode_states(x, z, &blocks, &states, None);
        if let Err(e) = store.save(x, z, &nbt) {
            tracing::error!("{e}");
        }
        (blocks.to_chunk(), light, origin)
    }

    /// Makes sure chunk (`x`, `z`) is saved: a chunk already in its region file is left as it
    /// is (so a resumed task skips what it did before the crash); returns whether it was
    /// generated now.
    pub fn ensure_saved(&self, scratch: &mut Scratch, rules: &BiomeRules, x: i32, z: i32) -> Result<bool, StoreError> {
        let Some(store) = &self.store else { return Ok(false) };
        if store.contains(x, z)? {
            return Ok(false);
        }
        // Encoded from the generator's arrays: no paletted chunk is built at all. Saved
        // without light, which Minecraft computes when it loads the chunk with its
        // neighbours (this one's own would be too dark where light crosses its borders).
        let blocks = self.generator.blocks(rules, &self.palette, x, z);
        let states = blocks.states();
        let nbt = scratch.encoder.encode_states(x, z, &blocks, &states, None);
        store.save(x, z, &nbt)?;
        Ok(true)
    }

    fn region_file(&self, x: i32, z: i32) -> String {
        let file = super::region::RegionPos::of_chunk(x, z).file_name();
        match &self.store {
            Some(store) => store.region_dir().join(file).display().to_string(),
            None => file,
        }
    }
}
