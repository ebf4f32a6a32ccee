//! The stage list as data: which stages of the hierarchy exist and which run.

/// Whether a stage runs.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum StageState {
    /// It runs and shapes the answers.
    Active,
    /// It does not exist yet; the pipeline runs without it.
    Missing {
        /// Why (which issue delivers it).
        reason: &'static str,
    },
}

/// One stage of the hierarchy.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StageStatus {
    /// Short name (`layout`, `coarse`, `core`, `detail`, `climate`).
    pub name: &'static str,
    /// What it contributes.
    pub role: &'static str,
    /// Whether it runs.
    pub state: StageState,
}

/// The hierarchy as it stands in this build.
pub fn current() -> Vec<StageStatus> {
    // Stages a configuration can turn on (`engine.learned`) start as off; the pipeline marks
    // the ones it loads as active.
    const OFF: &str = "off (not in engine.learned): the layout stands in";
    const UPSAMPLED: &str = "off (not in engine.learned): the core's relief is bilinearly upsampled";
    vec![
        StageStatus {
            name: "layout",
            role: "procedural continental sketch (fBm, quantile-mapped)",
            state: StageState::Active,
        },
        StageStatus {
            name: "coarse",
            role: "refines the sketch: continents, shelves, basins",
            state: StageState::Missing { reason: OFF },
        },
        StageStatus {
            name: "core",
            role: "relief at the native resolution",
            state: StageState::Missing { reason: OFF },
        },
        StageStatus {
            name: "detail",
            role: "high-frequency residual",
            state: StageState::Missing { reason: UPSAMPLED },
        },
        StageStatus {
            name: "climate",
            role: "lapse-rate temperature, orographic precipitation",
            state: StageState::Active,
        },
    ]
}
