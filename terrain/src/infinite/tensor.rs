//! A windowed infinite tensor: the InfiniteDiffusion update for one step of one stage.

use std::sync::atomic::Ordering;
use std::sync::Arc;

use super::engine::{Engine, Lookup, WindowKey};
use super::window::{WindowIndex, WindowLayout};
use super::Source;
use crate::tile::{Rect, Tile};

/// Φ: what a windowed tensor computes for each window.
///
/// Implementations query their inputs (other [`Source`]s: the previous step, the stage
/// above, conditioning fields) over whatever region they need, and must be pure functions of
/// the window index and those inputs, which is what makes the whole tensor seed-consistent.
pub trait WindowFn: Send + Sync {
    /// A short name for logs and statistics.
    fn name(&self) -> &str;
    /// Channels of every output.
    fn channels(&self) -> usize;
    /// The window layout (size, stride, offset per axis).
    fn layout(&self) -> WindowLayout;
    /// How many windows Φ prefers to see at once (a network's batch).
    fn batch_size(&self) -> usize {
        1
    }
    /// Φ for a batch of windows: one tile per window, over `layout().rect(window)`.
    fn eval(&self, windows: &[WindowIndex]) -> Vec<Tile>;
}

/// An unbounded tensor whose value is the tent-weighted average of Φ over all windows
/// touching each cell (J_t[R] = Σ U(W ⊙ Φ) / Σ U(W)), evaluated lazily and cached.
pub struct Windowed {
    id: u32,
    f: Box<dyn WindowFn>,
    layout: WindowLayout,
    weight_y: Vec<f32>,
    weight_x: Vec<f32>,
    engine: Arc<Engine>,
}

impl Windowed {
    /// Wraps Φ as a tensor served by `engine`'s cache. Panics on a layout that leaves cells
    /// uncovered (stride > size), which is a programming error.
    pub fn new(engine: &Arc<Engine>, f: impl WindowFn + 'static) -> Arc<Windowed> {
        let layout = f.layout();
        if let Err(e) = layout.validate() {
            panic!("window layout of {}: {e}", f.name());
        }
        Arc::new(Windowed {
            id: engine.register(f.name()),
            weight_y: layout.y.tent(),
            weight_x: layout.x.tent(),
            layout,
            f: Box::new(f),
            engine: engine.clone(),
        })
    }

    /// Windows of this tensor evaluated so far.
    pub fn evaluations(&self) -> u64 {
        self.engine.evaluations_of(self.id)
    }

    /// The window layout.
    pub fn layout(&self) -> WindowLayout {
        self.layout
    }

    /// Φ's name.
    pub fn name(&self) -> &str {
        self.f.name()
    }

    fn key(&self, i: WindowIndex) -> WindowKey {
        (self.id, i.iy, i.ix)
    }

    /// Evaluates Φ on `windows` (all claimed by the caller) and publishes each contribution.
    fn compute(&self, windows: &[WindowIndex]) -> Vec<Arc<[f32]>> {
        /// Releases unpublished claims if Φ panics, so waiters can claim them instead.
        struct Claims<'a> {
            engine: &'a Engine,
            keys: Vec<WindowKey>,
            published: Vec<std::sync::atomic::AtomicBool>,
        }
        impl Drop for Claims<'_> {
            fn drop(&mut self) {
                let left: Vec<_> = self
                    .keys
                    .iter()
                    .zip(&self.published)
                    .filter(|(_, p)| !p.load(Ordering::Acquire))
                    .map(|(k, _)| *k)
                    .collect();
                if !left.is_empty() {
                    self.engine.abandon(&left);
                }
            }
        }
        let claims = Claims {
            engine: &self.engine,
            keys: windows.iter().map(|&i| self.key(i)).collect(),
            published: windows.iter().map(|_| Default::default()).collect(),
        };
        // Batches of at most Φ's preferred size, but never fewer batches than worker threads
        // when there are enough windows: two windows claimed by one query run on two threads
        // rather than as one batch on one (what a player walking into fresh ground triggers).
        let batch = self.f.batch_size().max(1).min(windows.len().div_ceil(self.engine.threads())).max(1);
        let batches: Vec<(usize, &[WindowIndex])> =
            windows.chunks(batch).enumerate().map(|(b, w)| (b * batch, w)).collect();
        let per_batch = self.engine.par_map(&batches, |&(first, ws)| {
            let start = std::time::Instant::now();
            let outs = self.f.eval(ws);
            assert_eq!(outs.len(), ws.len(), "{} returned the wrong number of windows", self.name());
            self.engine.count_evaluations(self.id, ws.len(), start.elapsed().as_secs_f64());
            outs.into_iter()
                .zip(ws)
                .enumerate()
                .map(|(k, (tile, &w))| {
                    let contribution = self.weigh(w, tile);
                    self.engine.publish(claims.keys[first + k], contribution.clone());
                    claims.published[first + k].store(true, Ordering::Release);
                    contribution
                })
                .collect::<Vec<_>>()
        });
        per_batch.into_iter().flatten().collect()
    }

    /// W ⊙ Φ for one window.
    fn weigh(&self, w: WindowIndex, tile: Tile) -> Arc<[f32]> {
        let rect = self.layout.rect(w);
        assert!(
            tile.rect == rect && tile.channels == self.f.channels(),
            "{}: window {w:?} returned {:?}×{} instead of {rect:?}×{}",
            self.name(),
            tile.rect,
            tile.channels,
            self.f.channels()
        );
        let (h, wd) = (rect.h as usize, rect.w as usize);
        let mut data = tile.data;
        for plane in data.chunks_mut(h * wd) {
            for (row, wy) in plane.chunks_mut(wd).zip(&self.weight_y) {
                for (v, wx) in row.iter_mut().zip(&self.weight_x) {
                    *v *= wy * wx;
                }
            }
        }
        data.into()
    }

    /// Sum of the weights of all windows covering each cell of `[start, stop)` on one axis.
    fn weight_sums(axis: &super::window::Axis, weights: &[f32], start: i64, stop: i64) -> Vec<f32> {
        let (lo, hi) = axis.windows(start, stop);
        (start..stop)
            .map(|c| {
                let mut s = 0.0f32;
                for i in lo..=hi {
                    let k = c - axis.start(i);
                    if (0..axis.size).contains(&k) {
                        s += weights[k as usize];
                    }
                }
                s
            })
            .collect()
    }
}

impl Source for Windowed {
    fn channels(&self) -> usize {
        self.f.channels()
    }

    fn query(&self, rect: Rect) -> Tile {
        let windows = self.layout.windows(&rect);
        let mut contributions: Vec<Option<Arc<[f32]>>> = vec![None; windows.len()];
        let mut todo: Vec<usize> = (0..windows.len()).collect();
        while !todo.is_empty() {
            let looked = self.engine.lookup(todo.iter().map(|&k| self.key(windows[k])));
            let (mut claimed, mut waiting) = (Vec::new(), Vec::new());
            for (&k, l) in todo.iter().zip(looked) {
                match l {
                    Lookup::Ready(v) => contributions[k] = Some(v),
                    Lookup::InFlight => waiting.push(k),
                    Lookup::Claimed => claimed.push(k),
                }
            }
            if !claimed.is_empty() {
                let ws: Vec<WindowIndex> = claimed.iter().map(|&k| windows[k]).collect();
                for (k, v) in claimed.into_iter().zip(self.compute(&ws)) {
                    contributions[k] = Some(v);
                }
            }
            if !waiting.is_empty() {
                let keys: Vec<WindowKey> = waiting.iter().map(|&k| self.key(windows[k])).collect();
                self.engine.wait_settled(&keys);
            }
            // Windows finished by others are normally cached now; one evicted in between is
            // simply claimed on the next pass.
            todo = waiting;
        }

        let channels = self.f.channels();
        let mut out = Tile::zeros(channels, rect);
        let (oh, ow) = (rect.h as usize, rect.w as usize);
        for (w, contribution) in windows.iter().zip(&contributions) {
            let contribution = contribution.as_ref().expect("every window was resolved");
            let wr = self.layout.rect(*w);
            let Some(part) = wr.intersect(&rect) else { continue };
            let (wh, ww) = (wr.h as usize, wr.w as usize);
            for c in 0..channels {
                for y in part.y0..part.y1() {
                    let src = (c * wh + (y - wr.y0) as usize) * ww + (part.x0 - wr.x0) as usize;
                    let dst = (c * oh + (y - rect.y0) as usize) * ow + (part.x0 - rect.x0) as usize;
                    let n = part.w as usize;
                    for (o, v) in out.data[dst..dst + n].iter_mut().zip(&contribution[src..src + n]) {
                        *o += v;
                    }
                }
            }
        }
        let sy = Self::weight_sums(&self.layout.y, &self.weight_y, rect.y0, rect.y1());
        let sx = Self::weight_sums(&self.layout.x, &self.weight_x, rect.x0, rect.x1());
        for plane in out.data.chunks_mut(oh * ow) {
            for (row, wy) in plane.chunks_mut(ow).zip(&sy) {
                for (v, wx) in row.iter_mut().zip(&sx) {
                    *v /= wy * wx;
                }
            }
        }
        out
    }
}
