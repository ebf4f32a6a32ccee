//! Deterministic per-position randomness for surface details and trees: a pure function of
//! (world seed, purpose, global coordinates), so chunks agree across borders whatever order
//! they are built in.

use crate::terrain::noise::floor;

/// A well-mixed 64-bit hash of the seed, a purpose tag and a position (SplitMix64 finaliser).
pub fn hash3(seed: u64, salt: u64, x: i64, y: i64, z: i64) -> u64 {
    let mut h = seed ^ salt.wrapping_mul(0x9E37_79B9_7F4A_7C15);
    for v in [x, y, z] {
        h = mix(h ^ (v as u64).wrapping_mul(0xD6E8_FEB8_6659_FD93));
    }
    h
}

/// A value in `[0, 1)` from [`hash3`].
pub fn unit3(seed: u64, salt: u64, x: i64, y: i64, z: i64) -> f32 {
    (hash3(seed, salt, x, y, z) >> 40) as f32 / (1u64 << 24) as f32
}

/// Smooth value noise in `[0, 1)` over the (x, z) plane with features about `scale` blocks
/// wide: bilinear between hashed lattice points, smoothstepped so patches have soft edges.
pub fn value_noise(seed: u64, salt: u64, x: i64, z: i64, scale: i64) -> f32 {
    let (cx, cz) = (x.div_euclid(scale), z.div_euclid(scale));
    let fx = smooth(x.rem_euclid(scale) as f32 / scale as f32);
    let fz = smooth(z.rem_euclid(scale) as f32 / scale as f32);
    // [`unit3`] of the four corners (at y = 0), sharing the hash's x and y steps between the
    // corners of one x: 8 mixes instead of 12, the same bits.
    let base = seed ^ salt.wrapping_mul(0x9E37_79B9_7F4A_7C15);
    let step = |h: u64, v: i64| mix(h ^ (v as u64).wrapping_mul(0xD6E8_FEB8_6659_FD93));
    let unit = |h: u64| (h >> 40) as f32 / (1u64 << 24) as f32;
    let (h0, h1) = (step(step(base, cx), 0), step(step(base, cx + 1), 0));
    let (a00, a10, a01, a11) = (unit(step(h0, cz)), unit(step(h1, cz)), unit(step(h0, cz + 1)), unit(step(h1, cz + 1)));
    let top = a00 + (a10 - a00) * fx;
    let bottom = a01 + (a11 - a01) * fx;
    top + (bottom - top) * fz
}

fn smooth(t: f32) -> f32 {
    t * t * (3.0 - 2.0 * t)
}

fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Smooth value noise in `[0, 1)` over 3-D space, in lattice units (a feature per unit):
/// trilinear between hashed lattice points, smoothstepped. For caves, sampled on a coarse
/// lattice and interpolated between.
pub fn value_noise3(seed: u64, salt: u64, x: f64, y: f64, z: f64) -> f32 {
    // `floor` by conversion: `f64::floor` is a libm call on the baseline x86-64 target.
    let (ix, iy, iz) = (floor(x), floor(y), floor(z));
    let (fx, fy, fz) = (smooth((x - ix) as f32), smooth((y - iy) as f32), smooth((z - iz) as f32));
    let (ix, iy, iz) = (ix as i64, iy as i64, iz as i64);
    // [`unit3`] of the eight corners, sharing the hash's steps: it mixes in x, then y, then z,
    // so the two x values need two mixes, the four (x, y) pairs four and the corners eight —
    // 14 mixes instead of 24, the same bits.
    let base = seed ^ salt.wrapping_mul(0x9E37_79B9_7F4A_7C15);
    let step = |h: u64, v: i64| mix(h ^ (v as u64).wrapping_mul(0xD6E8_FEB8_6659_FD93));
    let unit = |h: u64| (h >> 40) as f32 / (1u64 << 24) as f32;
    let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
    let (hx0, hx1) = (step(base, ix), step(base, ix + 1));
    let plane = |dy: i64| {
        let (h0, h1) = (step(hx0, iy + dy), step(hx1, iy + dy));
        let near = lerp(unit(step(h0, iz)), unit(step(h1, iz)), fx);
        let far = lerp(unit(step(h0, iz + 1)), unit(step(h1, iz + 1)), fx);
        lerp(near, far, fz)
    };
    lerp(plane(0), plane(1), fy)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hashes_depend_on_every_input() {
        let base = hash3(1, 2, 3, 4, 5);
        assert_eq!(base, hash3(1, 2, 3, 4, 5));
        for other in [hash3(9, 2, 3, 4, 5), hash3(1, 9, 3, 4, 5), hash3(1, 2, 9, 4, 5), hash3(1, 2, 3, 9, 5)] {
            assert_ne!(base, other);
        }
        assert_ne!(hash3(1, 2, 3, 4, 5), hash3(1, 2, 3, 4, -5));
    }

    #[test]
    fn unit_values_cover_the_interval_evenly() {
        let n = 10_000;
        let values: Vec<f32> = (0..n).map(|i| unit3(7, 0, i, 0, -i)).collect();
        assert!(values.iter().all(|v| (0.0..1.0).contains(v)));
        let mean = values.iter().sum::<f32>() / n as f32;
        assert!((mean - 0.5).abs() < 0.02, "mean {mean}");
    }

    #[test]
    fn value_noise3_interpolates_the_hashed_corners() {
        // The corners by `unit3` itself, interpolated as the noise documents.
        let plain = |x: f64, y: f64, z: f64| {
            let (ix, iy, iz) = (x.floor(), y.floor(), z.floor());
            let (fx, fy, fz) = (smooth((x - ix) as f32), smooth((y - iy) as f32), smooth((z - iz) as f32));
            let (ix, iy, iz) = (ix as i64, iy as i64, iz as i64);
            let at = |dx: i64, dy: i64, dz: i64| unit3(5, 9, ix + dx, iy + dy, iz + dz);
            let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
            let plane = |dy: i64| lerp(lerp(at(0, dy, 0), at(1, dy, 0), fx), lerp(at(0, dy, 1), at(1, dy, 1), fx), fz);
            lerp(plane(0), plane(1), fy)
        };
        for i in -50..50 {
            let (x, y, z) = (i as f64 * 0.37, -(i as f64) * 1.13 + 0.5, i as f64 * i as f64 * 0.011 - 7.0);
            assert_eq!(value_noise3(5, 9, x, y, z).to_bits(), plain(x, y, z).to_bits(), "({x}, {y}, {z})");
        }
    }

    #[test]
    fn value_noise_interpolates_the_hashed_corners() {
        for (x, z) in [(0i64, 0i64), (-1, 7), (33, -65), (-1000, 999), (17, 16)] {
            let scale = 8;
            let (cx, cz) = (x.div_euclid(scale), z.div_euclid(scale));
            let fx = smooth(x.rem_euclid(scale) as f32 / scale as f32);
            let fz = smooth(z.rem_euclid(scale) as f32 / scale as f32);
            let at = |dx: i64, dz: i64| unit3(4, 6, cx + dx, 0, cz + dz);
            let top = at(0, 0) + (at(1, 0) - at(0, 0)) * fx;
            let bottom = at(0, 1) + (at(1, 1) - at(0, 1)) * fx;
            assert_eq!(value_noise(4, 6, x, z, scale).to_bits(), (top + (bottom - top) * fz).to_bits(), "({x}, {z})");
        }
    }

    #[test]
    fn value_noise_is_continuous_across_lattice_cells() {
        for x in -40..40 {
            let a = value_noise(3, 1, x, 5, 8);
            let b = value_noise(3, 1, x + 1, 5, 8);
            assert!((a - b).abs() < 0.3, "jump at {x}: {a} → {b}");
            assert!((0.0..1.0).contains(&a));
        }
    }
}
