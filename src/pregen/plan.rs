//! What a pre-generation task covers and in which order: region by region (nearest region
//! first, spiralling out), and a spiral inside each region, so consecutive chunks share the
//! pipeline's cached windows and each region file is finished before the next is begun.
//!
//! Every chunk of the task has an ordinal (its place in that order); progress is "the first
//! N ordinals are saved", which is all a crash needs to resume.

use std::fmt;

use serde::{Deserialize, Serialize};

use crate::world::region::RegionPos;

/// Chunks per region edge.
const REGION: i32 = 32;
/// Blocks per chunk edge.
const CHUNK: i64 = 16;

/// The outline of the area.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Shape {
    /// Every chunk whose centre is within `radius` blocks on both axes.
    Square,
    /// Every chunk whose centre is within `radius` blocks of the centre.
    Circle,
}

impl std::str::FromStr for Shape {
    type Err = String;
    fn from_str(s: &str) -> Result<Shape, String> {
        match s {
            "square" => Ok(Shape::Square),
            "circle" => Ok(Shape::Circle),
            other => Err(format!("unknown shape {other:?}: use square or circle")),
        }
    }
}

impl fmt::Display for Shape {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Shape::Square => "square",
            Shape::Circle => "circle",
        })
    }
}

/// A pre-generation task: centre and radius in blocks, as Chunky takes them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Task {
    /// Centre block x.
    pub center_x: i64,
    /// Centre block z.
    pub center_z: i64,
    /// Radius in blocks.
    pub radius: i64,
    /// Outline.
    pub shape: Shape,
}

/// Largest radius accepted, blocks (the world border of vanilla is at 29,999,984).
pub const MAX_RADIUS: i64 = 30_000_000;

impl Task {
    /// Checks the numbers; the error says which value is wrong.
    pub fn validate(&self) -> Result<(), String> {
        if !(0..=MAX_RADIUS).contains(&self.radius) {
            return Err(format!("radius {} is out of range (allowed 0..={MAX_RADIUS} blocks)", self.radius));
        }
        for (axis, v) in [("x", self.center_x), ("z", self.center_z)] {
            if v.abs() > MAX_RADIUS {
                return Err(format!("centre {axis} = {v} is outside the world (±{MAX_RADIUS})"));
            }
        }
        Ok(())
    }

    /// True when chunk (`x`, `z`) belongs to the task (its centre block is inside the shape).
    pub fn contains(&self, x: i32, z: i32) -> bool {
        let dx = i64::from(x) * CHUNK + CHUNK / 2 - self.center_x;
        let dz = i64::from(z) * CHUNK + CHUNK / 2 - self.center_z;
        match self.shape {
            Shape::Square => dx.abs() <= self.radius && dz.abs() <= self.radius,
            Shape::Circle => (dx as i128).pow(2) + (dz as i128).pow(2) <= (self.radius as i128).pow(2),
        }
    }

    /// The chunk range (inclusive) that can hold chunks of the task.
    fn chunk_bounds(&self) -> (i32, i32, i32, i32) {
        let lo = |c: i64| (c - self.radius - CHUNK / 2).div_euclid(CHUNK) as i32;
        let hi = |c: i64| (c + self.radius - CHUNK / 2).div_euclid(CHUNK) as i32 + 1;
        (lo(self.center_x), hi(self.center_x), lo(self.center_z), hi(self.center_z))
    }
}

impl fmt::Display for Task {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} of radius {} around {}, {}", self.shape, self.radius, self.center_x, self.center_z)
    }
}

/// One shard of a batch job: shard `index` of `count` takes every `count`-th region of the
/// order, so shards write disjoint region files and get similar amounts of work.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// 0-based.
    pub index: u32,
    /// At least 1.
    pub count: u32,
}

impl Shard {
    /// The whole task.
    pub const ALL: Shard = Shard { index: 0, count: 1 };
}

impl std::str::FromStr for Shard {
    type Err = String;
    /// `i/N`, 0-based: `0/4` … `3/4`.
    fn from_str(s: &str) -> Result<Shard, String> {
        let bad = || format!("shard {s:?}: expected i/N with 0 <= i < N, e.g. 0/4");
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let (index, count): (u32, u32) = (i.trim().parse().map_err(|_| bad())?, n.trim().parse().map_err(|_| bad())?);
        if count == 0 || index >= count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// The task's chunks in visiting order, addressable by ordinal without listing them all
/// (a 30,000-block radius has 14 million chunks; its plan holds only 14,000 regions).
#[derive(Clone, Debug)]
pub struct Plan {
    task: Task,
    shard: Shard,
    regions: Vec<RegionPos>,
    /// `starts[i]`: ordinal of the first chunk of `regions[i]`; one extra entry = total.
    starts: Vec<u64>,
}

impl Plan {
    /// The plan of `task`, restricted to `shard`.
    pub fn new(task: Task, shard: Shard) -> Plan {
        let (x0, x1, z0, z1) = task.chunk_bounds();
        let (rx0, rx1) = (x0.div_euclid(REGION), x1.div_euclid(REGION));
        let (rz0, rz1) = (z0.div_euclid(REGION), z1.div_euclid(REGION));
        let centre = RegionPos::of_chunk(
            task.center_x.div_euclid(CHUNK).clamp(i32::MIN.into(), i32::MAX.into()) as i32,
            task.center_z.div_euclid(CHUNK).clamp(i32::MIN.into(), i32::MAX.into()) as i32,
        );
        let mut all: Vec<RegionPos> = (rz0..=rz1).flat_map(|z| (rx0..=rx1).map(move |x| RegionPos { x, z })).collect();
        all.sort_by_key(|r| spiral_key(r.x - centre.x, r.z - centre.z));
        let mut regions = Vec::new();
        let mut starts = vec![0u64];
        let mut nth = 0u32;
        for region in all {
            let count = region_chunks(&task, region).len() as u64;
            if count == 0 {
                continue;
            }
            if nth % shard.count == shard.index {
                regions.push(region);
                starts.push(starts.last().copied().unwrap_or(0) + count);
            }
            nth += 1;
        }
        Plan { task, shard, regions, starts }
    }

    /// The task.
    pub fn task(&self) -> Task {
        self.task
    }

    /// The shard.
    pub fn shard(&self) -> Shard {
        self.shard
    }

    /// Chunks in the plan.
    pub fn total(&self) -> u64 {
        self.starts.last().copied().unwrap_or(0)
    }

    /// Region files the plan writes, in order.
    pub fn regions(&self) -> &[RegionPos] {
        &self.regions
    }

    /// The chunk with ordinal `n` (< [`total`](Self::total)).
    pub fn chunk(&self, n: u64) -> (i32, i32) {
        let i = self.region_index(n);
        let chunks = region_chunks(&self.task, self.regions[i]);
        chunks[(n - self.starts[i]) as usize]
    }

    /// Every chunk of region number `i` of the plan, in order (cheaper than `chunk` per chunk).
    pub fn region_chunks(&self, i: usize) -> Vec<(i32, i32)> {
        region_chunks(&self.task, self.regions[i])
    }

    /// Which region of the plan holds ordinal `n`.
    pub fn region_index(&self, n: u64) -> usize {
        self.starts.partition_point(|&s| s <= n).saturating_sub(1)
    }

    /// Ordinal of the first chunk of region number `i`.
    pub fn region_start(&self, i: usize) -> u64 {
        self.starts[i]
    }
}

/// The task's chunks inside `region`, spiralling out from the region's centre.
fn region_chunks(task: &Task, region: RegionPos) -> Vec<(i32, i32)> {
    let (x0, z0) = (region.x * REGION, region.z * REGION);
    let mut chunks: Vec<(i32, i32)> = (z0..z0 + REGION)
        .flat_map(|z| (x0..x0 + REGION).map(move |x| (x, z)))
        .filter(|&(x, z)| task.contains(x, z))
        .collect();
    // Centre of the region between chunks 15 and 16: offsets -16..=15 → rings 0..=15.
    chunks.sort_by_key(|&(x, z)| spiral_key(x - x0 - REGION / 2, z - z0 - REGION / 2));
    chunks
}

/// Sort key walking square rings outwards, each ring clockwise from its top-left corner.
fn spiral_key(dx: i32, dz: i32) -> (u32, u32) {
    let k = dx.unsigned_abs().max(dz.unsigned_abs()) as i64;
    let (dx, dz) = (i64::from(dx), i64::from(dz));
    let along = if dz == -k {
        dx + k
    } else if dx == k {
        2 * k + dz + k
    } else if dz == k {
        4 * k + (k - dx)
    } else {
        6 * k + (k - dz)
    };
    (k as u32, along as u32)
}

#[cfg(test)]
mod tests {
    use std::collections::HashSet;

    use super::*;

    fn task(radius: i64, shape: Shape) -> Task {
        Task { center_x: 100, center_z: -37, radius, shape }
    }

    fn every_chunk(plan: &Plan) -> Vec<(i32, i32)> {
        (0..plan.regions().len()).flat_map(|i| plan.region_chunks(i)).collect()
    }

    #[test]
    fn the_plan_visits_every_chunk_of_the_shape_exactly_once() {
        for shape in [Shape::Square, Shape::Circle] {
            let t = task(700, shape);
            let plan = Plan::new(t, Shard::ALL);
            let chunks = every_chunk(&plan);
            let unique: HashSet<_> = chunks.iter().copied().collect();
            assert_eq!(unique.len(), chunks.len(), "{shape}: a chunk is visited twice");
            assert_eq!(chunks.len() as u64, plan.total());
            // Brute force over a box well beyond the radius.
            let expected: HashSet<_> =
                (-60..70).flat_map(|z| (-60..70).map(move |x| (x, z))).filter(|&(x, z)| t.contains(x, z)).collect();
            assert_eq!(unique, expected, "{shape}");
            for (n, &c) in chunks.iter().enumerate().step_by(97) {
                assert_eq!(plan.chunk(n as u64), c);
            }
        }
        let square = Plan::new(task(700, Shape::Square), Shard::ALL).total();
        let circle = Plan::new(task(700, Shape::Circle), Shard::ALL).total();
        // Chunk centres x·16+8 within 100 ± 700 → x in −38..=49; z·16+8 within −37 ± 700 →
        // z in −46..=40. The circle holds about π/4 of them.
        assert_eq!(square, 88 * 87);
        assert!((circle as f64 / square as f64 - std::f64::consts::FRAC_PI_4).abs() < 0.02, "{circle}");
    }

    #[test]
    fn regions_come_one_after_another_nearest_first() {
        let plan = Plan::new(task(2000, Shape::Square), Shard::ALL);
        let chunks = every_chunk(&plan);
        let mut seen = Vec::new();
        for &(x, z) in &chunks {
            let r = RegionPos::of_chunk(x, z);
            if seen.last() != Some(&r) {
                assert!(!seen.contains(&r), "region {r:?} is entered twice");
                seen.push(r);
            }
        }
        assert_eq!(seen, plan.regions());
        assert_eq!(seen[0], RegionPos::of_chunk(100 / 16, -37i32.div_euclid(16)));
        // Within a region, consecutive chunks are neighbours except when a ring turns a corner
        // or a new ring starts.
        let first = plan.region_chunks(0);
        let far_steps = first.windows(2).filter(|w| (w[0].0 - w[1].0).abs().max((w[0].1 - w[1].1).abs()) > 2).count();
        assert!(far_steps < 20, "{far_steps} jumps in {} chunks", first.len());
    }

    #[test]
    fn shards_split_by_region_file_disjointly_and_completely() {
        let t = task(3000, Shape::Circle);
        let whole: HashSet<_> = every_chunk(&Plan::new(t, Shard::ALL)).into_iter().collect();
        let mut union = HashSet::new();
        let mut files = HashSet::new();
        for index in 0..3 {
            let plan = Plan::new(t, Shard { index, count: 3 });
            assert!(plan.total() > 0);
            for r in plan.regions() {
                assert!(files.insert(*r), "region {r:?} is in two shards");
            }
            for c in every_chunk(&plan) {
                assert!(union.insert(c));
            }
        }
        assert_eq!(union, whole);
    }

    #[test]
    fn shards_and_shapes_parse_with_clear_errors() {
        assert_eq!("2/5".parse::<Shard>(), Ok(Shard { index: 2, count: 5 }));
        for bad in ["5/5", "1/0", "a/2", "3"] {
            let err = bad.parse::<Shard>().unwrap_err();
            assert!(err.contains(bad), "{err}");
        }
        assert_eq!("circle".parse::<Shape>(), Ok(Shape::Circle));
        assert!("round".parse::<Shape>().unwrap_err().contains("round"));
        assert!(task(-1, Shape::Square).validate().unwrap_err().contains("-1"));
    }

    #[test]
    fn a_radius_under_a_chunk_is_the_one_chunk_holding_the_centre_block() {
        let plan = Plan::new(Task { center_x: 5, center_z: 5, radius: 8, shape: Shape::Square }, Shard::ALL);
        assert_eq!(plan.total(), 1);
        assert_eq!(plan.chunk(0), (0, 0));
    }
}
