//! The world, pinned: every block state and biome of a few regions, hashed into one number
//! recorded here. A refactor of chunk generation must leave these numbers unchanged; a change
//! to the world must change them on purpose (and say so in its commit).
//!
//! The hash is FNV-1a (64-bit, written out below, not std's randomised hasher) over, in order:
//! for each region, for each chunk (rows of `z`, then `x`): the chunk coordinates (`i32`
//! little-endian), then for each column (`z`, then `x`) that is not masked out, every block
//! state from the floor up ([`BlockState::to_raw`], `u16` little-endian), then every biome
//! cell (`z`, `x`, then `y`) as its id's index (`u32` little-endian).
//!
//! Two numbers pin the procedural world:
//!
//! - [`OUTSIDE_SHALLOWS_HASH`], recorded before the sea fix, leaves out the shallow sea
//!   (columns whose elevation is in (−60 m, 0 m)) and every column within [`SHALLOWS_REACH`]
//!   blocks of it. Until the fix that ground lay at the water top (Y 62), dry and level with
//!   the sea; the fix sinks it one block under water, which also uproots the trees that grew
//!   there, whose crowns reached up to two blocks onto the land next to them. It proves the
//!   fix changed nothing else.
//! - [`PROCEDURAL_HASH`], recorded after the sea fix and before chunk generation became passes,
//!   hashes every column: it proves the passes build the very same world.

use std::path::Path;
use std::sync::Arc;

use valence::prelude::{Chunk, UnloadedChunk};
use valence::registry::RegistryIdx;

use super::*;
use crate::biome::BiomeRules;
use crate::terrain::Rect;

/// FNV-1a, 64-bit.
struct Fnv(u64);

impl Fnv {
    fn new() -> Fnv {
        Fnv(0xcbf2_9ce4_8422_2325)
    }

    fn bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
}

/// The shipped biome rules (`biomes/`).
fn shipped_rules() -> BiomeRules {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("biomes");
    BiomeRules::load_dir(&dir).unwrap_or_else(|e| panic!("the shipped rules must load: {e}"))
}

/// True for a shallow-sea column (elevation in (−60 m, 0 m)).
fn shallow(elevation_m: f32) -> bool {
    elevation_m < 0.0 && elevation_m > -60.0
}

/// How far the sea fix reaches from a shallow-sea column, blocks (Chebyshev): a tree rooted
/// one block away may lose its root to the new steepness, and crowns reach two blocks further
/// (less than `trees::REACH`).
const SHALLOWS_REACH: i64 = 3;

/// Hashes the `n`×`n` chunks from chunk (`cx0`, `cz0`) into `h` as the module says, leaving
/// out the columns within `mask` blocks of the shallow sea (`None`: leaving out nothing);
/// returns how many columns were left out.
fn hash_region(
    g: &Generator,
    rules: &BiomeRules,
    palette: &BiomePalette,
    (cx0, cz0): (i32, i32),
    n: i32,
    mask: Option<i64>,
    h: &mut Fnv,
) -> usize {
    let (x0, z0) = (i64::from(cx0) * CHUNK, i64::from(cz0) * CHUNK);
    let (size, m) = (i64::from(n) * CHUNK, mask.unwrap_or(0));
    let columns = Columns::query(g.pipeline(), g.vertical(), Rect::new(z0 - m, x0 - m, size + 2 * m, size + 2 * m));
    let masked = |x: i64, z: i64| {
        mask.is_some() && (-m..=m).any(|dz| (-m..=m).any(|dx| shallow(columns.elevation(x + dx, z + dz))))
    };
    let mut count = 0;
    for cz in cz0..cz0 + n {
        for cx in cx0..cx0 + n {
            let chunk = g.chunk(rules, palette, cx, cz);
            h.bytes(&cx.to_le_bytes());
            h.bytes(&cz.to_le_bytes());
            for lz in 0..16u32 {
                for lx in 0..16u32 {
                    if masked(i64::from(cx) * CHUNK + i64::from(lx), i64::from(cz) * CHUNK + i64::from(lz)) {
                        count += 1;
                        continue;
                    }
                    for y in 0..chunk.height() {
                        h.bytes(&chunk.block_state(lx, y, lz).to_raw().to_le_bytes());
                    }
                }
            }
            hash_biomes(&chunk, h);
        }
    }
    count
}

fn hash_biomes(chunk: &UnloadedChunk, h: &mut Fnv) {
    for z in 0..4 {
        for x in 0..4 {
            for y in 0..chunk.height() / 4 {
                h.bytes(&(chunk.biome(x, y, z).to_index() as u32).to_le_bytes());
            }
        }
    }
}

/// Regions of the default configuration's world (seed 1, procedural pipeline), as the chunk
/// of their north-west corner: deep sea, a coast with shallows, and mountains (at the
/// default 40 m/block; the places of the 125 m world, in the same metres).
const PROCEDURAL_REGIONS: [(i32, i32); 3] = [(0, -94), (43, 7), (-150, 225)];

/// [`hash_region`] of every region in [`PROCEDURAL_REGIONS`] (on the default configuration's
/// world with the shipped biome rules) outside the shallow sea, re-recorded when ore veins
/// took vanilla's mean block counts (granite blobs of ~685 blocks, diamond veins of ~2), and
/// again for acacias that bend and 2×2 dark oaks (trees reach 4 blocks from their trunk), and
/// again when vegetation became data (`biomes/vegetation.toml`: sixteen species by weight,
/// every plant by name) and warm seas grew coral, and again when the water's plants
/// followed the biomes' tables instead of the temperature, and for huge mushrooms, and again
/// when gentle land's erosion octaves fell off faster (`erosion::GENTLE_SLOPE`; the learned
/// mountains below, all steeper, held), and again when river courses began to wind between
/// their nodes (`hydrology::rivers::MEANDER`).
const OUTSIDE_SHALLOWS_HASH: u64 = 0x88af_4cf9_ada1_ba8a;
/// [`hash_region`] of every column of [`PROCEDURAL_REGIONS`], re-recorded as above.
const PROCEDURAL_HASH: u64 = 0xc682_dad8_e070_53ac;
/// [`hash_region`] of the first 2×2 chunks of the mountain region of [`PROCEDURAL_REGIONS`]
/// with the shipped learned core; re-recorded when the core's windows went from a half
/// overlap to a quarter (stride 32 → 48), and when river courses began to wind.
#[cfg(feature = "learned")]
const LEARNED_HASH: u64 = 0x6e42_02e0_1e55_fe57;

fn procedural_hash(mask: Option<i64>) -> (u64, usize) {
    let config = Config::default();
    let g = Generator::new(Arc::new(Pipeline::new(config.world.seed, &config.terrain())), &config);
    let (rules, palette) = (shipped_rules(), BiomePalette::vanilla());
    let mut h = Fnv::new();
    let masked =
        PROCEDURAL_REGIONS.iter().map(|&corner| hash_region(&g, &rules, &palette, corner, 6, mask, &mut h)).sum();
    (h.0, masked)
}

#[test]
fn the_procedural_world_is_the_recorded_one_outside_the_shallow_sea() {
    let (hash, masked) = procedural_hash(Some(SHALLOWS_REACH));
    assert!(masked > 3000, "only {masked} columns near the shallow sea: the coast moved");
    assert_eq!(hash, OUTSIDE_SHALLOWS_HASH, "the world changed: {hash:#018x}");
}

#[test]
fn the_procedural_world_is_the_recorded_one() {
    let (hash, _) = procedural_hash(None);
    assert_eq!(hash, PROCEDURAL_HASH, "the world changed: {hash:#018x}");
}

#[cfg(feature = "learned")]
#[test]
fn the_world_of_the_shipped_core_is_the_recorded_one() {
    let mut config = Config::default();
    config.engine.learned = vec!["core".parse().expect("a learned stage")];
    config.engine.models = Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
    let pipeline = Pipeline::build(config.world.seed, &config.terrain()).expect("the shipped core loads");
    let g = Generator::new(Arc::new(pipeline), &config);
    let (rules, palette) = (shipped_rules(), BiomePalette::vanilla());
    let mut h = Fnv::new();
    hash_region(&g, &rules, &palette, PROCEDURAL_REGIONS[2], 2, None, &mut h);
    assert_eq!(h.0, LEARNED_HASH, "the world changed: {:#018x}", h.0);
}
