//! A small radix-2 FFT: spectra of 256² tiles and fBm synthesis need nothing more, and a
//! dependency for it would cost more build time than these lines.

use std::f64::consts::TAU;

/// A complex number `(re, im)`.
pub type Complex = (f64, f64);

/// In-place forward DFT `X[k] = Σ x[n]·e^(−2πi·kn/N)` (unnormalised); `inverse` uses
/// `e^(+2πi·kn/N)` and divides by N. Panics unless the length is a power of two (callers
/// crop to one).
pub fn fft(x: &mut [Complex], inverse: bool) {
    let n = x.len();
    assert!(n.is_power_of_two(), "FFT length {n} is not a power of two");
    // Bit-reversal permutation, then iterative butterflies.
    let mut j = 0;
    for i in 1..n {
        let mut bit = n >> 1;
        while j & bit != 0 {
            j ^= bit;
            bit >>= 1;
        }
        j |= bit;
        if i < j {
            x.swap(i, j);
        }
    }
    let sign = if inverse { 1.0 } else { -1.0 };
    let mut len = 2;
    while len <= n {
        let angle = sign * TAU / len as f64;
        for start in (0..n).step_by(len) {
            for k in 0..len / 2 {
                let (s, c) = (angle * k as f64).sin_cos();
                let (a, b) = (x[start + k], x[start + k + len / 2]);
                let t = (b.0 * c - b.1 * s, b.0 * s + b.1 * c);
                x[start + k] = (a.0 + t.0, a.1 + t.1);
                x[start + k + len / 2] = (a.0 - t.0, a.1 - t.1);
            }
        }
        len <<= 1;
    }
    if inverse {
        let inv = 1.0 / n as f64;
        x.iter_mut().for_each(|v| *v = (v.0 * inv, v.1 * inv));
    }
}

/// 2-D FFT of a row-major `rows × cols` array in place (rows, then columns).
pub fn fft2(x: &mut [Complex], rows: usize, cols: usize, inverse: bool) {
    assert_eq!(x.len(), rows * cols);
    for row in x.chunks_exact_mut(cols) {
        fft(row, inverse);
    }
    let mut column = vec![(0.0, 0.0); rows];
    for c in 0..cols {
        for r in 0..rows {
            column[r] = x[r * cols + c];
        }
        fft(&mut column, inverse);
        for r in 0..rows {
            x[r * cols + c] = column[r];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn naive_dft(x: &[Complex]) -> Vec<Complex> {
        let n = x.len();
        (0..n)
            .map(|k| {
                x.iter().enumerate().fold((0.0, 0.0), |acc, (i, v)| {
                    let (s, c) = (-TAU * (k * i) as f64 / n as f64).sin_cos();
                    (acc.0 + v.0 * c - v.1 * s, acc.1 + v.0 * s + v.1 * c)
                })
            })
            .collect()
    }

    #[test]
    fn fft_matches_the_naive_dft_and_inverts() {
        let x: Vec<Complex> = (0..32).map(|i| (((i * 7919) % 13) as f64 - 6.0, ((i * 31) % 5) as f64)).collect();
        let mut y = x.clone();
        fft(&mut y, false);
        for (a, b) in y.iter().zip(naive_dft(&x)) {
            assert!((a.0 - b.0).abs() < 1e-9 && (a.1 - b.1).abs() < 1e-9, "{a:?} vs {b:?}");
        }
        fft(&mut y, true);
        for (a, b) in y.iter().zip(&x) {
            assert!((a.0 - b.0).abs() < 1e-12 && (a.1 - b.1).abs() < 1e-12);
        }
    }

    #[test]
    fn fft2_of_a_single_frequency_is_one_peak() {
        let (rows, cols) = (8, 16);
        let mut x: Vec<Complex> = (0..rows * cols)
            .map(|i| ((TAU * (2.0 * (i / cols) as f64 / 8.0 + 3.0 * (i % cols) as f64 / 16.0)).cos(), 0.0))
            .collect();
        fft2(&mut x, rows, cols, false);
        let big: Vec<usize> = (0..x.len()).filter(|&i| x[i].0.hypot(x[i].1) > 1e-6).collect();
        // cos splits into +k and −k: (2, 3) and (6, 13).
        assert_eq!(big, vec![2 * cols + 3, 6 * cols + 13]);
    }
}
