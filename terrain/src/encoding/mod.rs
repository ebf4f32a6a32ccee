//! Encodings shared by training and inference: signed square root on elevations and the
//! Laplacian split into a low-frequency channel and a residual, with the paper's
//! "Laplacian denoising" after generation.
//!
//! Owns: array-level transforms on finite tiles. Must not touch: windows, caches, models.

mod laplacian;

pub use laplacian::{
    blur, box_downsample, laplacian_denoise, laplacian_merge, laplacian_split, lowpass, upsample_low, ContextSpec,
    BLUR_RADIUS, LAPLACIAN_FACTOR,
};

/// Signed square root, `sign(e)·√|e|`: compresses the huge range of elevations (metres)
/// so that valleys and the deep sea get a fair share of the model's precision.
pub fn signed_sqrt(e: f32) -> f32 {
    e.signum() * e.abs().sqrt()
}

/// Inverse of [`signed_sqrt`]: `sign(h)·h²`.
pub fn signed_square(h: f32) -> f32 {
    h.signum() * h * h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn signed_sqrt_round_trips() {
        for &e in &[-10_994.0f32, -4000.5, -1.0, -1e-3, 0.0, 1e-3, 0.25, 431.0, 8848.86] {
            let back = signed_square(signed_sqrt(e));
            assert!((back - e).abs() <= e.abs() * 2e-7 + 1e-9, "{e} -> {back}");
        }
        assert_eq!(signed_sqrt(-9.0), -3.0);
        assert_eq!(signed_sqrt(0.0), 0.0);
    }
}
