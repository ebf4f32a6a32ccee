#!/usr/bin/env python3
"""Read blocks and biomes from a Minecraft Java (1.20.1) Anvil world with amulet-core.

This is an *independent* reader used by the Rust integration tests: the world is
written by our generator and decoded here by a third-party library, so both the
region/NBT encoding and the block/biome naming are checked against an outside
implementation.

Usage:
    python read_world.py WORLD_DIR < positions.json

stdin:  a JSON array of block positions ``[[x, y, z], ...]``.
stdout: one JSON object::

    {
      "platform": "java",
      "data_version": 3465,
      "version": [1, 20, 1],
      "positions": [
        {"x": 0, "y": -64, "z": 0,
         "block": "minecraft:bedrock",
         "biome": "minecraft:plains",
         "raw_block": "minecraft:bedrock",
         "raw_biome": "minecraft:plains"},
        {"x": 5, "y": 70, "z": 9, "error": "chunk (0, 0) does not exist"},
        ...
      ]
    }

``block`` uses Java 1.20.1's own naming: ``namespace:name`` followed by the
properties sorted by key, ``[k=v,k2=v2]``, or no brackets when the block has no
properties.  ``biome`` is the Java 1.20.1 biome id of the 4x4x4 biome cell that
contains the block.  Both go through amulet's translation (Java -> universal ->
Java 1.20.1), which fills in defaults for missing properties (a stored
``minecraft:oak_log`` reads back as ``minecraft:oak_log[axis=y]``) and passes
unknown blocks through unchanged (with a warning on stderr).

``raw_block`` / ``raw_biome`` are the palette entries exactly as stored on disk
(decoded from the raw section NBT, no translation, no defaults, same string
format); they are omitted and ``raw_error`` is set if the raw data cannot be
decoded (e.g. a packed array of the wrong length).

A missing/unreadable chunk yields an ``error`` entry for
that position only.  If the world cannot be opened at all the script prints a
message on stderr and exits with status 2 (status 1 for bad input).

Requires amulet-core (tested with 1.9.50, PyMCTranslate 1.2.52, amulet-nbt 2.1.8).
"""

import json
import os
import sys
import tempfile

# amulet creates cache/log directories on import; keep them out of $HOME.
os.environ.setdefault(
    "CACHE_DIR", os.path.join(tempfile.gettempdir(), "amulet_read_world", "cache")
)
os.environ.setdefault(
    "LOG_DIR", os.path.join(tempfile.gettempdir(), "amulet_read_world", "log")
)

import logging  # noqa: E402

DIMENSION = "minecraft:overworld"
TARGET_PLATFORM = "java"
TARGET_VERSION = (1, 20, 1)


def fail(message, code=2):
    print(f"read_world.py: {message}", file=sys.stderr)
    sys.exit(code)


def tag_to_str(value):
    """Convert an amulet-nbt property tag (normally StringTag) to a plain string."""
    py_str = getattr(value, "py_str", None)
    if isinstance(py_str, str):
        return py_str
    py_data = getattr(value, "py_data", value)
    if isinstance(py_data, bool):
        return "true" if py_data else "false"
    return str(py_data)


def format_block(block):
    """Java blockstate string: ns:name[k=v,...] with keys sorted, extra layers dropped."""
    name = f"{block.namespace}:{block.base_name}"
    props = block.properties
    if not props:
        return name
    inner = ",".join(f"{k}={tag_to_str(props[k])}" for k in sorted(props))
    return f"{name}[{inner}]"


def unpack_index(container, index, size, bits, palette_len):
    """Palette index `index` of a 1.16+ (non-spanning) packed long array.

    A palette of one entry has no `data` (all zeros).  Validates the array length.
    """
    if palette_len == 0:
        raise ValueError("empty palette")
    if bits == 0 or "data" not in container:
        if palette_len != 1:
            raise ValueError(f"palette of {palette_len} entries without data")
        return 0
    longs = container["data"].np_array
    per_long = 64 // bits
    expected = -(-size // per_long)
    if len(longs) != expected:
        raise ValueError(
            f"packed array has {len(longs)} longs, expected {expected} ({bits} bits)"
        )
    word = int(longs[index // per_long]) & 0xFFFFFFFFFFFFFFFF
    value = (word >> ((index % per_long) * bits)) & ((1 << bits) - 1)
    if value >= palette_len:
        raise ValueError(f"palette index {value} out of range ({palette_len})")
    return value


class Reader:
    def __init__(self, level):
        self.level = level
        self.tm = level.translation_manager
        self.target = self.tm.get_version(TARGET_PLATFORM, TARGET_VERSION)
        self.block_tr = self.target.block
        self.biome_tr = self.target.biome
        self._chunks = {}

    # -- chunk access -----------------------------------------------------
    def chunk(self, cx, cz):
        """Return (chunk, None) or (None, error string); cached per run."""
        from amulet.api.errors import ChunkDoesNotExist

        key = (cx, cz)
        if key not in self._chunks:
            try:
                self._chunks[key] = (self.level.get_chunk(cx, cz, DIMENSION), None)
            except ChunkDoesNotExist:
                self._chunks[key] = (None, f"chunk ({cx}, {cz}) does not exist")
            except Exception as e:  # ChunkLoadError, ...
                kind = type(e).__name__
                self._chunks[key] = (
                    None,
                    f"chunk ({cx}, {cz}) could not be loaded: {kind}: {e}",
                )
        return self._chunks[key]

    def universal_block_at(self, x, y, z):
        chunk, _ = self.chunk(x >> 4, z >> 4)
        if chunk is None:
            from amulet.api.block import UniversalAirBlock

            return UniversalAirBlock, None
        return (
            chunk.get_block(x & 15, y, z & 15),
            chunk.block_entities.get((x, y, z)),
        )

    # -- blocks -----------------------------------------------------------
    def java_block(self, chunk, x, y, z):
        """Translate the universal block at (x, y, z) to Java 1.20.1.

        Mirrors amulet's own save path (Translator._blocks_entities_from_universal
        + JavaBlockstateTranslator._pack_block_palette): every layer of the
        universal block is translated; translations that ask for neighbour
        context are redone with a callback; a water extra layer becomes
        ``waterlogged=true`` (amulet strips the waterlogged property on load).
        """
        from amulet.api.block import Block

        ublock = chunk.get_block(x & 15, y, z & 15)
        block_entity = chunk.block_entities.get((x, y, z))
        result = None
        for depth, layer in enumerate(ublock.block_tuple):
            be = block_entity if depth == 0 else None

            def callback(rel, _layer=layer, _depth=depth):
                if tuple(rel) == (0, 0, 0):
                    return _layer, (block_entity if _depth == 0 else None)
                dx, dy, dz = rel
                return self.universal_block_at(x + dx, y + dy, z + dz)

            out, _, extra = self.block_tr.from_universal(
                layer, be, block_location=(x, y, z)
            )
            if extra:
                out, _, _ = self.block_tr.from_universal(
                    layer, be, block_location=(x, y, z), get_block_callback=callback
                )
            if not isinstance(out, Block):
                # translated to an entity (e.g. item frames): not a block
                continue
            result = out if result is None else result + out

        if result is None:
            return "minecraft:air"

        base = result.base_block
        if self.block_tr.is_waterloggable(base.namespaced_name):
            props = dict(base.properties)
            extra_blocks = result.extra_blocks
            from amulet_nbt import StringTag

            waterlogged = bool(extra_blocks) and (
                extra_blocks[0].namespaced_name == "minecraft:water"
            )
            props["waterlogged"] = StringTag("true" if waterlogged else "false")
            base = Block(base.namespace, base.base_name, props)
        return format_block(base)

    # -- biomes -----------------------------------------------------------
    def java_biome(self, chunk, x, y, z):
        """Java biome id of the 4x4x4 cell containing (x, y, z).

        amulet stores 1.18+ biomes as Biomes3D: one (4, 4, 4) uint32 array per
        16-block section, indexed [x, y, z] (the anvil decoder transposes the
        on-disk y,z,x order), with values indexing chunk.biome_palette, which
        holds *universal* biome names.
        """
        from amulet.api.chunk.biomes import BiomesShape

        biomes = chunk.biomes
        if biomes.dimension == BiomesShape.Shape3D:
            sy = y >> 4
            if sy not in biomes.sections:
                raise LookupError(f"no biome data for section {sy}")
            section = biomes.get_section(sy)
            idx = int(section[(x >> 2) & 3, (y >> 2) & 3, (z >> 2) & 3])
        elif biomes.dimension == BiomesShape.Shape2D:
            idx = int(biomes[x & 15, z & 15])
        else:
            raise LookupError("chunk has no biome data")
        universal = chunk.biome_palette[idx]
        return self.biome_tr.from_universal(universal)

    # -- raw on-disk data ---------------------------------------------------
    def raw_sections(self, cx, cz):
        """{section_y: section CompoundTag} straight from the region file (no translation)."""
        key = ("raw", cx, cz)
        if key not in self._chunks:
            raw = self.level.level_wrapper.get_raw_chunk_data(cx, cz, DIMENSION)
            sections = {}
            root = raw.compound
            for section in (root["sections"] if "sections" in root else []):
                sections[int(section["Y"].py_int)] = section
            self._chunks[key] = sections
        return self._chunks[key]

    def raw_block(self, x, y, z):
        """The block exactly as stored in the section palette (properties NOT defaulted)."""
        section = self.raw_sections(x >> 4, z >> 4).get(y >> 4)
        if section is None or "block_states" not in section:
            return "minecraft:air"  # absent section reads as air in vanilla
        states = section["block_states"]
        palette = states["palette"]
        index = (y & 15) * 256 + (z & 15) * 16 + (x & 15)
        bits = max(4, (len(palette) - 1).bit_length())
        entry = palette[unpack_index(states, index, 4096, bits, len(palette))]
        name = entry["Name"].py_str
        props = entry.get("Properties")
        if not props:
            return name
        inner = ",".join(f"{k}={tag_to_str(props[k])}" for k in sorted(props.keys()))
        return f"{name}[{inner}]"

    def raw_biome(self, x, y, z):
        """The biome id exactly as stored in the section's biome palette."""
        section = self.raw_sections(x >> 4, z >> 4).get(y >> 4)
        if section is None or "biomes" not in section:
            raise LookupError(f"no biome data for section {y >> 4}")
        biomes = section["biomes"]
        palette = biomes["palette"]
        index = ((y >> 2) & 3) * 16 + ((z >> 2) & 3) * 4 + ((x >> 2) & 3)
        bits = (len(palette) - 1).bit_length()
        return palette[unpack_index(biomes, index, 64, bits, len(palette))].py_str

    # -- one position -----------------------------------------------------
    def read(self, x, y, z):
        entry = {"x": x, "y": y, "z": z}
        chunk, err = self.chunk(x >> 4, z >> 4)
        if chunk is None:
            entry["error"] = err
            return entry
        try:
            entry["block"] = self.java_block(chunk, x, y, z)
        except Exception as e:
            entry["error"] = f"block read failed: {type(e).__name__}: {e}"
            return entry
        try:
            entry["biome"] = self.java_biome(chunk, x, y, z)
        except Exception as e:
            entry["error"] = f"biome read failed: {type(e).__name__}: {e}"
        try:
            entry["raw_block"] = self.raw_block(x, y, z)
            entry["raw_biome"] = self.raw_biome(x, y, z)
        except Exception as e:
            entry["raw_error"] = f"{type(e).__name__}: {e}"
        return entry


def parse_positions(text):
    try:
        data = json.loads(text)
    except json.JSONDecodeError as e:
        fail(f"stdin is not valid JSON: {e}", 1)
    if not isinstance(data, list):
        fail("stdin must be a JSON array of [x, y, z] positions", 1)
    positions = []
    for item in data:
        if (
            not isinstance(item, (list, tuple))
            or len(item) != 3
            or not all(isinstance(v, int) and not isinstance(v, bool) for v in item)
        ):
            fail(f"bad position {item!r}: expected [x, y, z] integers", 1)
        positions.append(tuple(item))
    return positions


def main(argv):
    if len(argv) != 2:
        fail("usage: read_world.py WORLD_DIR < positions.json", 1)
    world_dir = argv[1]
    positions = parse_positions(sys.stdin.read())

    if not os.path.isfile(os.path.join(world_dir, "level.dat")):
        fail(f"cannot open world {world_dir!r}: no level.dat")

    # amulet logs (INFO) to stderr; keep stdout clean for the JSON result.
    logging.disable(logging.INFO)
    try:
        import amulet
    except ImportError as e:
        fail(f"amulet-core is not installed: {e}")

    try:
        level = amulet.load_level(world_dir)
    except Exception as e:
        fail(f"cannot open world {world_dir!r}: {type(e).__name__}: {e}")

    try:
        wrapper = level.level_wrapper
        platform = wrapper.platform
        data_version = wrapper.version
        try:
            version = list(
                level.translation_manager.get_version(
                    platform, data_version
                ).version_number
            )
        except Exception:
            version = None
        reader = Reader(level)
        out = {
            "platform": platform,
            "data_version": data_version,
            "version": version,
            "positions": [reader.read(x, y, z) for (x, y, z) in positions],
        }
    finally:
        level.close()

    json.dump(out, sys.stdout)
    sys.stdout.write("\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
