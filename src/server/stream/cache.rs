//! Finished chunks kept for revisits, least recently used dropped first.

use std::num::NonZeroUsize;

use lru::LruCache;
use valence::prelude::ChunkPos;

use super::workers::Built;

/// A bounded cache of chunks; capacity 0 keeps nothing.
pub struct ChunkCache(Option<LruCache<ChunkPos, Built>>);

impl ChunkCache {
    /// A cache of at most `capacity` chunks.
    pub fn new(capacity: usize) -> ChunkCache {
        ChunkCache(NonZeroUsize::new(capacity).map(LruCache::new))
    }

    /// Keeps `chunk`, dropping the least recently used one when full.
    pub fn put(&mut self, pos: ChunkPos, chunk: Built) {
        if let Some(cache) = &mut self.0 {
            cache.put(pos, chunk);
        }
    }

    /// Takes the chunk at `pos` out of the cache.
    pub fn take(&mut self, pos: ChunkPos) -> Option<Built> {
        self.0.as_mut()?.pop(&pos)
    }

    /// Chunks held.
    pub fn len(&self) -> usize {
        self.0.as_ref().map_or(0, LruCache::len)
    }

    /// Drops the chunk at `pos`, if held.
    pub fn drop_chunk(&mut self, pos: ChunkPos) {
        if let Some(cache) = &mut self.0 {
            cache.pop(&pos);
        }
    }

    /// Drops everything.
    pub fn clear(&mut self) {
        if let Some(cache) = &mut self.0 {
            cache.clear();
        }
    }
}

#[cfg(test)]
mod tests {
    use valence::prelude::UnloadedChunk;
    use valence::protocol::CompressionThreshold;

    use super::super::light::Lit;
    use super::*;
    use crate::chunkgen::Light;

    fn built() -> Built {
        let (chunk, pos) = (UnloadedChunk::with_height(16), ChunkPos::new(0, 0));
        Built { lit: Lit::alone(pos, Light::of(&chunk), CompressionThreshold::default()).expect("encodes"), chunk }
    }

    #[test]
    fn keeps_at_most_its_capacity_and_drops_the_least_recent() {
        let mut cache = ChunkCache::new(2);
        for x in 0..3 {
            cache.put(ChunkPos::new(x, 0), built());
        }
        assert_eq!(cache.len(), 2);
        assert!(cache.take(ChunkPos::new(0, 0)).is_none());
        assert!(cache.take(ChunkPos::new(2, 0)).is_some());
        assert_eq!(cache.len(), 1);
        cache.clear();
        assert_eq!(cache.len(), 0);
    }

    #[test]
    fn capacity_zero_keeps_nothing() {
        let mut cache = ChunkCache::new(0);
        cache.put(ChunkPos::new(0, 0), built());
        assert_eq!(cache.len(), 0);
        assert!(cache.take(ChunkPos::new(0, 0)).is_none());
    }
}
