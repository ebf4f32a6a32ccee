//! `render` and `export`: maps and raw heightmaps of any rectangle.

use std::path::PathBuf;

use clap::{Args, ValueEnum};

use super::progress::Progress;
use super::{world_sources, Failure, Size, Sources};
use crate::chunkgen::Generator;
use crate::config::Config;
use crate::export::{self, ExportRequest, Grid, Quantity, Vertical};
use crate::lab::relief_compare::{self, CompareRequest};
use crate::render::{self, CutawayRequest, Layer, ObliqueRequest, RenderRequest};
use crate::terrain::model_files::ModelFiles;
use crate::terrain::Pipeline;

/// A rectangle of the world in block coordinates (x east, z south).
#[derive(Debug, Args)]
pub struct AreaArgs {
    /// West edge, block x.
    #[arg(long, allow_hyphen_values = true)]
    pub x0: i64,
    /// North edge, block z.
    #[arg(long, allow_hyphen_values = true)]
    pub z0: i64,
    /// Size in blocks: `W` or `WxH`.
    #[arg(long)]
    pub size: Size,
}

/// Arguments of `infiniterra water`.
#[derive(Debug, Args)]
pub struct WaterArgs {
    /// The rectangle of the world.
    #[command(flatten)]
    pub area: AreaArgs,
}

/// Arguments of `infiniterra render`.
#[derive(Debug, Args)]
pub struct RenderArgs {
    /// The rectangle of the world.
    #[command(flatten)]
    pub area: AreaArgs,
    /// Blocks per image pixel.
    #[arg(long, default_value_t = 1)]
    pub zoom: i64,
    /// What to draw: elevation, temperature, precipitation, seasonality, variability, biome.
    #[arg(long, default_value = "elevation")]
    pub layer: Layer,
    /// `map`: seen from straight above, one colour per pixel; `oblique`: the block columns as
    /// a player sees them from above at an angle (from the south-west, one block up as long as
    /// one across), coloured by their top blocks.
    #[arg(long, value_enum, default_value_t = View::Map)]
    pub view: View,
    /// Draw a relief comparison instead of a map: hillshades of generated mountains, hills
    /// and plains (the highest, median and lowest relief among windows of the rectangle)
    /// beside tiles of this prepared set (`data/prepared/NAME`) picked alike, at one block per
    /// pixel.
    #[arg(long, value_name = "DIR", conflicts_with_all = ["view", "zoom", "layer"])]
    pub compare_real: Option<PathBuf>,
    /// Output PNG.
    #[arg(long)]
    pub out: PathBuf,
    /// Folder of biome rules (for `--layer biome`; default: `biomes/` here if it exists,
    /// else the built-in rules).
    #[arg(long)]
    pub biomes: Option<PathBuf>,
}

/// How `render` looks at the world.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum View {
    /// From straight above.
    Map,
    /// From above at an angle, block columns as voxels.
    Oblique,
    /// A vertical slice along the rectangle's north edge (z = z0, the size's width), every
    /// block from the bedrock to the sky: caves, ores, rock and the deepslate transition.
    Cutaway,
}

/// Arguments of `infiniterra export`.
#[derive(Debug, Args)]
pub struct ExportArgs {
    /// The rectangle of the world.
    #[command(flatten)]
    pub area: AreaArgs,
    /// `block`: one value per block column; `model`: one per model pixel (4×4 blocks).
    #[arg(long, default_value = "block")]
    pub grid: Grid,
    /// What to write: elevation (ground, metres), water-level (river and lake surface,
    /// metres, NaN where none), discharge (m³/s) or surface (what a DEM records: the water
    /// surface where there is water, the ground elsewhere); all but elevation on the block grid.
    #[arg(long, value_enum, default_value_t = Quantity::Elevation)]
    pub quantity: Quantity,
    /// Output `.npy` (a `.json` with the same stem is written beside it).
    #[arg(long)]
    pub out: PathBuf,
}

/// Exit code 2 when the user's input is at fault, 1 otherwise.
fn classify<E: std::error::Error + Send + Sync + 'static>(bad_input: bool, e: E) -> Failure {
    if bad_input {
        Failure::input(e)
    } else {
        Failure::runtime(e)
    }
}

fn pipeline(config: &Config, models: &ModelFiles) -> Result<Pipeline, Failure> {
    Pipeline::build_with_models(config.world.seed, &config.terrain(), models).map_err(Failure::input)
}

/// Runs `water`: the region's river and lake shares, river density and river ends, as a
/// Markdown table.
pub fn water(config: &Config, sources: &Sources, a: &WaterArgs) -> Result<(), Failure> {
    let (_, models) = world_sources(config, sources, None);
    let pipeline = pipeline(config, &models)?;
    let area = crate::terrain::Rect::new(a.area.z0, a.area.x0, a.area.size.height, a.area.size.width);
    let mut progress = Progress::new("water", "tiles");
    let s = crate::lab::water::measure(&pipeline, area, |d, t| progress.update(d, t));
    progress.finish();
    let km = |blocks: i64| blocks as f64 * pipeline.block_metres() / 1000.0;
    let (d01, drawn) = s.density();
    let ends = s.ends_pct();
    println!(
        "water of x {}..{}, z {}..{} ({:.0} × {:.0} km, seed {}, stages: {})",
        area.x0,
        area.x1(),
        area.y0,
        area.y1(),
        km(area.w),
        km(area.h),
        config.world.seed,
        pipeline.active_stages().join(", ")
    );
    println!();
    println!("| measure | generated |");
    println!("|---|---|");
    println!("| land columns | {} |", s.land_columns);
    println!("| river water, % of land columns | {:.2} |", s.river_pct());
    println!("| lake water, % of land columns | {:.2} |", s.lake_pct());
    println!("| dry lake bed, % of land columns | {:.2} |", s.dry_bed_pct());
    println!("| river length ≥ 0.1 m³/s, km per 1,000 km² of land | {d01:.0} |");
    println!(
        "| river length ≥ {} m³/s (drawn), km per 1,000 km² | {drawn:.0} |",
        crate::terrain::hydrology::RIVER_DISCHARGE
    );
    println!("| drawn river length ending in the sea, % | {:.1} |", ends[0]);
    println!("| … in a lake, % | {:.1} |", ends[1]);
    println!("| … in a dry basin, % | {:.1} |", ends[2]);
    println!("| … leaving by more than 400 km with no end down the continent's rivers, % | {:.1} |", ends[3]);
    println!("| … nowhere (a dead end or a loop), % | {:.1} |", ends[4]);
    println!("| land draining to the sea (exorheic), % | {:.1} |", s.exorheic_pct());
    Ok(())
}

/// Runs `render`.
pub fn render(config: &Config, sources: &Sources, a: &RenderArgs) -> Result<(), Failure> {
    let (rules, models) = world_sources(config, sources, a.biomes.as_deref());
    if a.zoom < 1 {
        return Err(Failure::input(anyhow::anyhow!("--zoom {} is out of range (allowed 1 or more)", a.zoom)));
    }
    let (x0, z0, width, height) = (a.area.x0, a.area.z0, a.area.size.width, a.area.size.height);
    if let Some(real) = &a.compare_real {
        let req = CompareRequest { x0, z0, width, height };
        let mut progress = Progress::new("render", "rows of windows");
        let image = relief_compare::render_relief_comparison(&pipeline(config, &models)?, real, &req, &mut |d, t| {
            progress.update(d, t)
        })
        .map_err(|e| classify(e.is_bad_input(), e))?;
        progress.finish();
        return save(&image, &a.out);
    }
    // The views drawn from the server's own chunks and columns.
    let block_view = match a.view {
        View::Map => None,
        View::Oblique => Some(("--view oblique draws every block column with its top block", "rows of columns")),
        View::Cutaway => Some(("--view cutaway draws every block of one row at 3 pixels a block", "chunks")),
    };
    if let Some((what, unit)) = block_view {
        if a.zoom != 1 || a.layer != Layer::Elevation {
            return Err(Failure::input(anyhow::anyhow!("{what}: --zoom and --layer do not apply")));
        }
        let rules = rules.load().map_err(Failure::input)?;
        let generator = Generator::new(std::sync::Arc::new(pipeline(config, &models)?), config);
        let mut progress = Progress::new("render", unit);
        let mut report = |d, t| progress.update(d, t);
        let image = if a.view == View::Oblique {
            render::render_oblique(&generator, &rules, &ObliqueRequest { x0, z0, width, height }, &mut report)
        } else {
            render::render_cutaway(&generator, &rules, &CutawayRequest { x0, z: z0, width }, &mut report)
        }
        .map_err(|e| classify(e.is_bad_input(), e))?;
        progress.finish();
        return save(&image, &a.out);
    }
    let req = RenderRequest {
        x0: a.area.x0,
        z0: a.area.z0,
        width: a.area.size.width,
        height: a.area.size.height,
        zoom: a.zoom,
        layer: a.layer,
    };
    let mut progress = Progress::new("render", "rows");
    let image = if a.layer == Layer::Biome {
        let rules = rules.load().map_err(Failure::input)?;
        let generator = Generator::new(std::sync::Arc::new(pipeline(config, &models)?), config);
        render::render_biomes(&generator, &rules, &req, &mut |d, t| progress.update(d, t))
    } else if a.layer == Layer::Water {
        render::render_water(&pipeline(config, &models)?, &req, &mut |d, t| progress.update(d, t))
    } else {
        render::render(&pipeline(config, &models)?, &req, &mut |d, t| progress.update(d, t))
    }
    .map_err(|e| classify(e.is_bad_input(), e))?;
    progress.finish();
    save(&image, &a.out)
}

fn save(image: &image::RgbImage, out: &std::path::Path) -> Result<(), Failure> {
    render::save_png(image, out).map_err(Failure::runtime)?;
    println!("wrote {} ({}×{} px)", out.display(), image.width(), image.height());
    Ok(())
}

/// Runs `export`.
pub fn export(config: &Config, sources: &Sources, a: &ExportArgs) -> Result<(), Failure> {
    let req = ExportRequest {
        x0: a.area.x0,
        z0: a.area.z0,
        width: a.area.size.width,
        height: a.area.size.height,
        grid: a.grid,
        quantity: a.quantity,
    };
    let vertical = Vertical {
        sea_level_y: config.world.sea_level_y as i32,
        metres_per_block: config.world.vertical_metres_per_block,
    };
    let (_, models) = world_sources(config, sources, None);
    let pipeline = pipeline(config, &models)?;
    let mut progress = Progress::new("export", "rows");
    let summary = export::export(&pipeline, &req, &vertical, &a.out, &mut |d, t| progress.update(d, t))
        .map_err(|e| classify(e.is_bad_input(), e))?;
    progress.finish();
    println!(
        "wrote {} ({}×{}, {:.1}..{:.1} m) and {}",
        summary.npy.display(),
        summary.shape.1,
        summary.shape.0,
        summary.min,
        summary.max,
        summary.json.display()
    );
    Ok(())
}
