//! Light across chunk borders: a chunk's light as its eight neighbours' blocks make it.
//!
//! Light fades one level a block, so nothing more than 15 blocks away lights a block: the
//! light of a chunk is decided by the blocks of the chunk and of the 15 blocks around it,
//! all inside its 3 × 3 neighbourhood. Flooding all nine chunks for each would cost nine
//! chunks' light; instead this starts from the light each chunk has alone
//! ([`Light::of_states`], walled in at its borders) and floods only what crosses a border.
//!
//! Why that is exact: take the brightest path from a source to a block of the centre. Up to
//! where it first crosses a border it runs inside one chunk, whose own light there is at
//! least what the path brings. Every block beside a border that can raise its neighbour
//! across it is a seed, so the flood follows the path from that crossing on, over however
//! many borders. The path never leaves the blocks within 15 of the centre (it would be dark
//! by the time it came back), which is all the flood looks at. Any start no darker than the
//! chunks' own light and no brighter than the true one gives the same answer, so the result
//! is a pure function of the nine chunks' blocks, whatever order they were loaded in.

use std::collections::{HashMap, VecDeque};

use super::{Light, Section};

/// How far light reaches from its source: 15 levels, one a block.
const REACH: i32 = 15;

/// Which light: sky (0) or block (1).
type Kind = usize;
const SKY: Kind = 0;
const BLOCK: Kind = 1;

impl Light {
    /// The light of the centre of `area` (3 × 3 chunks, rows north to south, each west to
    /// east: the centre is `area[4]`) with its neighbours' light let in, or `None` when its
    /// own light is already right. Each chunk's light is as [`Light::of_states`] computed it
    /// (alone) or as a joined light (no darker than that, no brighter than the truth).
    pub fn joined(area: [&Light; 9]) -> Option<Light> {
        let mut flood = Flood::new(area);
        for kind in [SKY, BLOCK] {
            let queue = flood.seeds(kind);
            flood.spread(kind, queue);
        }
        flood.into_centre()
    }
}

/// The neighbourhood being flooded: area coordinates run from −16 to 31 on x and z (the
/// centre 0…15), y from the world's floor.
struct Flood<'a> {
    area: [&'a Light; 9],
    height: u32,
    /// Levels the flood raised, by [`key`], per kind.
    raised: [HashMap<u32, u8>; 2],
}

impl<'a> Flood<'a> {
    fn new(area: [&'a Light; 9]) -> Flood<'a> {
        let height = (area[4].section_count() as u32 - 2) * 16;
        debug_assert!(area.iter().all(|l| l.section_count() == area[4].section_count()));
        Flood { area, height, raised: [HashMap::new(), HashMap::new()] }
    }

    /// The chunk holding area column (`x`, `z`) and the column within it.
    fn chunk(&self, x: i32, z: i32) -> (&'a Light, u32, u32) {
        let c = ((z + 16) / 16 * 3 + (x + 16) / 16) as usize;
        (self.area[c], x.rem_euclid(16) as u32, z.rem_euclid(16) as u32)
    }

    /// The level of `kind` at (`x`, `y`, `z`) before the flood.
    fn own(&self, kind: Kind, x: i32, y: u32, z: i32) -> u8 {
        let (light, cx, cz) = self.chunk(x, z);
        let sections = if kind == SKY { &light.sky } else { &light.block };
        sections[(y / 16) as usize + 1].get(cx, y, cz)
    }

    fn level(&self, kind: Kind, x: i32, y: u32, z: i32) -> u8 {
        match self.raised[kind].get(&key(x, y, z)) {
            Some(&level) => level,
            None => self.own(kind, x, y, z),
        }
    }

    fn damp(&self, x: i32, y: u32, z: i32) -> u8 {
        let (light, cx, cz) = self.chunk(x, z);
        light.opacity[(y / 16) as usize + 1].get(cx, y, cz).max(1)
    }

    /// Blocks beside a border between two chunks whose light raises the block across it.
    /// Section by section, skipping those where it cannot: the giver dark, the taker opaque,
    /// or both at full light.
    fn seeds(&self, kind: Kind) -> VecDeque<(i32, u32, i32)> {
        let mut queue = VecDeque::new();
        let span = -REACH..16 + REACH;
        // Borders at x = 0 and x = 16 (between x − 1 and x), then the same across z.
        for across_x in [true, false] {
            for border in [0, 16] {
                for row in [-16, 0, 16] {
                    let along: Vec<i32> = (row..row + 16).filter(|v| span.contains(v)).collect();
                    let at = |v: i32, side: i32| if across_x { (border - 1 + side, v) } else { (v, border - 1 + side) };
                    for side in [0, 1] {
                        let (from, to) = (at(along[0], side), at(along[0], 1 - side));
                        let (giver, taker) = (self.chunk(from.0, from.1).0, self.chunk(to.0, to.1).0);
                        let (given, taken) =
                            if kind == SKY { (&giver.sky, &taker.sky) } else { (&giver.block, &taker.block) };
                        for s in 1..given.len() - 1 {
                            let (g, t, opacity) = (&given[s], &taken[s], &taker.opacity[s]);
                            if matches!(g, Section::Dark)
                                || matches!(t, Section::Full)
                                || matches!(opacity, Section::Full)
                            {
                                continue;
                            }
                            for &v in &along {
                                let ((fx, fz), (tx, tz)) = (at(v, side), at(v, 1 - side));
                                let (fx, fz, tx, tz) = (
                                    fx.rem_euclid(16) as u32,
                                    fz.rem_euclid(16) as u32,
                                    tx.rem_euclid(16) as u32,
                                    tz.rem_euclid(16) as u32,
                                );
                                for y in (s as u32 - 1) * 16..s as u32 * 16 {
                                    let l = g.get(fx, y, fz);
                                    let d = opacity.get(tx, y, tz).max(1);
                                    if l > d && t.get(tx, y, tz) < l - d {
                                        let (x, z) = at(v, side);
                                        queue.push_back((x, y, z));
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
        queue
    }

    /// Vanilla's flood fill from `queue`, over the blocks within [`REACH`] of the centre.
    fn spread(&mut self, kind: Kind, mut queue: VecDeque<(i32, u32, i32)>) {
        const STEPS: [(i32, i32, i32); 6] = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)];
        let span = -REACH..16 + REACH;
        while let Some((x, y, z)) = queue.pop_front() {
            let l = self.level(kind, x, y, z);
            for (dx, dy, dz) in STEPS {
                let (a, b, c) = (x + dx, y as i32 + dy, z + dz);
                if !span.contains(&a) || !span.contains(&c) || !(0..self.height as i32).contains(&b) {
                    continue;
                }
                let b = b as u32;
                let d = self.damp(a, b, c);
                if l > d && self.level(kind, a, b, c) < l - d {
                    self.raised[kind].insert(key(a, b, c), l - d);
                    queue.push_back((a, b, c));
                }
            }
        }
    }

    /// The centre's light with what the flood raised in it, or `None` if it raised nothing
    /// there.
    fn into_centre(self) -> Option<Light> {
        let mut out: Option<Light> = None;
        for kind in [SKY, BLOCK] {
            for (&k, &level) in &self.raised[kind] {
                let (x, y, z) = unkey(k);
                if !(0..16).contains(&x) || !(0..16).contains(&z) {
                    continue;
                }
                let light = out.get_or_insert_with(|| self.area[4].clone());
                let sections = if kind == SKY { &mut light.sky } else { &mut light.block };
                sections[(y / 16) as usize + 1].set(x as u32, y, z as u32, level);
            }
        }
        out
    }
}

/// One number for an area block: x and z offset by 16 (6 bits each), y above them.
fn key(x: i32, y: u32, z: i32) -> u32 {
    (y << 12) | (((z + 16) as u32) << 6) | (x + 16) as u32
}

fn unkey(k: u32) -> (i32, u32, i32) {
    ((k & 63) as i32 - 16, k >> 12, ((k >> 6) & 63) as i32 - 16)
}

#[cfg(test)]
mod tests;
