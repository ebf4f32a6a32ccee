//! The engine's guarantees, each as a test: seed consistency, equivalence with a direct
//! MultiDiffusion computation, constant-time access, bounded memory, no double computation.

use std::collections::HashMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

use super::*;
use crate::noise::{GaussianNoise, NoiseKey};
use crate::tile::{Rect, Tile};

/// A non-trivial Φ: a blur of its input plus a term that depends on the window index, so a
/// wrong blend, a wrong weight or a wrong window shows up in the values.
struct Smear {
    input: Arc<dyn Source>,
    layout: WindowLayout,
    channels: usize,
    /// Windows currently being computed, to catch the same window computed twice at once.
    busy: Arc<Mutex<HashMap<WindowIndex, usize>>>,
    overlaps: Arc<AtomicUsize>,
}

impl Smear {
    fn new(input: Arc<dyn Source>, layout: WindowLayout, channels: usize) -> Smear {
        Smear { input, layout, channels, busy: Default::default(), overlaps: Default::default() }
    }
}

impl WindowFn for Smear {
    fn name(&self) -> &str {
        "test.smear"
    }
    fn channels(&self) -> usize {
        self.channels
    }
    fn layout(&self) -> WindowLayout {
        self.layout
    }
    fn batch_size(&self) -> usize {
        3
    }
    fn eval(&self, windows: &[WindowIndex]) -> Vec<Tile> {
        windows
            .iter()
            .map(|&w| {
                {
                    let mut busy = self.busy.lock().unwrap();
                    let n = busy.entry(w).or_default();
                    *n += 1;
                    if *n > 1 {
                        self.overlaps.fetch_add(1, Ordering::Relaxed);
                    }
                }
                let r = self.layout.rect(w);
                let src = self.input.query(r.pad(1));
                let mut out = Tile::zeros(self.channels, r);
                for c in 0..self.channels {
                    let ci = c % src.channels;
                    for y in r.y0..r.y1() {
                        for x in r.x0..r.x1() {
                            let s = src.get(ci, y, x) * 0.4
                                + 0.15
                                    * (src.get(ci, y - 1, x)
                                        + src.get(ci, y + 1, x)
                                        + src.get(ci, y, x - 1)
                                        + src.get(ci, y, x + 1));
                            let i = (c * r.h as usize + (y - r.y0) as usize) * r.w as usize + (x - r.x0) as usize;
                            out.data[i] = s.tanh() + 0.1 * ((w.iy * 7 + w.ix * 3) as f32).sin();
                        }
                    }
                }
                *self.busy.lock().unwrap().get_mut(&w).unwrap() -= 1;
                out
            })
            .collect()
    }
}

/// A two-step chain, as a diffusion stage uses: noise → step 1 → step 0.
struct Chain {
    engine: Arc<Engine>,
    step1: Arc<Windowed>,
    step0: Arc<Windowed>,
    overlaps: Vec<Arc<AtomicUsize>>,
}

fn chain(seed: u64, cache_bytes: usize, threads: usize) -> Chain {
    let engine = Engine::new(EngineConfig { cache_bytes, threads });
    let noise: Arc<dyn Source> = Arc::new(GaussianNoise { key: NoiseKey { seed, stage: 0, step: 2 }, channels: 2 });
    let f1 = Smear::new(noise, WindowLayout::square(16, 8, 3), 2);
    let overlaps = vec![f1.overlaps.clone()];
    let step1 = Windowed::new(&engine, f1);
    let f0 = Smear::new(step1.clone(), WindowLayout { y: Axis::new(12, 4, -5), x: Axis::new(10, 5, 1) }, 2);
    let overlaps = [overlaps, vec![f0.overlaps.clone()]].concat();
    let step0 = Windowed::new(&engine, f0);
    Chain { engine, step1, step0, overlaps }
}

/// A deterministic shuffle (Fisher–Yates with an LCG), so the test needs no RNG crate.
fn shuffled<T>(mut v: Vec<T>, seed: u64) -> Vec<T> {
    let mut s = seed;
    for i in (1..v.len()).rev() {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        v.swap(i, (s >> 33) as usize % (i + 1));
    }
    v
}

fn region_by_parts(c: &Chain, whole: Rect, part: i64, order_seed: u64) -> Tile {
    let mut parts = Vec::new();
    for y in (whole.y0..whole.y1()).step_by(part as usize) {
        for x in (whole.x0..whole.x1()).step_by(part as usize) {
            parts.push(Rect::new(y, x, part.min(whole.y1() - y), part.min(whole.x1() - x)));
        }
    }
    let mut out = Tile::zeros(2, whole);
    for r in shuffled(parts, order_seed) {
        let t = c.step0.query(r);
        for ch in 0..2 {
            for y in r.y0..r.y1() {
                for x in r.x0..r.x1() {
                    let i =
                        (ch * whole.h as usize + (y - whole.y0) as usize) * whole.w as usize + (x - whole.x0) as usize;
                    out.data[i] = t.get(ch, y, x);
                }
            }
        }
    }
    out
}

#[test]
fn same_region_is_bit_identical_across_orders_caches_and_threads() {
    let whole = Rect::new(-37, 1000, 60, 52);
    let reference = chain(11, 64 << 20, 1).step0.query(whole);
    for (cache, threads, part, order) in [
        (64 << 20, 1, 7, 1),
        (64 << 20, 4, 13, 2),
        (3_000, 1, 5, 3),
        (3_000, 4, 9, 4),
        (0, 4, 11, 5),
        (200_000, 2, 17, 6),
    ] {
        let c = chain(11, cache, threads);
        let got = region_by_parts(&c, whole, part, order);
        assert!(got.data == reference.data, "cache {cache} threads {threads} part {part} differs");
        assert!(c.engine.stats().cache_bytes <= cache);
    }
    assert_ne!(chain(12, 64 << 20, 1).step0.query(whole).data, reference.data, "the seed must matter");
}

#[test]
fn concurrent_queries_agree_and_never_compute_a_window_twice() {
    let c = Arc::new(chain(5, 256 << 20, 2));
    let whole = Rect::new(0, 0, 80, 80);
    let reference = &chain(5, 256 << 20, 1).step0.query(whole);
    std::thread::scope(|s| {
        for t in 0..4u64 {
            let c = c.clone();
            s.spawn(move || {
                for r in shuffled((0..16).map(|i| Rect::new((i / 4) * 20, (i % 4) * 20, 20, 20)).collect(), t) {
                    assert_eq!(c.step0.query(r), reference.crop(r));
                }
            });
        }
    });
    assert!(c.overlaps.iter().all(|o| o.load(Ordering::Relaxed) == 0), "a window was computed twice at once");
    // With a cache that never evicts, each window is evaluated exactly once in total.
    let distinct = c.step0.layout().windows(&whole).len() as u64;
    assert_eq!(c.step0.evaluations(), distinct);
}

#[test]
fn engine_equals_direct_multidiffusion_on_a_finite_canvas() {
    let c = chain(3, 64 << 20, 2);
    let canvas = Rect::new(-64, -64, 160, 160);
    // Direct computation: every window of step 1 fully inside the canvas, blended on a
    // finite array; then the same for step 0 reading the step-1 canvas.
    let direct = |layout: WindowLayout, channels: usize, input: &Tile, f: &dyn Fn(WindowIndex, &Tile) -> Tile| {
        let mut acc = Tile::zeros(channels, canvas);
        let mut wsum = Tile::zeros(1, canvas);
        let (wy, wx) = (layout.y.tent(), layout.x.tent());
        for w in layout.windows(&canvas) {
            let r = layout.rect(w);
            if !canvas.contains_rect(&r.pad(1)) {
                continue;
            }
            let out = f(w, input);
            for y in r.y0..r.y1() {
                for x in r.x0..r.x1() {
                    let weight = wy[(y - r.y0) as usize] * wx[(x - r.x0) as usize];
                    let i = ((y - canvas.y0) * canvas.w + (x - canvas.x0)) as usize;
                    wsum.data[i] += weight;
                    for ch in 0..channels {
                        acc.data[ch * canvas.area() + i] += weight * out.get(ch, y, x);
                    }
                }
            }
        }
        for (i, v) in acc.data.iter_mut().enumerate() {
            *v /= wsum.data[i % canvas.area()];
        }
        acc
    };
    let noise = GaussianNoise { key: NoiseKey { seed: 3, stage: 0, step: 2 }, channels: 2 }.query(canvas);
    let phi = |layout: WindowLayout| {
        move |w: WindowIndex, input: &Tile| {
            let stub = Smear::new(Arc::new(TileSource(input.clone())), layout, 2);
            stub.eval(&[w]).remove(0)
        }
    };
    let l1 = c.step1.layout();
    let l0 = c.step0.layout();
    let j1 = direct(l1, 2, &noise, &phi(l1));
    let j0 = direct(l0, 2, &j1, &phi(l0));
    // Away from the canvas edge, where the finite computation saw every window.
    let inner = canvas.pad(-40);
    let engine = c.step0.query(inner);
    let expected = j0.crop(inner);
    let worst = engine.data.iter().zip(&expected.data).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
    assert!(worst < 1e-5, "engine differs from direct MultiDiffusion by {worst}");
}

/// A finite tile served as a source (for the direct computation).
struct TileSource(Tile);
impl Source for TileSource {
    fn channels(&self) -> usize {
        self.0.channels
    }
    fn query(&self, rect: Rect) -> Tile {
        self.0.crop(rect)
    }
}

#[test]
fn far_queries_cost_the_same_number_of_windows() {
    let count = |y: i64, x: i64| {
        let c = chain(1, 256 << 20, 1);
        c.step0.query(Rect::new(y, x, 32, 32));
        (c.step0.evaluations(), c.step1.evaluations())
    };
    let at_origin = count(0, 0);
    let l0 = chain(1, 0, 1).step0.layout();
    let bound0 = l0.max_windows(32, 32) as u64;
    for (y, x) in
        [(-7_500_000, 7_500_000), (7_500_000, -7_500_000), (30_000_000, 30_000_000), (-30_000_000, -29_999_999)]
    {
        let far = count(y, x);
        assert!(far.0 <= bound0 && at_origin.0 <= bound0, "step 0: {far:?} vs {at_origin:?}, bound {bound0}");
        // Alignment can shift one row/column of windows; the bound is the layout's own.
        let slack = (l0.y.max_windows(32) + l0.x.max_windows(32)) as u64 * 2;
        assert!(far.1.abs_diff(at_origin.1) <= slack, "step 1: {far:?} vs {at_origin:?}");
    }
}

#[test]
fn a_long_random_walk_stays_under_the_cache_limit() {
    let limit = 150_000;
    let c = chain(9, limit, 2);
    let (mut y, mut x) = (0i64, 0i64);
    let mut s = 42u64;
    for _ in 0..400 {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1);
        y += ((s >> 40) % 41) as i64 - 20;
        x += ((s >> 20) % 41) as i64 - 20;
        c.step0.query(Rect::new(y, x, 12, 12));
        let st = c.engine.stats();
        assert!(st.cache_bytes <= limit, "cache {} over limit {limit}", st.cache_bytes);
    }
    let st = c.engine.stats();
    assert!(st.evictions > 0, "the walk should have forced evictions: {st:?}");
    assert!(st.peak_cache_bytes <= limit);
}

#[test]
fn a_panicking_window_releases_its_claim() {
    struct Flaky(AtomicUsize);
    impl WindowFn for Flaky {
        fn name(&self) -> &str {
            "flaky"
        }
        fn channels(&self) -> usize {
            1
        }
        fn layout(&self) -> WindowLayout {
            WindowLayout::square(4, 2, 0)
        }
        fn eval(&self, w: &[WindowIndex]) -> Vec<Tile> {
            if self.0.fetch_add(1, Ordering::SeqCst) == 0 {
                panic!("first call fails");
            }
            w.iter().map(|&w| Tile::from_data(1, self.layout().rect(w), vec![1.0; 16])).collect()
        }
    }
    let engine = Engine::new(EngineConfig { cache_bytes: 1 << 20, threads: 1 });
    let t = Windowed::new(&engine, Flaky(AtomicUsize::new(0)));
    let r = Rect::new(0, 0, 1, 1);
    assert!(std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| t.query(r))).is_err());
    // Had the claim leaked, this would wait forever.
    assert!(t.query(r).data.iter().all(|&v| (v - 1.0).abs() < 1e-6));
}

#[test]
fn the_engine_counts_each_functions_windows_by_name() {
    let engine = Engine::new(EngineConfig { cache_bytes: 64 << 20, threads: 2 });
    let a = Windowed::new(&engine, Named("first", WindowLayout::square(8, 4, 0)));
    let b = Windowed::new(&engine, Named("second", WindowLayout::square(16, 16, 0)));
    a.query(Rect::new(0, 0, 8, 8));
    b.query(Rect::new(0, 0, 40, 8));
    // Cached windows are not evaluated again.
    a.query(Rect::new(0, 0, 8, 8));
    let stats = engine.function_stats();
    let names: Vec<&str> = stats.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(names, ["first", "second"]);
    assert_eq!(stats[0].windows, a.evaluations());
    assert_eq!(stats[1].windows, b.evaluations());
    assert_eq!(stats[1].windows, 3, "rows 0..40 of 16-row windows: three windows");
    assert!(stats[0].windows >= 4 && stats.iter().all(|f| f.seconds >= 0.0), "{stats:?}");
    assert_eq!(engine.stats().windows_evaluated, stats[0].windows + stats[1].windows);
}

/// A window function that returns zeros, under a name.
struct Named(&'static str, WindowLayout);

impl WindowFn for Named {
    fn name(&self) -> &str {
        self.0
    }
    fn channels(&self) -> usize {
        1
    }
    fn layout(&self) -> WindowLayout {
        self.1
    }
    fn eval(&self, windows: &[WindowIndex]) -> Vec<Tile> {
        windows.iter().map(|&w| Tile::zeros(1, self.1.rect(w))).collect()
    }
}
