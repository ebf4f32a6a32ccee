//! Water in generated chunks (issue 25): found by the terrain's own drainage network near the
//! spawn, generated chunk by chunk, and checked as a player would see it — no water face open
//! to air, no floating water, level lakes, rivers whose surface never rises downstream and
//! that reach the sea, a lake, a dry basin or the edge of the region, the river biome on
//! them, and the same blocks in any order on any number of threads.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use valence::prelude::{BlockState, Chunk, PropName, PropValue, UnloadedChunk};

use super::columns::Water;
use super::*;
use crate::biome::BiomeRules;
use crate::terrain::hydrology::{grid, Kind, CELL_METRES};
use crate::terrain::Rect;

/// Chunks per side of a checked region.
const N: i32 = 5;

fn generator() -> Generator {
    let config = Config::default();
    Generator::new(Arc::new(Pipeline::new(config.world.seed, &config.terrain())), &config)
}

fn shipped_rules() -> BiomeRules {
    BiomeRules::load_dir(&Path::new(env!("CARGO_MANIFEST_DIR")).join("biomes")).expect("the shipped rules load")
}

/// The N×N chunks (corner chunk) centred on the first network cell near the spawn that
/// satisfies `want` (searched over a square of cells around the spawn).
fn region_where(
    g: &Generator,
    rules: &BiomeRules,
    want: impl Fn(&crate::terrain::Tile, i64, i64) -> bool,
) -> (i32, i32) {
    let spawn = crate::world::find_spawn(g, rules).block;
    let block_m = g.pipeline().block_metres();
    let cell = |b: i64| ((b as f64 * block_m) / CELL_METRES).floor() as i64;
    let (cy, cx) = (cell(i64::from(spawn.z)), cell(i64::from(spawn.x)));
    let cells = Rect::new(cy - 60, cx - 60, 121, 121);
    let network = g.pipeline().network(cells);
    let mut best = None;
    for ring in 0..60i64 {
        for (dy, dx) in (-ring..=ring).flat_map(|a| (-ring..=ring).map(move |b| (a, b))) {
            if dy.abs().max(dx.abs()) == ring && want(&network, cy + dy, cx + dx) {
                best = Some((cy + dy, cx + dx));
                break;
            }
        }
        if best.is_some() {
            break;
        }
    }
    let (y, x) = best.expect("no such network cell within 60 km of the spawn");
    let chunk = |c: i64| ((((c as f64 + 0.5) * CELL_METRES / block_m) as i64).div_euclid(16) - i64::from(N / 2)) as i32;
    (chunk(x), chunk(y))
}

/// A river cell of modest discharge (so its course is a few blocks wide and crosses chunk
/// borders within the region).
fn river_region(g: &Generator, rules: &BiomeRules) -> (i32, i32) {
    region_where(g, rules, |t, y, x| {
        let q = t.get(grid::DISCHARGE, y, x);
        Kind::from_code(t.get(grid::KIND, y, x)) == Kind::Land && (2.0..50.0).contains(&q)
    })
}

/// A lake cell.
fn lake_region(g: &Generator, rules: &BiomeRules) -> (i32, i32) {
    region_where(g, rules, |t, y, x| Kind::from_code(t.get(grid::KIND, y, x)) == Kind::Lake)
}

/// The region's chunks, generated in the order given.
struct Region {
    corner: (i32, i32),
    chunks: HashMap<(i32, i32), UnloadedChunk>,
    columns: Columns,
    min_y: i32,
}

impl Region {
    fn generate(g: &Generator, rules: &BiomeRules, corner: (i32, i32), order: &[(i32, i32)]) -> Region {
        let palette = BiomePalette::vanilla();
        let chunks = order.iter().map(|&(cx, cz)| ((cx, cz), g.chunk(rules, &palette, cx, cz))).collect();
        Region {
            corner,
            chunks,
            columns: Columns::query(g.pipeline(), g.vertical(), self_rect(corner)),
            min_y: g.vertical().min_y,
        }
    }

    fn rect(&self) -> Rect {
        self_rect(self.corner)
    }

    /// The block at global (x, y, z), if inside the region.
    fn block(&self, x: i64, y: i32, z: i64) -> Option<BlockState> {
        let chunk = self.chunks.get(&(x.div_euclid(16) as i32, z.div_euclid(16) as i32))?;
        let ly = y - self.min_y;
        (ly >= 0 && (ly as u32) < chunk.height())
            .then(|| chunk.block_state(x.rem_euclid(16) as u32, ly as u32, z.rem_euclid(16) as u32))
    }

    fn each_column(&self) -> impl Iterator<Item = (i64, i64)> {
        let r = self.rect();
        (r.y0..r.y1()).flat_map(move |z| (r.x0..r.x1()).map(move |x| (x, z)))
    }
}

fn self_rect((cx, cz): (i32, i32)) -> Rect {
    Rect::new(i64::from(cz) * 16, i64::from(cx) * 16, 16 * i64::from(N), 16 * i64::from(N))
}

fn chunk_list((cx, cz): (i32, i32)) -> Vec<(i32, i32)> {
    (0..N).flat_map(|dz| (0..N).map(move |dx| (cx + dx, cz + dz))).collect()
}

const SIDES: [(i64, i64); 4] = [(1, 0), (-1, 0), (0, 1), (0, -1)];

fn is_source(b: BlockState) -> bool {
    b == BlockState::WATER
}

fn is_water(b: BlockState) -> bool {
    b.to_kind() == BlockState::WATER.to_kind() || b.get(PropName::Waterlogged) == Some(PropValue::True)
}

/// No water block has air below it; no still (source) water block has air beside it.
fn assert_water_sits_right(r: &Region) {
    let mut checked = 0;
    for (x, z) in r.each_column() {
        for y in r.min_y + 1..r.min_y + 384 {
            let Some(b) = r.block(x, y, z) else { break };
            if !is_water(b) {
                continue;
            }
            checked += 1;
            assert!(!r.block(x, y - 1, z).is_some_and(|b| b.is_air()), "water over air at ({x}, {y}, {z})");
            if is_source(b) {
                for (dx, dz) in SIDES {
                    let side = r.block(x + dx, y, z + dz);
                    assert!(
                        !side.is_some_and(|s| s.is_air()),
                        "still water open to air at ({x}, {y}, {z}) towards ({dx}, {dz})"
                    );
                }
            }
        }
    }
    assert!(checked > 100, "only {checked} water blocks");
}

/// Every river column reaches the sea, a lake, a dry basin or the region's edge through wet
/// columns whose water tops never rise: the surface is non-increasing downstream and no river
/// ends in mid-land.
fn assert_rivers_drain(r: &Region) -> usize {
    let c = &r.columns;
    let rect = r.rect();
    let inside = |x: i64, z: i64| x >= rect.x0 && x < rect.x1() && z >= rect.y0 && z < rect.y1();
    let edge = |x: i64, z: i64| x == rect.x0 || x == rect.x1() - 1 || z == rect.y0 || z == rect.y1() - 1;
    let mut drained: HashMap<(i64, i64), bool> = HashMap::new();
    let rivers: Vec<(i64, i64)> = r.each_column().filter(|&(x, z)| c.water(x, z) == Water::River).collect();
    for &(x, z) in &rivers {
        let sink = edge(x, z) || SIDES.iter().any(|&(dx, dz)| inside(x + dx, z + dz) && c.is_dry_bed(x + dx, z + dz));
        drained.insert((x, z), sink);
    }
    for (x, z) in r.each_column() {
        if matches!(c.water(x, z), Water::Sea | Water::Lake) {
            drained.insert((x, z), true);
        }
    }
    loop {
        let mut changed = false;
        for &(x, z) in &rivers {
            if drained[&(x, z)] {
                continue;
            }
            let top = c.water_top_y(x, z).unwrap();
            let out = SIDES.iter().any(|&(dx, dz)| {
                let n = (x + dx, z + dz);
                drained.get(&n).copied().unwrap_or(false) && c.water_top_y(n.0, n.1).is_some_and(|t| t <= top)
            });
            if out {
                drained.insert((x, z), true);
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    let stuck: Vec<_> = rivers.iter().filter(|p| !drained[*p]).collect();
    assert!(
        stuck.is_empty(),
        "{} of {} river columns cannot drain without climbing: {:?}",
        stuck.len(),
        rivers.len(),
        &stuck[..stuck.len().min(10)]
    );
    rivers.len()
}

/// Each lake (4-connected lake columns) has one water top.
fn assert_lakes_are_level(r: &Region) -> usize {
    let c = &r.columns;
    let mut seen: HashMap<(i64, i64), ()> = HashMap::new();
    let rect = r.rect();
    let mut lakes = 0;
    for start in r.each_column() {
        if c.water(start.0, start.1) != Water::Lake || seen.contains_key(&start) {
            continue;
        }
        lakes += 1;
        let top = c.water_top_y(start.0, start.1);
        let mut stack = vec![start];
        seen.insert(start, ());
        while let Some((x, z)) = stack.pop() {
            assert_eq!(c.water_top_y(x, z), top, "lake surface not level at ({x}, {z})");
            for (dx, dz) in SIDES {
                let n = (x + dx, z + dz);
                let inside = n.0 >= rect.x0 && n.0 < rect.x1() && n.1 >= rect.y0 && n.1 < rect.y1();
                if inside && !seen.contains_key(&n) && c.water(n.0, n.1) == Water::Lake {
                    seen.insert(n, ());
                    stack.push(n);
                }
            }
        }
    }
    lakes
}

/// Every column whose ground is under the sea's water top is water up to it.
fn assert_no_dry_sea(r: &Region, v: &Vertical) {
    for (x, z) in r.each_column() {
        let ground = r.columns.surface_y(x, z);
        for y in ground + 1..=v.water_top_y() {
            let b = r.block(x, y, z).unwrap();
            assert!(
                is_water(b) || b == BlockState::ICE || super::passes::is_sea_growth(b),
                "dry sea column at ({x}, {y}, {z}): {b:?}"
            );
        }
    }
}

#[test]
fn rivers_and_lakes_sit_right_drain_downhill_and_are_river_biomes() {
    let (g, rules) = (generator(), shipped_rules());
    let v = *g.vertical();
    let corner = river_region(&g, &rules);
    let region = Region::generate(&g, &rules, corner, &chunk_list(corner));
    assert_water_sits_right(&region);
    assert_no_dry_sea(&region, &v);
    let rivers = assert_rivers_drain(&region);
    assert!(rivers >= 30, "only {rivers} river columns around a river cell");
    // A river crosses at least one chunk border inside the region.
    let crossing = region.each_column().any(|(x, z)| {
        x.rem_euclid(16) == 15
            && region.columns.water(x, z) == Water::River
            && region.columns.water(x + 1, z) == Water::River
            || z.rem_euclid(16) == 15
                && region.columns.water(x, z) == Water::River
                && region.columns.water(x, z + 1) == Water::River
    });
    assert!(crossing, "no river crosses a chunk border");
    // The distance to a river's bank (the rules' `river_distance_m`): 0 in river water and
    // never on dry ground, growing about a block a block away.
    let block_m = g.pipeline().block_metres() as f32;
    let distance = |x: i64, z: i64| region.columns.get(crate::terrain::pipeline::channel::RIVER_DISTANCE, x, z);
    let rect = region.rect();
    for (x, z) in region.each_column() {
        let (d, water) = (distance(x, z), region.columns.water(x, z));
        assert!(water != Water::River || d == 0.0, "river column ({x}, {z}) is {d} m from a river");
        assert!(d > 0.0 || water != Water::Dry, "dry column ({x}, {z}) lies in a river's bed");
        for (nx, nz) in [(x + 1, z), (x, z + 1)] {
            if nx < rect.x1() && nz < rect.y1() {
                let step = (distance(nx, nz) - d).abs();
                assert!(step <= 1.5 * block_m, "the distance jumps {step} m from ({x}, {z}) to ({nx}, {nz})");
            }
        }
    }
    assert!(region.each_column().any(|(x, z)| (100.0..600.0).contains(&distance(x, z))));
    // The river biome over river water.
    let palette = BiomePalette::vanilla();
    let (river, frozen) = (palette.id("minecraft:river"), palette.id("minecraft:frozen_river"));
    let mut river_cells = 0;
    for (x, z) in region.each_column().filter(|&(x, z)| region.columns.water(x, z) == Water::River) {
        let chunk = &region.chunks[&(x.div_euclid(16) as i32, z.div_euclid(16) as i32)];
        let cell_y = ((region.columns.surface_y(x, z) - v.min_y) / 4) as u32;
        let biome = chunk.biome((x.rem_euclid(16) / 4) as u32, cell_y, (z.rem_euclid(16) / 4) as u32);
        assert!(biome == river || biome == frozen, "column ({x}, {z}) in river water is not a river biome");
        river_cells += 1;
    }
    assert!(river_cells > 0);
}

#[test]
fn lakes_are_level_and_closed_to_air() {
    let (g, rules) = (generator(), shipped_rules());
    let corner = lake_region(&g, &rules);
    let region = Region::generate(&g, &rules, corner, &chunk_list(corner));
    assert_water_sits_right(&region);
    assert!(assert_lakes_are_level(&region) >= 1, "no lake near a lake cell");
    assert_rivers_drain(&region);
}

#[test]
fn water_is_the_same_in_any_order_on_any_thread_count_and_across_column_queries() {
    let (g, rules) = (generator(), shipped_rules());
    let corner = river_region(&g, &rules);
    let forward = Region::generate(&g, &rules, corner, &chunk_list(corner));
    // A fresh generator (empty caches), chunks in reverse order over three threads.
    let fresh = generator();
    let mut order = chunk_list(corner);
    order.reverse();
    let palette = BiomePalette::vanilla();
    let chunks: Vec<((i32, i32), UnloadedChunk)> = std::thread::scope(|s| {
        let handles: Vec<_> = order
            .chunks(order.len().div_ceil(3))
            .map(|part| {
                let (fresh, rules, palette) = (&fresh, &rules, &palette);
                s.spawn(move || {
                    part.iter().map(|&(cx, cz)| ((cx, cz), fresh.chunk(rules, palette, cx, cz))).collect::<Vec<_>>()
                })
            })
            .collect();
        handles.into_iter().flat_map(|h| h.join().unwrap()).collect()
    });
    for ((cx, cz), chunk) in chunks {
        let a = &forward.chunks[&(cx, cz)];
        for y in 0..a.height() {
            for z in 0..16 {
                for x in 0..16 {
                    assert_eq!(
                        a.block_state(x, y, z),
                        chunk.block_state(x, y, z),
                        "chunk ({cx}, {cz}) block ({x}, {y}, {z})"
                    );
                }
            }
        }
    }
    // Columns asked for over a shifted rectangle agree on the water of every shared column.
    let r = forward.rect();
    let shifted = Columns::query(g.pipeline(), g.vertical(), Rect::new(r.y0 + 7, r.x0 - 5, r.h, r.w));
    let mut shared = 0;
    for (x, z) in forward.each_column().filter(|&(x, z)| z >= r.y0 + 7 && x < r.x1() - 5) {
        assert_eq!(forward.columns.water_top_y(x, z), shifted.water_top_y(x, z), "({x}, {z})");
        assert_eq!(forward.columns.surface_y(x, z), shifted.surface_y(x, z), "({x}, {z})");
        shared += 1;
    }
    assert!(shared > 1000);
    // Falling water is drawn only where a neighbour's water stands higher.
    let falling = BlockState::WATER.set(PropName::Level, PropValue::_8);
    let mut falls = 0;
    for (x, z) in forward.each_column().filter(|&(x, z)| x > r.x0 && x < r.x1() - 1 && z > r.y0 && z < r.y1() - 1) {
        let ground = forward.columns.surface_y(x, z);
        for y in ground + 1..ground + 64 {
            if forward.block(x, y, z) == Some(falling) {
                falls += 1;
                let higher =
                    SIDES.iter().any(|&(dx, dz)| forward.columns.water_top_y(x + dx, z + dz).is_some_and(|t| t >= y));
                assert!(higher, "falling water at ({x}, {y}, {z}) with nothing to fall from");
            }
        }
    }
    eprintln!("{falls} falling water blocks");
}
