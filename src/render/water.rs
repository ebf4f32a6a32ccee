//! The water layer: rivers by discharge, lakes, dry lake beds and the sea over a pale
//! hillshade, with a legend of what covers the map.
//!
//! Close up (under 4 blocks a pixel) every pixel shows its block column's water exactly as
//! chunks are built; further out lakes and dry beds come from the drainage network's cells
//! and rivers are drawn as their courses, as thick as they are wide (at least a pixel), so a
//! continent's network stays visible at any zoom.

use std::collections::HashMap;

use image::{Rgb, RgbImage};

use super::biomes::frame;
use super::sample::{self, CellGrid, Geometry};
use super::{check, ramp, shade, title_lines, RenderError, RenderRequest};
use crate::terrain::hydrology::{self, Kind, WaterColumns};
use crate::terrain::pipeline::{channel, BLOCKS_PER_MODEL_PIXEL};
use crate::terrain::{Pipeline, Rect, Tile};

/// What a pixel shows, and its legend entry.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
enum Cover {
    Land,
    Sea,
    River,
    Lake,
    DryBed,
}

impl Cover {
    fn name(self) -> &'static str {
        match self {
            Cover::Land => "land",
            Cover::Sea => "sea",
            Cover::River => "river",
            Cover::Lake => "lake",
            Cover::DryBed => "dry lake bed",
        }
    }

    fn colour(self) -> [u8; 3] {
        match self {
            Cover::Land => [200, 200, 190],
            Cover::Sea => [40, 70, 140],
            Cover::River => [20, 90, 230],
            Cover::Lake => [60, 140, 235],
            Cover::DryBed => [230, 210, 160],
        }
    }

    fn from_name(name: &str) -> Rgb<u8> {
        let all = [Cover::Land, Cover::Sea, Cover::River, Cover::Lake, Cover::DryBed];
        Rgb(all.into_iter().find(|c| c.name() == name).map_or([0, 0, 0], Cover::colour))
    }

    /// From a [`channel::WATER`] code and the elevation.
    fn of(code: f32, elevation: f32) -> Cover {
        match code as u8 {
            WaterColumns::RIVER => Cover::River,
            c if c == Kind::Lake as u8 => Cover::Lake,
            c if c == Kind::Dry as u8 => Cover::DryBed,
            _ if elevation < 0.0 => Cover::Sea,
            _ => Cover::Land,
        }
    }
}

/// Draws the water map `req` asks for; `progress(done, total)` counts image rows.
pub fn render_water(
    pipeline: &Pipeline,
    req: &RenderRequest,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<RgbImage, RenderError> {
    let (width, height) = check(req)?;
    let b = pipeline.block_metres();
    let metres_per_px = req.zoom as f64 * b;
    let geometry = Geometry { x0: req.x0, z0: req.z0, zoom: req.zoom };
    let close = req.zoom < BLOCKS_PER_MODEL_PIXEL;
    let (grid, mut query): (CellGrid, Box<dyn FnMut(Rect) -> Tile>) = if close {
        (CellGrid::BLOCKS, Box::new(|r| pipeline.columns(r).select(&[channel::ELEVATION, channel::WATER])))
    } else {
        (CellGrid::MODEL, Box::new(|r| model_cover(pipeline, r)))
    };
    let exaggeration = shade::exaggeration(metres_per_px);
    let mut map = RgbImage::new(width, height);
    let mut counts: HashMap<String, u64> = HashMap::new();
    let (w, h) = (width as i64, height as i64);
    let rows = 64;
    let mut top = 0;
    while top < h {
        let bottom = (top + rows).min(h);
        let s = sample::strip(&geometry, grid, top - 1..bottom + 1, -1..w + 1, &[0, 1], &mut *query);
        for py in top..bottom {
            for px in 0..w {
                let (r, c) = ((py - top + 1) as usize, (px + 1) as usize);
                let e = s.get(0, r, c);
                let cover = Cover::of(s.get(1, r, c), e);
                let light = shade::illumination(
                    s.get(0, r, c - 1),
                    s.get(0, r, c + 1),
                    s.get(0, r - 1, c),
                    s.get(0, r + 1, c),
                    metres_per_px as f32,
                    exaggeration,
                );
                let base = match cover {
                    // Pale relief, so water stands out.
                    Cover::Land => ramp::elevation(e).map(|v| 0.45 * v + 0.55 * 225.0),
                    Cover::Sea => ramp::elevation(e),
                    other => other.colour().map(f32::from),
                };
                let strength = if cover == Cover::Land { 0.9 } else { 0.2 };
                map.put_pixel(px as u32, py as u32, ramp::to_rgb(shade::apply(base, light, strength)));
                *counts.entry(cover.name().to_string()).or_default() += 1;
            }
        }
        top = bottom;
        progress(top as u64, h as u64);
    }
    if !close {
        let blocks = Rect::new(req.z0, req.x0, req.height, req.width);
        let drawn = draw_courses(&mut map, &pipeline.river_courses(blocks), (req.x0, req.z0), b, metres_per_px);
        *counts.entry(Cover::River.name().to_string()).or_default() += drawn;
    }
    let title = title_lines(req, pipeline.seed(), &pipeline.active_stages(), b);
    Ok(frame(map, &title, counts, Cover::from_name))
}

/// Elevation and water code of model pixels: lakes and dry beds from the network cell under
/// each pixel's centre (rivers are drawn as courses on top).
fn model_cover(pipeline: &Pipeline, r: Rect) -> Tile {
    let elevation = pipeline.elevation(r);
    let pixel_m = pipeline.model_pixel_metres();
    let cell = |i: i64| ((i as f64 + 0.5) * pixel_m / hydrology::CELL_METRES).floor() as i64;
    let cells = Rect::new(cell(r.y0), cell(r.x0), cell(r.y1() - 1) - cell(r.y0) + 1, cell(r.x1() - 1) - cell(r.x0) + 1);
    let network = pipeline.network(cells);
    let mut out = Tile::stack(&[&elevation, &elevation]);
    let n = r.area();
    let mut i = 0;
    for y in r.y0..r.y1() {
        for x in r.x0..r.x1() {
            let kind = Kind::from_code(network.get(hydrology::grid::KIND, cell(y), cell(x)));
            // As the blocks show them: ground under the basin's level.
            let level = network.get(hydrology::grid::LEVEL, cell(y), cell(x));
            let under = elevation.data[i] < level;
            let bed = f64::from(elevation.data[i]) + hydrology::DRY_BED_DEPTH_M < f64::from(level);
            out.data[n + i] = match kind {
                Kind::Lake if under => kind as u8 as f32,
                Kind::Dry if bed => kind as u8 as f32,
                _ => 0.0,
            };
            i += 1;
        }
    }
    out
}

/// Draws river courses on `map` (whose pixel (0, 0) is block `origin`), each as wide as
/// the river (at least one pixel) and darker the more it carries; returns the pixels drawn.
fn draw_courses(map: &mut RgbImage, courses: &[hydrology::Course], origin: (i64, i64), block_m: f64, px_m: f64) -> u64 {
    let mut drawn = 0;
    let (w, h) = (map.width() as f64, map.height() as f64);
    let to_px = |(x, z): (f64, f64)| {
        ((x / block_m - origin.0 as f64) * block_m / px_m, (z / block_m - origin.1 as f64) * block_m / px_m)
    };
    for course in courses {
        let radius = (hydrology::water_width_m(course.discharge, block_m) / px_m / 2.0).max(0.5);
        let shade = (course.discharge.max(0.1).log10() / 4.0).clamp(0.0, 1.0);
        let colour = Rgb([(60.0 * (1.0 - shade)) as u8, (130.0 - 80.0 * shade) as u8, (240.0 - 60.0 * shade) as u8]);
        for seg in course.points.windows(2) {
            let (a, b) = (to_px(seg[0]), to_px(seg[1]));
            let steps = ((b.0 - a.0).hypot(b.1 - a.1) * 2.0).ceil().max(1.0) as usize;
            for k in 0..=steps {
                let t = k as f64 / steps as f64;
                let (cx, cy) = (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1));
                let r = radius.ceil() as i64;
                for dy in -r..=r {
                    for dx in -r..=r {
                        let (px, py) = (cx.floor() + dx as f64, cy.floor() + dy as f64);
                        let inside = (px + 0.5 - cx).hypot(py + 0.5 - cy) <= radius.max(0.71);
                        if inside && px >= 0.0 && py >= 0.0 && px < w && py < h {
                            let p = map.get_pixel_mut(px as u32, py as u32);
                            if *p != colour {
                                *p = colour;
                                drawn += 1;
                            }
                        }
                    }
                }
            }
        }
    }
    drawn
}
