//! The stage list as data: the learned stages of the hierarchy in ONE table ([`LEARNED`]),
//! and which stages run.
//!
//! The table drives everything that differs between learned stages: which names
//! `engine.learned` accepts and which stages each needs (`settings`), how `Pipeline::build`
//! chains them, what `infiniterra train STAGE` trains and ships, and the per-stage constants
//! of the data preparation (`scripts/data/prepare.py`, checked against this table by a test).
//! Adding a stage is one entry here (docs/architecture.md, "Where to add: A learned stage").

use crate::encoding::ContextSpec;

/// The network a learned stage is built with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Network {
    /// `UNetConfig::core()`.
    Core,
    /// `UNetConfig::detail()`.
    Detail,
}

#[cfg(feature = "learned")]
impl Network {
    /// The network's shape.
    pub fn config(self) -> crate::model::UNetConfig {
        match self {
            Network::Core => crate::model::UNetConfig::core(),
            Network::Detail => crate::model::UNetConfig::detail(),
        }
    }
}

/// The sampler a learned stage ships with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SamplerChoice {
    /// `Sampler::few_step()`.
    FewStep,
}

#[cfg(feature = "learned")]
impl SamplerChoice {
    /// The sampler.
    pub fn sampler(self) -> crate::model::Sampler {
        match self {
            SamplerChoice::FewStep => crate::model::Sampler::few_step(),
        }
    }
}

/// One learned stage: everything that tells it apart from the others.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LearnedStageSpec {
    /// Its name in `engine.learned`, `models/<name>.json`, `infiniterra train <name>` and
    /// `data/prepared/<name>/`.
    pub name: &'static str,
    /// What it contributes (the stage list shown to owners).
    pub role: &'static str,
    /// Why the pipeline runs without it when it is not in `engine.learned`.
    pub off: &'static str,
    /// Real size of one of its pixels, metres (its training data's resolution).
    pub metres_per_pixel: f64,
    /// The stage whose output it refines (`"layout"`: the procedural sketch). When that stage
    /// is off and not in [`requires`](Self::requires), it refines the layout's sketch instead.
    pub context_stage: &'static str,
    /// Stages that must run with it.
    pub requires: &'static [&'static str],
    /// How its context is made from the grid above it.
    pub context: ContextSpec,
    /// Its network.
    pub network: Network,
    /// Its sampler.
    pub sampler: SamplerChoice,
    /// Side of its windows, pixels.
    pub window: usize,
    /// Window stride at inference (0: half the window).
    pub stride: usize,
    /// Back-projection passes of each window onto its context cells (`None`: none).
    pub projection_passes: Option<usize>,
}

/// The learned stages, coarse to fine: the pipeline chains them in this order.
pub const LEARNED: [LearnedStageSpec; 3] = [
    // The core's network one level up: 8 km relief (continents, shelves, basins) refining
    // the layout's sketch from its blurred 16 km means. (The first coarse weights used
    // 64 km means, as the core does one level down, and flattened the layout's narrower
    // ranges: a 3,000 m range came out as 1,000 m blobs.)
    LearnedStageSpec {
        name: "coarse",
        role: "refines the sketch: continents, shelves, basins",
        off: "off (not in engine.learned): the layout stands in",
        metres_per_pixel: 8000.0,
        context_stage: "layout",
        requires: &[],
        context: ContextSpec { factor: 2, blur: true },
        network: Network::Core,
        sampler: SamplerChoice::FewStep,
        window: 64,
        stride: 0,
        projection_passes: None,
    },
    // 1 km relief over 8 km box means, unblurred: the blurred means of the paper's Laplacian
    // split take the 16–64 km band out of the context, and a 64-pixel window cannot put it
    // back (the first cores drew a third of its power, with or without window overlap);
    // unblurred, the context carries it and the model draws what is finer than 8 km. Its
    // windows missed their context cells by 23 m on held-out land, and part of the 16–45 km
    // band with them, hence the back-projection (see `model::projection`). Windows overlap
    // by a quarter (stride 48): on held-out land that measured as the half overlap did
    // (docs/learned-terrain.md) with 40 % fewer windows, and the network is most of a new
    // area's cost.
    LearnedStageSpec {
        name: "core",
        role: "relief at the native resolution",
        off: "off (not in engine.learned): the layout stands in",
        metres_per_pixel: 1000.0,
        context_stage: "coarse",
        requires: &[],
        context: ContextSpec { factor: 8, blur: false },
        network: Network::Core,
        sampler: SamplerChoice::FewStep,
        window: 64,
        stride: 48,
        projection_passes: Some(4),
    },
    // The last stage: 500 m relief over the core's own 1 km grid, unblurred (the core's
    // relief is kept; only what is finer than 1 km is generated), with the paper's 75 %
    // window overlap for the decoder. Without the core it has nothing to refine.
    LearnedStageSpec {
        name: "detail",
        role: "high-frequency residual",
        off: "off (not in engine.learned): the core's relief is bilinearly upsampled",
        metres_per_pixel: 500.0,
        context_stage: "core",
        requires: &["core"],
        context: ContextSpec { factor: 2, blur: false },
        network: Network::Detail,
        sampler: SamplerChoice::FewStep,
        window: 64,
        stride: 16,
        projection_passes: None,
    },
];

/// The table entry of `name`, if it is a learned stage.
pub fn learned(name: &str) -> Option<&'static LearnedStageSpec> {
    LEARNED.iter().find(|s| s.name == name)
}

/// The names of the learned stages, in table order.
pub fn learned_names() -> Vec<&'static str> {
    LEARNED.iter().map(|s| s.name).collect()
}

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

/// The hierarchy as it stands in this build: the layout, the learned stages (off until the
/// pipeline loads them) and the climate.
pub fn current() -> Vec<StageStatus> {
    let layout = StageStatus {
        name: "layout",
        role: "procedural continental sketch (fBm, quantile-mapped)",
        state: StageState::Active,
    };
    let learned = LEARNED.iter().map(|s| StageStatus {
        name: s.name,
        role: s.role,
        state: StageState::Missing { reason: s.off },
    });
    let climate = StageStatus {
        name: "climate",
        role: "lapse-rate temperature, orographic precipitation",
        state: StageState::Active,
    };
    std::iter::once(layout).chain(learned).chain(std::iter::once(climate)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_is_coarse_to_fine_and_every_context_and_requirement_comes_before() {
        for (i, s) in LEARNED.iter().enumerate() {
            assert!(s.window % 8 == 0 && s.stride < s.window, "{}", s.name);
            let earlier = |name: &str| LEARNED[..i].iter().any(|e| e.name == name);
            assert!(s.context_stage == "layout" || earlier(s.context_stage), "{}", s.name);
            assert!(s.requires.iter().all(|r| earlier(r)), "{}", s.name);
            if i > 0 {
                assert!(s.metres_per_pixel < LEARNED[i - 1].metres_per_pixel, "{} is finer", s.name);
            }
        }
        assert_eq!(learned_names(), ["coarse", "core", "detail"]);
        assert_eq!(learned("detail").map(|s| s.requires), Some(&["core"][..]));
        assert!(learned("canyon").is_none());
    }
}
