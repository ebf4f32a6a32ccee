use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use infiniterra_terrain::model::burn;
use infiniterra_terrain::model::{ComputeBackend, ModelManifest, NoiseDistribution, Precision, UNetConfig};

use super::checkpoint::CheckpointState;
use super::data::TileSet;
use super::*;

fn smoke_args(out: &Path, steps: u64, resume: bool) -> TrainOptions {
    TrainOptions {
        stage: "core".into(),
        steps,
        resume,
        init_from: None,
        batch: 2,
        crop: 32,
        lr: 4e-3,
        lr_ref_steps: 2,
        ema: 0.9,
        p_mean: -1.2,
        p_std: 1.2,
        data: PathBuf::from("unused"),
        out: out.to_path_buf(),
        checkpoint_every: 2,
        preview_every: 1000,
        log_every: 1,
        minutes: None,
        precision: Precision::F32,
        backend: ComputeBackend::Cpu,
        tiles: 0,
        generate_heldout: None,
        draws: 1,
        counterpart: None,
        fit_relief_hint: false,
        hint_block_statistics: false,
        calibrate_relief_hint: false,
        calibrate_relief_response: false,
        calibrate_spectrum: false,
        calibrate_infill: false,
        picture: PathBuf::from("unused.png"),
        half_width: false,
        smoke: true,
    }
}

fn train(args: &TrainOptions) -> CheckpointState {
    let spec = stage_spec("core", true).expect("core is trainable");
    let mut t = Trainer::new(args, 5, spec, data::synthetic(6, 128), data::synthetic(2, 128)).expect("trainer");
    t.run(&AtomicBool::new(false)).expect("training runs");
    t.state
}

/// A calibration of the smoke core in `dir` on 2 of the tiles in `data`.
fn job<'a>(dir: &'a Path, data: &'a Path) -> shipped::Calibration<'a> {
    shipped::Calibration { models: dir, stage: "core", data, tiles: 2, seed: 0, backend: ComputeBackend::Cpu }
}

fn tempdir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("infiniterra-train-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn training_is_deterministic_and_resumes_exactly() {
    let straight = tempdir("straight");
    let a = train(&smoke_args(&straight, 4, false));
    assert_eq!(a.step, 4);
    assert!(a.losses.iter().all(|(_, l)| l.is_finite()));

    let resumed = tempdir("resumed");
    let half = train(&smoke_args(&resumed, 2, false));
    assert_eq!(half.step, 2);
    let b = train(&smoke_args(&resumed, 4, true));
    assert_eq!(b.step, 4);
    // Same losses step by step, same shipped weights byte for byte.
    let tail = |s: &CheckpointState| s.losses.iter().filter(|(k, _)| *k > 2).cloned().collect::<Vec<_>>();
    assert_eq!(tail(&a), tail(&b));
    let weights = |d: &Path| std::fs::read(d.join("core.safetensors")).expect("shipped weights");
    assert_eq!(weights(&straight), weights(&resumed));
    let manifest: ModelManifest =
        serde_json::from_str(&std::fs::read_to_string(resumed.join("core.json")).expect("manifest")).expect("parses");
    assert_eq!(manifest.training.steps, 4);
    assert!(manifest.parameters > 0 && !manifest.weights_sha256.is_empty());
    assert!(manifest.relief_hint.is_some(), "shipping fits the relief hint");
    assert!(resumed.join("checkpoints/core/samples_000004.png").exists());
    let _ = std::fs::remove_dir_all(&straight);
    let _ = std::fs::remove_dir_all(&resumed);
}

#[test]
fn a_half_width_guide_trains_into_its_own_folder_and_its_manifest_says_how() {
    let out = tempdir("guide");
    let mut args = smoke_args(&out, 2, false);
    args.half_width = true;
    run(&args, Some(5)).expect("trains");
    let manifest: ModelManifest =
        serde_json::from_str(&std::fs::read_to_string(out.join("core.json")).expect("manifest")).expect("parses");
    assert_eq!(manifest.architecture, UNetConfig::tiny().halved());
    assert!(manifest.recreate.contains(&format!("--half-width --out {}", out.display())), "{}", manifest.recreate);
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn a_shipped_model_continues_training_from_its_weights_and_step() {
    let first = tempdir("first");
    train(&smoke_args(&first, 2, false));
    let continued = tempdir("continued");
    let mut args = smoke_args(&continued, 4, false);
    args.init_from = Some(first.join("core.json"));
    // Different settings on the command line are overridden by the shipped record, but the
    // noise levels are this run's own choice (continuing with more weight on high σ).
    args.batch = 3;
    args.p_mean = -0.4;
    let state = train(&args);
    assert_eq!((state.step, state.batch), (4, 2), "continues at the shipped step with the shipped batch");
    assert!(state.losses.iter().all(|&(k, l)| k > 2 && l.is_finite()), "{:?}", state.losses);
    let weights = |d: &Path| std::fs::read(d.join("core.safetensors")).expect("shipped weights");
    assert_ne!(weights(&first), weights(&continued), "the optimiser moved the loaded weights");
    let manifest: ModelManifest =
        serde_json::from_str(&std::fs::read_to_string(continued.join("core.json")).expect("manifest")).expect("parses");
    let start: ModelManifest =
        serde_json::from_str(&std::fs::read_to_string(first.join("core.json")).expect("manifest")).expect("parses");
    assert_eq!(manifest.training.steps, 4);
    assert_eq!(manifest.normalisation, start.normalisation, "normalisation is the shipped one");
    let (before, after) = manifest.recreate.split_once(" && ").expect("recreate chains both runs");
    assert_eq!(before, start.recreate);
    assert!(after.contains("--init-from ") && after.contains("--steps 4"), "{after}");
    assert!(after.contains("--p-mean -0.4 --p-std 1.2") && !before.contains("--p-mean"), "{after}");
    assert_eq!(manifest.training.noise, Some(NoiseDistribution { p_mean: -0.4, p_std: 1.2 }));
    assert_eq!(start.training.noise, None, "EDM's default noise levels are not spelled out");

    // Another stage's (or architecture's) manifest is refused, naming the file.
    let mut wrong = smoke_args(&tempdir("wrong"), 4, false);
    wrong.init_from = Some(first.join("core.json"));
    wrong.stage = "coarse".into();
    let spec = stage_spec("coarse", true).expect("coarse is trainable");
    let err = Trainer::new(&wrong, 0, spec, data::synthetic(2, 64), data::synthetic(1, 64))
        .err()
        .expect("a core model cannot continue as coarse");
    assert!(matches!(err, TrainError::Input(_)), "{err}");
    assert!(err.to_string().contains("core.json"), "{err}");
    let _ = std::fs::remove_dir_all(&first);
    let _ = std::fs::remove_dir_all(&continued);
}

#[test]
fn the_detail_stage_trains_on_its_own_context_and_ships_its_overlap() {
    let dir = tempdir("detail");
    let mut args = smoke_args(&dir, 2, false);
    args.stage = "detail".into();
    let spec = stage_spec("detail", true).expect("detail is trainable");
    let context = spec.context;
    assert_eq!((context.factor, context.blur), (2, false));
    let (train_set, heldout) = (data::synthetic_with(6, 128, context), data::synthetic_with(2, 128, context));
    // A 2× unblurred context leaves a much smaller residual than the core's 8× blurred one.
    let residual = |t: &TileSet| t.tiles[0].h.iter().zip(&t.tiles[0].low).map(|(h, l)| (h - l).abs()).sum::<f32>();
    assert!(residual(&train_set) < residual(&data::synthetic(6, 128)) / 2.0);
    let mut t = Trainer::new(&args, 5, spec, train_set, heldout).expect("trainer");
    t.run(&AtomicBool::new(false)).expect("training runs");
    let model = infiniterra_terrain::model::load_model(&dir, "detail", &burn::tensor::Device::flex()).expect("loads");
    assert_eq!(model.manifest.context, context);
    assert_eq!((model.manifest.window, model.manifest.window_stride()), (64, 16), "75 % overlap");
    assert_eq!(model.manifest.metres_per_pixel, 500.0);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn resuming_without_a_checkpoint_is_an_input_error() {
    let dir = tempdir("nockpt");
    let spec = stage_spec("core", true).expect("core");
    let err = Trainer::new(&smoke_args(&dir, 4, true), 0, spec, data::synthetic(2, 64), data::synthetic(1, 64))
        .err()
        .expect("no checkpoint to resume");
    assert!(matches!(err, TrainError::Input(_)), "{err}");
    assert!(err.to_string().contains("state.json"), "{err}");
    assert!(stage_spec("canyon", false).is_err());
}

#[test]
fn a_counterpart_keeps_the_real_region_s_shape_and_is_drawn_beside_it() {
    let dir = tempdir("counterpart");
    train(&smoke_args(&dir, 2, false));
    let real = dir.join("region.npy");
    let tile = &data::synthetic(1, 64).tiles[0];
    let metres: Vec<f32> = tile.h.iter().map(|&h| infiniterra_terrain::encoding::signed_square(h)).collect();
    crate::npy::write_npy_f32(&real, (64, 64), &metres).expect("write region");
    let png = dir.join("pictures/side.png");
    heldout::compare(&dir, "core", &real, &png, 3, ComputeBackend::Cpu).expect("counterpart");
    let ((rows, cols), generated) =
        crate::npy::read_npy_f32(&dir.join("region_generated.npy")).expect("generated region");
    assert_eq!((rows, cols), (64, 64));
    assert!(generated.iter().all(|v| v.is_finite()));
    assert_ne!(generated, metres, "generated, not copied");
    let img = image::open(&png).expect("picture");
    assert!(img.width() >= 3 * 64 && img.height() >= 64);

    // Not a square multiple of the window: refused, naming the file.
    crate::npy::write_npy_f32(&real, (64, 32), &metres[..64 * 32]).expect("write region");
    let err = heldout::compare(&dir, "core", &real, &png, 3, ComputeBackend::Cpu).expect_err("not square");
    assert!(err.to_string().contains("region.npy"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A smoke-trained core in a fresh folder `name`, and `count` real-looking 256² training tiles
/// (metres) written to its `data/core/train.npy`: (folder, data folder, the tiles' stack).
fn smoke_core_with_training_tiles(name: &str, count: usize) -> (PathBuf, PathBuf, Vec<f32>) {
    let dir = tempdir(name);
    train(&smoke_args(&dir, 2, false));
    let data_dir = dir.join("data");
    std::fs::create_dir_all(data_dir.join("core")).expect("data dir");
    let tiles = data::synthetic(count, data::PREPARED_TILE);
    let stack: Vec<f32> =
        tiles.tiles.iter().flat_map(|t| t.h.iter().map(|&h| infiniterra_terrain::encoding::signed_square(h))).collect();
    let train_npy = data_dir.join("core/train.npy");
    crate::npy::write_npy_f32(&train_npy, (count * data::PREPARED_TILE, data::PREPARED_TILE), &stack).expect("write");
    (dir, data_dir, stack)
}

#[test]
fn calibrating_the_response_writes_ascending_knots_and_nothing_else() {
    let (dir, data_dir, _) = smoke_core_with_training_tiles("response", 2);
    let manifest_text = || std::fs::read_to_string(dir.join("core.json")).expect("manifest");
    let before: serde_json::Value = serde_json::from_str(&manifest_text()).expect("JSON");
    response::run(&job(&dir, &data_dir)).expect("calibrates");

    let after: serde_json::Value = serde_json::from_str(&manifest_text()).expect("JSON");
    let knots: Vec<[f64; 2]> =
        serde_json::from_value(after["relief_hint"]["response"].clone()).expect("a response curve was written");
    assert!(!knots.is_empty() && knots.windows(2).all(|w| w[1][0] > w[0][0]), "{knots:?}");
    assert_eq!(after["relief_hint"]["offset"].as_f64(), Some(0.0), "the curve replaces the offset");
    let without_curve = |v: &serde_json::Value| {
        let mut v = v.clone();
        let hint = v["relief_hint"].as_object_mut().expect("object");
        hint.remove("response");
        hint.remove("offset");
        v
    };
    assert_eq!(without_curve(&after), without_curve(&before), "nothing but the curve and the offset changed");
    let model = infiniterra_terrain::model::load_model(&dir, "core", &ComputeBackend::Cpu.device().expect("cpu"))
        .expect("still loads");
    assert_eq!(model.manifest.relief_hint.expect("hint").response, knots);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn calibrating_the_relief_hint_changes_only_its_offset() {
    // Four real-looking 256² training tiles: two to generate, two for the floor.
    let (dir, data_dir, stack) = smoke_core_with_training_tiles("calibrate", 4);
    let train_npy = data_dir.join("core/train.npy");
    let manifest_text = || std::fs::read_to_string(dir.join("core.json")).expect("manifest");
    let before: serde_json::Value = serde_json::from_str(&manifest_text()).expect("JSON");
    calibrate::run(&job(&dir, &data_dir)).expect("calibrates");

    let after: serde_json::Value = serde_json::from_str(&manifest_text()).expect("JSON");
    let offset = after["relief_hint"]["offset"].as_f64().expect("an offset was written");
    assert!((0.0..=calibrate::GRID_MAX + calibrate::REFINE).contains(&offset), "offset {offset} is outside the sweep");
    let without_offset = |v: &serde_json::Value| {
        let mut v = v.clone();
        v["relief_hint"].as_object_mut().expect("object").remove("offset");
        v
    };
    assert_eq!(without_offset(&after), without_offset(&before), "nothing but the offset changed");
    assert!(
        infiniterra_terrain::model::load_model(&dir, "core", &ComputeBackend::Cpu.device().expect("cpu")).is_ok(),
        "still loads"
    );

    // Too few tiles: refused, naming the folder.
    crate::npy::write_npy_f32(&train_npy, (2 * data::PREPARED_TILE, data::PREPARED_TILE), &stack[..stack.len() / 2])
        .expect("write");
    let err = calibrate::run(&job(&dir, &data_dir)).expect_err("two tiles");
    assert!(err.to_string().contains("at least 4"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn calibrating_the_spectrum_writes_a_loadable_equaliser_measured_without_the_old_one() {
    let (dir, data_dir, _) = smoke_core_with_training_tiles("spectrum", 2);
    let read = || -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(dir.join("core.json")).expect("manifest")).expect("JSON")
    };
    let before = read();
    spectrum::run(&job(&dir, &data_dir)).expect("calibrates");
    let first = read();
    let eq: infiniterra_terrain::model::SpectralEqualiser =
        serde_json::from_value(first["spectral_equaliser"].clone()).expect("an equaliser was written");
    eq.validate(64).expect("valid gains");
    assert_eq!(eq.gains[1], [spectrum::KNOTS[0], 1.0], "the longest wavelengths are left alone");
    let mut rest = first.clone();
    rest.as_object_mut().expect("object").remove("spectral_equaliser");
    assert_eq!(rest, before, "nothing but the equaliser changed");
    // The model still loads with it, and a second calibration measures the network itself,
    // not the network through the first equaliser: the same gains again.
    infiniterra_terrain::model::load_model(&dir, "core", &ComputeBackend::Cpu.device().expect("cpu")).expect("loads");
    spectrum::run(&job(&dir, &data_dir)).expect("calibrates again");
    assert_eq!(read()["spectral_equaliser"], first["spectral_equaliser"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn calibrating_the_infill_writes_one_of_its_depth_scales_or_none_and_nothing_else() {
    let (dir, data_dir, _) = smoke_core_with_training_tiles("infill", 4);
    let read = || -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(dir.join("core.json")).expect("manifest")).expect("JSON")
    };
    let before = read();
    infill::run(&job(&dir, &data_dir)).expect("calibrates");
    let first = read();
    if let Some(entry) = first.get("depression_infill") {
        let infill: infiniterra_terrain::model::DepressionInfill =
            serde_json::from_value(entry.clone()).expect("a loadable entry");
        assert!(infill::DEPTH_SCALES_M.contains(&infill.depth_scale_m), "{infill:?} was not tried");
    }
    let mut rest = first.clone();
    rest.as_object_mut().expect("object").remove("depression_infill");
    assert_eq!(rest, before, "nothing but the infill changed");
    infiniterra_terrain::model::load_model(&dir, "core", &ComputeBackend::Cpu.device().expect("cpu")).expect("loads");
    // Every trial sets the infill itself, so the entry the first run wrote does not change
    // what a second run measures.
    infill::run(&job(&dir, &data_dir)).expect("calibrates again");
    assert_eq!(read(), first);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn held_out_draws_stack_draw_by_draw_and_draw_one_is_the_next_seed_block() {
    let (dir, data_dir, stack) = smoke_core_with_training_tiles("draws", 2);
    let heldout_npy = data_dir.join("core/heldout.npy");
    crate::npy::write_npy_f32(&heldout_npy, (2 * data::PREPARED_TILE, data::PREPARED_TILE), &stack).expect("write");
    let generate = |name: &str, draws: usize, seed: u64| {
        let out = dir.join(name);
        heldout::generate(&dir, "core", &data_dir, &out, 2, draws, seed, ComputeBackend::Cpu).expect("generates");
        let side: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.with_extension("json")).expect("sidecar")).expect("JSON");
        (crate::npy::read_npy_f32(&out).expect("npy"), side)
    };
    let (((rows, cols), two), side) = generate("two.npy", 2, 7);
    let n = data::PREPARED_TILE * data::PREPARED_TILE;
    assert_eq!((rows, cols), (4 * data::PREPARED_TILE, data::PREPARED_TILE), "2 tiles × 2 draws");
    assert_eq!(
        (side["count"].as_u64(), side["heldout_counterparts"].as_u64(), side["draws"].as_u64()),
        (Some(4), Some(2), Some(2))
    );
    let (((_, _), first), _) = generate("first.npy", 1, 7);
    let (((_, _), second), _) = generate("second.npy", 1, 7 + heldout::DRAW_SEED_STRIDE);
    assert_eq!(&two[..2 * n], &first[..], "draw 0 is the single-draw set");
    assert_eq!(&two[2 * n..], &second[..], "draw 1 is the set of the next seed block");
    assert_ne!(&two[..n], &two[2 * n..3 * n], "two draws of a tile differ");
    let _ = std::fs::remove_dir_all(&dir);
}
