"""The contact sheet: a few sample tiles of every prepared set and split, hillshaded, so a
person can see at a glance that the data is terrain (and which way is north)."""

import json
import os

import numpy as np
from PIL import Image, ImageDraw

THUMB = 128
PER_ROW = 6
LABEL_H = 14
LEFT = 110


def colour(tile, land, metres):
    """Hypsometric tint (blue sea, green→brown→white land) times a NW hillshade."""
    dy, dx = np.gradient(tile.astype(np.float64), metres)
    shade = np.clip(0.55 + 0.45 * (-dx + dy) / np.sqrt(1 + dx * dx + dy * dy) / np.sqrt(2) * 4, 0.25, 1.2)
    top = max(float(np.percentile(tile[land > 0], 99)) if land.any() else 1.0, 1.0)
    t = np.clip(tile / top, 0, 1)[..., None]
    low, mid, high = np.array([70, 140, 70.0]), np.array([150, 120, 80.0]), np.array([245, 245, 245.0])
    land_rgb = np.where(t < 0.5, low + (mid - low) * (t / 0.5), mid + (high - mid) * ((t - 0.5) / 0.5))
    depth = np.clip(-tile / 6000.0, 0, 1)[..., None]
    sea_rgb = np.array([120, 170, 220.0]) * (1 - depth) + np.array([20, 40, 110.0]) * depth
    rgb = np.where(land[..., None] > 0, land_rgb * shade[..., None], sea_rgb)
    return np.clip(rgb, 0, 255).astype(np.uint8)


def contact_sheet(root, stages, out):
    """Draws PER_ROW evenly spaced tiles of each stage × split into `out`."""
    rows = [(s["name"], split) for s in stages for split in ("train", "heldout")]
    cell_h = THUMB + LABEL_H
    sheet = Image.new("RGB", (LEFT + PER_ROW * (THUMB + 4), len(rows) * (cell_h + 6) + 4), (250, 250, 248))
    draw = ImageDraw.Draw(sheet)
    for r, (name, split) in enumerate(rows):
        folder = os.path.join(root, name)
        with open(os.path.join(folder, "manifest.json"), encoding="utf-8") as f:
            manifest = json.load(f)
        size, metres = manifest["tile"], manifest["metres_per_pixel"]
        elev = np.load(os.path.join(folder, f"{split}.npy"), mmap_mode="r").reshape(-1, size, size)
        land = np.load(os.path.join(folder, f"{split}_land.npy"), mmap_mode="r").reshape(-1, size, size)
        metas = [t for t in manifest["tiles"] if t["split"] == split]
        y = 4 + r * (cell_h + 6)
        count = manifest["splits"][split]["count"]
        draw.text((6, y + 40), f"{name}\n{split}\n{count} tiles\n{metres:.0f} m/px", fill=(0, 0, 0))
        picks = np.linspace(0, len(elev) - 1, min(PER_ROW, len(elev))).round().astype(int)
        for c, i in enumerate(picks):
            img = Image.fromarray(colour(np.asarray(elev[i]), np.asarray(land[i]), metres))
            x = LEFT + c * (THUMB + 4)
            sheet.paste(img.resize((THUMB, THUMB), Image.BILINEAR), (x, y))
            m = metas[i]
            draw.text((x, y + THUMB + 1), f"{m['lat']:.1f}N {m['lon']:.1f}E", fill=(0, 0, 0))
    tmp = out + ".tmp.png"
    sheet.save(tmp)
    os.replace(tmp, out)
