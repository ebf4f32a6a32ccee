//! The infinite-tensor engine: lazily evaluated, unbounded 2-D tensors.
//!
//! Owns the InfiniteDiffusion update (κ(R), tent-weighted blending of overlapping windows,
//! normalisation by summed weights), the byte-bounded window cache and the batched parallel
//! evaluation of missing windows. It knows nothing about terrain, climate or Minecraft:
//! stages plug in as [`WindowFn`]s and as plain [`Source`]s.

mod engine;
mod tensor;
mod tiled;
mod window;

pub use engine::{cache_capacity_hint, Engine, EngineConfig, EngineStats, FunctionStats};
pub use tensor::{WindowFn, Windowed};
pub use tiled::tiled;
pub use window::{Axis, WindowIndex, WindowLayout, EDGE_WEIGHT};

use crate::tile::{Rect, Tile};

/// Anything that answers "the values of this rectangle" on an unbounded grid: a windowed
/// tensor, a noise field, a procedural layout. Answers must be pure functions of the
/// rectangle (and the source's own seed), so any order of queries gives the same values.
pub trait Source: Send + Sync {
    /// Channels of every answer.
    fn channels(&self) -> usize;
    /// The values over `rect`.
    fn query(&self, rect: Rect) -> Tile;
}

impl<S: Source + ?Sized> Source for std::sync::Arc<S> {
    fn channels(&self) -> usize {
        (**self).channels()
    }
    fn query(&self, rect: Rect) -> Tile {
        (**self).query(rect)
    }
}

#[cfg(test)]
mod tests;
