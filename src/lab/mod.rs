//! The lab: the tools that make and judge the learned terrain, kept apart from the product
//! (docs/architecture.md, "The lab").
//!
//! - [`data`]: `infiniterra data fetch | prepare`, the real elevation data the models learn from;
//! - [`eval`]: `infiniterra eval`, how realistic generated terrain is against real terrain;
//! - `train`: `infiniterra train STAGE` and the calibrations of a shipped model (behind the
//!   `learned` feature);
//! - [`bench`]: `infiniterra bench`, the engine's and the pipeline's numbers on this machine;
//! - [`relief_compare`]: `infiniterra render --compare-real`, generated relief beside real
//!   tiles of a prepared set.
//!
//! The rule: the lab may use the product (the pipeline, exports, the configuration), the
//! product never uses the lab — nothing outside `src/lab/` and `src/cli/` imports
//! `crate::lab`. The server, pre-generation, the world, chunk generation, maps and exports
//! build and run without it, and a refactor of the lab cannot change the world.

pub mod bench;
pub mod data;
pub mod eval;
pub mod manifest_edit;
pub mod relief_compare;
#[cfg(feature = "learned")]
pub mod train;
pub mod water;
