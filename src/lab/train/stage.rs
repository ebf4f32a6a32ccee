//! What each stage trains on and at what resolution: its grid, network, sampler, context,
//! window stride and back-projection, and where its prepared tiles are read from.

use std::path::Path;

use anyhow::anyhow;
use infiniterra_terrain::encoding::ContextSpec;
use infiniterra_terrain::model::{ContextProjection, Sampler, UNetConfig};

use super::data::{read_split, TileSet};
use super::TrainError;

/// Back-projection passes of the core's windows onto their context cells.
const PROJECTION_PASSES: usize = 4;

/// What a stage trains on and at what resolution.
pub(super) struct StageSpec {
    pub metres_per_pixel: f64,
    pub config: UNetConfig,
    pub sampler: Sampler,
    /// How its context is made from the grid above it.
    pub context: ContextSpec,
    /// Window stride at inference (0: half the window).
    pub stride: usize,
    /// Back-projection of each window onto its context cells (unblurred contexts only).
    pub projection: Option<ContextProjection>,
}

pub(super) fn stage_spec(stage: &str, smoke: bool) -> Result<StageSpec, TrainError> {
    let pick = |full: UNetConfig| if smoke { UNetConfig::tiny() } else { full };
    match stage {
        // 1 km relief over 8 km box means, unblurred: the blurred means of the paper's
        // Laplacian split take the 16–64 km band out of the context, and a 64-pixel window
        // cannot put it back (the first cores drew a third of its power, with or without
        // window overlap); unblurred, the context carries it and the model draws what is
        // finer than 8 km.
        "core" => Ok(StageSpec {
            metres_per_pixel: 1000.0,
            config: pick(UNetConfig::core()),
            sampler: Sampler::few_step(),
            context: ContextSpec { factor: 8, blur: false },
            stride: 0,
            // Its windows missed their context cells by 23 m on held-out land, and part of the
            // 16–45 km band with them (see `model::projection`).
            projection: Some(ContextProjection { iterations: PROJECTION_PASSES }),
        }),
        // The same network one level up: 8 km relief (continents, shelves, basins) refining
        // the layout's sketch from its blurred 16 km means. (The first coarse weights used
        // 64 km means, as the core does one level down, and flattened the layout's narrower
        // ranges: a 3,000 m range came out as 1,000 m blobs.)
        "coarse" => Ok(StageSpec {
            metres_per_pixel: 8000.0,
            config: pick(UNetConfig::core()),
            sampler: Sampler::few_step(),
            context: ContextSpec { factor: 2, blur: true },
            stride: 0,
            projection: None,
        }),
        // The last stage: 500 m relief over the core's own 1 km grid, unblurred (the core's
        // relief is kept; only what is finer than 1 km is generated), with the paper's 75 %
        // window overlap for the decoder.
        "detail" => Ok(StageSpec {
            metres_per_pixel: 500.0,
            config: pick(UNetConfig::detail()),
            sampler: Sampler::few_step(),
            context: ContextSpec { factor: 2, blur: false },
            stride: 16,
            projection: None,
        }),
        _ => Err(TrainError::input(anyhow!("unknown stage `{stage}` (stages: coarse, core, detail)"))),
    }
}

/// Loads a stage's prepared set (`<dir>/<stage>/`), train and held-out, encoded with the
/// stage's context: ETOPO5 8 km tiles for coarse, GLOBE 1 km tiles for core, GEBCO 500 m
/// tiles (Kyrgyzstan) for detail. The 500 m tiles are not added to the core's (downsampled):
/// they lie inside the core set's held-out band (60–90°E), so training on them would leak
/// held-out terrain into the core.
pub(super) fn stage_data(stage: &str, dir: &Path, spec: ContextSpec) -> Result<(TileSet, TileSet), String> {
    Ok((read_split(&dir.join(stage), "train", 1, spec)?, read_split(&dir.join(stage), "heldout", 1, spec)?))
}
