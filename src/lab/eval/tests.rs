//! End to end on small synthetic files: a prepared-set directory and an exported map.

use std::path::Path;

use super::*;
use crate::npy::write_npy_f32;

/// Terrain-like values: positive fBm relief (no sea) so every metric has something to see.
fn hills(rows: usize, cols: usize, metres: f64, seed: u64) -> Raster {
    let mut r = fbm(rows, cols, metres, -3.0, seed);
    r.data.iter_mut().for_each(|v| *v = 800.0 + 300.0 * *v);
    r
}

/// A stack of `n` tiles written as a prepared split: `name.npy` + `name.json`.
fn write_split(dir: &Path, name: &str, n: usize, tile: usize, seed: u64) {
    let data: Vec<f32> = (0..n).flat_map(|i| hills(tile, tile, 1000.0, seed + i as u64).data).collect();
    write_npy_f32(&dir.join(format!("{name}.npy")), (n * tile, tile), &data).unwrap();
    let side = serde_json::json!({"metres_per_pixel": 1000.0, "tile": tile, "count": n, "split": name});
    std::fs::write(dir.join(format!("{name}.json")), side.to_string()).unwrap();
}

/// A prepared set `<dir>/core/` of `heldout` held-out and 3 training 64² tiles.
fn prepared_set(dir: &Path, heldout: usize) -> std::path::PathBuf {
    let set = dir.join("core");
    std::fs::create_dir(&set).unwrap();
    write_split(&set, "heldout", heldout, 64, 1);
    write_split(&set, "train", 3, 64, 10);
    set
}

/// A generated map at 500 m with an export sidecar.
fn write_generated(path: &Path, side: usize) {
    let r = hills(side, side, 500.0, 99);
    write_npy_f32(path, (side, side), &r.data).unwrap();
    let meta = serde_json::json!({
        "x0": -256, "z0": 128, "width": side, "height": side, "grid": "model", "metres_per_pixel": 500.0,
        "seed": 1, "stages": ["layout"], "vertical": {"sea_level_y": 63, "metres_per_block": 25.0}
    });
    std::fs::write(path.with_extension("json"), meta.to_string()).unwrap();
}

fn args(generated: &Path, reference: &Path, out: &Path) -> EvalOptions {
    EvalOptions {
        generated: generated.into(),
        reference: reference.into(),
        out: out.into(),
        seam_stride: 32,
        record: None,
        min_land: 0.0,
    }
}

#[test]
fn the_realism_bar_passes_real_terrain_fails_rougher_terrain_and_is_recorded_in_a_manifest() {
    let dir = tempfile::tempdir().unwrap();
    let set = prepared_set(dir.path(), 3);
    // "Generated" = the held-out tiles themselves: every distance is 0.
    let same = dir.path().join("same.npy");
    std::fs::copy(set.join("heldout.npy"), &same).unwrap();
    std::fs::copy(set.join("heldout.json"), same.with_extension("json")).unwrap();
    let manifest = dir.path().join("core.json");
    std::fs::write(&manifest, r#"{"stage": "core", "realism": {"old": 1.0}}"#).unwrap();
    let mut a = args(&same, &set, &dir.path().join("a.png"));
    a.record = Some(manifest.clone());
    let report = run(&a, &mut |_, _| {}).unwrap();
    let slope = report.targets.iter().find(|t| t.key == "slope_w1_deg").expect("slope target");
    assert!(slope.pass && slope.value == 0.0, "{slope:?}");
    // docs/realism.md's two drainage numbers are both on the bar.
    for key in ["depressions_per_1000_km2", "fill_volume_per_km2"] {
        let t = report.targets.iter().find(|t| t.key == key).unwrap_or_else(|| panic!("{key} target"));
        assert!(t.pass, "{t:?}");
    }
    assert!(report.to_string().contains("realism bar (generated)"), "{report}");
    let written: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&manifest).unwrap()).unwrap();
    assert_eq!(written["stage"], "core", "other fields are kept");
    assert_eq!(written["realism"]["slope_w1_deg"], 0.0);
    assert_eq!(written["realism"]["slope_w1_deg_met"], 1.0);
    assert!(written["realism"].get("old").is_none(), "old numbers are replaced");
    // Beside the bar: real land on the same lines, and real-vs-real splits of the spectral slope.
    assert_eq!(report.real_land.len(), report.targets.len());
    let real_slope = report.real_land.iter().find(|t| t.key == "slope_w1_deg").expect("slope line for real land");
    assert_eq!(
        Some(format!("{:.2}", real_slope.value).as_str()),
        report.get("slope W1", 3),
        "the train column's distance"
    );
    let splits = report.beta_splits.as_ref().expect("a train split gives real-vs-real splits");
    assert_eq!(splits.sizes, (3, 3));
    assert!(splits.median <= splits.p90 && (0.0..=1.0).contains(&splits.within_line), "{splits:?}");
    // Generated = the reference itself, at distance 0: real sets of different hills lie farther apart.
    assert_eq!(splits.generated, 0.0);
    assert!(splits.farther_than_generated > 0.9, "{splits:?}");
    assert!(report.to_string().contains("real vs real by chance"), "{report}");
    assert_eq!(written["realism"]["real_land_lines_met"], report.real_land.iter().filter(|t| t.pass).count() as f64);
    assert_eq!(written["realism"]["real_split_abs_delta_beta_median"], splits.median);

    // Ten times the relief: slopes far off, the bar is not met.
    let rough = dir.path().join("rough.npy");
    let data: Vec<f32> = (0..3).flat_map(|i| hills(64, 64, 1000.0, 1 + i).data).map(|v| 10.0 * (v - 800.0)).collect();
    write_npy_f32(&rough, (3 * 64, 64), &data).unwrap();
    std::fs::copy(set.join("heldout.json"), rough.with_extension("json")).unwrap();
    let report = run(&args(&rough, &set, &dir.path().join("b.png")), &mut |_, _| {}).unwrap();
    let slope = report.targets.iter().find(|t| t.key == "slope_w1_deg").expect("slope target");
    assert!(!slope.pass, "{slope:?}");
    assert!(report.to_string().contains("NOT met"), "{report}");
}

#[test]
fn counterparts_of_the_first_heldout_tiles_are_compared_with_those_tiles_only() {
    let dir = tempfile::tempdir().unwrap();
    let set = prepared_set(dir.path(), 3);
    // The first held-out tile itself, as `train core --generate-heldout --tiles 1` labels it.
    let first = dir.path().join("first.npy");
    let (_, heldout) = crate::npy::read_npy_f32(&set.join("heldout.npy")).unwrap();
    write_npy_f32(&first, (64, 64), &heldout[..64 * 64]).unwrap();
    let side = serde_json::json!({"metres_per_pixel": 1000.0, "tile": 64, "count": 1, "heldout_counterparts": 1});
    std::fs::write(first.with_extension("json"), side.to_string()).unwrap();
    let report = run(&args(&first, &set, &dir.path().join("a.png")), &mut |_, _| {}).unwrap();
    assert_eq!(report.get("tiles", 0), Some("1"), "the reference is cut to the first tile");
    let slope = report.targets.iter().find(|t| t.key == "slope_w1_deg").expect("slope target");
    assert_eq!(slope.value, 0.0, "a tile is at distance 0 from itself");

    // Without the label the same tile is compared with all three (other hills: not 0).
    std::fs::write(first.with_extension("json"), r#"{"metres_per_pixel": 1000.0, "tile": 64}"#).unwrap();
    let report = run(&args(&first, &set, &dir.path().join("b.png")), &mut |_, _| {}).unwrap();
    assert_eq!(report.get("tiles", 0), Some("3"));
    let slope = report.targets.iter().find(|t| t.key == "slope_w1_deg").expect("slope target");
    assert!(slope.value > 0.0, "{slope:?}");
}

#[test]
fn eval_measures_generated_fbm_and_real_and_writes_the_image() {
    let dir = tempfile::tempdir().unwrap();
    let set = prepared_set(dir.path(), 2);
    let generated = dir.path().join("gen.npy");
    write_generated(&generated, 256);
    let out = dir.path().join("report/eval.png");

    let mut calls = 0;
    let report = run(&args(&generated, &set, &out), &mut |_, _| calls += 1).unwrap();
    let text = report.to_string();
    for row in [
        "slope mean",
        "slope W1",
        "slope χ²",
        "rel. elevation W1",
        "spectral slope β",
        "β standard error",
        "|Δβ|",
        "depressions",
        "fill volume",
        "seam ratio",
    ] {
        assert!(text.contains(row), "row {row} missing:\n{text}");
    }
    assert_eq!(report.columns, ["reference", "generated", "fBm", "train (real)"]);
    // 256² at 500 m → 128² at 1000 m → four 64² tiles, and as many fBm tiles.
    assert_eq!(report.get("tiles", 1), Some("4"));
    assert_eq!(report.get("tiles", 2), Some("4"));
    assert_eq!(report.get("tiles", 3), Some("3"));
    assert_eq!(report.get("slope W1", 0), Some("-"), "no distance of the reference to itself");
    assert!(text.contains("resampled bilinearly from 500 m"), "{text}");
    assert_eq!(calls, 4 + 4 + 2 + 3, "progress once per tile");
    let beta: f64 = report.get("spectral slope", 2).unwrap().parse().unwrap();
    assert!((-3.6..=-2.4).contains(&beta), "fBm baseline β = {beta}");
    let sd: f64 = report.get("β standard error", 0).unwrap().parse().unwrap();
    assert!(sd > 0.0 && sd < 0.5, "four different tiles: a finite, non-zero standard error, got {sd}");
    let seam: f64 = report.get("seam ratio", 1).unwrap().parse().unwrap();
    assert!((0.8..1.25).contains(&seam), "seamless noise has seam ratio ≈ 1, got {seam}");
    let img = image::open(&out).unwrap();
    assert!(img.width() >= 1000 && img.height() >= 400);
    let panels = 2 + report.beta_splits.is_some() as u32;
    assert_eq!(panels, 3, "a train split adds the real-vs-real panel");
    assert_eq!(img.width() % panels, 0, "{} px for {panels} panels", img.width());
    assert!(img.width() / panels >= 500);
}

#[test]
fn generated_tiles_with_too_little_land_are_left_out_on_request() {
    let dir = tempfile::tempdir().unwrap();
    let set = prepared_set(dir.path(), 2);
    let generated = dir.path().join("gen.npy");
    write_generated(&generated, 256);
    // Sink the west half under the sea: two of the four 1 km tiles become sea.
    let (_, mut data) = crate::npy::read_npy_f32(&generated).unwrap();
    data.chunks_mut(256).for_each(|row| row[..128].iter_mut().for_each(|v| *v -= 5000.0));
    write_npy_f32(&generated, (256, 256), &data).unwrap();
    let out = dir.path().join("eval.png");
    let all = run(&args(&generated, &set, &out), &mut |_, _| {}).unwrap();
    assert_eq!(all.get("tiles", 1), Some("4"));
    let land = run(&EvalOptions { min_land: 0.99, ..args(&generated, &set, &out) }, &mut |_, _| {}).unwrap();
    assert_eq!(land.get("tiles", 1), Some("2"));
    assert_eq!(land.get("land fraction (> 0 m)", 1), Some("1.00"));
    let none = run(&EvalOptions { min_land: 1.0, ..args(&generated, &set, &out) }, &mut |_, _| {});
    data.iter_mut().for_each(|v| *v -= 5000.0);
    write_npy_f32(&generated, (256, 256), &data).unwrap();
    let none_at_all = run(&EvalOptions { min_land: 0.5, ..args(&generated, &set, &out) }, &mut |_, _| {});
    assert!(none.is_ok(), "the two land tiles are wholly land");
    let err = none_at_all.expect_err("an all-sea map has no land tile").to_string();
    assert!(err.contains("gen.npy") && err.contains("none with at least 0.5 land"), "{err}");
}

#[test]
fn a_single_reference_file_has_no_train_column() {
    let dir = tempfile::tempdir().unwrap();
    write_split(dir.path(), "ref", 1, 64, 3);
    let generated = dir.path().join("gen.npy");
    write_generated(&generated, 64);
    let report =
        run(&args(&generated, &dir.path().join("ref.npy"), &dir.path().join("r.png")), &mut |_, _| {}).unwrap();
    assert_eq!(report.columns, ["reference", "generated", "fBm"]);
    assert!(report.places.is_none(), "one file says nothing of where its tiles lie");
}

#[test]
fn bad_inputs_are_input_errors_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let generated = dir.path().join("gen.npy");
    write_generated(&generated, 64);
    let missing = dir.path().join("nowhere");
    let err = run(&args(&generated, &missing, &dir.path().join("r.png")), &mut |_, _| {}).unwrap_err();
    assert!(matches!(&err, EvalError::Input(m) if m.contains("nowhere")), "{err}");

    write_split(dir.path(), "ref", 1, 64, 3);
    std::fs::remove_file(generated.with_extension("json")).unwrap();
    let err =
        run(&args(&generated, &dir.path().join("ref.npy"), &dir.path().join("r.png")), &mut |_, _| {}).unwrap_err();
    assert!(matches!(&err, EvalError::Input(m) if m.contains("gen.json")), "{err}");

    std::fs::write(generated.with_extension("json"), r#"{"metres_per_pixel": -1}"#).unwrap();
    let err =
        run(&args(&generated, &dir.path().join("ref.npy"), &dir.path().join("r.png")), &mut |_, _| {}).unwrap_err();
    assert!(err.to_string().contains("metres_per_pixel"), "{err}");
}

#[test]
fn seams_of_the_generated_map_follow_its_window_lines() {
    // Steps of 200 m on every model-pixel column x ≡ 0 (mod 32) in global coordinates; the map
    // starts at block x −256 = model pixel −64, so the lines fall on array columns 0, 32, 64.
    let dir = tempfile::tempdir().unwrap();
    let generated = dir.path().join("gen.npy");
    write_generated(&generated, 128);
    let mut map = Heightmap::load(&generated).unwrap();
    assert_eq!(map.origin, Some((-64, 32)));
    let smooth = native_seams(&map, 32).ratio();
    map.raster = Raster::from_fn(128, 128, 500.0, |y, x| map.raster.at(y, x) + 200.0 * (x / 32) as f32);
    let stepped = native_seams(&map, 32).ratio();
    assert!(stepped > smooth * 1.3, "steps on the window lines: {stepped} vs {smooth}");
}

#[test]
fn a_prepared_sets_manifest_places_its_tiles_and_the_real_splits_deal_whole_squares() {
    let dir = tempfile::tempdir().unwrap();
    let set = prepared_set(dir.path(), 3);
    // Held-out tiles in square (1, 1), training tiles in squares (0, 0) and (0, 1).
    let entry = |split: &str, index: usize, row: i64, col: i64| serde_json::json!({"split": split, "index": index, "row": row, "col": col, "lat": 0.0});
    let tiles = vec![
        entry("heldout", 0, 2, 2),
        entry("heldout", 1, 2, 3),
        entry("heldout", 2, 3, 2),
        entry("train", 0, 0, 0),
        entry("train", 1, 1, 1),
        entry("train", 2, 0, 2),
    ];
    std::fs::write(set.join("manifest.json"), serde_json::json!({"stage": "core", "tiles": tiles}).to_string())
        .unwrap();
    let reference = Reference::load(&set).unwrap();
    let regions = reference.regions.as_ref().expect("regions from the manifest");
    assert!(regions.heldout.iter().all(|k| *k == regions.heldout[0]), "one square: {regions:?}");
    assert_eq!(regions.train[0], regions.train[1], "tiles (0,0) and (1,1) share a square");
    assert_ne!(regions.train[0], regions.train[2]);
    let generated = dir.path().join("gen.npy");
    write_generated(&generated, 256);
    let report = run(&args(&generated, &set, &dir.path().join("a.png")), &mut |_, _| {}).unwrap();
    assert!(report.beta_splits.as_ref().is_some_and(|b| b.by_region), "{report}");
    assert!(report.to_string().contains("whole 2×2-tile squares"), "{report}");
    // Real places: rows and columns 0…3 split at 2; the south-west quarter holds no tile.
    let places = report.places.as_ref().expect("the manifest places the tiles");
    assert_eq!(places.tiles, vec![2, 1, 3], "{places:?}");
    assert_eq!(places.distances.len(), 3);
    assert!(places.distances.iter().all(|d| d.is_finite() && *d > 0.0), "{places:?}");
    assert!(report.to_string().contains("slope W1 between real places"), "{report}");

    // A manifest that misplaces a tile is an input error naming it.
    let tiles = vec![entry("heldout", 7, 2, 2)];
    std::fs::write(set.join("manifest.json"), serde_json::json!({"tiles": tiles}).to_string()).unwrap();
    let err = Reference::load(&set).unwrap_err();
    assert!(err.to_string().contains("manifest.json") && err.to_string().contains("index 7"), "{err}");
}

#[test]
fn the_calibrations_realism_bar_is_the_reports_bar() {
    let dir = tempfile::tempdir().unwrap();
    let set = prepared_set(dir.path(), 3);
    let rough = dir.path().join("rough.npy");
    let data: Vec<f32> = (0..3).flat_map(|i| hills(64, 64, 1000.0, 7 + i).data).map(|v| 3.0 * (v - 800.0)).collect();
    write_npy_f32(&rough, (3 * 64, 64), &data).unwrap();
    std::fs::copy(set.join("heldout.json"), rough.with_extension("json")).unwrap();
    let report = run(&args(&rough, &set, &dir.path().join("a.png")), &mut |_, _| {}).unwrap();
    let reference = Reference::load(&set).unwrap();
    let tiles = |h: &Heightmap| h.tiles_at(1000.0, 64);
    let generated = tiles(&Heightmap::load(&rough).unwrap());
    let train = tiles(reference.train.as_ref().unwrap());
    let bar = realism_bar(&tiles(&reference.heldout), &generated, &train, 32);
    // The report measures the generated map's seams on its own window lines; all else is equal.
    let without_seams = |t: &[Target]| -> Vec<(String, f64)> {
        t.iter().filter(|t| t.key != "seam_ratio").map(|t| (t.key.clone(), t.value)).collect()
    };
    assert_eq!(without_seams(&bar), without_seams(&report.targets));
    assert_eq!(bar.len(), report.targets.len());
}
