#!/usr/bin/env python3
"""One real square region, larger than a training tile, for side-by-side pictures and
evaluation: GLOBE land + ETOPO5 sea (the core set's recipe), sampled on the region's own
local sinusoidal projection (square, equal-area pixels; see geo.py).

    python3 scripts/data/region.py --lat 40 --lon 75 --size 1024 --metres 1000 \
        --out data/regions/pamir_1km.npy [--data-dir data]

Writes OUT (float32 metres, row 0 north) and its sidecar OUT with `.json` (metres_per_pixel,
tile, count = 1: a stack of one tile, which `infiniterra eval` and `infiniterra train core
--counterpart` read). The default place (40°N 75°E: Pamir, Tien Shan, Tarim basin) lies in
the core set's held-out band (60–90°E): the model never saw it.
"""

import argparse
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import DataError, ensure_pydeps, main_guard  # noqa: E402


def region(data_dir, lat, lon, size, metres):
    ensure_pydeps(data_dir)
    import numpy as np

    import sources
    from geo import tile_coords

    extracted = os.path.join(data_dir, "raw", "extracted")
    globe, etopo = sources.globe(extracted), sources.etopo5(extracted)
    lats, lons = tile_coords(lat, lon, size, metres)
    if not globe.contains(lats, lons):
        raise DataError(f"a {size}×{size} region of {metres:.0f} m at {lat}°N {lon}°E leaves GLOBE tile G "
                        "(0–50°N, 0–90°E)")
    half = size * metres / 2 / 111_000 + 1
    mask = sources.LandMask(extracted).crop(lat + half, lat - half, float(lons.min()) - 1, float(lons.max()) + 1)
    land = mask.sample(lats, lons, metres) >= 0.5
    sea = np.minimum(etopo.sample(lats, lons, metres), -1.0)
    return np.where(land, globe.sample(lats, lons, metres), sea).astype(np.float32)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--lat", type=float, default=40.0, help="centre latitude, degrees north")
    p.add_argument("--lon", type=float, default=75.0, help="centre longitude, degrees east")
    p.add_argument("--size", type=int, default=1024, help="side in pixels")
    p.add_argument("--metres", type=float, default=1000.0, help="pixel size")
    p.add_argument("--out", default="data/regions/pamir_1km.npy")
    p.add_argument("--data-dir", default="data", help="holds raw/ (from `infiniterra data fetch`)")
    a = p.parse_args()
    if a.size < 64 or a.size % 64:
        raise DataError(f"--size {a.size} must be a positive multiple of 64")
    elev = region(a.data_dir, a.lat, a.lon, a.size, a.metres)
    import numpy as np

    os.makedirs(os.path.dirname(os.path.abspath(a.out)), exist_ok=True)
    np.save(a.out, elev)
    side = {"metres_per_pixel": a.metres, "tile": a.size, "count": 1, "lat": a.lat, "lon": a.lon,
            "source": "GLOBE 30\" tile G land, ETOPO5 sea (scripts/data/region.py)"}
    with open(os.path.splitext(a.out)[0] + ".json", "w", encoding="utf-8") as f:
        json.dump(side, f, indent=1)
    print(f"wrote {a.out}: {a.size}×{a.size} at {a.metres:.0f} m, {elev.min():.0f}..{elev.max():.0f} m")


if __name__ == "__main__":
    main_guard(main)
