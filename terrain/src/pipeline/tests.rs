//! The pipeline's guarantees end to end: seed consistency, constant-time access, bounded
//! memory, and upsampling that agrees on shared borders.

use super::*;
use crate::settings::{EngineSettings, TerrainSettings};

fn pipeline(seed: u64, cache_mib: u64, threads: u64) -> Pipeline {
    let settings =
        TerrainSettings { engine: EngineSettings { cache_mib, threads, ..Default::default() }, ..Default::default() };
    Pipeline::new(seed, &settings)
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

#[test]
fn a_region_is_bit_identical_whatever_the_order_cache_and_threads() {
    // 96×96 blocks spread over several coarse windows, far from the origin.
    let whole = Rect::new(-1_000_040, 2_345_600, 96, 96);
    let reference = pipeline(77, 256, 1).columns(whole);
    for (cache_mib, threads, order) in [(256, 4, 1), (1, 1, 2), (1, 4, 3)] {
        let p = pipeline(77, cache_mib, threads);
        let chunks: Vec<Rect> =
            (0..36).map(|i| Rect::new(whole.y0 + (i / 6) * 16, whole.x0 + (i % 6) * 16, 16, 16)).collect();
        for r in shuffled(chunks, order) {
            assert!(
                p.columns(r) == reference.crop(r),
                "chunk {r:?} differs (cache {cache_mib} MiB, {threads} threads)"
            );
        }
    }
    assert_ne!(pipeline(78, 256, 1).columns(whole).data, reference.data, "the seed must matter");
}

#[test]
fn neighbouring_chunks_agree_with_one_big_query() {
    let p = pipeline(5, 64, 2);
    let big = p.columns(Rect::new(-40, -40, 80, 80));
    for r in [Rect::new(-40, -40, 16, 16), Rect::new(-24, -40, 16, 16), Rect::new(-1, -1, 2, 2), Rect::new(7, 33, 1, 7)]
    {
        assert!(p.columns(r) == big.crop(r), "{r:?}");
    }
}

#[test]
fn far_away_costs_the_same_windows_and_never_overflows() {
    let count = |x: i64, z: i64| {
        let p = pipeline(3, 256, 1);
        let t = p.columns(Rect::new(z, x, 512, 512));
        assert!(t.data.iter().all(|v| v.is_finite()), "non-finite values at {x},{z}");
        p.engine_stats().windows_evaluated as i64
    };
    let origin = count(0, 0);
    // The bound from the window layout: a 512-block query touches at most this many
    // orographic windows on the coarse grid (plus one coarse cell of bilinear padding).
    let coarse_len = 512 / (BLOCKS_PER_MODEL_PIXEL * COARSE_FACTOR) + 3;
    let layout = WindowLayout::square(32, 16, 0);
    let bound = layout.max_windows(coarse_len, coarse_len);
    assert!(origin > 0 && origin <= bound);
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
    let p = pipeline(9, 1, 2);
    let (mut x, mut z) = (0i64, 0i64);
    let mut s = 1u64;
    for _ in 0..300 {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        x += ((s >> 33) % 2001) as i64 - 600; // a drift east, so new windows keep coming
        z += ((s >> 45) % 1001) as i64 - 500;
        p.columns(Rect::new(z, x, 16, 16));
        assert!(p.engine_stats().cache_bytes <= 1 << 20);
    }
    let st = p.engine_stats();
    assert!(st.evictions > 0 && st.peak_cache_bytes <= 1 << 20, "{st:?}");
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
    settings.engine.learned = vec!["core".into()];
    let err = Pipeline::build(1, &settings).err().expect("refused").to_string();
    assert!(err.contains("core") && err.contains("--no-default-features") && err.contains("learned = []"), "{err}");
}

/// The learned core stage inside the pipeline, with a small untrained network (what it
/// computes does not matter here, only that the pipeline around it keeps its guarantees).
#[cfg(feature = "learned")]
mod learned {
    use super::*;
    use crate::model::{save_model, ModelManifest, Normalisation, Precision, Sampler, SamplerKind, UNet, UNetConfig};

    fn models_dir(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("infiniterra-pipeline-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let net = UNet::new(&UNetConfig::tiny(), 3, &burn::tensor::Device::flex());
        let mut manifest =
            ModelManifest::new("core", net.config.clone(), Sampler::karras(SamplerKind::Euler, 2, 0.05, 40.0, 7.0));
        manifest.window = 32;
        manifest.metres_per_pixel = 1000.0;
        manifest.normalisation =
            Normalisation { target_scale: 4.0, cond_mean: 10.0, cond_scale: 20.0, relief_mean: 0.0, relief_std: 1.0 };
        save_model(&dir, &net, manifest, Precision::F32).expect("save");
        dir
    }

    fn learned(seed: u64, models: &std::path::Path, cache_mib: u64, threads: u64) -> Pipeline {
        let engine = EngineSettings {
            cache_mib,
            threads,
            learned: vec!["core".into()],
            models: models.to_path_buf(),
            backend: "cpu".into(),
        };
        Pipeline::build(seed, &TerrainSettings { engine, ..Default::default() }).expect("learned pipeline")
    }

    #[test]
    fn with_the_core_stage_a_region_is_bit_identical_whatever_the_order_cache_and_threads() {
        let models = models_dir("determinism");
        let whole = Rect::new(40_000, -123_456, 64, 64);
        let reference = learned(5, &models, 256, 1);
        assert!(reference.active_stages().contains(&"core".to_string()), "{:?}", reference.active_stages());
        let reference = reference.columns(whole);
        assert!(reference.data.iter().all(|v| v.is_finite()), "the learned pipeline made non-finite values");
        for (cache_mib, threads, order) in [(256, 2, 1), (1, 2, 2)] {
            let p = learned(5, &models, cache_mib, threads);
            let chunks: Vec<Rect> =
                (0..16).map(|i| Rect::new(whole.y0 + (i / 4) * 16, whole.x0 + (i % 4) * 16, 16, 16)).collect();
            for r in shuffled(chunks, order) {
                assert!(
                    p.columns(r) == reference.crop(r),
                    "chunk {r:?} differs (cache {cache_mib} MiB, {threads} threads)"
                );
            }
        }
        // The learned stage really shapes the terrain: not the layout's elevation.
        let procedural = pipeline(5, 256, 1).columns(whole);
        assert_ne!(procedural.channel(channel::ELEVATION), reference.channel(channel::ELEVATION));
        let _ = std::fs::remove_dir_all(&models);
    }

    #[test]
    fn missing_weights_name_the_file_and_the_command_that_makes_them() {
        let empty = std::env::temp_dir().join(format!("infiniterra-no-models-{}", std::process::id()));
        let mut settings = TerrainSettings::default();
        settings.engine.learned = vec!["core".into()];
        settings.engine.models = empty;
        let err = Pipeline::build(1, &settings).err().expect("refused").to_string();
        assert!(err.contains("core.json") && err.contains("train core"), "{err}");
    }
}
