//! Realism metrics (defined in docs/realism.md): how far a heightmap's statistics are from real terrain's.
//!
//! Owns: the math — slope distributions, style histograms and their distances, radially
//! averaged power spectra, Priority-Flood depression statistics, seam ratios, and the fBm
//! baseline. Everything works on square-metre rasters ([`Raster`]) at one resolution; callers
//! resample first. Must not touch: files, the pipeline, the command line (the root crate's
//! `eval` module loads data and prints the report).

mod distance;
mod drainage;
mod fbm;
mod fft;
mod raster;
mod relief;
mod seams;
mod slope;
mod spectrum;

pub use distance::{chi2_distance, histogram, quantile_edges, wasserstein1};
pub use drainage::{depressions, priority_flood, Depressions, MIN_DEPRESSION_DEPTH_M};
pub use fbm::{fbm, FBM_BETA};
pub use fft::{fft, fft2, Complex};
pub use raster::Raster;
pub use relief::{relative_elevation, RELIEF_RADIUS};
pub use seams::{seam_ratio, SeamLines, SeamStats};
pub use slope::slope_degrees;
pub use spectrum::{beta_sampling_sd, fit_beta, radial_power_spectrum, real_split_distances, Spectrum, REAL_SPLITS};
