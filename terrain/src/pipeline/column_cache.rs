//! Block columns remembered in aligned squares, so that neighbouring queries do not compute
//! the same columns again.
//!
//! Chunk generation asks for a chunk's columns with a border (trees rooted outside it, banks
//! settled with their neighbours): 26 × 26 columns for a 16 × 16 chunk, 2.6 times the chunk.
//! Every block column is a pure function of its position (the seam and order tests hold the
//! pipeline to that), so a column computed for one chunk is the same for the next: this cache
//! keeps the columns of aligned [`SIDE`] × [`SIDE`] squares and assembles any small query from
//! them, computing only the squares it lacks (a run of them per row, in one pipeline call).
//! Large queries (maps, exports) go straight to the pipeline: they would only churn the cache.

use std::num::NonZeroUsize;
use std::sync::{Arc, Mutex};

use lru::LruCache;

use crate::tile::{div_floor, Rect, Tile};

/// Side of a cached square, blocks (a chunk's).
pub const SIDE: i64 = 16;
/// Squares kept: 2,048 squares of 10 channels are 20 MiB, several regions' worth of chunk
/// rows, and far more than the view distance of a few players.
pub const CAPACITY: usize = 2048;
/// Queries touching more squares than this skip the cache.
const MAX_SQUARES: i64 = 64;

/// The cache: squares of block columns by (row, column) of [`SIDE`]-block squares.
pub struct ColumnCache {
    squares: Mutex<LruCache<(i64, i64), Arc<Tile>>>,
}

impl Default for ColumnCache {
    fn default() -> Self {
        ColumnCache { squares: Mutex::new(LruCache::new(NonZeroUsize::new(CAPACITY).expect("capacity > 0"))) }
    }
}

impl ColumnCache {
    /// The columns of `blocks`, from cached squares where there are, computing the rest with
    /// `compute` (which must answer any rectangle, the same value for a column whatever the
    /// rectangle around it).
    pub fn columns(&self, blocks: Rect, compute: impl Fn(Rect) -> Tile) -> Tile {
        let (r0, r1) = (div_floor(blocks.y0, SIDE), div_floor(blocks.y1() - 1, SIDE));
        let (c0, c1) = (div_floor(blocks.x0, SIDE), div_floor(blocks.x1() - 1, SIDE));
        if blocks.is_empty() || (r1 - r0 + 1) * (c1 - c0 + 1) > MAX_SQUARES {
            return compute(blocks);
        }
        let mut have: Vec<Option<Arc<Tile>>> = {
            let mut squares = self.lock();
            (r0..=r1).flat_map(|r| (c0..=c1).map(move |c| (r, c))).map(|k| squares.get(&k).cloned()).collect()
        };
        let row_len = (c1 - c0 + 1) as usize;
        for (ri, r) in (r0..=r1).enumerate() {
            let row = &mut have[ri * row_len..(ri + 1) * row_len];
            let (Some(first), Some(last)) =
                (row.iter().position(Option::is_none), row.iter().rposition(Option::is_none))
            else {
                continue;
            };
            // One call for the row's run of missing squares (any cached ones inside it are
            // recomputed to the same values: cheaper than a call each).
            let run = Rect::new(r * SIDE, (c0 + first as i64) * SIDE, SIDE, (last - first + 1) as i64 * SIDE);
            let fresh = compute(run);
            let mut squares = self.lock();
            for (i, slot) in row.iter_mut().enumerate().take(last + 1).skip(first) {
                let c = c0 + i as i64;
                let square = Arc::new(fresh.crop(Rect::new(r * SIDE, c * SIDE, SIDE, SIDE)));
                squares.put((r, c), square.clone());
                slot.get_or_insert(square);
            }
        }
        assemble(blocks, &have, (r0, c0), row_len)
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, LruCache<(i64, i64), Arc<Tile>>> {
        // A panic while holding the lock leaves only whole squares in the cache.
        self.squares.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// Copies `blocks` out of the squares `have` (row-major from square (`r0`, `c0`), `row_len`
/// a row).
fn assemble(blocks: Rect, have: &[Option<Arc<Tile>>], (r0, c0): (i64, i64), row_len: usize) -> Tile {
    let channels = have[0].as_ref().expect("every square is filled").channels;
    let mut out = Tile::zeros(channels, blocks);
    let (h, w) = (blocks.h as usize, blocks.w as usize);
    for z in blocks.y0..blocks.y1() {
        let r = div_floor(z, SIDE);
        let mut x = blocks.x0;
        while x < blocks.x1() {
            let c = div_floor(x, SIDE);
            let square =
                have[(r - r0) as usize * row_len + (c - c0) as usize].as_ref().expect("every square is filled");
            let end = ((c + 1) * SIDE).min(blocks.x1());
            let (sy, sx) = ((z - r * SIDE) as usize, (x - c * SIDE) as usize);
            let (oy, ox, len) = ((z - blocks.y0) as usize, (x - blocks.x0) as usize, (end - x) as usize);
            let side = SIDE as usize;
            for ch in 0..channels {
                let src = (ch * side + sy) * side + sx;
                let dst = (ch * h + oy) * w + ox;
                out.data[dst..dst + len].copy_from_slice(&square.data[src..src + len]);
            }
            x = end;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// A field that is a pure function of position, two channels.
    fn field(rect: Rect) -> Tile {
        let mut t = Tile::zeros(2, rect);
        let n = rect.area();
        let mut i = 0;
        for y in rect.y0..rect.y1() {
            for x in rect.x0..rect.x1() {
                t.data[i] = (y * 1000 + x) as f32;
                t.data[n + i] = ((x * 7) ^ (y * 13)) as f32;
                i += 1;
            }
        }
        t
    }

    #[test]
    fn any_rectangle_is_assembled_exactly_and_squares_are_computed_once() {
        let cache = ColumnCache::default();
        let calls = AtomicUsize::new(0);
        let compute = |r: Rect| {
            calls.fetch_add(r.area() / (SIDE * SIDE) as usize, Ordering::Relaxed);
            assert_eq!((r.y0 % SIDE, r.x0 % SIDE, r.h % SIDE, r.w % SIDE), (0, 0, 0, 0), "aligned runs: {r:?}");
            field(r)
        };
        for rect in [
            Rect::new(-5, -37, 26, 26),
            Rect::new(-4, -36, 26, 26),
            Rect::new(0, 0, 1, 1),
            Rect::new(-17, 15, 3, 40),
            Rect::new(31, -1, 2, 2),
        ] {
            assert_eq!(cache.columns(rect, compute), field(rect), "{rect:?}");
        }
        let after = calls.load(Ordering::Relaxed);
        // The same rectangles again: all from the cache.
        for rect in [Rect::new(-5, -37, 26, 26), Rect::new(-17, 15, 3, 40)] {
            assert_eq!(cache.columns(rect, compute), field(rect));
        }
        assert_eq!(calls.load(Ordering::Relaxed), after);
    }

    #[test]
    fn large_queries_go_straight_through() {
        let cache = ColumnCache::default();
        let rect = Rect::new(3, 3, 200, 200);
        assert_eq!(cache.columns(rect, field), field(rect));
        assert_eq!(cache.lock().len(), 0);
    }
}
