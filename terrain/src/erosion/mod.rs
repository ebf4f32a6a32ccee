//! Relief below the learned grids: an erosion filter that carves branching gullies and spurs
//! along the downhill direction of the relief it is given, octave by octave, down to blocks.
//!
//! The learned stages stop at 1 km (500 m with the `detail` stage); real terrain keeps its
//! structure down to tens of metres: valleys branch into gullies, ridges into spurs, and all
//! of them run downhill. The filter sums octaves of *gully noise* ([`gullies`]): stripes
//! whose crests and troughs run along the local downhill direction, blended over a jittered
//! lattice. Each octave is steered by the slopes of the octaves before it, so small gullies
//! run down the sides of large ones and the pattern branches. Amplitudes follow a self-affine
//! law (Hurst exponent [`HURST`]) scaled by the smooth relief's slope: steep mountains get
//! deep gullies, plains stay nearly flat. The constants were fitted on real terrain the
//! models never train on (docs/learned-terrain.md, "Relief on foot").
//!
//! Written by hand: no crate does gradient-aligned erosion noise; the method follows the
//! "erosion noise" of Clay John and Rune Skovbo Johansen's erosion filter (public shader
//! code), adapted to metres, an explicit slope-scaled amplitude law and 64-bit hashing.
//!
//! A pure function of (seed, position in metres, the relief's gradient and slope there): no
//! state and no neighbours, so any order of evaluation and any split into tiles or windows
//! gives the same bits, and there is nothing to seam.

#[cfg(test)]
mod tests;

use std::f64::consts::TAU;
use std::ops::Range;

use crate::noise::{floor, sin_cos_turns, sin_cos_turns_by_floor};

/// Wavelength of the longest octave, metres: the band the 1 km learned grid only half
/// resolves (its cubic resampling keeps little below ~3 km).
pub const LONGEST_M: f64 = 4000.0;
/// Amplitude of an octave relative to (slope × wavelength) at [`LONGEST_M`], at the
/// [`REFERENCE_SLOPE`].
pub const AMPLITUDE: f64 = 0.35;
/// Hurst exponent of the octave amplitudes: each halving of the wavelength keeps 2^−H of the
/// amplitude. Real 3″ DEMs judged on 6 km tiles at 93 m fall off as β ≈ −4.4 (H ≈ 1.2; the
/// 0.8–0.9 of the literature holds over longer ranges); 1.2 puts the block grid's β inside
/// the real tiles' range ± 0.3 for hills and mountains (docs/realism.md, "The block grid").
pub const HURST: f64 = 1.2;
/// Slope (m/m) below which a plain is treated as this steep, so flat land keeps a few metres
/// of relief instead of none.
pub const FLOOR_SLOPE: f64 = 0.005;
/// Octaves smaller than this (metres) are not carved: a fiftieth of a 25 m block, below what
/// rounding to blocks can show, and they cost as much as the big ones.
pub const MIN_AMPLITUDE_M: f64 = 0.5;
/// How strongly an octave's slopes turn the next octave's downhill direction.
const STEER: f64 = 1.0;
/// Turn between the lattices of successive octaves, radians (the golden angle: no two
/// octaves of the ladder share an orientation).
const GOLDEN_ANGLE: f64 = 2.399_963_229_728_653;
/// Turn of the first octave's lattice, radians (off the world's axes).
const LATTICE_ANGLE: f64 = 0.5;
/// Shortest wavelength a resampled grid carries, in its own pixels. The model grid is
/// upsampled 4× to blocks by a cubic; octaves of a few of its pixels come out of that with a
/// beat of the grid's period — block steps midway between model-pixel centres 8–10 % larger
/// than across them (4-block facets) with octaves down to 2 or 4 pixels — so everything
/// shorter than 8 pixels is carved on the block grid itself.
pub const SHORTEST_ON_GRID_PIXELS: f64 = 8.0;
/// Octaves that exist at all (wavelength 4 km down to ≈ 1 m).
pub const MAX_OCTAVES: u32 = 12;

/// Wavelength of octave `k` (0 is the longest), metres.
pub fn wavelength(k: u32) -> f64 {
    LONGEST_M / f64::from(1u32 << k)
}

/// The octaves whose wavelength is at least `shortest_m` and below `longest_m` (metres).
pub fn octaves_between(shortest_m: f64, longest_m: f64) -> Range<u32> {
    let first = (0..MAX_OCTAVES).find(|&k| wavelength(k) < longest_m).unwrap_or(MAX_OCTAVES);
    let end = (0..MAX_OCTAVES).find(|&k| wavelength(k) < shortest_m).unwrap_or(MAX_OCTAVES);
    first..end.max(first)
}

/// Slope (m/m) at which an octave's amplitude is [`AMPLITUDE`] × slope × wavelength; it grows
/// as slope^[`SLOPE_POWER`] around it.
pub const REFERENCE_SLOPE: f64 = 0.1;
/// How an octave's amplitude follows the smooth relief's slope: less than in proportion, as
/// real hillslopes do — gentle land is still textured, and steep land is not cut ever deeper
/// (hillslopes stop steepening near their threshold, ≈ 30–35°).
pub const SLOPE_POWER: f64 = 0.75;

/// Slope (m/m) below which an octave's amplitude falls off faster with wavelength than
/// [`HURST`] says, the more so the flatter the land. Real plains keep their kilometre-scale
/// undulation but are smooth at hillslope scale (soil creep and deposition fill what little
/// is cut): the real savanna plateau the block grid is judged on (Kossou, docs/realism.md)
/// has a spectrum steep below 1 km, where one Hurst exponent everywhere left the generated
/// plains' too flat (β −3.8 on their dry tiles against −4.4).
pub const GENTLE_SLOPE: f64 = 0.04;
/// Extra Hurst exponent on dead-flat land; it fades linearly to 0 at [`GENTLE_SLOPE`], so
/// hills and mountains are carved as before, bit for bit.
pub const GENTLE_EXTRA_HURST: f64 = 0.25;
/// The octave whose amplitude the extra falloff leaves as it is (1 km): longer ones grow a
/// little, shorter ones shrink, so gentle land keeps about its mean slope.
pub const GENTLE_PIVOT: u32 = 2;

/// Amplitude (metres) of octave `k` over relief of slope `slope`.
#[cfg(test)]
fn amplitude(k: u32, slope: f64) -> f64 {
    AMPLITUDE * steepness(slope) * octave_scale(wavelength(k)) * gentle_tilt(slope).powi(k as i32 - GENTLE_PIVOT as i32)
}

/// Each octave's amplitude relative to the one before's, beyond [`HURST`]: 2^−extra, 1 on
/// land at least [`GENTLE_SLOPE`] steep.
fn gentle_tilt(slope: f64) -> f64 {
    let extra = GENTLE_EXTRA_HURST * (1.0 - slope / GENTLE_SLOPE);
    if extra > 0.0 {
        (-extra * std::f64::consts::LN_2).exp()
    } else {
        1.0
    }
}

/// The slope's part of an octave's amplitude.
fn steepness(slope: f64) -> f64 {
    REFERENCE_SLOPE * (slope.max(FLOOR_SLOPE) / REFERENCE_SLOPE).powf(SLOPE_POWER)
}

/// The wavelength's part of an octave's amplitude, metres.
fn octave_scale(lambda: f64) -> f64 {
    let relative = lambda / LONGEST_M;
    // The longest octaves overlap what the learned grid already holds: taper them.
    let taper = 1.0 - 0.5 * relative;
    lambda * relative.powf(HURST - 1.0) * taper
}

/// [`octave_scale`] of every octave, computed once (the filter runs per block column).
static OCTAVE_SCALES: std::sync::LazyLock<[f64; MAX_OCTAVES as usize]> =
    std::sync::LazyLock::new(|| std::array::from_fn(|k| octave_scale(wavelength(k as u32))));

/// (sin, cos) of each octave's lattice turn, computed once.
static LATTICE_TURNS: std::sync::LazyLock<[(f64, f64); MAX_OCTAVES as usize]> =
    std::sync::LazyLock::new(|| std::array::from_fn(|k| (k as f64 * GOLDEN_ANGLE + LATTICE_ANGLE).sin_cos()));

/// The erosion filter of one world seed.
#[derive(Clone, Copy, Debug)]
pub struct ErosionFilter {
    seed: u64,
}

/// What [`ErosionFilter::apply`] adds at a point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Carved {
    /// Height added, metres.
    pub height: f64,
    /// The gradient (∂h/∂x, ∂h/∂z) carried on: the input gradient plus the octaves' slopes
    /// (steers finer octaves run after these).
    pub gradient: (f64, f64),
}

impl ErosionFilter {
    /// The filter of world seed `seed`.
    pub fn new(seed: u64) -> ErosionFilter {
        ErosionFilter { seed: splitmix(seed ^ 0xE205_1011_F11E_0001) }
    }

    /// Octaves `octaves` at the point (`x`, `z`) metres, over relief whose gradient there is
    /// `gradient` (m/m, x east, z south) and whose slope (the smooth relief's, which sets the
    /// amplitudes) is `slope`.
    pub fn apply(&self, x: f64, z: f64, slope: f64, gradient: (f64, f64), octaves: Range<u32>) -> Carved {
        self.apply_with(&mut Lattice::default(), x, z, slope, gradient, octaves)
    }

    /// [`ErosionFilter::apply`], remembering in `lattice` the jittered lattice points of the
    /// cell each octave was last evaluated in: neighbouring columns mostly share them (a
    /// cell of a 1 km octave spans 25 blocks at 40 m), and hashing them anew for every column
    /// was a third of the filter's cost. The same bits as `apply`, whatever `lattice` holds.
    pub fn apply_with(
        &self,
        lattice: &mut Lattice,
        x: f64,
        z: f64,
        slope: f64,
        gradient: (f64, f64),
        octaves: Range<u32>,
    ) -> Carved {
        let (mut gx, mut gz) = gradient;
        let mut height = 0.0;
        let steep = AMPLITUDE * steepness(slope);
        // Multiplying by exactly 1 changes no bit: on land of GENTLE_SLOPE or steeper the
        // octaves are those of HURST alone.
        let tilt = gentle_tilt(slope);
        let mut gentle = tilt.powi(octaves.start as i32 - GENTLE_PIVOT as i32);
        for k in octaves {
            let lambda = wavelength(k);
            let amp = steep * OCTAVE_SCALES[k as usize] * gentle;
            gentle *= tilt;
            // Octaves only shrink from here on (Hurst > 1, the tilt ≤ 1): none of the rest
            // would add a visible fraction of a block either.
            if amp < MIN_AMPLITUDE_M {
                break;
            }
            // Not `hypot`: a libm call, and gradients are far from overflowing.
            let norm = (gx * gx + gz * gz).sqrt();
            // Downhill; on dead-flat ground any fixed direction will do.
            let dir = if norm > 1e-12 { (-gx / norm, -gz / norm) } else { (1.0, 0.0) };
            // Each octave's lattice is turned by its own angle: the noise's cells are squares,
            // and on one common axis-aligned lattice their edges line up into straight
            // north-south and east-west lines across the hillshade.
            let (sin, cos) = LATTICE_TURNS[k as usize];
            let turn = |(a, b): (f64, f64)| (cos * a - sin * b, sin * a + cos * b);
            let (px, pz) = turn((x / lambda, z / lambda));
            let (ix, iz) = (floor(px), floor(pz));
            let cell = (ix as i64, iz as i64);
            let points = lattice.points(self.seed, k, cell);
            let g = gullies(points, px - ix, pz - iz, turn(dir));
            // Back from the lattice's frame (the inverse turn) for the derivatives.
            let (dx, dz) = (cos * g.dx + sin * g.dz, -sin * g.dx + cos * g.dz);
            height += amp * g.value;
            gx += STEER * amp * dx / lambda;
            gz += STEER * amp * dz / lambda;
        }
        Carved { height, gradient: (gx, gz) }
    }
}

/// The jittered lattice points around the cell each octave was last evaluated in (see
/// [`ErosionFilter::apply_with`]); one per thread or loop, never shared.
#[derive(Clone, Debug, Default)]
pub struct Lattice {
    /// Per octave, the points last hashed.
    octaves: [Option<Cell>; MAX_OCTAVES as usize],
}

/// The filter's seed and the cell the points are for, and the 4 × 4 points' jitters
/// (offsets in half cells, row by row from the cell's (−1, −1) neighbour).
type Cell = (u64, (i64, i64), [(f64, f64); 16]);

impl Lattice {
    /// The jitters of the 4 × 4 points around `cell` of octave `k` of the filter seeded
    /// `seed` (the octave's own seed is derived only when the points are hashed anew).
    fn points(&mut self, seed: u64, k: u32, cell: (i64, i64)) -> &[(f64, f64); 16] {
        let slot = &mut self.octaves[k as usize];
        match slot {
            Some((s, c, _)) if *s == seed && *c == cell => {}
            _ => *slot = Some((seed, cell, jitters(splitmix(seed ^ u64::from(k)), cell))),
        }
        &slot.as_ref().expect("just filled").2
    }
}

/// The jitters of the 4 × 4 lattice points around `(cx, cz)`, each in [0, 1) per axis.
fn jitters(seed: u64, (cx, cz): (i64, i64)) -> [(f64, f64); 16] {
    let mut out = [(0.0, 0.0); 16];
    for (n, (j, i)) in (-1..=2i64).flat_map(|j| (-1..=2i64).map(move |i| (j, i))).enumerate() {
        let h = splitmix(
            seed ^ (cx.wrapping_add(i) as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
                ^ (cz.wrapping_add(j) as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F),
        );
        let jx = (h >> 40) as f64 / (1u64 << 24) as f64;
        let jz = ((h >> 16) & 0xFF_FFFF) as f64 / (1u64 << 24) as f64;
        out[n] = (jx, jz);
    }
    out
}

/// One octave of gully noise and its derivatives (per unit of the octave's coordinates).
#[derive(Clone, Copy, Debug)]
struct Gully {
    value: f64,
    dx: f64,
    dz: f64,
}

/// Reach of a lattice point's weight, lattice units: every point this close to a query lies
/// in its 4×4 neighbourhood (points sit jittered by at most half a cell), and one always does.
const REACH: f64 = 1.5;

/// Gully noise at (`px`, `pz`) in lattice units: a cosine stripe through every jittered
/// lattice point whose crests run along `dir` (unit, downhill), blended over the 4×4 nearest
/// points with weights (1 − r²/[`REACH`]²)⁴ — as narrow as a Gaussian of σ = ½ near the point,
/// but exactly zero before a point leaves the neighbourhood. (A Gaussian's 1 % tail, cut off at
/// the cell lines, left steps of metres along a straight lattice there, visible in hillshades.)
/// In [−1, 1].
///
/// On processors with AVX2 the same arithmetic runs four points to an instruction: the
/// filter is the largest single cost of pre-generation. Both paths do the same IEEE operations
/// in the same order (Rust never fuses a multiply and an add), so they give the same bits.
fn gullies(points: &[(f64, f64); 16], fx: f64, fz: f64, dir: (f64, f64)) -> Gully {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the processor has just been found to support AVX2.
        return unsafe { gullies_avx2(points, fx, fz, dir) };
    }
    gullies_with(points, fx, fz, dir, sin_cos_turns)
}

/// [`gullies`] compiled for AVX2, where `floor` is an instruction.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn gullies_avx2(points: &[(f64, f64); 16], fx: f64, fz: f64, dir: (f64, f64)) -> Gully {
    gullies_with(points, fx, fz, dir, sin_cos_turns_by_floor)
}

/// [`gullies`] with `sin_cos` for [`sin_cos_turns`] (or its bit-identical twin): every step a
/// loop over the 16 points without branches, so the compiler can run points side by side in
/// vector registers.
#[inline(always)]
fn gullies_with(
    points: &[(f64, f64); 16],
    fx: f64,
    fz: f64,
    dir: (f64, f64),
    sin_cos: impl Fn(f64) -> (f64, f64),
) -> Gully {
    // Across the flow: the stripe's phase changes only in this direction.
    let across = (-dir.1, dir.0);
    let (mut phase, mut weight) = ([0.0f64; 16], [0.0f64; 16]);
    for (n, &(jx, jz)) in points.iter().enumerate() {
        let (i, j) = ((n % 4) as f64 - 1.0, (n / 4) as f64 - 1.0);
        let (ox, oz) = (fx - (i + 0.5 * jx), fz - (j + 0.5 * jz));
        let r2 = ox * ox + oz * oz;
        phase[n] = ox * across.0 + oz * across.1;
        // Beyond reach (a third of the points) the weight is exactly zero.
        let w = (1.0 - r2 / (REACH * REACH)).powi(4);
        weight[n] = if r2 < REACH * REACH { w } else { 0.0 };
    }
    let (mut sin, mut cos) = ([0.0f64; 16], [0.0f64; 16]);
    for n in 0..16 {
        (sin[n], cos[n]) = sin_cos(phase[n]);
    }
    // Summed in lattice order. A point out of reach adds a zero, which leaves every sum as
    // it was (the sums start at +0 and so are never −0).
    let (mut value, mut dx, mut dz, mut total) = (0.0, 0.0, 0.0, 0.0);
    for n in 0..16 {
        let (s, c, w) = (sin[n], cos[n], weight[n]);
        value += c * w;
        dx -= s * TAU * across.0 * w;
        dz -= s * TAU * across.1 * w;
        total += w;
    }
    Gully { value: value / total, dx: dx / total, dz: dz / total }
}

/// SplitMix64's finaliser: a well-mixed 64-bit hash of `x`.
fn splitmix(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}
