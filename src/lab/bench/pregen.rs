//! Pre-generation and joining, the whole way: terrain, climate, biomes, blocks, light, NBT,
//! compression and region files, with the same code the server and `infiniterra pregen` run.

use std::sync::Arc;
use std::time::{Duration, Instant};

use valence::prelude::{ChunkPos, ChunkView};

use super::needed::Needed;
use super::Measurement;
use crate::biome::BiomeRules;
use crate::chunkgen::{BiomePalette, Generator, Light};
use crate::config::Config;
use crate::pregen::{run_to_end, Hooks, Job, Plan, Shape, Shard, Task};
use crate::terrain::Pipeline;
use crate::world::codec::Encoder;
use crate::world::{region, ChunkSource, Store};

/// Blocks per region edge.
const REGION_BLOCKS: i64 = 512;

/// Everything a run needs, built fresh (so "cold" is cold).
struct Rig {
    source: Arc<ChunkSource>,
    store: Arc<Store>,
    rules: Arc<BiomeRules>,
    _dir: tempfile::TempDir,
}

impl Rig {
    fn new(config: &Config, rules: &Arc<BiomeRules>) -> anyhow::Result<Rig> {
        let dir = tempfile::tempdir()?;
        let pipeline = Arc::new(Pipeline::build(config.world.seed, &config.terrain())?);
        let generator = Arc::new(Generator::new(pipeline, config));
        let store = Arc::new(Store::open(dir.path())?);
        let source = Arc::new(ChunkSource::new(generator, Arc::new(BiomePalette::vanilla()), Some(store.clone())));
        Ok(Rig { source, store, rules: rules.clone(), _dir: dir })
    }

    /// Runs `task` on `threads` threads to the end; returns the seconds it took.
    fn pregen(&self, config: &Config, task: Task, threads: usize) -> anyhow::Result<(f64, u64)> {
        let plan = Plan::new(task, Shard::ALL);
        let total = plan.total();
        let progress = self._dir.path().join("pregen.json");
        let start = Instant::now();
        let job = Job::start(
            plan,
            config.world.seed,
            self.store.clone(),
            progress,
            0,
            Hooks { report_every: Duration::MAX, report: Box::new(|_| {}), on_work: Box::new(|| {}) },
        )?;
        let status = run_to_end(&job, &self.source, &self.rules, threads);
        if let Some(e) = status.error {
            anyhow::bail!("pre-generation failed: {e}");
        }
        self.store.flush()?;
        Ok((start.elapsed().as_secs_f64(), total))
    }
}

/// The pre-generation suite. `chunks`: size of the throughput run (0 skips it).
pub fn measure(config: &Config, runs: usize, chunks: u64) -> anyhow::Result<Vec<Measurement>> {
    let rules = Arc::new(BiomeRules::load_dir(std::path::Path::new("biomes"))?);
    let threads = config.server.chunk_threads as usize;
    let mut out = Vec::new();

    // Time to the first region file, from nothing: pipeline start-up (layout calibration)
    // included. Each run at a fresh far place.
    let mut first = Vec::new();
    for run in 0..runs as i64 {
        let start = Instant::now();
        let rig = Rig::new(config, &rules)?;
        let rx = 1_000 + run * 97;
        let centre = rx * REGION_BLOCKS + REGION_BLOCKS / 2;
        rig.pregen(config, Task { center_x: centre, center_z: -centre, radius: 256, shape: Shape::Square }, threads)?;
        first.push(start.elapsed().as_secs_f64());
    }
    out.push(Measurement::new("pregen: first region file (1,024 chunks), cold start", "s", first));

    // A player joining a place nobody has been, in a warm server: every chunk of view
    // distance 10, nearest first, on the worker threads (network not included).
    let rig = Rig::new(config, &rules)?;
    let (mut join, mut busy, mut needed) = (Vec::new(), Vec::new(), Needed::default());
    let engine = rig.source.generator().pipeline().engine();
    for run in 0..runs as i32 {
        let centre = ChunkPos::new(-40_000 - run * 1_000, 25_000 + run * 1_000);
        let mut wanted: Vec<ChunkPos> = ChunkView::new(centre, 10).iter().collect();
        wanted.sort_by_key(|p| std::cmp::Reverse(centre.distance_squared(*p)));
        let queue = std::sync::Mutex::new(wanted);
        let (start, cpu, before) = (Instant::now(), cpu_seconds(), engine.function_stats());
        std::thread::scope(|scope| {
            for _ in 0..threads {
                let (queue, rig) = (&queue, &rig);
                scope.spawn(move || {
                    let mut scratch = rig.source.scratch();
                    while let Some(pos) = queue.lock().ok().and_then(|mut q| q.pop()) {
                        rig.source.get(&mut scratch, &rig.rules, pos.x, pos.z);
                    }
                });
            }
        });
        join.push(start.elapsed().as_secs_f64());
        busy.extend(busy_percent(start, cpu));
        needed.add(&before, &engine.function_stats());
    }
    out.push(Measurement::new("join: all 441 chunks of view 10 at a new place, warm server", "s", join));
    // Below 100 %, the join waits on work that one thread does while the others idle.
    out.push(Measurement::new("  how busy the hardware threads were meanwhile", "%", busy));
    out.extend(needed.measurements());

    // Where a chunk's time goes, one thread, chunks in pre-generation order: far east
    // (mostly sea, the same sample as every earlier table), then on land by the spawn, where
    // trees, plants and rivers are.
    let rig = Rig::new(config, &rules)?;
    let generator = rig.source.generator();
    let sea = Task { center_x: 7_000_000, center_z: 0, radius: 160, shape: Shape::Square };
    out.extend(per_chunk(generator, &rules, sea, "per chunk, 1 thread", true));
    let spawn = crate::world::find_spawn(generator, &rules).block;
    let land = Task { center_x: i64::from(spawn.x), center_z: i64::from(spawn.z), radius: 160, shape: Shape::Square };
    out.extend(per_chunk(generator, &rules, land, "per chunk on land by the spawn, 1 thread", false));
    out.extend(super::light::measure(generator, &rules, (spawn.x, spawn.z), "light on land by the spawn, 1 thread"));

    if chunks > 0 {
        // Throughput and memory of a long run: a square of about `chunks` chunks.
        reset_peak_rss();
        let side = (chunks as f64).sqrt().ceil() as i64;
        let rig = Rig::new(config, &rules)?;
        let task = Task { center_x: -3_000_000, center_z: 3_000_000, radius: side * 8, shape: Shape::Square };
        let (seconds, total) = rig.pregen(config, task, threads)?;
        out.push(Measurement::new(
            &format!("pregen: {} chunks, full pipeline + region files, {threads} threads", total),
            "chunks/s",
            vec![total as f64 / seconds],
        ));
        let peak = peak_rss_mib().unwrap_or(f64::NAN);
        out.push(Measurement::new("pregen: peak resident memory during that run", "MiB", vec![peak]));
        // Where a fresh area's time goes: the windows each stage and layer needed for it
        // (the learned core's are the costly ones).
        for f in rig.source.generator().pipeline().engine().function_stats() {
            out.push(Measurement::new(
                &format!("  windows of {} it evaluated", f.name),
                "windows",
                vec![f.windows as f64],
            ));
        }
    }
    Ok(out)
}

/// Where the time of each chunk of `task` goes, one thread, in pre-generation order: the fill
/// and each pass, and with `all`, light, NBT and zlib too. Lines start with `label`.
fn per_chunk(generator: &Generator, rules: &BiomeRules, task: Task, label: &str, all: bool) -> Vec<Measurement> {
    let palette = BiomePalette::vanilla();
    let mut encoder = Encoder::new(generator.vertical().min_y, palette.names().to_vec());
    let plan = Plan::new(task, Shard::ALL);
    let (mut fill, mut light, mut encode, mut compress) = (0.0, 0.0, 0.0, 0.0);
    let mut passes: Vec<(&'static str, f64)> = Vec::new();
    for n in 0..plan.total() {
        let (x, z) = plan.chunk(n);
        let t = Instant::now();
        let (chunk, timings) = generator.chunk_timed(rules, &palette, x, z);
        fill += t.elapsed().as_secs_f64();
        for (i, timing) in timings.iter().enumerate() {
            if passes.len() <= i {
                passes.push((timing.name, 0.0));
            }
            passes[i].1 += timing.nanos as f64 * 1e-9;
        }
        if !all {
            continue;
        }
        let t = Instant::now();
        // Reading the blocks counts with light, as the first to need them.
        let states = chunk.states();
        let sky = Light::of_states(&states);
        light += t.elapsed().as_secs_f64();
        let t = Instant::now();
        // Saved as pre-generation saves it: without light.
        let nbt = encoder.encode_states(x, z, &chunk, &states, None);
        std::hint::black_box(&sky);
        encode += t.elapsed().as_secs_f64();
        let t = Instant::now();
        std::hint::black_box(region::compress(&nbt));
        compress += t.elapsed().as_secs_f64();
    }
    let per = |s: f64| vec![1e3 * s / plan.total() as f64];
    let mut out = vec![Measurement::new(&format!("{label}: terrain + blocks + biomes (fill)"), "ms", per(fill))];
    for (name, seconds) in passes {
        out.push(Measurement::new(&format!("  of which the {name} pass"), "ms", per(seconds)));
    }
    if all {
        out.push(Measurement::new(&format!("{label}: light (sky and block)"), "ms", per(light)));
        out.push(Measurement::new(&format!("{label}: NBT encoding"), "ms", per(encode)));
        out.push(Measurement::new(&format!("{label}: zlib compression"), "ms", per(compress)));
    }
    out
}

/// Resets the kernel's peak-RSS counter (Linux: `echo 5 > /proc/self/clear_refs`), so the
/// peak reported is that of the run that follows.
fn reset_peak_rss() {
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}

/// CPU time this process has used (user and system, all threads), seconds (Linux:
/// `/proc/self/stat`, in the kernel's clock ticks of 1/100 s).
pub fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which may hold spaces, so split after its ')').
    let fields: Vec<&str> = stat.rsplit_once(')')?.1.split_whitespace().collect();
    let ticks = |i: usize| fields.get(i).and_then(|f| f.parse::<f64>().ok());
    // utime and stime are fields 14 and 15 of the line, 12 and 13 after the name.
    Some((ticks(11)? + ticks(12)?) / 100.0)
}

/// How busy the hardware threads were since `start`, when the process had used `cpu`
/// seconds of CPU ([`cpu_seconds`]), % of all of them.
pub fn busy_percent(start: Instant, cpu: Option<f64>) -> Option<f64> {
    let used = cpu_seconds()? - cpu?;
    let hardware = std::thread::available_parallelism().map_or(1, |n| n.get());
    Some(100.0 * used / (start.elapsed().as_secs_f64() * hardware as f64))
}

/// Peak resident memory of this process since start (or the last reset), MiB.
pub fn peak_rss_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}
