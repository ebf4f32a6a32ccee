//! The pipeline facade: one call answers "elevation (m) and the four climate values for
//! every block column of this rectangle".
//!
//! Owns: the stage list (coarse → core → detail, as data in [`stages::LEARNED`]), the grids
//! they live on, the world's horizontal scale, the model grid (always 4 blocks: the finest
//! learned grid resampled to it, plus the erosion filter's longer octaves) and the 4×
//! upsampling from model pixels to blocks (plus the erosion filter's shortest octaves).
//! Must not touch: Minecraft (block ids, biomes, chunks) — callers map metres and climate to
//! blocks themselves.

mod column_cache;
mod finest;
mod network_inputs;

pub use crate::stages;

use std::sync::Arc;

pub use stages::{LearnedStageSpec, StageState, StageStatus, LEARNED};

use crate::climate::{precipitation, temperature_at, Orographic, OrographicSweep};
use crate::encoding::box_downsample;
use crate::erosion::{octaves_between, ErosionFilter, Lattice, SHORTEST_ON_GRID_PIXELS};
use crate::hydrology::continental::Continental;
use crate::hydrology::{Basins, Rivers, Stitched, WaterColumns, CELL_METRES, RIVER_DISTANCE_MAX_M};
use crate::infinite::{tiled, Engine, EngineConfig, EngineStats, Source, WindowLayout, Windowed};
use crate::layout::{sketch, Layout};
use crate::model_files::ModelFiles;
use crate::resample;
pub use crate::settings::BLOCKS_PER_MODEL_PIXEL;
use crate::settings::{StageName, TerrainSettings};
use crate::tile::{Rect, Tile};
use column_cache::ColumnCache;
use finest::Finest;
use network_inputs::NetworkInputs;

/// The finest grid a stage is trained on, metres: the layout's and the `detail` stage's
/// (the learned windows' seams are measured on it).
pub const BASE_METRES: f64 = 500.0;
/// The coarse grid, metres: continents, shelves, climate.
pub const COARSE_METRES: f64 = 8000.0;
/// Side of the cached tiles of the layout's coarse fields, cells (512 km).
const COARSE_TILE: i64 = 64;
/// Ratio of the 4× block upsampling (block size / model pixel size).
const BLOCK_RATIO: f64 = 1.0 / BLOCKS_PER_MODEL_PIXEL as f64;
/// Block columns from which a query is a region, not a chunk: its drainage network is
/// evaluated beside its relief, and its carving split over the engine's threads (a chunk's
/// query runs on one of many chunk workers, which keep the threads busy already). See
/// [`Pipeline::splits`].
const REGION_QUERY_COLUMNS: usize = 128 * 128;
/// Rows of block columns carved per task when a region's carving is split.
const CARVE_ROWS: i64 = 32;

/// Channels of every pipeline answer.
pub mod channel {
    /// Elevation, metres above sea level (negative under the sea).
    pub const ELEVATION: usize = 0;
    /// Annual mean air temperature at the surface, °C.
    pub const TEMPERATURE: usize = 1;
    /// Temperature seasonality: standard deviation of monthly means, °C.
    pub const SEASONALITY: usize = 2;
    /// Annual precipitation, mm.
    pub const PRECIPITATION: usize = 3;
    /// Precipitation variability (coefficient of variation), %.
    pub const VARIABILITY: usize = 4;
    /// Steepness of the land around, degrees: the slope of the smooth relief under the
    /// erosion filter (what the learned grid resolves, ~1 km), the same at any world scale;
    /// biome rules use it, so gullies do not speckle biomes.
    pub const RELIEF_SLOPE: usize = 5;
    /// Water surface of a river or lake over the column, metres (NaN where there is none;
    /// the sea is everything below 0 m). Block columns only (NaN on the model grid).
    pub const WATER_LEVEL: usize = 6;
    /// What water the column holds: 0 none, 2 lake, 3 dry lake bed (its level is the
    /// basin's spill level), 4 river ([`crate::hydrology::Kind`] codes and
    /// [`crate::hydrology::WaterColumns::RIVER`]).
    pub const WATER: usize = 7;
    /// Discharge of the river or lake, m³/s (0 elsewhere).
    pub const DISCHARGE: usize = 8;
    /// Distance to the nearest river's bank, metres: 0 in a river, at most
    /// [`crate::hydrology::RIVER_DISTANCE_MAX_M`] (what the model grid reads
    /// everywhere). Block columns only.
    pub const RIVER_DISTANCE: usize = 9;
    /// Number of channels.
    pub const COUNT: usize = 10;
    /// Channel names, in order, for files and legends.
    pub const NAMES: [&str; COUNT] = [
        "elevation_m",
        "temperature_c",
        "seasonality_c",
        "precipitation_mm",
        "variability_pct",
        "relief_slope_deg",
        "water_level_m",
        "water",
        "discharge_m3s",
        "river_distance_m",
    ];
}

/// Why a pipeline could not be built.
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    /// Learned stages were asked for in a build without the learned-model code.
    #[error(
        "engine.learned = {0:?} needs the learned-model code, which this binary was built without \
         (--no-default-features): build with the default features (`cargo build --release`), or set \
         `learned = []` for the procedural layout alone"
    )]
    NotBuilt(Vec<StageName>),
    /// A model could not be loaded (the message names the file and the command that makes it).
    #[cfg(feature = "learned")]
    #[error(transparent)]
    Model(#[from] crate::model::ModelError),
    /// The backend is not known or not built in.
    #[cfg(feature = "learned")]
    #[error(transparent)]
    Backend(#[from] crate::model::BackendError),
    /// A model was trained at a resolution its place in the hierarchy cannot use.
    #[error(
        "{file}: metres_per_pixel = {found} does not fit the {stage} stage (needs {needed}); retrain it with \
         `infiniterra train {stage}`"
    )]
    Resolution {
        /// The manifest.
        file: String,
        /// The stage.
        stage: String,
        /// What the manifest says.
        found: f64,
        /// What the stage needs.
        needed: String,
    },
}

/// A grid `factor`× coarser than its source's, each cell the mean of its `factor`² source
/// cells: the context a learned stage is conditioned on (the box downsample of training's
/// low band; the stage applies the blur).
#[cfg_attr(not(feature = "learned"), allow(dead_code))]
struct BoxMean {
    source: Arc<dyn Source>,
    factor: i64,
}

impl Source for BoxMean {
    fn channels(&self) -> usize {
        self.source.channels()
    }

    fn query(&self, rect: Rect) -> Tile {
        let f = self.factor;
        let fine = self.source.query(Rect::new(rect.y0 * f, rect.x0 * f, rect.h * f, rect.w * f));
        let (h, w) = (fine.rect.h as usize, fine.rect.w as usize);
        let data = (0..fine.channels).flat_map(|c| box_downsample(fine.channel(c), h, w, f as usize)).collect();
        Tile::from_data(fine.channels, rect, data)
    }
}

/// The terrain pipeline for one seed: thread-safe, shared by every chunk worker.
pub struct Pipeline {
    seed: u64,
    settings: TerrainSettings,
    engine: Arc<Engine>,
    stages: Vec<StageStatus>,
    finest: Finest,
    erosion: ErosionFilter,
    coarse_elevation: Arc<dyn Source>,
    coarse_sketch: Arc<dyn Source>,
    precipitation: Arc<Windowed>,
    continental: Arc<dyn Source>,
    network: Arc<dyn Source>,
    rivers: Rivers,
    /// Block columns already computed, in chunk-sized squares.
    column_cache: ColumnCache,
}

impl Pipeline {
    /// Builds the pipeline of `seed` with validated `settings` that ask for no learned stage
    /// (tests, tools); panics otherwise — use [`Pipeline::build`].
    pub fn new(seed: u64, settings: &TerrainSettings) -> Pipeline {
        Pipeline::build(seed, settings).unwrap_or_else(|e| panic!("Pipeline::new: {e}"))
    }

    /// Builds the pipeline of `seed` with validated `settings`, loading the learned stages
    /// they name (`engine.learned`) from `engine.models` on `engine.backend`.
    pub fn build(seed: u64, settings: &TerrainSettings) -> Result<Pipeline, PipelineError> {
        Pipeline::build_with_models(seed, settings, &ModelFiles::Dir(settings.engine.models.clone()))
    }

    /// [`Pipeline::build`], reading the learned stages from `models` (a folder, or the models
    /// built into the binary) instead of `engine.models`.
    pub fn build_with_models(
        seed: u64,
        settings: &TerrainSettings,
        models: &ModelFiles,
    ) -> Result<Pipeline, PipelineError> {
        let engine = Engine::new(EngineConfig {
            cache_bytes: (settings.engine.cache_mib as usize) << 20,
            threads: settings.engine.threads as usize,
        });
        let layout = Layout::new(seed, &settings.layout);
        let coarse_metres = COARSE_METRES;
        let mut stages = stages::current();
        // The layout's coarse fields are read over continents (drainage, rain): cached.
        let sketch = StageGrid::layout(
            tiled(&engine, Arc::new(layout.elevation(coarse_metres)), COARSE_TILE, "coarse layout"),
            coarse_metres,
        );
        // The learned stages, coarse to fine, each refining the output of its context stage
        // (the layout's sketch when that stage is off).
        let mut ran: Vec<StageGrid> = Vec::new();
        for spec in LEARNED.iter().filter(|s| settings.engine.runs(s.name)) {
            let above = ran.iter().rev().find(|g| g.name == spec.context_stage).unwrap_or(&sketch);
            let grid = learned_stage(spec, seed, settings, models, &engine, above, &mut stages)?;
            ran.push(grid);
        }
        // The coarse grid (climate, spawn search) carries the finest stage that lives on it.
        let coarse_elevation =
            ran.iter().rev().find(|g| g.metres == coarse_metres).map_or(sketch.source.clone(), |g| g.source.clone());
        let coarse_sketch: Arc<dyn Source> =
            tiled(&engine, Arc::new(layout.climate_sketch(coarse_metres)), COARSE_TILE, "climate sketch");
        let orographic = || Orographic {
            elevation: coarse_elevation.clone(),
            sketch: coarse_sketch.clone(),
            settings: settings.climate.clone(),
            pixel_metres: coarse_metres,
            layout: WindowLayout::square(32, 16, 0),
            // Rain shadows fade over ~500 km of land: keep ~400 km of upwind history.
            margin: 48,
        };
        let precipitation = Windowed::new(&engine, orographic());
        // The model grid carries the finest stage that ran (the layout's 500 m grid when none
        // did), resampled to it, with the erosion filter's octaves the grid can hold.
        let base = ran.pop().unwrap_or_else(|| StageGrid::layout(Arc::new(layout.elevation(BASE_METRES)), BASE_METRES));
        let erosion = ErosionFilter::new(seed);
        let inputs = |base: Arc<dyn Source>, base_metres: f64, cell_metres: f64| NetworkInputs {
            cell_metres,
            base,
            base_metres,
            erosion,
            sketch: coarse_sketch.clone(),
            precipitation: precipitation.clone(),
            temperature_offset_c: settings.climate.temperature_offset_c as f32,
            lapse_c_per_km: settings.climate.lapse_rate_c_per_km as f32,
        };
        // The continent's rain comes from one sweep over each tile's whole window (see
        // `OrographicSweep`), not from the windowed tensor the network reads.
        let continental_inputs = NetworkInputs {
            precipitation: Arc::new(OrographicSweep(orographic())),
            ..inputs(coarse_elevation.clone(), coarse_metres, coarse_metres)
        };
        let continental: Arc<dyn Source> =
            Windowed::new(&engine, Continental { inputs: Arc::new(continental_inputs), cell_metres: coarse_metres });
        let basins = Windowed::new(
            &engine,
            Basins {
                fine: Arc::new(inputs(base.source.clone(), base.metres, CELL_METRES)),
                coarse: Arc::new(inputs(coarse_elevation.clone(), coarse_metres, CELL_METRES)),
                continental: continental.clone(),
                coarse_metres,
            },
        );
        let network: Arc<dyn Source> = Windowed::new(&engine, Stitched { basins });
        let rivers = Rivers::new(network.clone(), seed);
        let finest = Finest::new(base.source, base.metres, settings.model_pixel_metres(), erosion);
        Ok(Pipeline {
            seed,
            settings: settings.clone(),
            engine,
            stages,
            finest,
            erosion,
            coarse_elevation,
            coarse_sketch,
            precipitation,
            continental,
            network,
            rivers,
            column_cache: ColumnCache::default(),
        })
    }

    /// The world seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// The settings it was built with.
    pub fn settings(&self) -> &TerrainSettings {
        &self.settings
    }

    /// Every stage of the hierarchy and whether it runs.
    pub fn stages(&self) -> &[StageStatus] {
        &self.stages
    }

    /// Names of the learned stages that run (a subset of [`LEARNED`]'s); empty for the
    /// procedural layout.
    pub fn learned_stages(&self) -> Vec<&'static str> {
        self.stages
            .iter()
            .filter(|s| s.state == StageState::Active && stages::learned(s.name).is_some())
            .map(|s| s.name)
            .collect()
    }

    /// Names of the stages that ran to produce answers (for file metadata and logs).
    pub fn active_stages(&self) -> Vec<String> {
        self.stages.iter().filter(|s| s.state == StageState::Active).map(|s| s.name.to_string()).collect()
    }

    /// The engine's counters (cache use, windows evaluated).
    pub fn engine_stats(&self) -> EngineStats {
        self.engine.stats()
    }

    /// The shared engine (cache size, thread count).
    pub fn engine(&self) -> &Arc<Engine> {
        &self.engine
    }

    /// Horizontal size of a block column, metres (`world.metres_per_block`).
    pub fn block_metres(&self) -> f64 {
        self.settings.metres_per_block
    }

    /// Size of a model pixel (4 blocks), metres.
    pub fn model_pixel_metres(&self) -> f64 {
        self.settings.model_pixel_metres()
    }

    /// All channels (see [`channel`]) on the model grid, one value per model pixel.
    pub fn model(&self, rect: Rect) -> Tile {
        self.model_and_slope(rect).0
    }

    /// [`Pipeline::model`] and the smooth relief's slope (m/m) under the erosion filter.
    fn model_and_slope(&self, rect: Rect) -> (Tile, Tile) {
        let finest = self.finest.query(rect);
        let ratio = self.model_pixel_metres() / COARSE_METRES;
        let coarse = resample::source_rect(&rect, ratio, 0);
        let sketch = resample::bilinear(&self.coarse_sketch.query(coarse), ratio, rect);
        let rain = resample::bilinear(&self.precipitation.query(coarse), ratio, rect);
        let elevation = finest.select(&[finest::ELEVATION]);

        let n = rect.area();
        let mut out = Tile::zeros(channel::COUNT, rect);
        let lapse = self.settings.climate.lapse_rate_c_per_km as f32;
        let offset = self.settings.climate.temperature_offset_c as f32;
        let t0 = sketch.channel(sketch::SEA_LEVEL_TEMPERATURE);
        for (i, &e) in elevation.data.iter().enumerate() {
            out.data[channel::ELEVATION * n + i] = e;
            out.data[channel::TEMPERATURE * n + i] = temperature_at(t0[i] + offset, e, lapse);
        }
        out.channel_mut(channel::SEASONALITY).copy_from_slice(sketch.channel(sketch::SEASONALITY));
        out.channel_mut(channel::PRECIPITATION).copy_from_slice(rain.channel(precipitation::ANNUAL_MM));
        out.channel_mut(channel::VARIABILITY).copy_from_slice(rain.channel(precipitation::VARIABILITY_PCT));
        for (d, &s) in out.channel_mut(channel::RELIEF_SLOPE).iter_mut().zip(finest.channel(finest::SLOPE)) {
            *d = s.atan().to_degrees();
        }
        out.channel_mut(channel::WATER_LEVEL).fill(f32::NAN);
        out.channel_mut(channel::RIVER_DISTANCE).fill(RIVER_DISTANCE_MAX_M as f32);
        (out, finest.select(&[finest::SLOPE]))
    }

    /// Elevation alone (metres, one channel) on the model grid: skips the climate model, so
    /// maps and exports of elevation stay cheap over huge areas.
    pub fn elevation(&self, rect: Rect) -> Tile {
        self.finest.query(rect).select(&[finest::ELEVATION])
    }

    /// The model pixels the block columns of `blocks` are made from (with the margin their
    /// gradients need).
    fn model_rect(blocks: &Rect) -> Rect {
        resample::source_rect(blocks, BLOCK_RATIO, 1).pad(1)
    }

    /// Elevation alone (metres, one channel) for every block column of `blocks`.
    pub fn elevation_columns(&self, blocks: Rect) -> Tile {
        let finest = self.finest.query(Pipeline::model_rect(&blocks));
        let (mut elevation, _) = self.carve_blocks(&finest, blocks);
        self.water_columns(blocks, &mut elevation);
        Tile::from_data(1, blocks, elevation)
    }

    /// The rivers, lakes and dry lake beds of `blocks`, their channels and valleys cut into
    /// `elevation` (metres, row-major over `blocks`).
    fn water_columns(&self, blocks: Rect, elevation: &mut [f32]) -> WaterColumns {
        self.rivers.columns(blocks, self.block_metres(), self.settings.vertical_metres_per_block, elevation)
    }

    /// The courses of the rivers near `blocks`, for maps.
    pub fn river_courses(&self, blocks: Rect) -> Vec<crate::hydrology::Course> {
        self.rivers.courses(blocks, self.block_metres())
    }

    /// The continent's drainage over `cells` of the coarse grid
    /// ([`crate::hydrology::continental::channel`]).
    pub fn continent(&self, cells: Rect) -> Tile {
        self.continental.query(cells)
    }

    /// The drainage network over `cells` (cells of [`crate::hydrology::CELL_METRES`]), with
    /// the [`crate::hydrology::grid`] channels: maps, statistics and tests read it.
    pub fn network(&self, cells: Rect) -> Tile {
        self.network.query(cells)
    }

    /// All channels for every block column of `blocks` (y = z, x = x in block coordinates):
    /// the model grid upsampled 4× (elevation by a cubic, climate bilinearly), with the
    /// erosion filter's octaves below the model grid carved into the elevation and the
    /// temperature following it down the lapse rate. Small queries are answered from (and
    /// remembered in) a cache of chunk-sized squares: neighbouring chunks share their borders.
    pub fn columns(&self, blocks: Rect) -> Tile {
        self.column_cache.columns(blocks, |rect| self.compute_columns(rect))
    }

    /// Whether a query over `blocks` is split over threads ([`REGION_QUERY_COLUMNS`]): only
    /// a region-sized one, and only when the engine may use more than one thread.
    fn splits(&self, blocks: Rect) -> bool {
        blocks.area() >= REGION_QUERY_COLUMNS && self.engine.threads() > 1
    }

    /// [`Pipeline::columns`], computed.
    fn compute_columns(&self, blocks: Rect) -> Tile {
        let relief = || {
            let (model, slope) = self.model_and_slope(Pipeline::model_rect(&blocks));
            let finest = Tile::stack(&[&model.select(&[channel::ELEVATION]), &slope]);
            let (elevation, smooth) = self.carve_blocks(&finest, blocks);
            (model, elevation, smooth)
        };
        let (model, mut elevation, smooth) = if self.splits(blocks) {
            // The network's windows (the continent's flood is one thread's work, and the
            // drained tiles wait on it) fill the threads that the relief's windows and
            // carving leave idle, and the other way round. The same windows either way.
            std::thread::scope(|scope| {
                scope.spawn(|| self.rivers.prefetch(blocks, self.block_metres()));
                relief()
            })
        } else {
            relief()
        };
        let water = self.water_columns(blocks, &mut elevation);
        let mut out = resample::bilinear(&model, BLOCK_RATIO, blocks);
        let lapse = self.settings.climate.lapse_rate_c_per_km as f32;
        let n = blocks.area();
        for (i, (&e, &b)) in elevation.iter().zip(&smooth).enumerate() {
            out.data[channel::ELEVATION * n + i] = e;
            // The climate model's lapse rate over the height the detail adds (nothing at sea).
            out.data[channel::TEMPERATURE * n + i] -= lapse * (e.max(0.0) - b.max(0.0)) / 1000.0;
        }
        out.channel_mut(channel::WATER_LEVEL).copy_from_slice(&water.level);
        for (d, &k) in out.channel_mut(channel::WATER).iter_mut().zip(&water.kind) {
            *d = f32::from(k);
        }
        out.channel_mut(channel::DISCHARGE).copy_from_slice(&water.discharge);
        out.channel_mut(channel::RIVER_DISTANCE).copy_from_slice(&water.river_distance);
        out
    }

    /// Block elevations of `blocks` from the model grid `finest` ([`finest`] channels, over
    /// [`Pipeline::model_rect`]): the cubic upsampling plus the erosion octaves from 2 blocks
    /// up to what the model grid carries, steered by the model grid's gradient. Also returns
    /// the bilinear upsampling (what the climate channels were interpolated with).
    fn carve_blocks(&self, finest: &Tile, blocks: Rect) -> (Vec<f32>, Vec<f32>) {
        let inner = resample::source_rect(&blocks, BLOCK_RATIO, 1);
        let g = self.model_pixel_metres();
        let mut fields = Tile::zeros(3, inner);
        let m = inner.area();
        let e = |y: i64, x: i64| f64::from(finest.get(finest::ELEVATION, y, x));
        let mut i = 0;
        for y in inner.y0..inner.y1() {
            for x in inner.x0..inner.x1() {
                fields.data[i] = ((e(y, x + 1) - e(y, x - 1)) / (2.0 * g)) as f32;
                fields.data[m + i] = ((e(y + 1, x) - e(y - 1, x)) / (2.0 * g)) as f32;
                fields.data[2 * m + i] = finest.get(finest::SLOPE, y, x);
                i += 1;
            }
        }
        let cubic = resample::cubic(&finest.select(&[finest::ELEVATION]), BLOCK_RATIO, blocks);
        let smooth = resample::bilinear(&finest.select(&[finest::ELEVATION]), BLOCK_RATIO, blocks);
        let fields = resample::bilinear(&fields, BLOCK_RATIO, blocks);
        let b = self.block_metres();
        let octaves = octaves_between(2.0 * b, SHORTEST_ON_GRID_PIXELS * g);
        let n = blocks.area();
        // Each column is carved alone (the lattice only remembers hashes), so a region's rows
        // are carved in bands on the engine's threads, a chunk's in one.
        let carve = |rows: &(i64, i64)| {
            let mut lattice = Lattice::default();
            let mut band = Vec::with_capacity(((rows.1 - rows.0) * blocks.w) as usize);
            for z in rows.0..rows.1 {
                let first = ((z - blocks.y0) * blocks.w) as usize;
                for (i, x) in (first..).zip(blocks.x0..blocks.x1()) {
                    let gradient = (f64::from(fields.data[i]), f64::from(fields.data[n + i]));
                    let slope = f64::from(fields.data[2 * n + i]);
                    let (xm, zm) = ((x as f64 + 0.5) * b, (z as f64 + 0.5) * b);
                    let carved = self.erosion.apply_with(&mut lattice, xm, zm, slope, gradient, octaves.clone());
                    band.push(cubic.data[i] + carved.height as f32);
                }
            }
            band
        };
        let out = if self.splits(blocks) {
            let bands: Vec<(i64, i64)> = (blocks.y0..blocks.y1())
                .step_by(CARVE_ROWS as usize)
                .map(|z| (z, (z + CARVE_ROWS).min(blocks.y1())))
                .collect();
            self.engine.par_map(&bands, carve).concat()
        } else {
            carve(&(blocks.y0, blocks.y1()))
        };
        (out, smooth.data)
    }

    /// Evaluates every window (learned stages and climate) that queries inside `blocks` need
    /// now, in full parallel batches, so those queries are cache hits (pre-generation calls it
    /// per region file). A no-op without learned stages: then windows are cheap and the
    /// procedural layout is computed per query anyway.
    pub fn prefetch(&self, blocks: Rect) {
        if !self.learned_stages().is_empty() {
            self.model(Pipeline::model_rect(&blocks));
            // The drainage network under the region reads the learned relief too.
            self.rivers.prefetch(blocks, self.block_metres());
        }
    }

    /// Coarse elevation (metres) of the coarse cell holding a block column: cheap, for
    /// searching a spawn point or a region's character without running the full pipeline.
    pub fn coarse_elevation_at_block(&self, x: i64, z: i64) -> f32 {
        let cell = |b: i64| ((b as f64 + 0.5) * self.block_metres() / COARSE_METRES).floor() as i64;
        self.coarse_elevation.query(Rect::new(cell(z), cell(x), 1, 1)).data[0]
    }
}

/// A stage's output on its own grid: a learned stage's, or the layout's.
#[derive(Clone)]
struct StageGrid {
    /// The stage's window function behind the engine's cache.
    source: Arc<dyn Source>,
    /// Real size of one of its pixels, metres.
    metres: f64,
    /// Its name (`layout` for the sketch).
    name: &'static str,
}

impl StageGrid {
    /// The layout's elevation on its grid of `metres`.
    fn layout(source: Arc<dyn Source>, metres: f64) -> StageGrid {
        StageGrid { source, metres, name: "layout" }
    }
}

/// The learned stage `spec` (`<engine.models>/<name>.json`), conditioned on `above` (box-
/// averaged further when the model's context, `context.factor` of its own pixels, is coarser
/// than `above`'s grid). Marks the stage active.
#[cfg(feature = "learned")]
#[allow(clippy::too_many_arguments)] // The stage's whole context; one call site per stage.
fn learned_stage(
    spec: &LearnedStageSpec,
    seed: u64,
    settings: &TerrainSettings,
    models: &ModelFiles,
    engine: &Arc<Engine>,
    above: &StageGrid,
    stages: &mut [StageStatus],
) -> Result<StageGrid, PipelineError> {
    use crate::model::{load_model_from, stage::LearnedStage, ComputeBackend};
    let name = spec.name;
    let backend: ComputeBackend = settings.engine.backend.as_str().parse()?;
    let device = backend.device()?;
    let model = load_model_from(models, name, &device)?;
    let file = models.shown(std::path::Path::new(&format!("{name}.json"))).display().to_string();
    let metres = model.manifest.metres_per_pixel;
    // The stage's place in the hierarchy is its grid: a model trained at another resolution
    // would put its relief at the wrong scale.
    if (metres - spec.metres_per_pixel).abs() > 1e-6 * spec.metres_per_pixel {
        return Err(PipelineError::Resolution {
            file,
            stage: name.to_string(),
            found: metres,
            needed: format!("{} m per pixel", spec.metres_per_pixel),
        });
    }
    let context_metres = above.metres;
    let cell = metres * model.manifest.context.factor as f64;
    let ratio = cell / context_metres;
    if ratio < 1.0 - 1e-6 || (ratio - ratio.round()).abs() > 1e-6 {
        return Err(PipelineError::Resolution {
            file,
            stage: name.to_string(),
            found: metres,
            needed: format!(
                "context.factor × metres_per_pixel = {cell} m, a whole multiple of the {context_metres} m grid above it"
            ),
        });
    }
    let context: Arc<dyn Source> = match ratio.round() as i64 {
        1 => above.source.clone(),
        factor => Arc::new(BoxMean { source: above.source.clone(), factor }),
    };
    let source = Windowed::new(engine, LearnedStage::new(model, device, context, seed, 8));
    for s in stages.iter_mut().filter(|s| s.name == name) {
        s.state = StageState::Active;
    }
    Ok(StageGrid { source, metres, name })
}

#[cfg(not(feature = "learned"))]
#[allow(clippy::too_many_arguments)]
fn learned_stage(
    _spec: &LearnedStageSpec,
    _seed: u64,
    settings: &TerrainSettings,
    _models: &ModelFiles,
    _engine: &Arc<Engine>,
    _above: &StageGrid,
    _stages: &mut [StageStatus],
) -> Result<StageGrid, PipelineError> {
    Err(PipelineError::NotBuilt(settings.engine.learned.clone()))
}

#[cfg(test)]
mod tests;
