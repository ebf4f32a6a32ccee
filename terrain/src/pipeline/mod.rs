//! The pipeline facade: one call answers "elevation (m) and the four climate values for
//! every block column of this rectangle".
//!
//! Owns: the stage list (coarse → core → detail, as data), the grids they live on, the 4×
//! upsampling from model pixels to blocks. Must not touch: Minecraft (block ids, biomes,
//! chunks) — callers map metres and climate to blocks themselves.

mod stages;

use std::sync::Arc;

pub use stages::{StageState, StageStatus};

use crate::climate::{precipitation, temperature_at, Orographic};
use crate::infinite::{Engine, EngineConfig, EngineStats, Source, WindowLayout, Windowed};
use crate::layout::{sketch, Layout};
use crate::settings::TerrainSettings;
use crate::tile::{Rect, Tile};
use crate::upsample;

/// Minecraft blocks per model pixel (horizontally), whatever the model's real resolution.
pub const BLOCKS_PER_MODEL_PIXEL: i64 = 4;
/// Real size of one model pixel, metres (the final stage's training resolution).
pub const MODEL_PIXEL_METRES: f64 = 500.0;
/// Model pixels per coarse pixel (the coarse grid: continents, shelves, climate).
pub const COARSE_FACTOR: i64 = 16;

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
    /// Number of channels.
    pub const COUNT: usize = 5;
    /// Channel names, in order, for files and legends.
    pub const NAMES: [&str; COUNT] =
        ["elevation_m", "temperature_c", "seasonality_c", "precipitation_mm", "variability_pct"];
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
    NotBuilt(Vec<String>),
    /// A model could not be loaded (the message names the file and the command that makes it).
    #[cfg(feature = "learned")]
    #[error(transparent)]
    Model(#[from] crate::model::ModelError),
    /// The backend is not known or not built in.
    #[cfg(feature = "learned")]
    #[error(transparent)]
    Backend(#[from] crate::model::BackendError),
}

/// A grid `factor`× finer than its source's, by exact bilinear interpolation.
#[cfg_attr(not(feature = "learned"), allow(dead_code))]
struct Upsampled {
    source: Arc<dyn Source>,
    factor: i64,
}

impl Source for Upsampled {
    fn channels(&self) -> usize {
        self.source.channels()
    }

    fn query(&self, rect: Rect) -> Tile {
        upsample::bilinear(&self.source.query(upsample::source_rect(&rect, self.factor)), self.factor, rect)
    }
}

/// The terrain pipeline for one seed: thread-safe, shared by every chunk worker.
pub struct Pipeline {
    seed: u64,
    settings: TerrainSettings,
    engine: Arc<Engine>,
    stages: Vec<StageStatus>,
    elevation: Arc<dyn Source>,
    coarse_elevation: Arc<dyn Source>,
    coarse_sketch: Arc<dyn Source>,
    precipitation: Arc<Windowed>,
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
        let engine = Engine::new(EngineConfig {
            cache_bytes: (settings.engine.cache_mib as usize) << 20,
            threads: settings.engine.threads as usize,
        });
        let layout = Layout::new(seed, &settings.layout);
        let coarse_metres = MODEL_PIXEL_METRES * COARSE_FACTOR as f64;
        let coarse_elevation: Arc<dyn Source> = Arc::new(layout.elevation(coarse_metres));
        let coarse_sketch: Arc<dyn Source> = Arc::new(layout.climate_sketch(coarse_metres));
        let precipitation = Windowed::new(
            &engine,
            Orographic {
                elevation: coarse_elevation.clone(),
                sketch: coarse_sketch.clone(),
                settings: settings.climate.clone(),
                pixel_metres: coarse_metres,
                layout: WindowLayout::square(32, 16, 0),
                // Rain shadows fade over ~500 km of land: keep ~400 km of upwind history.
                margin: 48,
            },
        );
        let mut stages = stages::current();
        let elevation: Arc<dyn Source> = if settings.engine.learned.is_empty() {
            Arc::new(layout.elevation(MODEL_PIXEL_METRES))
        } else {
            learned_elevation(seed, settings, &engine, coarse_elevation.clone(), &mut stages)?
        };
        Ok(Pipeline {
            seed,
            settings: settings.clone(),
            engine,
            stages,
            elevation,
            coarse_elevation,
            coarse_sketch,
            precipitation,
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

    /// All channels (see [`channel`]) on the model grid, one value per model pixel.
    pub fn model(&self, rect: Rect) -> Tile {
        let elevation = self.elevation.query(rect);
        let coarse = upsample::source_rect(&rect, COARSE_FACTOR);
        let sketch = upsample::bilinear(&self.coarse_sketch.query(coarse), COARSE_FACTOR, rect);
        let rain = upsample::bilinear(&self.precipitation.query(coarse), COARSE_FACTOR, rect);

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
        out
    }

    /// Elevation alone (metres, one channel) on the model grid: skips the climate model, so
    /// maps and exports of elevation stay cheap over huge areas.
    pub fn elevation(&self, rect: Rect) -> Tile {
        self.elevation.query(rect)
    }

    /// Elevation alone (metres, one channel) for every block column of `blocks`.
    pub fn elevation_columns(&self, blocks: Rect) -> Tile {
        let model = self.elevation(upsample::source_rect(&blocks, BLOCKS_PER_MODEL_PIXEL));
        upsample::bilinear(&model, BLOCKS_PER_MODEL_PIXEL, blocks)
    }

    /// All channels for every block column of `blocks` (y = z, x = x in block coordinates),
    /// bilinearly upsampled 4× from the model grid.
    pub fn columns(&self, blocks: Rect) -> Tile {
        let model = self.model(upsample::source_rect(&blocks, BLOCKS_PER_MODEL_PIXEL));
        upsample::bilinear(&model, BLOCKS_PER_MODEL_PIXEL, blocks)
    }

    /// Coarse elevation (metres) of the coarse cell holding a block column: cheap, for
    /// searching a spawn point or a region's character without running the full pipeline.
    pub fn coarse_elevation_at_block(&self, x: i64, z: i64) -> f32 {
        let f = BLOCKS_PER_MODEL_PIXEL * COARSE_FACTOR;
        let (cy, cx) = (crate::tile::div_floor(z, f), crate::tile::div_floor(x, f));
        self.coarse_elevation.query(Rect::new(cy, cx, 1, 1)).data[0]
    }
}

/// The learned core stage on its 1 km grid, conditioned on the 8 km sketch, brought to the
/// 500 m model grid (the detail stage that would add the finest relief is not trained yet).
#[cfg(feature = "learned")]
fn learned_elevation(
    seed: u64,
    settings: &TerrainSettings,
    engine: &Arc<Engine>,
    coarse: Arc<dyn Source>,
    stages: &mut [StageStatus],
) -> Result<Arc<dyn Source>, PipelineError> {
    use crate::model::{load_model, stage::CoreStage, ComputeBackend};
    let backend: ComputeBackend = settings.engine.backend.parse()?;
    let device = backend.device()?;
    let model = load_model(&settings.engine.models, "core", &device)?;
    let core_metres = model.manifest.metres_per_pixel;
    let factor = (core_metres / MODEL_PIXEL_METRES).round().max(1.0) as i64;
    let core = Windowed::new(engine, CoreStage::new(model, device, coarse, seed, 8));
    for s in stages.iter_mut().filter(|s| s.name == "core") {
        s.state = StageState::Active;
    }
    Ok(Arc::new(Upsampled { source: core, factor }))
}

#[cfg(not(feature = "learned"))]
fn learned_elevation(
    _seed: u64,
    settings: &TerrainSettings,
    _engine: &Arc<Engine>,
    _coarse: Arc<dyn Source>,
    _stages: &mut [StageStatus],
) -> Result<Arc<dyn Source>, PipelineError> {
    Err(PipelineError::NotBuilt(settings.engine.learned.clone()))
}

#[cfg(test)]
mod tests;
