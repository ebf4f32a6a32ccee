//! Tests of the whole map: sizes, panel, determinism, errors — on a synthetic field where the
//! pipeline is not the point, and on the real pipeline for the end-to-end checks.

use std::collections::HashSet;

use super::*;
use crate::terrain::TerrainSettings;

fn request(layer: Layer) -> RenderRequest {
    RenderRequest { x0: -64, z0: 32, width: 128, height: 128, zoom: 2, layer }
}

/// A synthetic terrain: sea in the west, rising land in the east, a ridge running north-south.
fn field(rect: Rect) -> Tile {
    let mut t = Tile::zeros(channel::COUNT, rect);
    let n = rect.area();
    let mut i = 0;
    for y in rect.y0..rect.y1() {
        for x in rect.x0..rect.x1() {
            let e = 40.0 * x as f32 + 300.0 * ((y as f32) / 9.0).sin();
            t.data[channel::ELEVATION * n + i] = e;
            t.data[channel::TEMPERATURE * n + i] = 25.0 - e / 100.0;
            t.data[channel::SEASONALITY * n + i] = (x.rem_euclid(20)) as f32;
            t.data[channel::PRECIPITATION * n + i] = (y * 20).rem_euclid(3000) as f32;
            t.data[channel::VARIABILITY * n + i] = 30.0;
            i += 1;
        }
    }
    t
}

fn draw_synthetic(req: &RenderRequest) -> (RgbImage, Vec<(u64, u64)>) {
    let style = layer::style(req.layer).unwrap();
    let size = check(req).unwrap();
    let title = title_lines(req, 7, &["layout".to_string()], 40.0);
    let grid = if req.zoom < 4 { CellGrid::BLOCKS } else { CellGrid::MODEL };
    let mut calls = Vec::new();
    let img = draw(req, size, &style, &title, (grid, 40.0), &mut field, &mut |d, t| calls.push((d, t)));
    (img, calls)
}

/// Clearly blue (the sea ramp).
fn is_sea(c: &[u8; 3]) -> bool {
    c[2] as i32 > c[0] as i32 + 40
}

/// Clearly green, yellow or brown (the land ramp), not blue.
fn is_land(c: &[u8; 3]) -> bool {
    c[1] as i32 > c[2] as i32 + 20 || c[0] as i32 > c[2] as i32 + 20
}

fn distinct_map_colours(img: &RgbImage, w: u32, h: u32) -> HashSet<[u8; 3]> {
    (0..h).flat_map(|y| (0..w).map(move |x| (x, y))).map(|(x, y)| img.get_pixel(x, y).0).collect()
}

#[test]
fn image_is_the_map_plus_a_panel_below() {
    let req = request(Layer::Elevation);
    let (img, calls) = draw_synthetic(&req);
    assert_eq!(img.width(), panel::MIN_FRAME_WIDTH, "narrow maps get a frame wide enough for the title");
    assert_eq!(img.height(), 64 + panel::height(1));
    assert_eq!(calls.last(), Some(&(64, 64)), "progress ends at all rows done");
    // The panel has ink (title, legend, scale bar) on its background.
    let panel_ink = (64..img.height())
        .flat_map(|y| (0..img.width()).map(move |x| (x, y)))
        .filter(|&(x, y)| img.get_pixel(x, y)[0] < 60)
        .count();
    assert!(panel_ink > 500, "panel shows text and bars ({panel_ink} dark pixels)");
    // Right of a narrow map the frame is plain panel background.
    assert_eq!(*img.get_pixel(100, 10), panel::BACKGROUND);
}

#[test]
fn elevation_map_shows_sea_and_land() {
    let (img, _) = draw_synthetic(&request(Layer::Elevation));
    let colours = distinct_map_colours(&img, 64, 64);
    assert!(colours.iter().any(is_sea), "some sea");
    assert!(colours.iter().any(is_land), "some land");
}

#[test]
fn every_drawable_layer_renders_at_block_and_model_zoom() {
    for layer in Layer::ALL.into_iter().filter(|&l| !matches!(l, Layer::Biome | Layer::Water)) {
        for zoom in [1, 3, 4, 7, 16] {
            let req = RenderRequest { zoom, ..request(layer) };
            let (img, _) = draw_synthetic(&req);
            let (w, h) = check(&req).unwrap();
            assert!(distinct_map_colours(&img, w, h).len() > 4, "{layer} at zoom {zoom} is nearly uniform");
        }
    }
}

#[test]
fn wide_maps_get_double_size_text() {
    let req = RenderRequest { width: 2000, height: 8, zoom: 1, ..request(Layer::Elevation) };
    let (img, _) = draw_synthetic(&req);
    assert_eq!((img.width(), img.height()), (2000, 8 + panel::height(2)));
}

#[test]
fn partial_pixels_round_the_size_up() {
    let req = RenderRequest { width: 10, height: 9, zoom: 4, ..request(Layer::Elevation) };
    assert_eq!(check(&req).unwrap(), (3, 3));
}

#[test]
fn bad_requests_are_refused_with_reasons() {
    let bad = |req: RenderRequest| check(&req).unwrap_err().to_string();
    assert!(bad(RenderRequest { zoom: 0, ..request(Layer::Elevation) }).contains("zoom"));
    assert!(bad(RenderRequest { width: 0, ..request(Layer::Elevation) }).contains("0x128"));
    let big = bad(RenderRequest { width: 1 << 20, zoom: 1, ..request(Layer::Elevation) });
    assert!(big.contains("16384"), "{big}");
    let far = bad(RenderRequest { x0: i64::MAX - 10, ..request(Layer::Elevation) });
    assert!(far.contains("range"), "{far}");
}

/// The real pipeline at default settings, for the end-to-end checks.
fn pipeline() -> Pipeline {
    Pipeline::new(42, &TerrainSettings::default())
}

#[test]
fn biome_layer_needs_rules() {
    let err = render(&pipeline(), &request(Layer::Biome), &mut |_, _| {}).unwrap_err();
    assert!(matches!(err, RenderError::BiomeNeedsRules));
    assert!(err.to_string().contains("render_biomes"));
}

#[test]
fn pipeline_render_is_deterministic_and_not_uniform() {
    let p = pipeline();
    for req in
        [request(Layer::Elevation), RenderRequest { zoom: 64, width: 8192, height: 4096, ..request(Layer::Elevation) }]
    {
        let a = render(&p, &req, &mut |_, _| {}).unwrap();
        let b = render(&pipeline(), &req, &mut |_, _| {}).unwrap();
        assert!(a == b, "two renders of the same request differ");
        let (w, h) = check(&req).unwrap();
        assert!(distinct_map_colours(&a, w, h).len() > 1, "map at zoom {} is uniform", req.zoom);
    }
}

#[test]
fn continental_map_has_sea_and_land() {
    // 1 px = 64 blocks = 8 km: 256 px span 2000 km, a continent's width at default settings.
    let req = RenderRequest { x0: -8192, z0: -8192, width: 16384, height: 16384, zoom: 64, layer: Layer::Elevation };
    let img = render(&pipeline(), &req, &mut |_, _| {}).unwrap();
    let colours = distinct_map_colours(&img, 256, 256);
    assert!(colours.iter().any(is_sea), "no sea in a 2000 km map");
    assert!(colours.iter().any(is_land), "no land in a 2000 km map");
}

#[test]
fn save_png_writes_a_readable_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("map.png");
    let (img, _) = draw_synthetic(&request(Layer::Temperature));
    save_png(&img, &path).unwrap();
    let back = image::open(&path).unwrap().to_rgb8();
    assert!(back == img);
    assert!(!dir.path().join("map.png.tmp").exists());
    let err = save_png(&img, &dir.path().join("missing/map.png")).unwrap_err();
    assert!(err.to_string().contains("missing"), "{err}");
}

#[test]
fn title_says_what_where_and_how_big() {
    let lines =
        title_lines(&RenderRequest { zoom: 256, ..request(Layer::Precipitation) }, 42, &["layout".into()], 125.0);
    assert_eq!(lines.len(), panel::TITLE_LINES);
    assert_eq!(lines[0], "precipitation - seed 42 - stages: layout");
    assert_eq!(lines[1], "x -64..64, z 32..160 (128×128 blocks)");
    assert_eq!(lines[2], "zoom 256 blocks/px = 32 km/px");
    assert_eq!(distance(125.0), "125 m");
    assert_eq!(distance(1500.0), "1.5 km");
}
