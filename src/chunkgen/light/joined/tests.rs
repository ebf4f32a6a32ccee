use std::collections::VecDeque;

use valence::prelude::{BlockState, Chunk, UnloadedChunk};

use super::super::properties;
use super::*;
use crate::chunkgen::hash::{hash3, unit3};

/// Height of the test chunks.
const H: u32 = 64;
/// Width of the 3 × 3 chunks.
const W: i32 = 48;

/// Blocks of a 3 × 3 neighbourhood, area coordinates −16…31 on x and z.
struct Scene(Vec<BlockState>);

impl Scene {
    fn new(fill: impl Fn(i32, u32, i32) -> BlockState) -> Scene {
        let mut blocks = Vec::with_capacity((W * W) as usize * H as usize);
        for y in 0..H {
            for z in -16..32 {
                for x in -16..32 {
                    blocks.push(fill(x, y, z));
                }
            }
        }
        Scene(blocks)
    }

    fn at(&self, x: i32, y: u32, z: i32) -> BlockState {
        self.0[cell(x, y, z)]
    }

    fn set(&mut self, x: i32, y: u32, z: i32, b: BlockState) {
        let i = cell(x, y, z);
        self.0[i] = b;
    }

    /// Each chunk's own light, rows north to south, each west to east.
    fn lights(&self) -> Vec<Light> {
        (0..9)
            .map(|c| {
                let (ox, oz) = ((c % 3) * 16 - 16, (c / 3) * 16 - 16);
                let mut chunk = UnloadedChunk::with_height(H);
                for y in 0..H {
                    for z in 0..16 {
                        for x in 0..16 {
                            chunk.set_block_state(x, y, z, self.at(ox + x as i32, y, oz + z as i32));
                        }
                    }
                }
                Light::of(&chunk)
            })
            .collect()
    }

    /// Sky and block light of the whole neighbourhood by one flood fill over all of it (right
    /// within 16 blocks of its edge, so everywhere in the centre).
    fn flooded(&self) -> [Vec<u8>; 2] {
        let table = properties();
        let n = self.0.len();
        let (mut damp, mut sky, mut block) = (vec![0u8; n], vec![0u8; n], vec![0u8; n]);
        for (i, b) in self.0.iter().enumerate() {
            let p = table[b.to_raw() as usize];
            damp[i] = p & 0xF;
            block[i] = p >> 4;
        }
        for z in -16..32 {
            for x in -16..32 {
                let mut l = 15u8;
                for y in (0..H).rev() {
                    l = l.saturating_sub(damp[cell(x, y, z)]);
                    sky[cell(x, y, z)] = l;
                }
            }
        }
        for levels in [&mut sky, &mut block] {
            let mut queue: VecDeque<usize> = (0..n).filter(|&i| levels[i] > 1).collect();
            while let Some(i) = queue.pop_front() {
                let (x, y, z) = uncell(i);
                for (dx, dy, dz) in [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)] {
                    let (a, b, c) = (x + dx, y as i32 + dy, z + dz);
                    if !(-16..32).contains(&a) || !(-16..32).contains(&c) || !(0..H as i32).contains(&b) {
                        continue;
                    }
                    let j = cell(a, b as u32, c);
                    let d = damp[j].max(1);
                    if levels[i] > d && levels[j] < levels[i] - d {
                        levels[j] = levels[i] - d;
                        queue.push_back(j);
                    }
                }
            }
        }
        [sky, block]
    }
}

fn cell(x: i32, y: u32, z: i32) -> usize {
    (y as usize * W as usize + (z + 16) as usize) * W as usize + (x + 16) as usize
}

fn uncell(i: usize) -> (i32, u32, i32) {
    let w = W as usize;
    ((i % w) as i32 - 16, (i / (w * w)) as u32, (i / w % w) as i32 - 16)
}

/// The centre's light: joined from `lights` (or its own, when nothing changed).
fn centre(lights: &[Light]) -> Light {
    let area: [&Light; 9] = std::array::from_fn(|i| &lights[i]);
    Light::joined(area).unwrap_or_else(|| lights[4].clone())
}

/// Whether `light` is the flood's in every block of the centre; the first difference if not.
fn differs(light: &Light, flooded: &[Vec<u8>; 2]) -> Option<String> {
    for y in 0..H {
        for z in 0..16 {
            for x in 0..16 {
                let want = (flooded[0][cell(x, y, z)], flooded[1][cell(x, y, z)]);
                let got = (light.sky(x as u32, y, z as u32), light.block(x as u32, y, z as u32));
                if got != want {
                    return Some(format!("at {x}, {y}, {z}: (sky, block) {got:?}, the flood over all nine {want:?}"));
                }
            }
        }
    }
    None
}

/// Rolling ground with overhanging ledges, tunnels and caves that cross chunk borders, lava
/// in the caves, trees' leaves, ponds.
fn rough(seed: u64) -> Scene {
    let ground = |x: i32, z: i32| 30 + (hash3(seed, 1, (x / 5) as i64, 0, (z / 5) as i64) % 9) as u32;
    let mut scene = Scene::new(|x, y, z| {
        let g = ground(x, z);
        let r = unit3(seed, 2, x as i64, y as i64, z as i64);
        if y == 0 {
            BlockState::BEDROCK
        } else if y < g {
            // Caves: air pockets, some with lava on the floor.
            let cave = unit3(seed, 3, (x / 4) as i64, (y / 3) as i64, (z / 4) as i64) < 0.25;
            match (cave, r) {
                (true, r) if r < 0.03 => BlockState::LAVA,
                (true, _) => BlockState::AIR,
                _ => BlockState::STONE,
            }
        } else if y < 34 && g < 33 {
            BlockState::WATER
        } else if (44..47).contains(&y) && unit3(seed, 4, (x / 3) as i64, 0, (z / 3) as i64) < 0.2 {
            BlockState::OAK_LEAVES
        } else {
            BlockState::AIR
        }
    });
    // Ledges: slabs of stone in the air, a few blocks above the ground.
    for i in 0..12u64 {
        let (x0, z0) =
            ((hash3(seed, 5, i as i64, 0, 0) % 44) as i32 - 16, (hash3(seed, 6, i as i64, 0, 0) % 44) as i32 - 16);
        let y = 40 + (hash3(seed, 7, i as i64, 0, 0) % 4) as u32;
        for z in z0..(z0 + 6).min(32) {
            for x in x0..(x0 + 7).min(32) {
                scene.set(x, y, z, BlockState::STONE);
            }
        }
    }
    // Tunnels from the open air straight into the ground, across borders.
    for i in 0..8u64 {
        let z = (hash3(seed, 8, i as i64, 0, 0) % 48) as i32 - 16;
        let y = 26 + (hash3(seed, 9, i as i64, 0, 0) % 6) as u32;
        for x in -16..32 {
            scene.set(x, y, z, BlockState::AIR);
        }
        for y in y..H {
            scene.set(-16 + (i as i32 % 3) * 20, y, z, BlockState::AIR);
        }
    }
    scene
}

#[test]
fn joined_light_is_one_flood_over_all_nine_chunks() {
    let mut changed = 0;
    for seed in 0..12 {
        let scene = rough(seed);
        let lights = scene.lights();
        let flooded = scene.flooded();
        if differs(&lights[4], &flooded).is_some() {
            changed += 1;
        }
        if let Some(d) = differs(&centre(&lights), &flooded) {
            panic!("scene {seed}: {d}");
        }
    }
    assert!(changed >= 10, "the scenes' borders matter: alone, {changed} of 12 centres were lit wrong");
}

#[test]
fn joined_light_is_the_same_from_neighbours_lit_brighter() {
    // A server may hold a neighbour's joined light instead of its own: any start between the
    // own light and the truth gives the same centre. The flood over the nine is such a start
    // for the neighbours (its outer rim misses light from beyond, never has too much).
    let scene = rough(7);
    let lights = scene.lights();
    let flooded = scene.flooded();
    let mut brighter = lights.clone();
    for (i, light) in brighter.iter_mut().enumerate().filter(|&(i, _)| i != 4) {
        let (ox, oz) = ((i as i32 % 3) * 16 - 16, (i as i32 / 3) * 16 - 16);
        for y in 0..H {
            for z in 0..16u32 {
                for x in 0..16u32 {
                    let c = cell(ox + x as i32, y, oz + z as i32);
                    light.sky[(y / 16) as usize + 1].set(x, y, z, flooded[0][c]);
                    light.block[(y / 16) as usize + 1].set(x, y, z, flooded[1][c]);
                }
            }
        }
    }
    assert_ne!(brighter[3], lights[3], "the start differs");
    assert_eq!(centre(&brighter), centre(&lights));
}

#[test]
fn a_cave_mouth_next_door_lights_the_tunnel_across_the_border() {
    // Stone up to Y 39 everywhere; the west neighbour's column x = −8 open to the sky, and a
    // tunnel at Y 30, z 5 from it east into the centre.
    let mut scene = Scene::new(|_, y, _| if y < 40 { BlockState::STONE } else { BlockState::AIR });
    for y in 30..40 {
        scene.set(-8, y, 5, BlockState::AIR);
    }
    for x in -8..10 {
        scene.set(x, 30, 5, BlockState::AIR);
    }
    // And one from 14 blocks west, as far as light reaches.
    for y in 30..40 {
        scene.set(-14, y, 9, BlockState::AIR);
    }
    for x in -14..10 {
        scene.set(x, 30, 9, BlockState::AIR);
    }
    let lights = scene.lights();
    assert_eq!(lights[4].sky(0, 30, 5), 0, "alone, the centre's end of the tunnel is dark");
    let joined = centre(&lights);
    let tunnel: Vec<u8> = (0..8).map(|x| joined.sky(x, 30, 5)).collect();
    assert_eq!(tunnel, [7, 6, 5, 4, 3, 2, 1, 0], "one level less a block from the mouth 8 blocks west");
    assert_eq!((joined.sky(0, 30, 9), joined.sky(1, 30, 9)), (1, 0), "the farthest light reaches the border");
    assert_eq!(joined.sky(0, 31, 5), 0, "rock stays dark");
    assert_eq!(differs(&joined, &scene.flooded()), None);
}

#[test]
fn lava_next_door_lights_the_cave_across_the_border() {
    let mut scene = Scene::new(|_, y, _| if y < 40 { BlockState::STONE } else { BlockState::AIR });
    // A cave at Y 10…12 from x −6 to 6 along z 20 (in the south-west and south neighbours),
    // lava on its floor at x 0, and a passage north from it at x 3 into the centre.
    for x in -6..7 {
        for y in 10..13 {
            scene.set(x, y, 20, BlockState::AIR);
        }
    }
    scene.set(0, 10, 20, BlockState::LAVA);
    for z in 15..20 {
        scene.set(3, 11, z, BlockState::AIR);
    }
    let lights = scene.lights();
    let joined = centre(&lights);
    assert_eq!(lights[4].block(3, 11, 15), 0);
    assert_eq!(joined.block(3, 11, 15), 6, "lava 4 + 5 blocks away lights the centre's end of the passage");
    assert_eq!(differs(&joined, &scene.flooded()), None);
}

#[test]
fn open_ground_needs_nothing_from_its_neighbours() {
    let scene =
        Scene::new(|x, y, z| if y < 30 + ((x + z).rem_euclid(3)) as u32 { BlockState::STONE } else { BlockState::AIR });
    let lights = scene.lights();
    let area: [&Light; 9] = std::array::from_fn(|i| &lights[i]);
    assert_eq!(Light::joined(area), None, "a height field is lit from straight above, inside each chunk");
}
