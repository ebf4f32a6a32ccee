#!/usr/bin/env python3
"""A diagnostic split of a stage's TRAINING tiles, to tell "the model is far from real terrain"
apart from "the held-out region is unlike the training region".

    python3 scripts/data/in_distribution.py --stage core --every 8 --out data/in_distribution

Writes OUT/STAGE/ in the layout of data/prepared/STAGE/: `heldout.npy` is every EVERY-th
training tile (spread over the whole training area), `train.npy` the others, each with its
land mask and sidecar. Then

    cargo run --release -- train core --data data/in_distribution --generate-heldout data/in_dist_core.npy --tiles 40
    cargo run --release -- eval --generated data/in_dist_core.npy --reference data/in_distribution/core

measures the model on terrain like the terrain it learned from, with a real-vs-real floor
from the remaining training tiles. The model has seen these tiles (as random crops), so this
is NOT a held-out result: it bounds what the held-out evaluation can show, nothing more.
"""

import argparse
import json
import os
import shutil
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import DataError, ensure_pydeps, main_guard  # noqa: E402

TILE = 256


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--stage", default="core")
    p.add_argument("--every", type=int, default=8, help="every N-th training tile becomes 'held-out'")
    p.add_argument("--prepared", default="data/prepared", help="output of `infiniterra data prepare`")
    p.add_argument("--out", default="data/in_distribution")
    p.add_argument("--data-dir", default="data", help="holds pydeps/")
    a = p.parse_args()
    ensure_pydeps(a.data_dir)
    import numpy as np

    src = os.path.join(a.prepared, a.stage)
    if not os.path.exists(os.path.join(src, "train.npy")):
        raise DataError(f"{src}/train.npy is missing: run `infiniterra data fetch` and `infiniterra data prepare`")
    if a.every < 2:
        raise DataError(f"--every {a.every} must be at least 2")
    heights = np.load(os.path.join(src, "train.npy"), mmap_mode="r")
    land = np.load(os.path.join(src, "train_land.npy"), mmap_mode="r")
    n = heights.shape[0] // TILE
    picked = list(range(a.every // 2, n, a.every))
    rest = [i for i in range(n) if i not in set(picked)]

    def stack(arr, idx):
        return np.concatenate([arr[i * TILE:(i + 1) * TILE] for i in idx])

    dst = os.path.join(a.out, a.stage)
    os.makedirs(dst, exist_ok=True)
    with open(os.path.join(src, "train.json"), encoding="utf-8") as f:
        side = json.load(f)
    for split, idx in (("heldout", picked), ("train", rest)):
        np.save(os.path.join(dst, f"{split}.npy"), stack(heights, idx))
        np.save(os.path.join(dst, f"{split}_land.npy"), stack(land, idx))
        meta = dict(side, split=split, count=len(idx),
                    note=f"diagnostic: every {a.every}-th training tile as 'held-out' (scripts/data/in_distribution.py)")
        with open(os.path.join(dst, f"{split}.json"), "w", encoding="utf-8") as f:
            json.dump(meta, f, indent=1)
    shutil.copy(os.path.join(src, "manifest.json"), dst)
    print(f"wrote {dst}: {len(picked)} 'held-out' and {len(rest)} train tiles, all from the training split")


if __name__ == "__main__":
    main_guard(main)
