//! Tests of whole exports: region → cells, streaming, sidecar contents, and equality with
//! the pipeline's own answers.

use super::*;
use crate::npy::read_npy_f32;
use crate::terrain::pipeline::channel;
use crate::terrain::TerrainSettings;

const VERTICAL: Vertical = Vertical { sea_level_y: 63, metres_per_block: 20.0 };

fn request(grid: Grid) -> ExportRequest {
    ExportRequest { x0: -37, z0: 21, width: 50, height: 30, grid, quantity: Quantity::Elevation }
}

#[test]
fn model_grid_covers_every_block_with_floor_division() {
    // Blocks −37..=12 → model −10..=3; blocks 21..=50 → model 5..=12.
    assert_eq!(cells(&request(Grid::Model)).unwrap(), Rect::new(5, -10, 8, 14));
    assert_eq!(cells(&request(Grid::Block)).unwrap(), Rect::new(21, -37, 30, 50));
    let one = ExportRequest { x0: -1, z0: 4, width: 1, height: 1, grid: Grid::Model, quantity: Quantity::Elevation };
    assert_eq!(cells(&one).unwrap(), Rect::new(1, -1, 1, 1));
}

#[test]
fn bad_regions_are_refused() {
    let bad = |r: ExportRequest| cells(&r).unwrap_err().to_string();
    assert!(bad(ExportRequest { width: 0, ..request(Grid::Block) }).contains("0x30"));
    assert!(bad(ExportRequest { x0: i64::MAX, ..request(Grid::Block) }).contains("range"));
}

#[test]
fn streaming_in_strips_writes_every_row_in_order() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("nested/dir/a.npy");
    // Wide enough that a strip holds fewer rows than the array.
    let rect = Rect::new(-3, 5, 7, (CELLS_PER_STRIP / 2) + 1);
    let mut queries = 0;
    let mut query = |r: Rect| {
        queries += 1;
        let mut t = Tile::zeros(2, r);
        let n = r.area();
        for (i, v) in t.data[..n].iter_mut().enumerate() {
            *v = (r.y0 + (i as i64) / r.w) as f32 * 10.0 + (i as i64 % r.w % 7) as f32;
        }
        t
    };
    let mut last = (0, 0);
    let (min, max) = write_array(&path, rect, Quantity::Elevation, &mut query, &mut |d, t| last = (d, t)).unwrap();
    assert_eq!(queries, 7, "one row per strip at this width");
    assert_eq!(last, (7, 7));
    assert_eq!((min, max), (-30.0, 36.0));
    let (shape, data) = read_npy_f32(&path).unwrap();
    assert_eq!(shape, (7, rect.w as usize));
    assert_eq!(data[0], -30.0);
    assert_eq!(data[6 * rect.w as usize + 3], 33.0);
}

#[test]
fn json_output_name_is_refused_before_any_work() {
    let p = Pipeline::new(1, &TerrainSettings::default());
    let err = export(&p, &request(Grid::Block), &VERTICAL, Path::new("x.json"), &mut |_, _| {}).unwrap_err();
    assert!(matches!(err, ExportError::OutputIsJson(_)), "{err}");
    assert!(err.is_bad_input());
    let bad = Vertical { metres_per_block: 0.0, ..VERTICAL };
    let err = export(&p, &request(Grid::Block), &bad, Path::new("x.npy"), &mut |_, _| {}).unwrap_err();
    assert!(err.to_string().contains("metres_per_block"), "{err}");
}

fn run(grid: Grid) -> (tempfile::TempDir, ExportSummary, Pipeline) {
    let dir = tempfile::tempdir().unwrap();
    let pipeline = Pipeline::new(42, &TerrainSettings::default());
    let out = dir.path().join("height.npy");
    let summary = export(&pipeline, &request(grid), &VERTICAL, &out, &mut |_, _| {}).unwrap();
    (dir, summary, pipeline)
}

#[test]
fn model_grid_export_equals_the_pipeline_model() {
    let (_dir, summary, pipeline) = run(Grid::Model);
    let rect = Rect::new(5, -10, 8, 14);
    let (shape, data) = read_npy_f32(&summary.npy).unwrap();
    assert_eq!(shape, (8, 14));
    assert_eq!(summary.shape, shape);
    let expected = pipeline.model(rect);
    assert_eq!(data, expected.channel(channel::ELEVATION));
    let meta = ExportMeta::read(&summary.json).unwrap();
    assert_eq!((meta.x0, meta.z0, meta.width, meta.height), (-40, 20, 14, 8));
    assert_eq!(meta.grid, Grid::Model);
    assert_eq!(meta.metres_per_pixel, 4.0 * crate::terrain::settings::DEFAULT_METRES_PER_BLOCK);
}

#[test]
fn block_grid_export_equals_the_pipeline_columns() {
    let (_dir, summary, pipeline) = run(Grid::Block);
    let (shape, data) = read_npy_f32(&summary.npy).unwrap();
    assert_eq!(shape, (30, 50));
    let expected = pipeline.columns(Rect::new(21, -37, 30, 50));
    assert_eq!(data, expected.channel(channel::ELEVATION));
    let lo = data.iter().copied().fold(f32::INFINITY, f32::min);
    let hi = data.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    assert_eq!((summary.min, summary.max), (lo, hi));
}

#[test]
fn json_sidecar_has_every_field() {
    let (_dir, summary, pipeline) = run(Grid::Block);
    assert_eq!(summary.json, summary.npy.with_extension("json"));
    let text = std::fs::read_to_string(&summary.json).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v["x0"], -37);
    assert_eq!(v["z0"], 21);
    assert_eq!(v["width"], 50);
    assert_eq!(v["height"], 30);
    assert_eq!(v["grid"], "block");
    assert_eq!(v["metres_per_pixel"], crate::terrain::settings::DEFAULT_METRES_PER_BLOCK);
    assert_eq!(v["seed"], 42);
    assert_eq!(v["stages"], serde_json::json!(pipeline.active_stages()));
    assert_eq!(v["vertical"]["sea_level_y"], 63);
    assert_eq!(v["vertical"]["metres_per_block"], 20.0);
}

#[test]
fn water_quantities_are_block_grid_only_and_say_what_they_are() {
    let pipeline = Pipeline::new(3, &TerrainSettings::default());
    let dir = tempfile::tempdir().unwrap();
    let vertical = Vertical { sea_level_y: 63, metres_per_block: 25.0 };
    let out = dir.path().join("q.npy");
    let model = ExportRequest { quantity: Quantity::Discharge, ..request(Grid::Model) };
    let err = export(&pipeline, &model, &vertical, &out, &mut |_, _| {}).unwrap_err();
    assert!(err.is_bad_input() && err.to_string().contains("--grid block"), "{err}");
    let block = ExportRequest { quantity: Quantity::Discharge, ..request(Grid::Block) };
    export(&pipeline, &block, &vertical, &out, &mut |_, _| {}).unwrap();
    assert_eq!(ExportMeta::read(&ExportMeta::path_for(&out)).unwrap().quantity, Quantity::Discharge);
    let values = read_npy_f32(&out).unwrap().1;
    let columns = pipeline.columns(Rect::new(21, -37, 30, 50));
    assert_eq!(values, columns.channel(channel::DISCHARGE));
}

#[test]
fn the_surface_is_the_water_where_there_is_water_and_the_ground_elsewhere() {
    let pipeline = Pipeline::new(3, &TerrainSettings::default());
    // A stretch of the world with both wet and dry columns (the first coast or river found
    // walking east), so that both halves of the rule are exercised.
    let rect = (0..64)
        .map(|i| Rect::new(0, i * 256, 32, 256))
        .find(|&r| {
            let water = pipeline.columns(r).channel(channel::WATER_LEVEL).to_vec();
            water.iter().any(|w| w.is_nan()) && water.iter().any(|w| !w.is_nan())
        })
        .expect("a stretch with water and dry land within 16,384 blocks");
    let dir = tempfile::tempdir().unwrap();
    let vertical = Vertical { sea_level_y: 63, metres_per_block: 25.0 };
    let out = dir.path().join("surface.npy");
    let req = ExportRequest {
        x0: rect.x0,
        z0: rect.y0,
        width: rect.w,
        height: rect.h,
        grid: Grid::Block,
        quantity: Quantity::Surface,
    };
    export(&pipeline, &req, &vertical, &out, &mut |_, _| {}).unwrap();
    let surface = read_npy_f32(&out).unwrap().1;
    let columns = pipeline.columns(rect);
    let (ground, water) = (columns.channel(channel::ELEVATION), columns.channel(channel::WATER_LEVEL));
    let mut wet_below = 0;
    for i in 0..surface.len() {
        if water[i].is_nan() {
            assert_eq!(surface[i], ground[i], "dry column {i}: the ground");
        } else {
            assert_eq!(surface[i], water[i].max(ground[i]), "wet column {i}: the water surface");
            wet_below += usize::from(ground[i] < water[i]);
        }
    }
    assert!(wet_below > 0, "some water stands over lower ground, so the surface differs from the ground");
}
