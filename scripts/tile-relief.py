#!/usr/bin/env python3
"""Where a block-grid export's slope distribution differs from a real set's, tile by tile
(docs/experiments.md, "More detail on flat land"): the export is resampled to the set's
metres per pixel as `eval` does it (Gaussian anti-alias, then bilinear with pixel centres
aligned), cut into the set's tiles, and set beside the real tiles (both splits) on

- the radial power spectrum, ring by ring (generated ÷ real),
- slope percentiles (central differences over two pixels, as `eval`),
- the tiles' elevation spread and mean slope, and the steepest and flattest tiles.

    PYTHONPATH=data/pydeps python3 scripts/tile-relief.py EXPORT.npy METRES_PER_BLOCK [SET]

SET defaults to data/prepared/fine-kossou-93m. numpy and scipy come with `infiniterra data
fetch` (data/pydeps).
"""

import json
import os
import sys

import numpy as np
from scipy.ndimage import gaussian_filter, map_coordinates


def resample(a, src_m, dst_m):
    f = dst_m / src_m
    if f > 2:
        a = gaussian_filter(a, (f - 1) / 2, mode="nearest")
    rows, cols = int(a.shape[0] / f), int(a.shape[1] / f)
    y = (np.arange(rows) + 0.5) * f - 0.5
    x = (np.arange(cols) + 0.5) * f - 0.5
    yy, xx = np.meshgrid(y, x, indexing="ij")
    return map_coordinates(a, [yy, xx], order=1, mode="nearest")


def tiles(a, n):
    return np.array([a[i:i + n, j:j + n] for i in range(0, a.shape[0] - n + 1, n)
                     for j in range(0, a.shape[1] - n + 1, n)])


def slopes(t, metres):
    gx = (t[:, 1:-1, 2:] - t[:, 1:-1, :-2]) / (2 * metres)
    gy = (t[:, 2:, 1:-1] - t[:, :-2, 1:-1]) / (2 * metres)
    return np.degrees(np.arctan(np.hypot(gx, gy)))


def radial(ts):
    """Mean power per ring of plane-detrended, Hann-windowed tiles, m² per bin."""
    n = ts.shape[-1]
    w = np.outer(np.hanning(n), np.hanning(n))
    ring = np.rint(np.hypot(np.fft.fftfreq(n)[:, None], np.fft.fftfreq(n)[None, :]) * n).astype(int)
    yy, xx = np.mgrid[0:n, 0:n]
    plane = np.c_[xx.ravel(), yy.ravel(), np.ones(n * n)]
    acc, cnt = np.zeros(n), np.zeros(n)
    for t in ts:
        c = np.linalg.lstsq(plane, t.ravel(), rcond=None)[0]
        p = np.abs(np.fft.fft2((t - (plane @ c).reshape(n, n)) * w)) ** 2 / (n * n) / (w ** 2).mean()
        np.add.at(acc, ring.ravel(), p.ravel())
        np.add.at(cnt, ring.ravel(), 1)
    return acc / np.maximum(cnt, 1)


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    export, block_m = sys.argv[1], float(sys.argv[2])
    ref = sys.argv[3] if len(sys.argv) == 4 else "data/prepared/fine-kossou-93m"
    with open(os.path.join(ref, "manifest.json")) as f:
        manifest = json.load(f)
    metres, n = float(manifest["metres_per_pixel"]), int(manifest["tile"])
    real = np.concatenate([np.load(os.path.join(ref, f"{s}.npy")).reshape(-1, n, n)
                           for s in ("train", "heldout")]).astype(np.float64)
    gen = tiles(resample(np.load(export).astype(np.float64), block_m, metres), n)
    pg, pr = radial(gen), radial(real)
    print(f"{len(gen)} generated tiles against {len(real)} real ({n} px of {metres:g} m)")
    print("ring  wavelength  generated ÷ real power")
    for k in sorted({2, 4, 6, 8, 12, 16, 20, 24, n // 2}):
        print(f"{k:4d} {n * metres / k:8.0f} m  {pg[k] / pr[k]:6.2f}")
    sg, sr = slopes(gen, metres), slopes(real, metres)
    q = [10, 25, 50, 75, 90, 99]
    print("slope percentiles", q)
    print("  generated", np.round(np.percentile(sg, q), 2))
    print("  real     ", np.round(np.percentile(sr, q), 2))
    u = np.linspace(0.0005, 0.9995, 2000)
    print(f"slope W1 ≈ {np.mean(np.abs(np.quantile(sg, u) - np.quantile(sr, u))):.3f}°")
    for name, t, s in (("generated", gen, sg), ("real", real, sr)):
        sd, mean = t.std(axis=(1, 2)), s.mean(axis=(1, 2))
        print(f"{name}: tile elevation sd, percentiles 0/10/50/90/100: {np.round(np.percentile(sd, [0, 10, 50, 90, 100]), 1)} m")
        print(f"{name}: tile mean slope, same percentiles: {np.round(np.percentile(mean, [0, 10, 50, 90, 100]), 2)}°")


if __name__ == "__main__":
    main()
