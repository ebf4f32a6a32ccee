#!/usr/bin/env python3
"""Count what is underground in a saved Java 1.20.1 world, read with amulet-core (the same
independent reader as read_world.py): ore blocks by kind with their heights, cave air under
the ground, and water under the ground of land columns away from the sea.

Usage:
    python census.py WORLD_DIR CX0 CZ0 CX1 CZ1      (chunks CX0..=CX1, CZ0..=CZ1)

stdout: one JSON object::

    {"chunks": 64,
     "ores": {"coal_ore": {"blocks": 812, "min_y": 3, "max_y": 61}, ...},
     "below_ground": 1234567,       # blocks under the top ground block of every column
     "cave_air": 12345,             # air (or cave air) among them
     "lava": 321,                   # lava among them
     "land_columns_away_from_sea": 900,
     "water_below_ground_away_from_sea": 0}

A column's ground is its highest block that is not air, water, ice, a plant, a log or leaves;
"away from the sea" means no column within 4 blocks has water or ice on top.
"""

import json
import logging
import os
import sys
import tempfile

os.environ.setdefault("CACHE_DIR", os.path.join(tempfile.gettempdir(), "amulet_read_world", "cache"))
os.environ.setdefault("LOG_DIR", os.path.join(tempfile.gettempdir(), "amulet_read_world", "log"))

import numpy as np  # noqa: E402

DIMENSION = "minecraft:overworld"
AIR = {"air", "cave_air", "void_air"}
WATERY = {"water", "ice"}
NOT_GROUND = AIR | WATERY | {
    "grass", "tall_grass", "fern", "large_fern", "dead_bush", "cactus", "sunflower", "lilac", "rose_bush", "peony",
    "dandelion", "poppy", "blue_orchid", "allium", "azure_bluet", "red_tulip", "orange_tulip", "white_tulip",
    "pink_tulip", "oxeye_daisy", "cornflower", "lily_of_the_valley", "pink_petals", "sweet_berry_bush",
    "brown_mushroom", "red_mushroom", "bamboo", "azalea", "flowering_azalea", "snow", "vine", "cocoa"}
SEA_REACH = 4


def fail(message, code=2):
    sys.stderr.write(message + "\n")
    sys.exit(code)


def java_names(level, chunk):
    """The Java 1.20.1 base name of every entry of the chunk's (universal) block palette."""
    target = level.translation_manager.get_version("java", (1, 20, 1)).block
    names = []
    for ublock in chunk.block_palette:
        try:
            block = target.from_universal(ublock)[0]
            names.append(block.base_name)
        except Exception:  # an untranslatable entry: keep its universal name
            names.append(ublock.base_name)
    return names


def column_blocks(level, cx, cz, min_y, max_y):
    """(names[y, z, x] as palette indices, names list) for one chunk, y from min_y."""
    chunk = level.get_chunk(cx, cz, DIMENSION)
    names = java_names(level, chunk)
    height = max_y - min_y
    grid = np.zeros((height, 16, 16), dtype=np.int64)
    for cy in range(min_y // 16, max_y // 16):
        if cy in chunk.blocks.sub_chunks:
            sub = np.asarray(chunk.blocks.get_sub_chunk(cy))  # [x, y, z]
            y0 = cy * 16 - min_y
            grid[y0:y0 + 16] = np.transpose(sub, (1, 2, 0))
        else:
            air = names.index("air") if "air" in names else 0
            grid[cy * 16 - min_y:cy * 16 - min_y + 16] = air
    return grid, names


def main(argv):
    if len(argv) != 6:
        fail("usage: census.py WORLD_DIR CX0 CZ0 CX1 CZ1", 1)
    world_dir = argv[1]
    cx0, cz0, cx1, cz1 = map(int, argv[2:])
    logging.disable(logging.INFO)
    import amulet

    level = amulet.load_level(world_dir)
    try:
        min_y, max_y = -64, 320
        height = max_y - min_y
        nx, nz = (cx1 - cx0 + 1) * 16, (cz1 - cz0 + 1) * 16
        # Names of every block of the area, as small integer codes into one shared list.
        codes = {}
        area = np.zeros((height, nz, nx), dtype=np.int32)
        for cz in range(cz0, cz1 + 1):
            for cx in range(cx0, cx1 + 1):
                grid, names = column_blocks(level, cx, cz, min_y, max_y)
                lut = np.array([codes.setdefault(n, len(codes)) for n in names], dtype=np.int32)
                area[:, (cz - cz0) * 16:(cz - cz0) * 16 + 16, (cx - cx0) * 16:(cx - cx0) * 16 + 16] = lut[grid]
    finally:
        level.close()
    names = sorted(codes, key=codes.get)
    is_in = lambda group: np.isin(area, [codes[n] for n in group if n in codes])  # noqa: E731
    # Trees stand on the ground; they are not it (nor is the air under their crowns).
    trees = {n for n in codes if n.endswith(("_log", "_leaves", "_mushroom_block")) or n in ("mangrove_roots", "mushroom_stem")}
    not_ground = is_in(NOT_GROUND | trees)
    # Ground: the highest block of each column that is neither in NOT_GROUND nor a tree.
    ground = np.full((nz, nx), -1)
    for y in range(height):
        ground[~not_ground[y]] = y
    top = np.take_along_axis(area, np.clip(ground, 0, None)[None], axis=0)[0]
    # Water or ice on top of the column (the first non-air block from above).
    first = np.argmax(~is_in(AIR)[::-1], axis=0)
    top_any = np.take_along_axis(area[::-1], first[None], axis=0)[0]
    sea = np.isin(top_any, [codes[n] for n in WATERY if n in codes])
    near_sea = np.zeros_like(sea)
    for dz in range(-SEA_REACH, SEA_REACH + 1):
        for dx in range(-SEA_REACH, SEA_REACH + 1):
            near_sea |= np.roll(np.roll(sea, dz, axis=0), dx, axis=1)
    # Edge columns see wrapped neighbours with np.roll: leave a margin out.
    inner = np.zeros_like(sea)
    inner[SEA_REACH:-SEA_REACH, SEA_REACH:-SEA_REACH] = True
    land_away = inner & ~near_sea & (ground >= 0)
    ys = np.arange(height)[:, None, None]
    below = ys < ground[None]
    air = is_in(AIR) & below
    lava = is_in({"lava"}) & below
    water = is_in(WATERY) & below & land_away[None]
    ores = {}
    for name in names:
        if name.endswith("_ore"):
            where = np.nonzero(area == codes[name])[0]
            ores[name] = {"blocks": int(where.size), "min_y": int(where.min()) + min_y,
                          "max_y": int(where.max()) + min_y}
    for name in ("granite", "diorite", "andesite", "tuff", "gravel", "dirt"):
        if name in codes:
            ores.setdefault(name, {"blocks": int((area == codes[name]).sum())})
    out = {
        "chunks": (cx1 - cx0 + 1) * (cz1 - cz0 + 1),
        "ores": ores,
        "below_ground": int(below.sum()),
        "cave_air": int(air.sum()),
        "lava": int(lava.sum()),
        "land_columns_away_from_sea": int(land_away.sum()),
        "water_below_ground_away_from_sea": int(water.sum()),
        "top_blocks": sorted({names[c] for c in np.unique(top)}),
    }
    json.dump(out, sys.stdout)
    sys.stdout.write("\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
