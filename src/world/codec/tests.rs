//! Codec tests: chunks survive encode → decode block by block and biome by biome, the bytes
//! follow Anvil's packing rules, and every kind of damage is reported by name.

use std::sync::Arc;
use std::time::Instant;

use valence::nbt::{Compound, List, Value};
use valence::prelude::{BiomeId, BlockState, Chunk, PropName, PropValue, UnloadedChunk};
use valence::registry::RegistryIdx;

use super::nbt::{bit_width, packed_len};
use super::*;
use crate::biome::BiomeRules;
use crate::chunkgen::{assert_same, BiomePalette, Generator, Light};
use crate::config::Config;
use crate::terrain::Pipeline;

const MIN_Y: i32 = -64;
const HEIGHT: u32 = 384;

fn palette() -> Arc<BiomePalette> {
    Arc::new(BiomePalette::vanilla())
}

fn encoder() -> Encoder {
    Encoder::new(MIN_Y, palette().names().to_vec())
}

fn decoder() -> Decoder {
    Decoder::new(MIN_Y, HEIGHT, palette())
}

fn encode(chunk: &UnloadedChunk, x: i32, z: i32) -> Vec<u8> {
    encoder().encode(x, z, chunk, Some(&Light::of(chunk)))
}

fn parse(bytes: &[u8]) -> Compound {
    let mut slice = bytes;
    match Compound::from_binary(&mut slice) {
        Ok((root, name)) => {
            assert_eq!(name, "");
            assert!(slice.is_empty(), "{} bytes after the root compound", slice.len());
            root
        }
        Err(e) => panic!("the encoder wrote bad NBT: {e}"),
    }
}

fn unparse(root: &Compound) -> Vec<u8> {
    let mut bytes = Vec::new();
    if let Err(e) = root.to_binary(&mut bytes, "") {
        panic!("cannot write NBT: {e}");
    }
    bytes
}

fn sections(root: &mut Compound) -> &mut Vec<Compound> {
    match root.get_mut("sections") {
        Some(Value::List(List::Compound(s))) => s,
        other => panic!("sections is {other:?}"),
    }
}

/// The section with `Y` = `y`.
fn section(root: &mut Compound, y: i8) -> &mut Compound {
    match sections(root).iter_mut().find(|s| s.get("Y") == Some(&Value::Byte(y))) {
        Some(s) => s,
        None => panic!("no section Y {y}"),
    }
}

fn sub<'a>(c: &'a mut Compound, key: &str) -> &'a mut Compound {
    match c.get_mut(key) {
        Some(Value::Compound(v)) => v,
        other => panic!("{key} is {other:?}"),
    }
}

fn decode_ok(bytes: &[u8], x: i32, z: i32) -> UnloadedChunk {
    match decoder().decode(x, z, bytes) {
        Ok(chunk) => chunk,
        Err(e) => panic!("decode failed: {e}"),
    }
}

fn decode_err(bytes: &[u8], x: i32, z: i32) -> String {
    match decoder().decode(x, z, bytes) {
        Ok(_) => panic!("damaged chunk decoded"),
        Err(e) => e.to_string(),
    }
}

/// Ground, water, snow, logs and plants over a few sections, biomes varying per cell.
fn varied_chunk() -> UnloadedChunk {
    let mut chunk = UnloadedChunk::with_height(HEIGHT);
    chunk.fill_block_state_section(0, BlockState::DEEPSLATE);
    chunk.fill_block_state_section(1, BlockState::STONE);
    let snow = [1, 2, 3, 5, 8].map(|n| BlockState::SNOW.set(PropName::Layers, PropValue::from_u16(n).unwrap()));
    for z in 0..16 {
        for x in 0..16 {
            chunk.set_block_state(x, 0, z, BlockState::BEDROCK);
            for y in 32..60 + x {
                chunk.set_block_state(x, y, z, if y % 7 == 0 { BlockState::GRANITE } else { BlockState::STONE });
            }
            let top = 60 + x;
            if z < 5 {
                for y in top..70 {
                    chunk.set_block_state(x, y, z, BlockState::WATER);
                }
            } else {
                chunk.set_block_state(x, top, z, BlockState::DIRT);
                chunk.set_block_state(x, top + 1, z, BlockState::GRASS_BLOCK.set(PropName::Snowy, PropValue::True));
                chunk.set_block_state(x, top + 2, z, snow[((x + z) % 5) as usize]);
            }
        }
    }
    let log_x = BlockState::OAK_LOG.set(PropName::Axis, PropValue::X);
    for x in 2..9 {
        chunk.set_block_state(x, 90, 10, log_x);
    }
    chunk.set_block_state(3, 91, 12, BlockState::GRASS);
    chunk.set_block_state(4, 91, 12, BlockState::OAK_LEAVES.set(PropName::Distance, PropValue::_3));
    chunk.set_block_state(15, 383, 15, BlockState::GLASS);
    let names = palette();
    let biomes =
        ["minecraft:plains", "minecraft:ocean", "minecraft:snowy_plains", "minecraft:forest"].map(|n| names.id(n));
    for y in 0..HEIGHT / 4 {
        for z in 0..4 {
            for x in 0..4 {
                let b = if (8..24).contains(&y) { biomes[((x + 2 * z + y) % 4) as usize] } else { biomes[0] };
                chunk.set_biome(x, y, z, b);
            }
        }
    }
    chunk
}

#[test]
fn a_varied_chunk_round_trips() {
    let chunk = varied_chunk();
    assert_eq!(chunk.block_state(5, 90, 10), BlockState::OAK_LOG.set(PropName::Axis, PropValue::X));
    let back = decode_ok(&encode(&chunk, 3, -7), 3, -7);
    assert_same(&chunk, &back);
}

#[test]
fn the_header_and_light_are_as_vanilla_writes_them() {
    let chunk = varied_chunk();
    let light = Light::of(&chunk);
    let mut root = parse(&encoder().encode(3, -7, &chunk, Some(&light)));
    assert_eq!(root.get("DataVersion"), Some(&Value::Int(3465)));
    assert_eq!(root.get("xPos"), Some(&Value::Int(3)));
    assert_eq!(root.get("zPos"), Some(&Value::Int(-7)));
    assert_eq!(root.get("yPos"), Some(&Value::Int(-4)));
    assert_eq!(root.get("Status"), Some(&Value::String("minecraft:full".into())));
    assert_eq!(root.get("isLightOn"), Some(&Value::Byte(1)));
    assert!(matches!(root.get("block_entities"), Some(Value::List(l)) if l.is_empty()));
    let ys: Vec<_> = sections(&mut root).iter().map(|s| s.get("Y").cloned()).collect();
    // Below the world is dark (no section); above it is open sky.
    assert_eq!(ys, (-4..=20).map(|y| Some(Value::Byte(y))).collect::<Vec<_>>());
    for (i, s) in sections(&mut root).iter().enumerate() {
        let expected = light.sky_bytes(i + 1).map(|b| b.iter().map(|&v| v as i8).collect::<Vec<_>>());
        let found = match s.get("SkyLight") {
            Some(Value::ByteArray(b)) => Some(b.clone()),
            None => None,
            other => panic!("SkyLight is {other:?}"),
        };
        assert_eq!(found, expected, "sky light of section {i}");
    }
    assert!(section(&mut root, 20).get("block_states").is_none(), "the section above holds light only");
    assert!(section(&mut root, -4).get("SkyLight").is_none(), "the floor section is dark");
    assert!(sections(&mut root).iter().all(|s| s.get("BlockLight").is_none()), "nothing glows");
    // Block light where something does: lava at chunk-local Y 20, section Y −3.
    let mut glowing = varied_chunk();
    glowing.set_block_state(4, 20, 4, BlockState::LAVA);
    let light = Light::of(&glowing);
    let mut root = parse(&encoder().encode(3, -7, &glowing, Some(&light)));
    let lit: Vec<i8> = light.block_bytes(2).expect("the lava's section is lit").iter().map(|&v| v as i8).collect();
    assert_eq!(section(&mut root, -3).get("BlockLight"), Some(&Value::ByteArray(lit)));
    assert!(section(&mut root, 0).get("BlockLight").is_none());
}

#[test]
fn a_chunk_saved_without_light_asks_minecraft_to_light_it() {
    let chunk = varied_chunk();
    let mut root = parse(&encoder().encode(3, -7, &chunk, None));
    assert_eq!(root.get("isLightOn"), Some(&Value::Byte(0)), "Minecraft lights the chunk when it loads it");
    let ys: Vec<_> = sections(&mut root).iter().map(|s| s.get("Y").cloned()).collect();
    assert_eq!(ys, (-4..20).map(|y| Some(Value::Byte(y))).collect::<Vec<_>>(), "the world's sections only");
    assert!(sections(&mut root).iter().all(|s| s.get("SkyLight").is_none() && s.get("BlockLight").is_none()));
    let back = decode_ok(&encoder().encode(3, -7, &chunk, None), 3, -7);
    assert_same(&chunk, &back);
}

#[test]
fn uniform_sections_have_one_palette_entry_and_no_data() {
    let mut root = parse(&encode(&varied_chunk(), 0, 0));
    for (y, name) in [(-3, "minecraft:stone"), (10, "minecraft:air")] {
        let blocks = sub(section(&mut root, y), "block_states");
        assert!(blocks.get("data").is_none(), "section {y} has block data");
        let Some(Value::List(List::Compound(palette))) = blocks.get("palette") else { panic!("no palette") };
        assert_eq!(palette.len(), 1);
        assert_eq!(palette[0].get("Name"), Some(&Value::String(name.into())));
        assert!(palette[0].get("Properties").is_none());
        let biomes = sub(section(&mut root, y), "biomes");
        assert!(biomes.get("data").is_none(), "section {y} has biome data");
        assert_eq!(biomes.get("palette"), Some(&Value::List(List::String(vec!["minecraft:plains".into()]))));
    }
    // Properties are written in full for blocks that have them.
    let blocks = sub(section(&mut root, 1), "block_states");
    let Some(Value::List(List::Compound(palette))) = blocks.get("palette") else { panic!("no palette") };
    let log = palette.iter().find(|e| e.get("Name") == Some(&Value::String("minecraft:oak_log".into())));
    let Some(Value::Compound(props)) = log.and_then(|e| e.get("Properties")) else { panic!("log: {log:?}") };
    assert_eq!(props.get("axis"), Some(&Value::String("x".into())));
}

/// Section `s` holds `sizes[s]` distinct block states (raw ids from a varying base, so many
/// kinds of blocks and properties pass through) and cell biomes likewise.
fn palette_chunk(block_sizes: &[usize], biome_sizes: &[usize]) -> UnloadedChunk {
    let mut chunk = UnloadedChunk::with_height(HEIGHT);
    let max = usize::from(BlockState::max_raw());
    for (s, &n) in block_sizes.iter().enumerate() {
        let base = (s * 1931) % (max + 1 - n);
        for i in 0..4096 {
            let raw = (base + i % n) as u16;
            let Some(state) = BlockState::from_raw(raw) else { panic!("no state {raw}") };
            chunk.set_block_state((i % 16) as u32, (s * 16 + i / 256) as u32, (i / 16 % 16) as u32, state);
        }
    }
    let biomes = palette().names().len();
    for (s, &n) in biome_sizes.iter().enumerate() {
        for i in 0..64 {
            let id = BiomeId::from_index((s * 5 + i % n) % biomes);
            chunk.set_biome((i % 4) as u32, (s * 4 + i / 16) as u32, (i / 4 % 4) as u32, id);
        }
    }
    chunk
}

#[test]
fn data_arrays_are_packed_without_spanning_longs() {
    // (distinct values, longs Anvil stores): 4096 blocks at max(4, bits) bits, 64 cells at
    // bits; e.g. 5 bits fit 12 to a long, so 4096 take ⌈4096 / 12⌉ = 342 longs.
    let blocks = [
        (1, None),
        (2, Some(256)),
        (16, Some(256)),
        (17, Some(342)),
        (32, Some(342)),
        (33, Some(410)),
        (64, Some(410)),
        (65, Some(456)),
        (128, Some(456)),
        (129, Some(512)),
        (256, Some(512)),
        (257, Some(586)),
        (512, Some(586)),
        (513, Some(683)),
        (1024, Some(683)),
        (1025, Some(820)),
        (2048, Some(820)),
        (2049, Some(820)),
        (4096, Some(820)),
    ];
    let biomes = [
        (1, None),
        (2, Some(1)),
        (3, Some(2)),
        (4, Some(2)),
        (5, Some(4)),
        (8, Some(4)),
        (9, Some(4)),
        (16, Some(4)),
        (17, Some(6)),
        (32, Some(6)),
        (33, Some(7)),
        (64, Some(7)),
    ];
    let block_sizes: Vec<usize> = blocks.iter().map(|b| b.0).collect();
    let biome_sizes: Vec<usize> = biomes.iter().map(|b| b.0).collect();
    let chunk = palette_chunk(&block_sizes, &biome_sizes);
    let bytes = encode(&chunk, 0, 0);
    assert_same(&chunk, &decode_ok(&bytes, 0, 0));
    let mut root = parse(&bytes);
    for (s, &(n, longs)) in blocks.iter().enumerate() {
        let section = sub(section(&mut root, (s as i32 - 4) as i8), "block_states");
        let Some(Value::List(List::Compound(palette))) = section.get("palette") else { panic!("no palette") };
        assert_eq!(palette.len(), n);
        let found = match section.get("data") {
            Some(Value::LongArray(d)) => Some(d.len()),
            _ => None,
        };
        assert_eq!(found, longs, "{n} block states");
        assert_eq!(longs.unwrap_or(0), if n == 1 { 0 } else { packed_len(4096, bit_width(n - 1).max(4)) });
    }
    for (s, &(n, longs)) in biomes.iter().enumerate() {
        let section = sub(section(&mut root, (s as i32 - 4) as i8), "biomes");
        let found = match section.get("data") {
            Some(Value::LongArray(d)) => Some(d.len()),
            _ => None,
        };
        assert_eq!(found, longs, "{n} biomes");
    }
}

#[test]
fn every_block_state_round_trips() {
    // 24 sections × 1006 states cover all of 1.20.1's 24 135 block states.
    let max = usize::from(BlockState::max_raw());
    let per = (max + 1).div_ceil(24);
    let mut chunk = UnloadedChunk::with_height(HEIGHT);
    for raw in 0..=max {
        let (s, i) = (raw / per, raw % per);
        let Some(state) = BlockState::from_raw(raw as u16) else { panic!("no state {raw}") };
        chunk.set_block_state((i % 16) as u32, (s * 16 + i / 256) as u32, (i / 16 % 16) as u32, state);
    }
    assert_same(&chunk, &decode_ok(&encode(&chunk, 0, 0), 0, 0));
}

#[test]
fn the_same_chunk_encodes_to_the_same_bytes() {
    let chunk = varied_chunk();
    let light = Light::of(&chunk);
    let mut reused = encoder();
    let first = reused.encode(1, 2, &chunk, Some(&light));
    let _other =
        reused.encode(0, 0, &palette_chunk(&[300, 5], &[7]), Some(&Light::of(&UnloadedChunk::with_height(HEIGHT))));
    assert_eq!(first, reused.encode(1, 2, &chunk, Some(&light)), "a reused encoder");
    assert_eq!(first, encoder().encode(1, 2, &chunk, Some(&light)), "a fresh encoder");
}

#[test]
fn a_chunk_at_another_position_is_refused() {
    let bytes = encode(&varied_chunk(), 0, 0);
    let e = decode_err(&bytes, 1, 0);
    assert!(e.contains("xPos 0") && e.contains("1, 0"), "{e}");
}

#[test]
fn another_data_version_is_refused() {
    let mut root = parse(&encode(&varied_chunk(), 0, 0));
    root.insert("DataVersion", 3700);
    let e = decode_err(&unparse(&root), 0, 0);
    assert!(e.contains("3700") && e.contains("3465"), "{e}");
}

#[test]
fn an_unknown_block_is_named() {
    let mut root = parse(&encode(&varied_chunk(), 0, 0));
    let blocks = sub(section(&mut root, 0), "block_states");
    let Some(Value::List(List::Compound(palette))) = blocks.get_mut("palette") else { panic!("no palette") };
    palette[0].insert("Name", "minecraft:not_a_block");
    let e = decode_err(&unparse(&root), 0, 0);
    assert!(e.contains("minecraft:not_a_block"), "{e}");
}

#[test]
fn unknown_properties_and_values_are_named() {
    for (key, value, named) in [("axis", "w", "\"w\""), ("colour", "x", "colour")] {
        let mut root = parse(&encode(&varied_chunk(), 0, 0));
        let blocks = sub(section(&mut root, 1), "block_states");
        let Some(Value::List(List::Compound(palette))) = blocks.get_mut("palette") else { panic!("no palette") };
        let Some(log) = palette.iter_mut().find(|e| e.get("Name") == Some(&Value::String("minecraft:oak_log".into())))
        else {
            panic!("no log")
        };
        let mut props = Compound::new();
        props.insert(key, value);
        log.insert("Properties", props);
        let e = decode_err(&unparse(&root), 0, 0);
        assert!(e.contains(named) && e.contains("oak_log"), "{e}");
    }
}

#[test]
fn a_palette_index_out_of_range_is_named() {
    let mut root = parse(&encode(&varied_chunk(), 0, 0));
    let blocks = sub(section(&mut root, 0), "block_states");
    let Some(Value::List(List::Compound(palette))) = blocks.get("palette") else { panic!("no palette") };
    assert!(palette.len() < 15, "test needs a short palette");
    let Some(Value::LongArray(data)) = blocks.get_mut("data") else { panic!("no data") };
    data[3] |= 0xF << 8; // Block 3·16 + 2 points at entry 15.
    let e = decode_err(&unparse(&root), 0, 0);
    assert!(e.contains("index 15") && e.contains("Y 0"), "{e}");
}

#[test]
fn a_data_array_of_the_wrong_length_is_named() {
    let mut root = parse(&encode(&varied_chunk(), 0, 0));
    let biomes = sub(section(&mut root, 0), "biomes");
    let Some(Value::LongArray(data)) = biomes.get_mut("data") else { panic!("no data") };
    data.push(0);
    let e = decode_err(&unparse(&root), 0, 0);
    assert!(e.contains("biome data has 3 longs, not 2"), "{e}");
}

#[test]
fn missing_sections_are_air_and_sections_outside_the_world_are_refused() {
    let mut root = parse(&encode(&varied_chunk(), 0, 0));
    sections(&mut root).retain(|s| s.get("Y") != Some(&Value::Byte(-4)));
    let chunk = decode_ok(&unparse(&root), 0, 0);
    assert_eq!(chunk.block_state(0, 5, 0), BlockState::AIR);
    assert_eq!(chunk.block_state(0, 16, 0), BlockState::STONE);

    section(&mut root, 0).insert("Y", 30i8);
    let e = decode_err(&unparse(&root), 0, 0);
    assert!(e.contains("section Y 30"), "{e}");
}

#[test]
fn truncated_or_foreign_bytes_are_not_nbt() {
    let bytes = encode(&varied_chunk(), 0, 0);
    for cut in [0, 1, 10, bytes.len() / 2, bytes.len() - 1] {
        let e = decode_err(&bytes[..cut], 0, 0);
        assert!(e.starts_with("not NBT"), "cut at {cut}: {e}");
    }
    let e = decode_err(&[0], 0, 0);
    assert!(e.contains("root tag 0"), "{e}");
}

fn rules() -> BiomeRules {
    crate::chunkgen::passes::testing::rules()
}

#[test]
fn generated_chunks_round_trip() {
    let mut config = Config::default();
    config.world.seed = 5;
    let g = Generator::new(Arc::new(Pipeline::new(5, &config.terrain())), &config);
    assert_eq!((g.vertical().min_y, g.vertical().height), (MIN_Y, HEIGHT as i32));
    let (rules, palette) = (rules(), palette());
    let mut encoder = encoder();
    let decoder = decoder();
    let chunks: Vec<_> =
        [(0, 0), (7, -3), (-20, 11)].iter().map(|&(x, z)| (x, z, g.chunk(&rules, &palette, x, z))).collect();
    let lights: Vec<_> = chunks.iter().map(|(_, _, c)| Light::of(c)).collect();
    let rounds = 20;
    let start = Instant::now();
    let mut bytes = Vec::new();
    for _ in 0..rounds {
        bytes = chunks.iter().zip(&lights).map(|((x, z, c), l)| encoder.encode(*x, *z, c, Some(l))).collect::<Vec<_>>();
    }
    let per_chunk = start.elapsed() / (rounds * chunks.len() as u32);
    eprintln!(
        "encode: {per_chunk:?} per chunk ({} bytes each on average)",
        bytes.iter().map(Vec::len).sum::<usize>() / 3
    );
    let start = Instant::now();
    for ((x, z, chunk), nbt) in chunks.iter().zip(&bytes) {
        match decoder.decode(*x, *z, nbt) {
            Ok(back) => assert_same(chunk, &back),
            Err(e) => panic!("chunk {x}, {z}: {e}"),
        }
    }
    eprintln!("decode (with comparison): {:?} per chunk", start.elapsed() / chunks.len() as u32);
}
