//! Sediment infill of closed basins in a stage's output.
//!
//! A network that sees 64 km windows does not learn drainage: real terrain's valleys run on
//! to the sea, its closed basins are few and shallow (filled with sediment over time), while
//! the core draws valleys dammed by stray ridges — held-out land generated without this step
//! needs 3.8× the real fill volume, its 16–64 km basins 3–4× as deep as real ones. Each
//! window's output is therefore Priority-Flood filled (window edges and the sea are outlets)
//! and every cell's depth below its spill level `d` is compressed to `c·tanh(d/c)`: pits much
//! shallower than the depth scale `c` keep their depth (so shallow closed depressions, common
//! in real terrain, stay), deep ones become at most `c` deep, with the gently graded floors
//! of sediment-filled basins. A pure function of the window's own values, applied before the
//! engine blends windows, so the world stays a function of (seed, region).

use serde::{Deserialize, Serialize};

use crate::metrics::{priority_flood, Raster};

/// Cells at or below this elevation (metres) are the sea: water reaching them leaves.
pub const SEA_LEVEL_M: f32 = 0.0;

/// The infill step, as a stage's manifest stores it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DepressionInfill {
    /// Depth scale `c`, metres: a closed basin ends at most this deep below its spill level.
    pub depth_scale_m: f64,
}

impl DepressionInfill {
    /// Checks the depth scale, naming the field when it is unusable.
    pub fn validate(&self) -> Result<(), String> {
        if self.depth_scale_m.is_finite() && self.depth_scale_m > 0.0 {
            Ok(())
        } else {
            Err(format!(
                "depression_infill.depth_scale_m = {} (must be a positive number of metres)",
                self.depth_scale_m
            ))
        }
    }

    /// `metres` (a `side`×`side` window, row-major) with every closed basin's depth `d` below
    /// its spill level compressed to `c·tanh(d/c)`.
    pub fn apply(&self, metres: &[f32], side: usize) -> Vec<f32> {
        let raster = Raster::new(side, side, 1.0, metres.to_vec());
        let filled = priority_flood(&raster, Some(SEA_LEVEL_M));
        let c = self.depth_scale_m;
        metres
            .iter()
            .zip(&filled)
            .map(|(&z, &f)| {
                let d = f64::from(f - z);
                if d > 0.0 {
                    (f64::from(f) - c * (d / c).tanh()) as f32
                } else {
                    z
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::HostRng;

    /// A plane at 200 m with a conical pit `depth` deep and 15 cells in radius in the middle.
    fn pit(depth: f32) -> Vec<f32> {
        (0..41 * 41)
            .map(|i| {
                let (y, x) = ((i / 41) as f32 - 20.0, (i % 41) as f32 - 20.0);
                200.0 - depth * (1.0 - (y * y + x * x).sqrt() / 15.0).max(0.0)
            })
            .collect()
    }

    #[test]
    fn a_deep_pit_ends_at_most_the_depth_scale_deep_and_the_rest_is_untouched() {
        let infill = DepressionInfill { depth_scale_m: 20.0 };
        let (z, out) = (pit(100.0), infill.apply(&pit(100.0), 41));
        let centre = 20 * 41 + 20;
        // Spill level 200 m: 100 m deep becomes 20·tanh(5) ≈ 19.998 m deep.
        assert!((200.0 - out[centre] - 20.0 * 5f32.tanh()).abs() < 1e-3, "{}", out[centre]);
        for (i, (&a, &b)) in z.iter().zip(&out).enumerate() {
            let d = 200.0 - a;
            if d <= 0.0 {
                assert_eq!(a, b, "cell {i} outside the pit moved");
            } else {
                let expected = 200.0 - 20.0 * (d / 20.0).tanh();
                assert!((b - expected).abs() < 1e-3 && b >= a, "cell {i}: {a} → {b}, expected {expected}");
            }
        }
        // A pit much shallower than the scale keeps nearly all of its depth (real terrain's
        // many shallow closed depressions stay).
        let shallow = infill.apply(&pit(2.0), 41);
        assert!(200.0 - shallow[centre] > 1.98, "{}", shallow[centre]);
    }

    #[test]
    fn no_basin_is_left_deeper_than_the_depth_scale_and_drained_land_and_sea_stay() {
        let infill = DepressionInfill { depth_scale_m: 15.0 };
        for trial in 0..10 {
            // Rough random land with a strip of sea along one edge on even trials.
            let noise = HostRng::keyed(7, trial, 0, 0).normals(32 * 32);
            let z: Vec<f32> = (0..32 * 32)
                .map(|i| {
                    let sea = trial % 2 == 0 && i % 32 < 4;
                    if sea {
                        -20.0
                    } else {
                        300.0 + 60.0 * noise[i]
                    }
                })
                .collect();
            let out = infill.apply(&z, 32);
            let before = priority_flood(&Raster::new(32, 32, 1.0, z.clone()), Some(SEA_LEVEL_M));
            let after = priority_flood(&Raster::new(32, 32, 1.0, out.clone()), Some(SEA_LEVEL_M));
            // The spill levels are the same; only the depth below them shrank.
            assert_eq!(before, after, "trial {trial}: spill levels moved");
            let deepest = after.iter().zip(&out).map(|(f, z)| f - z).fold(0.0f32, f32::max);
            assert!(deepest < 15.0 + 1e-3, "trial {trial}: a basin {deepest} m deep is left");
            assert!(before.iter().zip(&z).any(|(f, z)| f > z), "trial {trial}: no basin to fill");
            for i in 0..z.len() {
                if before[i] == z[i] {
                    assert_eq!(out[i], z[i], "trial {trial}: drained cell {i} moved");
                }
            }
        }
    }

    #[test]
    fn a_depth_scale_that_is_not_a_positive_number_is_refused_by_name() {
        for bad in [0.0, -5.0, f64::NAN, f64::INFINITY] {
            let msg = DepressionInfill { depth_scale_m: bad }.validate().expect_err("refused");
            assert!(msg.contains("depression_infill.depth_scale_m"), "{msg}");
        }
        assert!(DepressionInfill { depth_scale_m: 20.0 }.validate().is_ok());
    }
}
