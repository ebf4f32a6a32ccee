//! The icebergs pass: mounds of packed ice in frozen seas, rising up to 14 blocks above the
//! water and reaching twice as deep below it, with blue ice in the biggest and snow on their
//! tops — vanilla's frozen oceans have them; our sea ice alone was a flat white plain.
//!
//! Where they stand is a smooth noise over the sea (patches about 20 blocks across, a few in
//! a hundred columns), a pure function of the column: bergs cross chunk borders whole.

use valence::prelude::{BlockState, Chunk};

use crate::chunkgen::Blocks;

use crate::chunkgen::columns::Water;
use crate::chunkgen::hash::value_noise;
use crate::chunkgen::surface::SEA_ICE_C;
use crate::chunkgen::ChunkContext;
use crate::terrain::pipeline::channel;

const SALT: u64 = 0x1CEB_E265;
/// Width of the noise's features, blocks.
const SCALE: i64 = 20;
/// Noise above which a berg stands.
const THRESHOLD: f32 = 0.8;
/// Height above the water of the tallest berg, blocks.
const MAX_ABOVE: f32 = 14.0;
/// Water at least this deep holds a berg, blocks.
const MIN_DEPTH: i32 = 4;

/// Blocks above the water top of the berg over column (`x`, `z`) (0: a berg's rim, awash),
/// or `None` where there is none. Needs only the seed and the column.
pub fn berg_height(seed: u64, x: i64, z: i64) -> Option<i32> {
    let f = value_noise(seed, SALT, x, z, SCALE);
    (f > THRESHOLD).then(|| ((f - THRESHOLD) / (1.0 - THRESHOLD) * MAX_ABOVE).round() as i32)
}

/// Raises the bergs.
pub fn run(ctx: &mut ChunkContext, chunk: &mut Blocks) {
    let (v, seed, columns) = (*ctx.vertical(), ctx.seed(), ctx.columns());
    let height = v.min_y + v.height;
    for (lx, lz, x, z) in ctx.each_column() {
        let (Water::Sea, Some(top)) = (columns.water(x, z), columns.water_top_y(x, z)) else { continue };
        let depth = top - columns.surface_y(x, z);
        if depth < MIN_DEPTH || columns.get(channel::TEMPERATURE, x, z) >= SEA_ICE_C {
            continue;
        }
        let Some(above) = berg_height(seed, x, z) else { continue };
        let below = (2 * above + 1).min(depth - 1);
        let peak = (top + above).min(height - 1);
        for y in top - below..=peak {
            let block = if y == peak && above >= 2 {
                BlockState::SNOW_BLOCK
            } else if above >= 8 && y < top {
                BlockState::BLUE_ICE
            } else {
                BlockState::PACKED_ICE
            };
            chunk.set_block_state(lx, (y - v.min_y) as u32, lz, block);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{testing, water};
    use super::*;
    use crate::terrain::Rect;

    /// Chunk (`cx`, `cz`) of sea 600 m deep, frozen where `frozen`, with its water and bergs.
    fn sea(g: &crate::chunkgen::Generator, (cx, cz): (i32, i32), frozen: bool) -> Blocks {
        let (palette, rules) = (testing::palette(), testing::single_biome("minecraft:frozen_ocean"));
        let mut ctx = ChunkContext::new(g, &rules, &palette, cx, cz);
        let (x0, z0) = (i64::from(cx) * 16, i64::from(cz) * 16);
        let t = if frozen { -8.0 } else { 5.0 };
        ctx.columns = Some(testing::columns(g, Rect::new(z0 - 5, x0 - 5, 26, 26), |_, _| (-600.0, t)));
        let mut chunk = Blocks::with_height(g.vertical().height as u32);
        water::run(&mut ctx, &mut chunk);
        run(&mut ctx, &mut chunk);
        chunk
    }

    #[test]
    fn frozen_seas_hold_bergs_that_rise_above_the_water_and_warm_seas_none() {
        let g = testing::generator();
        let v = *g.vertical();
        let top = (v.water_top_y() - v.min_y) as u32;
        let (mut bergs, mut tall, mut chunks) = (0, 0, 0);
        for cz in 0..6 {
            for cx in 0..6 {
                let chunk = sea(&g, (cx, cz), true);
                chunks += 1;
                for z in 0..16 {
                    for x in 0..16 {
                        let above = (top + 1..top + 16).take_while(|&y| !chunk.block_state(x, y, z).is_air()).count();
                        let (gx, gz) = (i64::from(cx) * 16 + i64::from(x), i64::from(cz) * 16 + i64::from(z));
                        let want = berg_height(g.seed(), gx, gz);
                        // Every berg column exactly as high as the noise says: seamless.
                        assert_eq!(above as i32, want.unwrap_or(0), "column {gx}, {gz}");
                        bergs += usize::from(want.is_some());
                        tall += usize::from(above >= 8);
                        if want.is_some() {
                            assert!(chunk.block_state(x, top, z).to_kind().to_str().contains("ice"));
                        }
                    }
                }
            }
        }
        let share = bergs as f32 / (chunks as f32 * 256.0);
        assert!((0.005..0.15).contains(&share) && tall > 0, "{bergs} berg columns ({share}), {tall} tall");
        let warm = sea(&g, (0, 0), false);
        assert!((0..16).all(|z| (0..16).all(|x| warm.block_state(x, top, z) == BlockState::WATER)));
    }
}
