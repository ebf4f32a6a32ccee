//! Light across chunk borders, measured on land: what joining a chunk's light with its
//! neighbours' ([`Light::joined`]) costs, and how much of the world it changes.

use std::collections::HashMap;
use std::time::Instant;

use super::Measurement;
use crate::biome::BiomeRules;
use crate::chunkgen::{BiomePalette, Generator, Light};

/// Chunks on a side of the square measured (its inner `SIDE − 2` squared are joined).
const SIDE: i32 = 18;

/// Generates a square of chunks around block (`x`, `z`), lights each alone, then joins every
/// chunk whose eight neighbours are in the square. Lines start with `label`.
pub fn measure(generator: &Generator, rules: &BiomeRules, (x, z): (i32, i32), label: &str) -> Vec<Measurement> {
    let palette = BiomePalette::vanilla();
    let (cx0, cz0) = (x.div_euclid(16) - SIDE / 2, z.div_euclid(16) - SIDE / 2);
    let mut own = HashMap::new();
    let mut alone = 0.0;
    for cz in cz0..cz0 + SIDE {
        for cx in cx0..cx0 + SIDE {
            let states = generator.blocks(rules, &palette, cx, cz).states();
            let t = Instant::now();
            own.insert((cx, cz), Light::of_states(&states));
            alone += t.elapsed().as_secs_f64();
        }
    }
    let (mut joining, mut changed, mut blocks, mut joined) = (0.0, 0usize, 0usize, 0usize);
    for cz in cz0 + 1..cz0 + SIDE - 1 {
        for cx in cx0 + 1..cx0 + SIDE - 1 {
            let area: [&Light; 9] = std::array::from_fn(|i| &own[&(cx + i as i32 % 3 - 1, cz + i as i32 / 3 - 1)]);
            let t = Instant::now();
            let result = Light::joined(area);
            joining += t.elapsed().as_secs_f64();
            joined += 1;
            if let Some(light) = result {
                changed += 1;
                blocks += differing(&light, area[4]);
            }
        }
    }
    let n = (SIDE * SIDE) as f64;
    vec![
        Measurement::new(&format!("{label}: light of a chunk alone"), "ms", vec![1e3 * alone / n]),
        Measurement::new(
            &format!("{label}: joining it with its neighbours'"),
            "ms",
            vec![1e3 * joining / joined as f64],
        ),
        Measurement::new(
            &format!("{label}: chunks whose light that changes"),
            "%",
            vec![100.0 * changed as f64 / joined as f64],
        ),
        Measurement::new(
            &format!("{label}: blocks lit brighter in such a chunk"),
            "blocks",
            vec![blocks as f64 / changed.max(1) as f64],
        ),
    ]
}

/// Blocks whose sky or block light differs between `a` and `b`.
fn differing(a: &Light, b: &Light) -> usize {
    let height = (a.section_count() as u32 - 2) * 16;
    let mut n = 0;
    for y in 0..height {
        for z in 0..16 {
            for x in 0..16 {
                n += usize::from(a.sky(x, y, z) != b.sky(x, y, z) || a.block(x, y, z) != b.block(x, y, z));
            }
        }
    }
    n
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::config::Config;
    use crate::terrain::Pipeline;

    /// The measurement alone, with the shipped models: `cargo test --release --lib
    /// light_across_borders -- --ignored --nocapture`.
    #[test]
    #[ignore = "a measurement with the shipped models, not a test"]
    fn light_across_borders() {
        let config = Config::load(std::path::Path::new("config/server.toml")).expect("config/server.toml");
        let pipeline = Arc::new(Pipeline::build(config.world.seed, &config.terrain()).expect("models"));
        let generator = Generator::new(pipeline, &config);
        let rules = BiomeRules::load_dir(std::path::Path::new("biomes")).expect("biomes");
        let spawn = crate::world::find_spawn(&generator, &rules).block;
        for m in measure(&generator, &rules, (spawn.x, spawn.z), "by the spawn") {
            println!("{:<60} {:>10.3} {}", m.name, m.value, m.unit);
        }
    }
}
