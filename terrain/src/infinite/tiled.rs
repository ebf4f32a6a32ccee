//! A plain [`Source`] behind the engine's cache, in non-overlapping tiles.
//!
//! Procedural fields are pure functions of position but not free: the layout's coarse
//! elevation is several octaves of warped gradient noise per cell, and the continent's
//! drainage, its rain sweep and the climate's overlapping windows each read it over thousands
//! of kilometres. Served as tiles of a windowed tensor whose windows do not overlap (weight
//! 1, one window per cell), each cell is computed once while it stays cached, and the values
//! are the source's bit for bit.

use std::sync::Arc;

use super::{Engine, Source, WindowFn, WindowIndex, WindowLayout, Windowed};
use crate::tile::Tile;

/// `source`, cached by `engine` in `tile` × `tile` tiles; `name` for statistics.
pub fn tiled(engine: &Arc<Engine>, source: Arc<dyn Source>, tile: i64, name: &'static str) -> Arc<Windowed> {
    Windowed::new(engine, Tiles { source, tile, name })
}

struct Tiles {
    source: Arc<dyn Source>,
    tile: i64,
    name: &'static str,
}

impl WindowFn for Tiles {
    fn name(&self) -> &str {
        self.name
    }

    fn channels(&self) -> usize {
        self.source.channels()
    }

    fn layout(&self) -> WindowLayout {
        WindowLayout::square(self.tile, self.tile, 0)
    }

    fn eval(&self, windows: &[WindowIndex]) -> Vec<Tile> {
        windows.iter().map(|&w| self.source.query(self.layout().rect(w))).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::infinite::EngineConfig;
    use crate::tile::Rect;

    struct Field;
    impl Source for Field {
        fn channels(&self) -> usize {
            2
        }
        fn query(&self, rect: Rect) -> Tile {
            let n = rect.area();
            let mut t = Tile::zeros(2, rect);
            let mut i = 0;
            for y in rect.y0..rect.y1() {
                for x in rect.x0..rect.x1() {
                    t.data[i] = ((y * 31 + x) as f32).sin() * 1234.5;
                    t.data[n + i] = (x - y) as f32 / 3.0;
                    i += 1;
                }
            }
            t
        }
    }

    #[test]
    fn tiles_answer_the_sources_bits() {
        let engine = Arc::new(Engine::new(EngineConfig { cache_bytes: 1 << 20, threads: 1 }));
        let cached = tiled(&engine, Arc::new(Field), 8, "field");
        for rect in [Rect::new(-13, 5, 30, 7), Rect::new(0, 0, 1, 1), Rect::new(-3, -40, 17, 33)] {
            assert_eq!(cached.query(rect), Field.query(rect), "{rect:?}");
        }
    }
}
