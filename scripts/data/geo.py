"""Geographic grids and square-metre tiles.

Every source is a regular latitude/longitude grid whose pixels are not square on the
ground (E–W spacing shrinks with cos(latitude)). A tile is sampled on its own local
sinusoidal projection centred on the tile: row i lies at latitude lat_c + y/R and column j
at longitude lon_c + x/(R·cos(lat)), with x, y the pixel centre's offset in metres. Pixels
are then square (s × s metres) and equal-area; the shear of the meridians is at most
atan(Δλ·sin φ) ≈ 1° at a tile's E–W edge for 256 km tiles, and tiles never straddle the
central meridian of a larger projection, so nothing distorts with distance.

Sampling is bilinear after a Gaussian anti-alias blur of the source with
σ = max(0, (f − 1)/2) source pixels per axis, f being the downsampling factor along that axis
at the tile's latitude (the convention of scikit-image's `resize`).
"""

import math

import numpy as np
from scipy import ndimage

EARTH_RADIUS_M = 6_371_008.8


class GeoGrid:
    """A lat/lon raster: `data[row, col]` is the value at the pixel centre
    (lat0 + row·dlat, lon0 + col·dlon)."""

    def __init__(self, data, lat0, dlat, lon0, dlon):
        self.data, self.lat0, self.dlat, self.lon0, self.dlon = data, lat0, dlat, lon0, dlon

    def wrapped(self, pad_deg):
        """A global grid extended by `pad_deg` of longitude on both sides (copied from the
        other side), so tiles near the antimeridian sample without special cases."""
        pad = int(math.ceil(pad_deg / abs(self.dlon)))
        data = np.concatenate([self.data[:, -pad:], self.data, self.data[:, :pad]], axis=1)
        return GeoGrid(data, self.lat0, self.dlat, self.lon0 - pad * self.dlon, self.dlon)

    def rows_cols(self, lat, lon):
        """Fractional pixel indices of (lat, lon) in degrees."""
        return (lat - self.lat0) / self.dlat, (lon - self.lon0) / self.dlon

    def contains(self, lat, lon):
        """True when every point lies within the grid's pixel centres (no extrapolation)."""
        r, c = self.rows_cols(lat, lon)
        return bool(r.min() >= 0 and c.min() >= 0 and r.max() <= self.data.shape[0] - 1
                    and c.max() <= self.data.shape[1] - 1)

    def sample(self, lat, lon, metres):
        """Bilinear values at (lat, lon) arrays for target pixels of `metres`, anti-aliased."""
        r, c = self.rows_cols(lat, lon)
        pad = 8
        r0 = max(int(math.floor(r.min())) - pad, 0)
        r1 = min(int(math.ceil(r.max())) + pad + 1, self.data.shape[0])
        c0 = max(int(math.floor(c.min())) - pad, 0)
        c1 = min(int(math.ceil(c.max())) + pad + 1, self.data.shape[1])
        window = self.data[r0:r1, c0:c1].astype(np.float32)
        row_m = abs(self.dlat) * math.pi / 180 * EARTH_RADIUS_M
        col_m = abs(self.dlon) * math.pi / 180 * EARTH_RADIUS_M * math.cos(math.radians(float(np.mean(lat))))
        sigma = [max(0.0, (metres / row_m - 1) / 2), max(0.0, (metres / col_m - 1) / 2)]
        if max(sigma) > 0.05:
            window = ndimage.gaussian_filter(window, sigma, mode="nearest")
        return ndimage.map_coordinates(window, [r - r0, c - c0], order=1, mode="nearest")


def tile_coords(lat_c, lon_c, size, metres):
    """(lat, lon) in degrees of the pixel centres of a size×size tile of `metres` pixels
    centred on (lat_c, lon_c); row 0 is the northern edge, column 0 the western."""
    offsets = (np.arange(size) - (size - 1) / 2) * metres
    y = -offsets[:, None]
    x = offsets[None, :]
    lat = lat_c + np.degrees(y / EARTH_RADIUS_M) + 0 * x
    lon = lon_c + np.degrees(x / (EARTH_RADIUS_M * np.cos(np.radians(lat))))
    return lat, lon


def tile_centres(lat_top, lat_bottom, lon_west, lon_east, size, metres, overlap=1):
    """Tile centres covering a lat/lon box row by row from the north, `overlap` tiles per
    tile side (1 = edge to edge, 2 = half-tile stride). In a row, tiles are spaced by their
    width at the poleward edge, the widest, so neighbours never overlap unless asked.
    Returns (lat, lon, row, column) per tile, row 0 north, column 0 west."""
    extent = size * metres
    dlat = math.degrees(extent / EARTH_RADIUS_M)
    centres = []
    lat_c = lat_top - dlat / 2
    row = 0
    while lat_c - dlat / 2 >= lat_bottom:
        poleward = min(abs(lat_c) + dlat / 2, 89.0)
        dlon = math.degrees(extent / (EARTH_RADIUS_M * math.cos(math.radians(poleward))))
        lon_c = lon_west + dlon / 2
        col = 0
        while lon_c + dlon / 2 <= lon_east:
            centres.append((lat_c, lon_c, row, col))
            lon_c += dlon / overlap
            col += 1
        lat_c -= dlat / overlap
        row += 1
    return centres
