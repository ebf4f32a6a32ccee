//! The CPU inference path of the networks' convolutions.
//!
//! burn's pure-Rust backend convolves by converting to channels-last, gathering an im2col
//! matrix element by element (with a bounds check per element) and scattering the GEMM's
//! result back; on the stages' small images that bookkeeping cost about as much as the
//! multiply–adds themselves. Here a `k × k` "same" convolution is one GEMM per band of
//! output rows whose right-hand side is assembled from **contiguous runs**: the input is
//! zero-padded once (applying the block's SiLU and per-channel modulation on the way, so
//! those element-wise passes disappear too), and in the padded layout every kernel tap is
//! the same plane shifted by a constant offset, so each (tap, channel) row of the band is a
//! single `memcpy`. Outputs are computed in the padded row stride and the two padding
//! columns per row dropped when the band is copied out.
//!
//! Every output element is a fixed-order sum whatever thread computes its band, so results
//! are bit-identical across thread counts. Used only on plain (not autodiff) flex tensors;
//! training and wgpu keep burn's kernels.

use burn::tensor::{Device, Tensor, TensorData};
use rayon::prelude::*;

/// E[silu(x)²]^½ for x ~ N(0, 1): dividing by it keeps unit magnitude (EDM2's constant).
/// Defined here, at the bottom of the model's layers, because both this kernel's fused SiLU
/// and the layers' `mp_silu` divide by it.
pub(super) const SILU_MAGNITUDE: f32 = 0.596;

/// Output positions (in the padded row stride) per GEMM: the band's right-hand side,
/// `k²·c_in` rows of this many floats, stays within L2.
const BAND: usize = 256;

/// What is applied to the input before it is convolved.
#[derive(Clone, Copy, Debug)]
pub enum Pre<'a> {
    /// The input as it is.
    Identity,
    /// `silu(x · s) / 0.596` (EDM2's magnitude-preserving SiLU), with `s` one factor per
    /// (image, channel), row-major `[batch, c_in]`, or 1 when `None`.
    Silu(Option<&'a [f32]>),
}

/// Whether this module's kernels apply to convolving `x` with `weight`: both plain f32 flex
/// (CPU) tensors. An autodiff tensor — or an untracked input meeting tracked weights, as in
/// training — keeps burn's kernels, which record the graph.
pub fn applies(x: &Tensor<4>, weight: &Tensor<4>) -> bool {
    plain(x) && plain(weight)
}

/// Whether a tensor is a plain (not autodiff) f32 tensor on burn's flex CPU backend, whose
/// values this module may compute on the host.
pub fn plain<const D: usize>(t: &Tensor<D>) -> bool {
    !t.is_autodiff() && t.device() == Device::flex() && t.dtype() == burn::tensor::DType::F32
}

/// `x · wᵀ` for plain tensors `x` (`[b, in]`) and `w` (`[out, in]`), every output a dot
/// product summed in the same order whatever the batch: burn's matmul picks its kernel by
/// shape, so the same row could come out a rounding step apart in a batch of 1 and one of 8 —
/// and the engine batches windows differently depending on what a query finds cached.
pub fn linear(x: Tensor<2>, w: Tensor<2>) -> Tensor<2> {
    let device = x.device();
    let [b, cin] = x.dims();
    let [cout, win] = w.dims();
    assert_eq!(cin, win, "linear: {cin} inputs for a [{cout}, {win}] weight");
    let x: Vec<f32> = x.into_data().try_into_vec().expect("linear: f32 input");
    let w: Vec<f32> = w.into_data().try_into_vec().expect("linear: f32 weight");
    let out: Vec<f32> = x
        .chunks(cin)
        .flat_map(|row| w.chunks(cin).map(move |col| row.iter().zip(col).fold(0.0f32, |acc, (a, b)| acc + a * b)))
        .collect();
    Tensor::from_data(TensorData::new(out, [b, cout]), &device)
}

/// `conv2d(pre(x), weight)` with "same" zero padding, stride 1, no bias, for a plain flex
/// tensor `x` (`[b, c_in, h, w]`) and kernel `weight` (`[c_out, c_in, k, k]`, k odd).
pub fn conv_same(x: Tensor<4>, weight: Tensor<4>, pre: Pre) -> Tensor<4> {
    let device = x.device();
    let shape = x.dims();
    let [cout, cin, k, kw] = weight.dims();
    assert!(k == kw && k % 2 == 1 && cin == shape[1], "conv_same: kernel {:?} for input {shape:?}", weight.dims());
    let x: Vec<f32> = x.into_data().try_into_vec().expect("conv_same: f32 input");
    let w: Vec<f32> = weight.into_data().try_into_vec().expect("conv_same: f32 kernel");
    let out = convolve(&x, shape, &w, cout, k, pre);
    Tensor::from_data(TensorData::new(out, [shape[0], cout, shape[2], shape[3]]), &device)
}

/// The kernel on host slices: `x` is `[b, c_in, h, w]`, `w` is `[c_out, c_in, k, k]`;
/// returns `[b, c_out, h, w]`.
pub fn convolve(x: &[f32], [b, cin, h, w]: [usize; 4], weight: &[f32], cout: usize, k: usize, pre: Pre) -> Vec<f32> {
    assert_eq!(x.len(), b * cin * h * w, "convolve: input length");
    assert_eq!(weight.len(), cout * cin * k * k, "convolve: kernel length");
    if let Pre::Silu(Some(s)) = pre {
        assert_eq!(s.len(), b * cin, "convolve: one modulation factor per image and channel");
    }
    let pad = k / 2;
    let (ph, pw) = (h + 2 * pad, w + 2 * pad);
    let plane = ph * pw;
    let taps = k * k;
    let depth = taps * cin;

    // The input once, padded and activated: planes of `ph × pw`, zero borders.
    let mut padded = vec![0.0f32; b * cin * plane];
    padded.par_chunks_mut(plane).zip(x.par_chunks(h * w)).enumerate().for_each(|(bc, (dst, src))| {
        let scale = match pre {
            Pre::Silu(Some(s)) => s[bc],
            _ => 1.0,
        };
        for (y, row) in src.chunks(w).enumerate() {
            let out = &mut dst[(y + pad) * pw + pad..(y + pad) * pw + pad + w];
            match pre {
                Pre::Identity => out.copy_from_slice(row),
                Pre::Silu(_) => {
                    for (o, &v) in out.iter_mut().zip(row) {
                        let v = v * scale;
                        *o = v / (1.0 + (-v).exp()) / SILU_MAGNITUDE;
                    }
                }
            }
        }
    });

    // The kernel as `[c_out, (tap, c_in)]`, matching the band's row order.
    let mut lhs = vec![0.0f32; cout * depth];
    for co in 0..cout {
        for ci in 0..cin {
            for tap in 0..taps {
                lhs[co * depth + tap * cin + ci] = weight[(co * cin + ci) * taps + tap];
            }
        }
    }

    // Output position q (padded stride) reads padded[q + dy·pw + dx]; the last valid output
    // is q = (h−1)·pw + w − 1, and stopping there keeps every read inside the plane.
    let positions = h * pw - 2 * pad;
    let rows_per_band = BAND.div_ceil(pw).max(1);
    let bands: Vec<(usize, usize)> = (0..b).flat_map(|i| (0..h).step_by(rows_per_band).map(move |y| (i, y))).collect();
    let results: Vec<Vec<f32>> = bands
        .par_iter()
        .map(|&(img, y0)| {
            let y1 = (y0 + rows_per_band).min(h);
            let q0 = y0 * pw;
            let n = (y1 * pw).min(positions) - q0;
            SCRATCH.with_borrow_mut(|rhs| {
                // Every row is written below: the buffer is only grown, never cleared (zeroing
                // it for each band cost as much as copying the rows in).
                if rhs.len() < depth * n {
                    rhs.resize(depth * n, 0.0);
                }
                for tap in 0..taps {
                    let off = (tap / k) * pw + tap % k;
                    for ci in 0..cin {
                        let src = (img * cin + ci) * plane + q0 + off;
                        let row = (tap * cin + ci) * n;
                        rhs[row..row + n].copy_from_slice(&padded[src..src + n]);
                    }
                }
                let mut dst = Vec::with_capacity(cout * n);
                // SAFETY: dst has capacity cout × n (row stride n), lhs is cout × depth (row
                // stride depth), rhs at least depth × n (row stride n), all contiguous. With
                // `read_dst` false the GEMM writes every element of dst without reading it, so
                // its length is set only once all of it is initialised.
                unsafe {
                    gemm::gemm(
                        cout,
                        n,
                        depth,
                        dst.as_mut_ptr(),
                        1,
                        n as isize,
                        false,
                        lhs.as_ptr(),
                        1,
                        depth as isize,
                        rhs.as_ptr(),
                        1,
                        n as isize,
                        0.0,
                        1.0,
                        false,
                        false,
                        false,
                        gemm::Parallelism::None,
                    );
                    dst.set_len(cout * n);
                }
                dst
            })
        })
        .collect();

    let mut out = Vec::with_capacity(b * cout * h * w);
    // Bands in order: image, then rows; within a band each output channel's rows. The
    // output is `[b, c_out, h, w]`, so an image's channels interleave the bands' rows.
    let per_image = h.div_ceil(rows_per_band);
    for (img, image_bands) in results.chunks(per_image).enumerate() {
        debug_assert!(bands[img * per_image].0 == img);
        for co in 0..cout {
            for (band, dst) in image_bands.iter().enumerate() {
                let y0 = band * rows_per_band;
                let y1 = (y0 + rows_per_band).min(h);
                let n = dst.len() / cout;
                for y in y0..y1 {
                    let src = co * n + (y - y0) * pw;
                    out.extend_from_slice(&dst[src..src + w]);
                }
            }
        }
    }
    debug_assert_eq!(out.len(), b * cout * h * w);
    out
}

thread_local! {
    /// Each thread's im2col buffer, reused from band to band and call to call.
    static SCRATCH: std::cell::RefCell<Vec<f32>> = const { std::cell::RefCell::new(Vec::new()) };
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::rng::HostRng;
    use burn::tensor::module::conv2d;
    use burn::tensor::ops::ConvOptions;

    fn reference(x: &[f32], shape: [usize; 4], w: &[f32], cout: usize, k: usize) -> Vec<f32> {
        let device = Device::flex();
        let xt = Tensor::<4>::from_data(TensorData::new(x.to_vec(), shape), &device);
        let wt = Tensor::<4>::from_data(TensorData::new(w.to_vec(), [cout, shape[1], k, k]), &device);
        let pad = k / 2;
        let y = conv2d(xt, wt, None, ConvOptions::new([1, 1], [pad, pad], [1, 1], 1));
        y.into_data().try_into_vec().unwrap()
    }

    fn max_diff(a: &[f32], b: &[f32]) -> f32 {
        assert_eq!(a.len(), b.len());
        a.iter().zip(b).map(|(p, q)| (p - q).abs()).fold(0.0, f32::max)
    }

    #[test]
    fn matches_burns_convolution_for_every_kernel_size_and_shape() {
        let mut rng = HostRng::keyed(7, 1, 2, 3);
        // Odd sizes, more than one band, batch > 1, a single row, 1×1 and 5×5 kernels.
        for &(b, cin, cout, h, w, k) in
            &[(2, 3, 5, 9, 7, 3), (1, 8, 16, 40, 33, 3), (3, 4, 2, 1, 12, 3), (2, 6, 3, 10, 11, 1), (1, 2, 4, 12, 9, 5)]
        {
            let x = rng.normals(b * cin * h * w);
            let wt = rng.normals(cout * cin * k * k);
            let ours = convolve(&x, [b, cin, h, w], &wt, cout, k, Pre::Identity);
            let theirs = reference(&x, [b, cin, h, w], &wt, cout, k);
            let d = max_diff(&ours, &theirs);
            assert!(d < 1e-4, "b{b} cin{cin} cout{cout} {h}×{w} k{k}: max difference {d}");
        }
    }

    #[test]
    fn fuses_the_modulated_silu_into_the_padding() {
        let mut rng = HostRng::keyed(8, 1, 2, 3);
        let (b, cin, cout, h, w) = (2, 5, 4, 13, 17);
        let x = rng.normals(b * cin * h * w);
        let wt = rng.normals(cout * cin * 9);
        let scale: Vec<f32> = (0..b * cin).map(|i| 0.5 + i as f32 * 0.1).collect();
        let activated: Vec<f32> = x
            .iter()
            .enumerate()
            .map(|(i, &v)| {
                let v = v * scale[i / (h * w)];
                v / (1.0 + (-v).exp()) / SILU_MAGNITUDE
            })
            .collect();
        let ours = convolve(&x, [b, cin, h, w], &wt, cout, 3, Pre::Silu(Some(&scale)));
        let theirs = reference(&activated, [b, cin, h, w], &wt, cout, 3);
        assert!(max_diff(&ours, &theirs) < 1e-4);
        // Padding is applied after the activation: silu(0) = 0, so borders stay zero either way,
        // but a wrong order would show as soon as the scale is not 1.
        let plain = convolve(&x, [b, cin, h, w], &wt, cout, 3, Pre::Silu(None));
        assert!(max_diff(&plain, &ours) > 1e-3, "the modulation must change the result");
    }

    #[test]
    fn is_bit_identical_whatever_the_thread_count() {
        let mut rng = HostRng::keyed(9, 1, 2, 3);
        let (b, cin, cout, h, w) = (3, 16, 24, 32, 32);
        let x = rng.normals(b * cin * h * w);
        let wt = rng.normals(cout * cin * 9);
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| convolve(&x, [b, cin, h, w], &wt, cout, 3, Pre::Silu(None)))
        };
        let one = run(1);
        assert_eq!(one, run(2));
        assert_eq!(one, run(5));
    }
}
