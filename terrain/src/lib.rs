//! The terrain side of infiniterra: everything that turns (seed, region) into elevation and
//! climate, with no knowledge of Minecraft.
//!
//! Data flows one way: [`pipeline`] → stages ([`layout`], [`climate`], learned models) →
//! [`infinite`] engine. The server and the command-line tools live in the root crate.

pub mod climate;
pub mod encoding;
pub mod erosion;
pub mod hydrology;
pub mod infinite;
pub mod layout;
pub mod metrics;
#[cfg(feature = "learned")]
pub mod model;
pub mod model_files;
pub mod noise;
pub mod pipeline;
pub mod range;
pub mod resample;
pub mod settings;
pub mod stages;
pub mod tile;
pub mod upsample;

pub use pipeline::Pipeline;
pub use settings::TerrainSettings;
pub use tile::{Rect, Tile};
