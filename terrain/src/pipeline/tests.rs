//! The pipeline's guarantees end to end: seed consistency, constant-time access, bounded
//! memory, and upsampling that agrees on shared borders.

use super::*;
use crate::settings::{EngineSettings, TerrainSettings};

fn pipeline(seed: u64, cache_mib: u64, threads: u64) -> Pipeline {
    let settings =
        TerrainSettings { engine: EngineSettings { cache_mib, threads, ..Default::default() }, ..Default::default() };
    Pipeline::new(seed, &settings)
}

/// Bit-identical tiles (NaN, the water level where there is none, equals itself).
fn same(a: &Tile, b: &Tile) -> bool {
    a.rect == b.rect && a.channels == b.channels && a.data.iter().zip(&b.data).all(|(x, y)| x.to_bits() == y.to_bits())
}

/// Every channel finite, the water level's NaN (no river or lake) aside.
fn finite(t: &Tile) -> bool {
    (0..t.channels).filter(|&c| c != channel::WATER_LEVEL).all(|c| t.channel(c).iter().all(|v| v.is_finite()))
}

/// A cache (MiB) a little over what one chunk's query needs (measured on a fresh pipeline
/// built by `build` with a cache of the MiB given): below the owner's minimum on purpose, so
/// that walking a region evicts, but never so small that a query evicts what it still needs.
fn tight_cache_mib(build: impl Fn(u64) -> Pipeline, chunk: Rect) -> u64 {
    let p = build(256);
    p.columns(chunk);
    ((p.engine_stats().peak_cache_bytes as u64 * 5 / 4) >> 20) + 1
}

/// Visits `chunks` in their order on `p`, checking each against `reference`; with `far`, a
/// chunk that far east is visited after every fourth, so that a tight cache must evict the
/// region's windows and bring them back.
fn visit(p: &Pipeline, chunks: Vec<Rect>, reference: &Tile, far: Option<i64>, what: &str) {
    for (i, r) in chunks.into_iter().enumerate() {
        assert!(same(&p.columns(r), &reference.crop(r)), "chunk {r:?} differs ({what})");
        if let Some(dx) = far.filter(|_| i % 4 == 3) {
            p.columns(Rect::new(r.y0, r.x0 + dx * (i as i64 + 1), 16, 16));
        }
    }
}

/// A deterministic shuffle (Fisher–Yates with an LCG).
fn shuffled<T>(mut v: Vec<T>, seed: u64) -> Vec<T> {
    let mut s = seed;
    for i in (1..v.len()).rev() {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        v.swap(i, (s >> 33) as usize % (i + 1));
    }
    v
}

/// x + 1000·y on every cell, two channels (the second negated).
struct Ramp;

impl Source for Ramp {
    fn channels(&self) -> usize {
        2
    }

    fn query(&self, rect: Rect) -> Tile {
        let mut t = Tile::zeros(2, rect);
        let n = rect.area();
        for (i, (y, x)) in (rect.y0..rect.y1()).flat_map(|y| (rect.x0..rect.x1()).map(move |x| (y, x))).enumerate() {
            t.data[i] = (x + 1000 * y) as f32;
            t.data[n + i] = -t.data[i];
        }
        t
    }
}

#[test]
fn box_means_average_each_block_of_the_finer_grid() {
    let coarse = BoxMean { source: Arc::new(Ramp), factor: 4 };
    let t = coarse.query(Rect::new(-1, 2, 2, 3));
    // Cell (y, x) averages fine rows 4y..4y+3 and columns 4x..4x+3: centre (4y+1.5, 4x+1.5).
    for (i, (y, x)) in [(-1, 2), (-1, 3), (-1, 4), (0, 2), (0, 3), (0, 4)].into_iter().enumerate() {
        let want = (4 * x) as f32 + 1.5 + 1000.0 * ((4 * y) as f32 + 1.5);
        assert_eq!(t.data[i], want, "cell ({y}, {x})");
        assert_eq!(t.data[6 + i], -want, "second channel of ({y}, {x})");
    }
}

#[test]
fn a_region_is_bit_identical_whatever_the_order_cache_and_threads() {
    // 96×96 blocks spread over several coarse windows, far from the origin.
    let whole = Rect::new(-1_000_040, 2_345_600, 96, 96);
    let reference = pipeline(77, 256, 1).columns(whole);
    let chunks: Vec<Rect> =
        (0..36).map(|i| Rect::new(whole.y0 + (i / 6) * 16, whole.x0 + (i % 6) * 16, 16, 16)).collect();
    let tight = tight_cache_mib(|mib| pipeline(77, mib, 1), chunks[0]);
    for (cache_mib, threads, order) in [(256, 4, 1), (tight, 1, 2), (tight, 4, 3)] {
        let p = pipeline(77, cache_mib, threads);
        let far = (cache_mib == tight).then_some(300_000);
        visit(
            &p,
            shuffled(chunks.clone(), order),
            &reference,
            far,
            &format!("cache {cache_mib} MiB, {threads} threads"),
        );
        if far.is_some() {
            assert!(p.engine_stats().evictions > 0, "a {cache_mib} MiB cache evicted nothing");
        }
    }
    assert_ne!(pipeline(78, 256, 1).columns(whole).data, reference.data, "the seed must matter");
}

#[test]
fn a_region_sized_query_is_the_same_bits_as_its_chunks() {
    // Large enough that its network is evaluated beside its relief and its carving is split
    // into bands, the last one short.
    let whole = Rect::new(-3_008, 7_008, 144, 160);
    assert!(whole.area() >= super::REGION_QUERY_COLUMNS && whole.h % super::CARVE_ROWS != 0);
    let region = pipeline(5, 256, 2).columns(whole);
    let p = pipeline(5, 256, 1);
    for y0 in (whole.y0..whole.y1()).step_by(16) {
        for x0 in (whole.x0..whole.x1()).step_by(16) {
            let chunk = Rect::new(y0, x0, 16, 16);
            assert!(same(&p.columns(chunk), &region.crop(chunk)), "{chunk:?}");
        }
    }
}

fn at_scale(metres_per_block: f64) -> Pipeline {
    Pipeline::new(21, &TerrainSettings { metres_per_block, ..Default::default() })
}

#[test]
fn the_world_scale_changes_blocks_not_metres() {
    // The same place in metres has the same continent and climate at any scale.
    let (fine, coarse) = (at_scale(30.0), at_scale(120.0));
    assert_eq!((fine.model_pixel_metres(), coarse.model_pixel_metres()), (120.0, 480.0));
    for (x, z) in [(0i64, 0i64), (100_000, -40_000), (-2_000_000, 3_000_000)] {
        // Block x at 120 m is block 4x at 30 m; both fall in the same 8 km cell.
        assert_eq!(fine.coarse_elevation_at_block(4 * x + 1, 4 * z + 1), coarse.coarse_elevation_at_block(x, z));
    }
    // A 4,096-block square spans 4× the metres at 4× the scale: more relief in it.
    let range = |p: &Pipeline| {
        let t = p.elevation(Rect::new(-512, -512, 1024, 1024));
        let (lo, hi) = t.data.iter().fold((f32::MAX, f32::MIN), |(a, b), &v| (a.min(v), b.max(v)));
        hi - lo
    };
    assert!(range(&coarse) > range(&fine), "{} vs {}", range(&coarse), range(&fine));
}

#[test]
fn the_erosion_filter_carves_relief_below_the_model_grid() {
    // Land, far enough inland to have slopes.
    let p = at_scale(40.0);
    let x = (0..4000i64).map(|i| i * 512).find(|&x| p.coarse_elevation_at_block(x, 0) > 800.0).expect("high land");
    let blocks = Rect::new(-64, x - 64, 128, 128);
    let carved = p.elevation_columns(blocks);
    let model = p.elevation(Pipeline::model_rect(&blocks));
    let smooth = resample::cubic(&model, BLOCK_RATIO, blocks);
    let rms = (carved.data.iter().zip(&smooth.data).map(|(a, b)| f64::from(a - b).powi(2)).sum::<f64>()
        / blocks.area() as f64)
        .sqrt();
    // The two block octaves add metres, not millimetres, and not hundreds of metres.
    assert!(rms > 0.5 && rms < 100.0, "rms {rms} m");
    // The block elevations are what the full answer carries.
    assert!(p.columns(blocks).select(&[channel::ELEVATION]) == carved);
}

#[test]
fn the_block_grid_has_no_seams_on_chunk_or_model_pixel_lines() {
    // High land at the default scale, 256² blocks: the mean height step between neighbouring
    // columns across the lines where chunks (16 blocks) or model pixels (4 blocks) meet is the
    // step elsewhere — no crease, no 4-block facets.
    let p = at_scale(40.0);
    let x = (0..4000i64).map(|i| i * 512).find(|&x| p.coarse_elevation_at_block(x, 0) > 800.0).expect("high land");
    let (n, rect) = (256usize, Rect::new(-128, x - 128, 256, 256));
    let e = p.elevation_columns(rect);
    let step = |y: usize, x: usize, dy: usize, dx: usize| (e.data[(y + dy) * n + x + dx] - e.data[y * n + x]).abs();
    for period in [16i64, 4] {
        let (mut on, mut off) = ((0.0f64, 0usize), (0.0f64, 0usize));
        for y in 0..n - 1 {
            for x in 0..n - 1 {
                // A step from column x to x + 1 crosses a line when x + 1 starts a cell.
                for (d, crosses) in [
                    (step(y, x, 0, 1), (rect.x0 + x as i64 + 1).rem_euclid(period) == 0),
                    (step(y, x, 1, 0), (rect.y0 + y as i64 + 1).rem_euclid(period) == 0),
                ] {
                    let acc = if crosses { &mut on } else { &mut off };
                    *acc = (acc.0 + f64::from(d), acc.1 + 1);
                }
            }
        }
        let ratio = (on.0 / on.1 as f64) / (off.0 / off.1 as f64);
        assert!((0.93..1.07).contains(&ratio), "steps across {period}-block lines are {ratio:.3}× the others");
    }
}

#[test]
fn neighbouring_chunks_agree_with_one_big_query() {
    let p = pipeline(5, 64, 2);
    let big = p.columns(Rect::new(-40, -40, 80, 80));
    for r in [Rect::new(-40, -40, 16, 16), Rect::new(-24, -40, 16, 16), Rect::new(-1, -1, 2, 2), Rect::new(7, 33, 1, 7)]
    {
        assert!(same(&p.columns(r), &big.crop(r)), "{r:?}");
    }
}

#[test]
fn far_away_costs_the_same_windows_and_never_overflows() {
    let count = |x: i64, z: i64| {
        let p = pipeline(3, 256, 1);
        let t = p.columns(Rect::new(z, x, 512, 512));
        assert!(finite(&t), "non-finite values at {x},{z}");
        p.engine_stats().windows_evaluated as i64
    };
    let origin = count(0, 0);
    // The bound from the window layout: a 512-block query touches at most this many
    // orographic windows on the coarse grid (plus one coarse cell of bilinear padding).
    let blocks_per_coarse_cell = COARSE_METRES / TerrainSettings::default().metres_per_block;
    let coarse_len = (512.0 / blocks_per_coarse_cell).ceil() as i64 + 3;
    let layout = WindowLayout::square(32, 16, 0);
    // The drainage network adds its tiles (at most 2 × 2 for 512 blocks of 40 m, with the
    // rivers' reach, and the joined windows over them), and those reach at most 2 × 2 tiles of the
    // continent's drainage, whose margins hold the most coarse windows.
    use crate::hydrology::{continental, CELL_METRES, MARGIN, TILE};
    let network_len = ((2 * TILE + 2 * MARGIN) as f64 * CELL_METRES / COARSE_METRES).ceil() as i64 + 3;
    assert!(network_len <= continental::TILE, "a network tile's context spans at most 2 continental tiles");
    let continental_len = 2 * continental::TILE + 2 * continental::MARGIN + 3;
    let len = coarse_len.max(continental_len);
    let bound = layout.max_windows(len, len) + 2 * 9 + 4 + 4;
    assert!(origin > 0 && origin <= bound, "{origin} windows at the origin, bound {bound}");
    for (x, z) in [(30_000_000, 30_000_000), (-30_000_000, -30_000_000), (-30_000_000, 29_999_488), (12_345_678, -7)] {
        let far = count(x, z);
        assert!(
            far <= bound && (far - origin).abs() <= bound - layout.max_windows(1, 1),
            "{far} windows at {x},{z} vs {origin}"
        );
    }
}

#[test]
fn a_long_walk_keeps_the_cache_under_its_limit() {
    let tight = tight_cache_mib(|mib| pipeline(9, mib, 2), Rect::new(0, 0, 16, 16));
    let p = pipeline(9, tight, 2);
    let (mut x, mut z) = (0i64, 0i64);
    let mut s = 1u64;
    for _ in 0..60 {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        // A drift east, so new windows keep coming (steps of a few km at the default scale).
        x += 4 * (((s >> 33) % 2001) as i64 - 600);
        z += 4 * (((s >> 45) % 1001) as i64 - 500);
        p.columns(Rect::new(z, x, 16, 16));
        assert!(p.engine_stats().cache_bytes <= (tight << 20) as usize);
    }
    let st = p.engine_stats();
    assert!(st.evictions > 0 && st.peak_cache_bytes <= (tight << 20) as usize, "{st:?}");
}

#[test]
fn the_stage_list_says_what_runs() {
    let p = pipeline(1, 8, 1);
    assert_eq!(p.active_stages(), vec!["layout".to_string(), "climate".to_string()]);
    assert!(p.stages().iter().any(|s| s.name == "core" && matches!(s.state, StageState::Missing { .. })));
}

#[test]
fn temperature_is_the_sea_level_field_minus_the_lapse_rate() {
    let p = pipeline(11, 64, 1);
    // Find high land on the coarse sketch first, so the test always has hills to look at.
    let x = (0..4000i64)
        .map(|i| i * 256)
        .find(|&x| p.coarse_elevation_at_block(x, 0) > 1500.0)
        .expect("some high land within 1,000,000 blocks east of the origin");
    let t = p.model(Rect::new(-32, x / BLOCKS_PER_MODEL_PIXEL - 32, 64, 64));
    // Where two neighbouring land pixels differ in height, the temperature difference is
    // the lapse rate times the height difference: the sea-level field is smooth, changing
    // by well under 10% of that between neighbours.
    let lapse = p.settings().climate.lapse_rate_c_per_km as f32;
    let mut checked = 0;
    for y in t.rect.y0..t.rect.y1() {
        for x in t.rect.x0..t.rect.x1() - 1 {
            let (e0, e1) = (t.get(channel::ELEVATION, y, x), t.get(channel::ELEVATION, y, x + 1));
            if e0 > 0.0 && e1 > 0.0 && (e1 - e0).abs() > 30.0 {
                let dt = t.get(channel::TEMPERATURE, y, x + 1) - t.get(channel::TEMPERATURE, y, x);
                let expected = -lapse * (e1 - e0) / 1000.0;
                assert!((dt - expected).abs() < 0.1 * expected.abs(), "dt {dt} vs {expected}");
                checked += 1;
            }
        }
    }
    assert!(checked > 20, "only {checked} pixel pairs on hills");
}

#[cfg(not(feature = "learned"))]
#[test]
fn learned_stages_in_a_build_without_them_say_how_to_build() {
    let mut settings = TerrainSettings::default();
    settings.engine.learned = vec!["core".parse().expect("a stage")];
    let err = Pipeline::build(1, &settings).err().expect("refused").to_string();
    assert!(err.contains("core") && err.contains("--no-default-features") && err.contains("learned = []"), "{err}");
}

/// The learned core stage inside the pipeline, with a small untrained network (what it
/// computes does not matter here, only that the pipeline around it keeps its guarantees).
#[cfg(feature = "learned")]
mod learned {
    use super::*;
    use crate::model::{save_model, ModelManifest, Normalisation, Precision, Sampler, SamplerKind, UNet, UNetConfig};

    /// Tiny untrained models of the core (1 km), coarse (`coarse_metres`) and detail (500 m,
    /// 2× unblurred context, 75 % overlap) stages.
    fn models_dir(name: &str, coarse_metres: f64) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("infiniterra-pipeline-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        for (stage, metres, seed) in [("core", 1000.0, 3), ("coarse", coarse_metres, 4), ("detail", 500.0, 5)] {
            let mut net = UNet::new(&UNetConfig::tiny(), seed, &burn::tensor::Device::flex());
            // A non-zero output gain, so the untrained network changes what it is given.
            net.out_gain = net.out_gain.map(|g| g.add_scalar(0.5));
            let mut manifest =
                ModelManifest::new(stage, net.config.clone(), Sampler::karras(SamplerKind::Euler, 2, 0.05, 40.0, 7.0));
            manifest.window = 32;
            manifest.metres_per_pixel = metres;
            if stage == "detail" {
                manifest.context = crate::encoding::ContextSpec { factor: 2, blur: false };
                manifest.stride = 8;
            }
            manifest.normalisation = Normalisation {
                target_scale: 4.0,
                cond_mean: 10.0,
                cond_scale: 20.0,
                relief_mean: 0.0,
                relief_std: 1.0,
            };
            save_model(&dir, &net, manifest, Precision::F32).expect("save");
        }
        dir
    }

    fn learned(seed: u64, models: &std::path::Path, cache_mib: u64, threads: u64) -> Pipeline {
        learned_stages(seed, models, cache_mib, threads, &["core"])
    }

    fn learned_stages(seed: u64, models: &std::path::Path, cache_mib: u64, threads: u64, stages: &[&str]) -> Pipeline {
        let engine = EngineSettings {
            cache_mib,
            threads,
            learned: stages.iter().map(|s| s.parse().expect("a stage")).collect(),
            models: models.to_path_buf(),
            backend: crate::settings::Backend::Cpu,
        };
        Pipeline::build(seed, &TerrainSettings { engine, ..Default::default() }).expect("learned pipeline")
    }

    #[test]
    fn with_the_core_stage_a_region_is_bit_identical_whatever_the_order_cache_and_threads() {
        let models = models_dir("determinism", 8000.0);
        let whole = Rect::new(40_000, -123_456, 64, 64);
        let reference = learned(5, &models, 256, 1);
        assert!(reference.active_stages().contains(&"core".to_string()), "{:?}", reference.active_stages());
        let reference = reference.columns(whole);
        assert!(finite(&reference), "the learned pipeline made non-finite values");
        let chunks: Vec<Rect> =
            (0..16).map(|i| Rect::new(whole.y0 + (i / 4) * 16, whole.x0 + (i % 4) * 16, 16, 16)).collect();
        let tight = tight_cache_mib(|mib| learned(5, &models, mib, 2), chunks[0]);
        for (cache_mib, threads, order) in [(256, 2, 1), (tight, 2, 2)] {
            let p = learned(5, &models, cache_mib, threads);
            let far = (cache_mib == tight).then_some(300_000);
            visit(
                &p,
                shuffled(chunks.clone(), order),
                &reference,
                far,
                &format!("cache {cache_mib} MiB, {threads} threads"),
            );
            if far.is_some() {
                assert!(p.engine_stats().evictions > 0, "a {cache_mib} MiB cache evicted nothing");
            }
        }
        // The learned stage really shapes the terrain: not the layout's elevation.
        let procedural = pipeline(5, 256, 1).columns(whole);
        assert_ne!(procedural.channel(channel::ELEVATION), reference.channel(channel::ELEVATION));
        let _ = std::fs::remove_dir_all(&models);
    }

    #[test]
    fn with_coarse_and_core_a_region_is_bit_identical_and_the_coarse_model_shapes_it() {
        let models = models_dir("coarse", 8000.0);
        // A region spanning two 8 km coarse windows' worth of chunks.
        let whole = Rect::new(-70_000, 52_000, 48, 48);
        let both = learned_stages(9, &models, 256, 1, &["coarse", "core"]);
        let active = both.active_stages();
        assert!(active.contains(&"coarse".to_string()) && active.contains(&"core".to_string()), "{active:?}");
        let reference = both.columns(whole);
        assert!(finite(&reference));
        let chunks: Vec<Rect> =
            (0..9).map(|i| Rect::new(whole.y0 + (i / 3) * 16, whole.x0 + (i % 3) * 16, 16, 16)).collect();
        let tight = tight_cache_mib(|mib| learned_stages(9, &models, mib, 2, &["coarse", "core"]), chunks[0]);
        let p = learned_stages(9, &models, tight, 2, &["coarse", "core"]);
        visit(&p, shuffled(chunks, 3), &reference, Some(300_000), &format!("cache {tight} MiB, 2 threads"));
        assert!(p.engine_stats().evictions > 0, "a {tight} MiB cache evicted nothing");
        // The coarse model changes the 8 km grid the climate and the core are built on.
        let core_only = learned(9, &models, 256, 1);
        let at = |p: &Pipeline| p.coarse_elevation_at_block(whole.x0, whole.y0);
        assert_ne!(at(&both), at(&core_only));
        assert_ne!(
            both.columns(whole).channel(channel::ELEVATION),
            core_only.columns(whole).channel(channel::ELEVATION)
        );
        let _ = std::fs::remove_dir_all(&models);
    }

    #[test]
    fn with_core_and_detail_a_region_is_bit_identical_and_the_detail_model_shapes_it() {
        let models = models_dir("detail", 8000.0);
        let whole = Rect::new(9_000, -31_000, 48, 48);
        let both = learned_stages(4, &models, 256, 1, &["core", "detail"]);
        assert!(both.active_stages().contains(&"detail".to_string()), "{:?}", both.active_stages());
        let reference = both.columns(whole);
        assert!(finite(&reference));
        let chunks: Vec<Rect> =
            (0..9).map(|i| Rect::new(whole.y0 + (i / 3) * 16, whole.x0 + (i % 3) * 16, 16, 16)).collect();
        let tight = tight_cache_mib(|mib| learned_stages(4, &models, mib, 2, &["core", "detail"]), chunks[0]);
        for (cache_mib, threads, order) in [(256, 2, 5), (tight, 2, 6)] {
            let p = learned_stages(4, &models, cache_mib, threads, &["core", "detail"]);
            let far = (cache_mib == tight).then_some(300_000);
            visit(
                &p,
                shuffled(chunks.clone(), order),
                &reference,
                far,
                &format!("cache {cache_mib} MiB, {threads} threads"),
            );
            if far.is_some() {
                assert!(p.engine_stats().evictions > 0, "a {cache_mib} MiB cache evicted nothing");
            }
        }
        // The detail model replaces the core's bilinear upsampling.
        let core_only = learned(4, &models, 256, 1).columns(whole);
        let (d, c) = (reference.channel(channel::ELEVATION), core_only.channel(channel::ELEVATION));
        assert_ne!(d, c);
        // Detail without the core is refused by the settings.
        let mut settings = TerrainSettings::default();
        settings.engine.learned = vec!["detail".parse().expect("a stage")];
        let err = settings.engine.validate().expect_err("detail needs core").to_string();
        assert!(err.contains("engine.learned") && err.contains("core"), "{err}");
        let _ = std::fs::remove_dir_all(&models);
    }

    #[test]
    fn after_a_prefetch_the_chunks_inside_evaluate_no_window_and_are_the_same_bits() {
        let models = models_dir("prefetch", 8000.0);
        let region = Rect::new(512, -1024, 512, 512);
        let chunks: Vec<Rect> = [(0, 0), (15, 7), (31, 31), (0, 31)]
            .iter()
            .map(|&(cz, cx)| Rect::new(region.y0 + cz * 16, region.x0 + cx * 16, 16, 16))
            .collect();
        let cold = learned(2, &models, 256, 1);
        let want: Vec<Tile> = chunks.iter().map(|&r| cold.columns(r)).collect();
        let p = learned(2, &models, 256, 2);
        p.prefetch(region);
        let before = p.engine_stats().windows_evaluated;
        assert!(before > 0, "the prefetch evaluated the region's windows");
        for (r, w) in chunks.iter().zip(&want) {
            assert!(same(&p.columns(*r), w), "chunk {r:?} differs after a prefetch");
        }
        assert_eq!(p.engine_stats().windows_evaluated, before, "a chunk inside the region needed a new window");
        // Without learned stages there is nothing to prefetch.
        let procedural = pipeline(2, 256, 1);
        procedural.prefetch(region);
        assert_eq!(procedural.engine_stats().windows_evaluated, 0);
        let _ = std::fs::remove_dir_all(&models);
    }

    #[test]
    fn a_coarse_model_of_the_wrong_resolution_is_refused_naming_its_manifest() {
        let models = models_dir("wrong", 1000.0);
        let settings = TerrainSettings {
            engine: EngineSettings {
                learned: vec!["coarse".parse().expect("a stage")],
                models: models.clone(),
                ..Default::default()
            },
            ..Default::default()
        };
        let err = Pipeline::build(1, &settings).err().expect("refused").to_string();
        assert!(err.contains("coarse.json") && err.contains("8000") && err.contains("train coarse"), "{err}");
        let _ = std::fs::remove_dir_all(&models);
    }

    #[test]
    fn missing_weights_name_the_file_and_the_command_that_makes_them() {
        let empty = std::env::temp_dir().join(format!("infiniterra-no-models-{}", std::process::id()));
        let mut settings = TerrainSettings::default();
        settings.engine.learned = vec!["core".parse().expect("a stage")];
        settings.engine.models = empty;
        let err = Pipeline::build(1, &settings).err().expect("refused").to_string();
        assert!(err.contains("core.json") && err.contains("train core"), "{err}");
    }
}
