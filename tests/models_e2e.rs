//! The shipped weights (`models/`) as the pipeline loads them: every manifest loads and says
//! how it was made, and the optional detail stage refines the shipped core deterministically.

#![cfg(feature = "learned")]

mod common;

use common::fixtures::{self, Pipeline};
use infiniterra::terrain::model::{burn::tensor::Device, load_model};
use infiniterra::terrain::pipeline::channel;
use infiniterra::terrain::tile::Rect;

/// The shipped configuration's pipeline with `learned` stages on `threads` engine threads.
/// At 125 m/block, where the model grid (4 blocks) is the detail stage's own 500 m grid, so
/// 1 km cells are exact 2×2 boxes of it.
fn pipeline(learned: &[&str], threads: u64) -> Pipeline {
    let mut config = fixtures::shipped_config();
    config.world.metres_per_block = 125.0;
    fixtures::learned_pipeline(&config, learned, threads)
}

#[test]
fn every_shipped_model_loads_and_names_the_command_that_rebuilds_it() {
    for (stage, metres) in [("coarse", 8000.0), ("core", 1000.0), ("detail", 500.0)] {
        let model = load_model(&fixtures::shipped_models(), stage, &Device::flex()).expect("shipped model loads");
        let m = &model.manifest;
        assert_eq!((m.stage.as_str(), m.metres_per_pixel), (stage, metres));
        assert!(m.recreate.contains(&format!("train {stage}")), "{stage}: {}", m.recreate);
        assert!(m.training.steps > 0 && m.weights_bytes < 4 << 20, "{stage}: small, trained weights");
        assert!(m.realism.contains_key("slope_w1_deg"), "{stage}: realism recorded by eval --record");
    }
}

#[test]
fn the_shipped_detail_stage_refines_the_core_and_is_the_same_whatever_the_order_and_threads() {
    let region = Rect::new(-2048, 1024, 64, 64);
    let detail = pipeline(&["core", "detail"], 1);
    assert!(detail.active_stages().iter().any(|s| s == "detail"), "{:?}", detail.active_stages());
    let whole = detail.columns(region);
    // Every channel finite but the water level, which is NaN where no river or lake is.
    let finite = (0..whole.channels).filter(|&c| c != channel::WATER_LEVEL);
    assert!(finite.into_iter().all(|c| whole.channel(c).iter().all(|v| v.is_finite())));
    let two = pipeline(&["core", "detail"], 2);
    for i in [3, 0, 2, 1] {
        let chunk = Rect::new(region.y0 + (i / 2) * 32, region.x0 + (i % 2) * 32, 32, 32);
        let (a, b) = (two.columns(chunk), whole.crop(chunk));
        let same = a.rect == b.rect && a.data.iter().zip(&b.data).all(|(x, y)| x.to_bits() == y.to_bits());
        assert!(same, "{chunk:?} differs with 2 threads, other order");
    }
    // It refines the core rather than replacing it: on the 1 km grid the two agree far more
    // closely than the core's own relief across the region.
    let core = pipeline(&["core"], 1);
    let km = Rect::new(region.y0 / 8, region.x0 / 8, region.h / 8, region.w / 8);
    let (d, c) = (detail_km(&detail, km), core.elevation(Rect::new(km.y0 * 2, km.x0 * 2, km.h * 2, km.w * 2)));
    let c = box2(c.channel(channel::ELEVATION), (km.w * 2) as usize);
    let diff = d.iter().zip(&c).map(|(a, b)| (a - b).abs()).sum::<f32>() / d.len() as f32;
    let (lo, hi) = c.iter().fold((f32::MAX, f32::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    assert!(hi - lo > 50.0, "pick a region with relief: {lo}..{hi} m");
    assert!(diff < 0.1 * (hi - lo), "1 km means moved by {diff} m against a {} m range", hi - lo);
    assert_ne!(d, c, "the detail stage changed nothing");
}

/// The detail pipeline's elevation box-averaged to 1 km cells of `km`.
fn detail_km(p: &Pipeline, km: Rect) -> Vec<f32> {
    let fine = p.elevation(Rect::new(km.y0 * 2, km.x0 * 2, km.h * 2, km.w * 2));
    box2(fine.channel(channel::ELEVATION), (km.w * 2) as usize)
}

/// 2×2 box means of a row-major grid `w` wide.
fn box2(v: &[f32], w: usize) -> Vec<f32> {
    let h = v.len() / w;
    let mut out = Vec::with_capacity(v.len() / 4);
    for y in (0..h).step_by(2) {
        for x in (0..w).step_by(2) {
            out.push((v[y * w + x] + v[y * w + x + 1] + v[(y + 1) * w + x] + v[(y + 1) * w + x + 1]) / 4.0);
        }
    }
    out
}
