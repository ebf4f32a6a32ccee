//! Seed-consistent noise: pure functions of (seed, stage, step, global coordinates).
//!
//! Diffusion noise is drawn per fixed 64×64 tile from a ChaCha8 stream whose 32-byte key is
//! exactly (world seed, stage, step, tile y, tile x), so every window overlapping a tile sees
//! the same values whatever order the world is explored in. Procedural noise (the layout)
//! uses an integer lattice hash instead: it is evaluated millions of times per second.

use rand_chacha::rand_core::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use std::f64::consts::TAU;

use crate::infinite::Source;
use crate::tile::{div_floor, Rect, Tile};

/// Side of the fixed noise tiles.
pub const NOISE_TILE: i64 = 64;

/// Which noise stream: the world seed plus the stage and step that consume it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct NoiseKey {
    /// The world seed.
    pub seed: u64,
    /// A stage number (each stage gets its own stream).
    pub stage: u32,
    /// A step number within the stage.
    pub step: u32,
}

impl NoiseKey {
    fn rng(&self, ty: i64, tx: i64) -> ChaCha8Rng {
        let mut key = [0u8; 32];
        key[0..8].copy_from_slice(&self.seed.to_le_bytes());
        key[8..12].copy_from_slice(&self.stage.to_le_bytes());
        key[12..16].copy_from_slice(&self.step.to_le_bytes());
        key[16..24].copy_from_slice(&ty.to_le_bytes());
        key[24..32].copy_from_slice(&tx.to_le_bytes());
        ChaCha8Rng::from_seed(key)
    }

    /// The standard-normal values of one tile, `channels × 64 × 64`.
    pub fn gaussian_tile(&self, channels: usize, ty: i64, tx: i64) -> Vec<f32> {
        let mut rng = self.rng(ty, tx);
        let n = channels * (NOISE_TILE * NOISE_TILE) as usize;
        let mut out = Vec::with_capacity(n);
        while out.len() < n {
            // Box–Muller on two 53-bit uniforms; u1 is kept away from 0 so ln() is finite.
            let u1 = ((rng.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64;
            let u2 = (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
            let r = (-2.0 * u1.ln()).sqrt();
            let a = std::f64::consts::TAU * u2;
            out.push((r * a.cos()) as f32);
            if out.len() < n {
                out.push((r * a.sin()) as f32);
            }
        }
        out
    }
}

/// Unbounded standard-normal noise with `channels` channels, as a [`Source`].
#[derive(Clone, Copy, Debug)]
pub struct GaussianNoise {
    /// Which stream.
    pub key: NoiseKey,
    /// Channels per cell.
    pub channels: usize,
}

impl Source for GaussianNoise {
    fn channels(&self) -> usize {
        self.channels
    }

    fn query(&self, rect: Rect) -> Tile {
        let mut out = Tile::zeros(self.channels, rect);
        let (ty0, ty1) = (div_floor(rect.y0, NOISE_TILE), div_floor(rect.y1() - 1, NOISE_TILE));
        let (tx0, tx1) = (div_floor(rect.x0, NOISE_TILE), div_floor(rect.x1() - 1, NOISE_TILE));
        let t = NOISE_TILE as usize;
        for ty in ty0..=ty1 {
            for tx in tx0..=tx1 {
                let tile_rect = Rect::new(ty * NOISE_TILE, tx * NOISE_TILE, NOISE_TILE, NOISE_TILE);
                let Some(part) = tile_rect.intersect(&rect) else { continue };
                let values = self.key.gaussian_tile(self.channels, ty, tx);
                for c in 0..self.channels {
                    for y in part.y0..part.y1() {
                        let src = (c * t + (y - tile_rect.y0) as usize) * t + (part.x0 - tile_rect.x0) as usize;
                        let dst = (c * rect.h as usize + (y - rect.y0) as usize) * rect.w as usize
                            + (part.x0 - rect.x0) as usize;
                        let n = part.w as usize;
                        out.data[dst..dst + n].copy_from_slice(&values[src..src + n]);
                    }
                }
            }
        }
        out
    }
}

/// A 64-bit integer hash of a seed and lattice coordinates (SplitMix64 finaliser chain).
pub fn hash3(seed: u64, a: i64, b: i64) -> u64 {
    fn mix(mut z: u64) -> u64 {
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    let h = mix(seed.wrapping_add(0x9e37_79b9_7f4a_7c15));
    let h = mix(h ^ (a as u64).wrapping_mul(0xd6e8_feb8_6659_fd93));
    mix(h ^ (b as u64).wrapping_mul(0xa076_1d64_78bd_642f))
}

/// Gradient (Perlin-style) noise at `(y, x)` in lattice units, range ≈ [-1, 1].
///
/// f64 coordinates are exact enough anywhere in the world: ±30,000,000 blocks is below 2^25,
/// which leaves 28 bits for the fraction.
pub fn gradient(seed: u64, y: f64, x: f64) -> f64 {
    let (cy, cx) = (floor(y), floor(x));
    let (fy, fx) = (y - cy, x - cx);
    let [g00, g01, g10, g11] = corner_gradients(seed, cy as i64, cx as i64);
    let grad = |(sin, cos): (f64, f64), dy: f64, dx: f64| cos * dx + sin * dy;
    let fade = |t: f64| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
    let (u, v) = (fade(fx), fade(fy));
    let n00 = grad(g00, fy, fx);
    let n01 = grad(g01, fy, fx - 1.0);
    let n10 = grad(g10, fy - 1.0, fx);
    let n11 = grad(g11, fy - 1.0, fx - 1.0);
    let top = n00 + u * (n01 - n00);
    let bottom = n10 + u * (n11 - n10);
    (top + v * (bottom - top)) * std::f64::consts::SQRT_2
}

/// The (sin, cos) gradients at the corners (`cy`, `cx`), (`cy`, `cx` + 1), (`cy` + 1, `cx`)
/// and (`cy` + 1, `cx` + 1) of a lattice cell of noise `seed`.
///
/// Remembered per thread: the layout samples its longest octaves many times per cell (a
/// continent-scale octave spans thousands of its pixels), and the corners' hashes and sines
/// were most of the layout's time. A small direct-mapped table keyed by (seed, cell), slot
/// by seed so each octave keeps its own last cell; a hit returns exactly what is computed.
fn corner_gradients(seed: u64, cy: i64, cx: i64) -> [(f64, f64); 4] {
    let compute = || {
        let at = |gy: i64, gx: i64| sin_cos_turns((hash3(seed, gy, gx) >> 11) as f64 / (1u64 << 53) as f64);
        [at(cy, cx), at(cy, cx + 1), at(cy + 1, cx), at(cy + 1, cx + 1)]
    };
    CORNERS.with_borrow_mut(|table| {
        let slot = &mut table[(seed >> (64 - CORNER_SLOTS.trailing_zeros())) as usize];
        match slot {
            Some((s, c, g)) if *s == seed && *c == (cy, cx) => *g,
            _ => {
                let g = compute();
                *slot = Some((seed, (cy, cx), g));
                g
            }
        }
    })
}

/// Slots of [`corner_gradients`]' table (a power of two: the slot is the seed's top bits).
const CORNER_SLOTS: usize = 128;

type Corners = Option<(u64, (i64, i64), [(f64, f64); 4])>;

thread_local! {
    /// [`corner_gradients`]' table, one per thread.
    static CORNERS: std::cell::RefCell<[Corners; CORNER_SLOTS]> =
        const { std::cell::RefCell::new([None; CORNER_SLOTS]) };
}

/// (sin 2πt, cos 2πt) of `t` turns.
///
/// By hand, not `f64::sin_cos`: the erosion filter runs a dozen of these per octave per block
/// column and the layout's gradient noise four per sample (together a sixth of
/// pre-generation's time was libm's), and plain multiplications and additions
/// give the same bits on every platform, where libm's last bit is the platform's. The turn is
/// reduced to an eighth of a circle around a quarter-turn; Taylor series to degree 13 there
/// are within 1e-11 of the true values.
pub fn sin_cos_turns(t: f64) -> (f64, f64) {
    // Rounding by conversion (`round` is a libm call); callers keep |t| below a few hundred.
    // To `i32`, not `i64`: processors convert four doubles to `i32` in one instruction, and
    // none (before AVX-512) to `i64`, so the erosion filter's loops over points vectorise.
    let r = t - ((t + 1024.5) as i32 - 1024) as f64;
    let quarter = (4.0 * r + 4.5) as i32 - 4;
    let a = TAU * (r - 0.25 * quarter as f64);
    let (sin, cos) = taylor_sin_cos(a);
    // Back to the quarter-turn, without branches (the quarter is random to a branch
    // predictor, which made a `match` as slow as libm): odd quarters swap sine and cosine,
    // quarters 2 and 3 negate the sine, 1 and 2 the cosine.
    let m = (quarter & 3) as u64;
    let swap = (m & 1).wrapping_neg();
    let (sb, cb) = (sin.to_bits(), cos.to_bits());
    let s = ((sb & !swap) | (cb & swap)) ^ ((m & 2) << 62);
    let c = ((cb & !swap) | (sb & swap)) ^ (((m + 1) & 2) << 62);
    (f64::from_bits(s), f64::from_bits(c))
}

/// [`sin_cos_turns`] with its rounding by `f64::floor` and its quarter-turn by comparisons, for
/// code compiled with SSE4.1 or later, where `floor` is one instruction on four doubles and
/// the whole of it vectorises (a conversion to an integer, with Rust's saturation, does not).
/// The same bits as [`sin_cos_turns`] for every `t` it accepts (test
/// `both_sine_cosines_agree_bit_for_bit`); without SSE4.1, `floor` is a libm call: use that.
#[inline(always)]
pub fn sin_cos_turns_by_floor(t: f64) -> (f64, f64) {
    // For t > −1024.5 the conversion truncates a positive number: the floor, exactly.
    let r = t - ((t + 1024.5).floor() - 1024.0);
    let quarter = (4.0 * r + 4.5).floor() - 4.0;
    let a = TAU * (r - 0.25 * quarter);
    let (sin, cos) = taylor_sin_cos(a);
    // The quarter is −2 … 2; as `sin_cos_turns`'s `quarter & 3`: odd quarters swap sine and
    // cosine, 2 and 3 (−2, −1, 2 here) negate the sine, 1 and 2 (1, 2, −2) the cosine.
    let odd = quarter == 1.0 || quarter == -1.0;
    let (s, c) = if odd { (cos, sin) } else { (sin, cos) };
    let s = if quarter == 2.0 || quarter == -2.0 || quarter == -1.0 { -s } else { s };
    let c = if quarter == 1.0 || quarter == 2.0 || quarter == -2.0 { -c } else { c };
    (s, c)
}

/// Sine and cosine of `a` radians (|a| ≤ π/4) by their Taylor series to degree 13 and 12:
/// the one polynomial both [`sin_cos_turns`] and [`sin_cos_turns_by_floor`] evaluate.
#[inline(always)]
fn taylor_sin_cos(a: f64) -> (f64, f64) {
    let a2 = a * a;
    let sin = a
        * (1.0
            + a2 * (-1.0 / 6.0
                + a2 * (1.0 / 120.0
                    + a2 * (-1.0 / 5040.0
                        + a2 * (1.0 / 362_880.0 + a2 * (-1.0 / 39_916_800.0 + a2 / 6_227_020_800.0))))));
    let cos = 1.0
        + a2 * (-0.5
            + a2 * (1.0 / 24.0
                + a2 * (-1.0 / 720.0 + a2 * (1.0 / 40_320.0 + a2 * (-1.0 / 3_628_800.0 + a2 / 479_001_600.0)))));
    (sin, cos)
}

/// The largest whole number at most `v`, by conversion (`f64::floor` is a libm call on the
/// baseline x86-64 target); `v` must lie far inside `i64` (lattice cells of a world do).
pub fn floor(v: f64) -> f64 {
    let i = v as i64;
    (if (i as f64) > v { i - 1 } else { i }) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gaussian_noise_is_a_function_of_global_coordinates() {
        let n = GaussianNoise { key: NoiseKey { seed: 7, stage: 1, step: 0 }, channels: 2 };
        let big = n.query(Rect::new(-70, -10, 150, 140));
        let small = n.query(Rect::new(-3, 50, 20, 30));
        assert_eq!(big.crop(small.rect), small);
        let other = GaussianNoise { key: NoiseKey { seed: 8, stage: 1, step: 0 }, channels: 2 };
        assert_ne!(other.query(small.rect), small);
        let mean = big.data.iter().map(|&v| v as f64).sum::<f64>() / big.data.len() as f64;
        let var = big.data.iter().map(|&v| (v as f64 - mean).powi(2)).sum::<f64>() / big.data.len() as f64;
        assert!(mean.abs() < 0.02 && (var - 1.0).abs() < 0.03, "mean {mean} var {var}");
    }

    #[test]
    fn gradient_noise_is_bounded_and_varies_far_from_the_origin() {
        let far: Vec<f64> = (0..64).map(|i| gradient(3, -7_500_001.3 + i as f64 * 0.37, 7.5e6)).collect();
        assert!(far.iter().all(|v| v.abs() <= 1.5));
        assert!(far.iter().any(|v| v.abs() > 0.1), "noise is flat far away");
        assert_eq!(gradient(3, 5.0, 9.0), 0.0, "zero on lattice points");
    }

    #[test]
    fn sine_and_cosine_in_turns_match_libm() {
        let mut worst: f64 = 0.0;
        for i in -40_000..=40_000 {
            let t = f64::from(i) * 7.3e-5 + 1e-9;
            let (s, c) = sin_cos_turns(t);
            let (es, ec) = (std::f64::consts::TAU * t).sin_cos();
            worst = worst.max((s - es).abs()).max((c - ec).abs());
        }
        assert!(worst < 1e-10, "worst error {worst:e}");
    }

    #[test]
    fn both_sine_cosines_agree_bit_for_bit() {
        // Every quarter, its boundaries and their neighbours, and whole turns either side.
        let mut ts: Vec<f64> = (-4000..=4000).map(|i| f64::from(i) / 1000.0).collect();
        ts.extend((-40..=40).flat_map(|q| {
            let t = f64::from(q) * 0.125;
            [t, f64::from_bits(t.to_bits() + 1), f64::from_bits(t.to_bits().wrapping_sub(1)), -t]
        }));
        ts.extend([0.0, -0.0, 1e-300, -1e-300, 0.5, -0.5, 0.25, -0.25, 0.75, -0.75, 123.456, -321.987]);
        for t in ts {
            let (a, b) = (sin_cos_turns(t), sin_cos_turns_by_floor(t));
            assert_eq!((a.0.to_bits(), a.1.to_bits()), (b.0.to_bits(), b.1.to_bits()), "t = {t:e}");
        }
    }

    #[test]
    fn gradient_noise_is_the_same_whatever_the_table_remembers() {
        // The formula without the table.
        let direct = |seed: u64, y: f64, x: f64| {
            let (cy, cx) = (floor(y), floor(x));
            let (fy, fx) = (y - cy, x - cx);
            let grad = |gy: i64, gx: i64, dy: f64, dx: f64| {
                let (sin, cos) = sin_cos_turns((hash3(seed, gy, gx) >> 11) as f64 / (1u64 << 53) as f64);
                cos * dx + sin * dy
            };
            let fade = |t: f64| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
            let (u, v) = (fade(fx), fade(fy));
            let (cy, cx) = (cy as i64, cx as i64);
            let top = grad(cy, cx, fy, fx) + u * (grad(cy, cx + 1, fy, fx - 1.0) - grad(cy, cx, fy, fx));
            let bottom = grad(cy + 1, cx, fy - 1.0, fx)
                + u * (grad(cy + 1, cx + 1, fy - 1.0, fx - 1.0) - grad(cy + 1, cx, fy - 1.0, fx));
            (top + v * (bottom - top)) * std::f64::consts::SQRT_2
        };
        // Seeds sharing a slot (same top bits) and seeds apart, interleaved; points walking
        // through cells and back, so the table both hits and is evicted.
        let seeds = [7u64, 7 | 1 << 40, u64::MAX, 0x0123_4567_89ab_cdef];
        let points: Vec<(f64, f64)> =
            (0..400).map(|i| (-3.3 + 0.037 * i as f64, 11.9 - 0.021 * (i % 97) as f64)).collect();
        for round in 0..2 {
            for (k, &(y, x)) in points.iter().enumerate() {
                let seed = seeds[(k + round) % seeds.len()];
                assert_eq!(gradient(seed, y, x).to_bits(), direct(seed, y, x).to_bits(), "seed {seed} at ({y}, {x})");
            }
        }
        // On another thread, with a table of its own, the same bits.
        let here: Vec<u64> = points.iter().map(|&(y, x)| gradient(7, y, x).to_bits()).collect();
        let there =
            std::thread::spawn(move || points.iter().map(|&(y, x)| gradient(7, y, x).to_bits()).collect::<Vec<_>>());
        assert_eq!(here, there.join().unwrap());
    }

    #[test]
    fn floor_by_conversion_is_floor() {
        for v in [-3.0, -2.5, -1e-12, 0.0, 1e-12, 0.999_999, 7.0, -1_234_567.25, 9.9e8] {
            assert_eq!(floor(v), v.floor(), "{v}");
        }
    }
}
