//! What each stage trains on and at what resolution — read from the pipeline's stage table
//! (`infiniterra_terrain::pipeline::stages::LEARNED`) — and where its prepared tiles are read
//! from.

use std::path::Path;

use anyhow::anyhow;
use infiniterra_terrain::encoding::ContextSpec;
use infiniterra_terrain::model::{ContextProjection, Sampler, UNetConfig};
use infiniterra_terrain::pipeline::stages;

use super::data::{read_split, TileSet};
use super::TrainError;

/// What a stage trains on and at what resolution: its entry of the stage table
/// ([`stages::LEARNED`]), made concrete.
pub(super) struct StageSpec {
    /// Real size of one of its pixels, metres.
    pub metres_per_pixel: f64,
    /// Its network (tiny in smoke runs).
    pub config: UNetConfig,
    /// The sampler it ships with.
    pub sampler: Sampler,
    /// How its context is made from the grid above it.
    pub context: ContextSpec,
    /// Side of its windows, pixels.
    pub window: usize,
    /// Window stride at inference (0: half the window).
    pub stride: usize,
    /// Back-projection of each window onto its context cells (unblurred contexts only).
    pub projection: Option<ContextProjection>,
}

/// The stage `stage` of the table; an input error listing the stages when there is none.
pub(super) fn stage_spec(stage: &str, smoke: bool) -> Result<StageSpec, TrainError> {
    let Some(spec) = stages::learned(stage) else {
        let names = stages::learned_names().join(", ");
        return Err(TrainError::input(anyhow!("unknown stage `{stage}` (stages: {names})")));
    };
    Ok(StageSpec {
        metres_per_pixel: spec.metres_per_pixel,
        config: if smoke { UNetConfig::tiny() } else { spec.network.config() },
        sampler: spec.sampler.sampler(),
        context: spec.context,
        window: spec.window,
        stride: spec.stride,
        projection: spec.projection_passes.map(|iterations| ContextProjection { iterations }),
    })
}

/// Loads a stage's prepared set (`<dir>/<stage>/`), train and held-out, encoded with the
/// stage's context: ETOPO5 8 km tiles for coarse, GLOBE 1 km tiles for core, GEBCO 500 m
/// tiles (Kyrgyzstan) for detail. The 500 m tiles are not added to the core's (downsampled):
/// they lie inside the core set's held-out band (60–90°E), so training on them would leak
/// held-out terrain into the core.
pub(super) fn stage_data(stage: &str, dir: &Path, spec: ContextSpec) -> Result<(TileSet, TileSet), String> {
    Ok((read_split(&dir.join(stage), "train", 1, spec)?, read_split(&dir.join(stage), "heldout", 1, spec)?))
}
