//! Where players appear: on dry, walkable land as near the origin as the world allows.

use valence::prelude::{BlockPos, BlockState, DVec3};

use crate::biome::BiomeRules;
use crate::chunkgen::{Columns, Generator, CHUNK};
use crate::terrain::Rect;

/// Coarse cells that look like land above this elevation are searched, metres (a margin above
/// the shore, where the exact surface may still dip under the sea).
const LAND_M: f32 = 20.0;
/// Side of the squares searched, blocks (a coarse elevation sample each).
const CELL: i64 = 64;
/// Rings of squares searched around the origin before giving up (12,800 blocks).
const MAX_RINGS: i64 = 200;
/// Ground that falls this many blocks to a neighbour is a cliff, not a spawn.
const MAX_DROP: i32 = 1;

/// The spawn point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpawnPoint {
    /// The column and ground block players stand on.
    pub block: BlockPos,
    /// Where their feet start (two blocks above the ground block, centred on the column).
    pub feet: DVec3,
}

/// Spirals out from the origin over the cheap coarse elevation to the nearest land, then
/// picks the walkable column nearest that coarse cell's centre. Runs once at start-up.
pub fn find_spawn(generator: &Generator, rules: &BiomeRules) -> SpawnPoint {
    let pipeline = generator.pipeline();
    let cell = CELL;
    for ring in 0..=MAX_RINGS {
        let mut candidates: Vec<(i64, i64)> = ring_cells(ring)
            .filter(|&(cx, cz)| pipeline.coarse_elevation_at_block(cx * cell + cell / 2, cz * cell + cell / 2) > LAND_M)
            .collect();
        candidates.sort_by_key(|&(cx, cz)| (cx * cx + cz * cz, cx, cz));
        for (cx, cz) in candidates {
            if let Some(spawn) = walkable_column(generator, rules, cx * cell, cz * cell, cell) {
                return spawn;
            }
        }
    }
    tracing::warn!("no land found within {} blocks of the origin: spawning at 0, 0", MAX_RINGS * cell);
    let surface = generator.surface(rules, 0, 0);
    at(0, surface.y, 0)
}

/// The coarse cells on the square ring `ring` cells from the origin.
fn ring_cells(ring: i64) -> impl Iterator<Item = (i64, i64)> {
    (-ring..=ring)
        .flat_map(move |z| (-ring..=ring).map(move |x| (x, z)))
        .filter(move |&(x, z)| x.abs().max(z.abs()) == ring)
}

/// The dry, gentle column of the square at (`x0`, `z0`) nearest its centre, if any.
fn walkable_column(generator: &Generator, rules: &BiomeRules, x0: i64, z0: i64, size: i64) -> Option<SpawnPoint> {
    let v = generator.vertical();
    let columns = Columns::query(generator.pipeline(), v, Rect::new(z0 - 1, x0 - 1, size + 2, size + 2));
    let centre = (x0 + size / 2, z0 + size / 2);
    let mut candidates: Vec<(i64, i64)> = (z0..z0 + size)
        .flat_map(|z| (x0..x0 + size).map(move |x| (x, z)))
        // Above the shoreline (the sea-level row of blocks is often a wet flat).
        .filter(|&(x, z)| columns.surface_y(x, z) > v.sea_level_y && columns.drop_blocks(x, z) <= MAX_DROP)
        .collect();
    candidates.sort_by_key(|&(x, z)| ((x - centre.0).pow(2) + (z - centre.1).pow(2), x, z));
    // The exact top block needs the biome; only a few columns are ever looked at.
    candidates.into_iter().take(CHUNK as usize).find_map(|(x, z)| {
        let surface = generator.surface(rules, x, z);
        let solid = !matches!(surface.top, "powder_snow" | "water" | "ice" | "air");
        // Grass and flowers are walked through; a cactus is not a place to stand.
        let no_cactus = !generator.plant_blocks(rules, x, z).contains(&BlockState::CACTUS);
        (solid && no_cactus && generator.clear_of_trees(rules, x, z)).then(|| at(x, surface.y, z))
    })
}

fn at(x: i64, surface_y: i32, z: i64) -> SpawnPoint {
    let (x, z) = (x as i32, z as i32);
    SpawnPoint {
        block: BlockPos::new(x, surface_y, z),
        feet: DVec3::new(f64::from(x) + 0.5, f64::from(surface_y) + 2.0, f64::from(z) + 0.5),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rings_are_hollow_squares() {
        assert_eq!(ring_cells(0).collect::<Vec<_>>(), vec![(0, 0)]);
        assert_eq!(ring_cells(1).count(), 8);
        assert_eq!(ring_cells(3).count(), 24);
        assert!(ring_cells(2).all(|(x, z)| x.abs() == 2 || z.abs() == 2));
    }
}
