//! `infiniterra pregen` as owners and batch engines run it: the real binary writing real
//! region files, killed with SIGKILL and resumed, and read back by Amulet (PyPI
//! `amulet-core`), an Anvil reader that shares no code with ours.
//!
//! Every wait is for a line or an exit; nothing sleeps to synchronise.

mod common;

use std::path::Path;
use std::process::Command;
use std::time::Duration;

use common::fixtures::{self, find_spawn, BiomePalette};
use common::pregen::{region_files, run_to_end, saved_chunks};
use common::process::{Finished, Process};
use common::{amulet, config};
use infiniterra::pregen::{Plan, Progress, Shape, Shard, State, Task};
use serde_json::Value;
use valence::prelude::Chunk;
use valence::registry::RegistryIdx;

/// How long the first checkpoint of a run may take (a debug build computes the terrain).
const PROGRESS_TIMEOUT: Duration = Duration::from_secs(300);

/// A configuration with `seed`, written into `dir`.
fn write_config(dir: &Path, seed: u64) -> std::path::PathBuf {
    config::write(dir, &config::seed_only(seed))
}

/// `infiniterra pregen` for the square of `radius` blocks around 0, 0 into `world`.
fn pregen(config: &Path, world: &Path, radius: i64) -> Command {
    common::pregen::command(config, world, (0, 0), radius)
}

#[test]
fn a_killed_pregen_resumes_and_ends_identical_to_an_uninterrupted_one() {
    let dir = tempfile::tempdir().expect("temp dir");
    let config = write_config(dir.path(), 7);
    // ≈ 6,400 chunks: several seconds even in an optimised build, so the kill lands mid-run.
    let radius = 640;
    let task = Task { center_x: 0, center_z: 0, radius, shape: Shape::Square };
    let total = Plan::new(task, Shard::ALL).total();

    // Run, and SIGKILL it as soon as it has saved some progress (the progress line is
    // printed right after a checkpoint).
    let killed = dir.path().join("killed");
    let mut first = pregen(&config, &killed, radius);
    first.args(["--report-every", "0"]);
    let mut child = Process::start(first);
    child.expect_line(
        |l| l.starts_with("pregen: ") && l.contains(" chunks (") && !l.starts_with("pregen: 0/"),
        PROGRESS_TIMEOUT,
    );
    let killed_run = child.kill();
    let seen = &killed_run.stdout;
    assert!(!killed_run.success(), "it finished before it could be killed: {seen:#?}");
    let saved = Progress::load(&killed.join("pregen.json")).expect("progress file").expect("progress saved");
    assert_eq!(saved.state, State::Running);
    assert!(saved.done > 0 && saved.done < total, "killed at {} of {total}: {seen:#?}", saved.done);

    // Run the same command again: it resumes and finishes.
    let resumed = run_to_end(pregen(&config, &killed, radius));
    assert!(resumed.contains("resuming after chunk"), "{resumed}");
    assert!(resumed.contains("finished"), "{resumed}");
    let finished = Progress::load(&killed.join("pregen.json")).expect("progress").expect("saved");
    assert_eq!((finished.state, finished.done), (State::Finished, total));
    // A third run has nothing left to do.
    assert!(run_to_end(pregen(&config, &killed, radius)).contains("already finished"));

    let whole = dir.path().join("whole");
    run_to_end(pregen(&config, &whole, radius));

    let (a, b) = (saved_chunks(&killed), saved_chunks(&whole));
    assert_eq!(a.len() as u64, total, "chunks lost or extra after the kill");
    assert_eq!(a.keys().collect::<Vec<_>>(), b.keys().collect::<Vec<_>>());
    for (pos, nbt) in &a {
        assert!(nbt == &b[pos], "chunk {pos:?} differs between the killed and the uninterrupted run");
    }
}

#[test]
fn a_progress_file_of_another_task_is_refused_with_its_name() {
    let dir = tempfile::tempdir().expect("temp dir");
    let config = write_config(dir.path(), 7);
    let world = dir.path().join("world");
    run_to_end(pregen(&config, &world, 16));
    // An unfinished task (as a crash leaves it) blocks a different one; a finished one does not.
    let mut unfinished = Progress::load(&world.join("pregen.json")).expect("load").expect("saved");
    unfinished.state = State::Running;
    unfinished.done = 0;
    unfinished.save(&world.join("pregen.json")).expect("save");
    let out = Finished::run(pregen(&config, &world, 48));
    assert_eq!(out.code(), Some(2));
    let stderr = out.stderr_text();
    assert!(stderr.contains("pregen.json") && stderr.contains("another task"), "{stderr}");

    unfinished.state = State::Finished;
    unfinished.save(&world.join("pregen.json")).expect("save");
    run_to_end(pregen(&config, &world, 48));

    // A world made with another seed is refused too: its chunks would not match.
    let elsewhere = dir.path().join("x");
    std::fs::create_dir_all(&elsewhere).expect("mkdir");
    let other = write_config(&elsewhere, 8);
    let out = Finished::run(pregen(&other, &world, 16));
    let stderr = out.stderr_text();
    assert_eq!(out.code(), Some(2), "{stderr}");
    assert!(stderr.contains("seed 7") && stderr.contains("level.dat"), "{stderr}");
}

#[test]
fn amulet_reads_the_blocks_and_biomes_we_generate() {
    let dir = tempfile::tempdir().expect("temp dir");
    let config_path = write_config(dir.path(), 7);
    let world = dir.path().join("world");
    let config = fixtures::Config::load(&config_path).expect("config");
    let generator = fixtures::generator(&config);
    let rules = fixtures::shipped_rules();
    let palette = BiomePalette::vanilla();
    let min_y = config.world.min_y as i32;
    // Around the spawn, on land (the origin of this seed is open sea): 8×8 chunks.
    let spawn = find_spawn(&generator, &rules);
    let (sx, sz) = (i64::from(spawn.block.x), i64::from(spawn.block.z));
    run_to_end(common::pregen::command(&config_path, &world, (sx, sz), 64));
    let plan = Plan::new(Task { center_x: sx, center_z: sz, radius: 64, shape: Shape::Square }, Shard::ALL);
    let chunks: Vec<(i32, i32)> = (0..plan.regions().len()).flat_map(|i| plan.region_chunks(i)).collect();
    assert_eq!(chunks.len(), 64);

    // Sampled positions: in every chunk, two columns, each at the surface, just above it
    // (plants, snow, water), just and a few blocks below it, at the floor, in the deepslate,
    // and near the top.
    let mut expected = Vec::new();
    let mut positions = Vec::new();
    for &(cx, cz) in &chunks {
        {
            let chunk = generator.chunk(&rules, &palette, cx, cz);
            for (i, (lx, lz)) in [(3u32, 11u32), (12, 5)].into_iter().enumerate() {
                let (lx, lz) = ((lx + (cx + cz).rem_euclid(4) as u32) % 16, (lz + i as u32) % 16);
                let (x, z) = (cx * 16 + lx as i32, cz * 16 + lz as i32);
                let surface = generator.surface(&rules, x.into(), z.into()).y;
                for y in [min_y, min_y + 1, surface - 5, surface - 1, surface, surface + 1, surface + 2, 300] {
                    let ly = (y - min_y) as u32;
                    let block = amulet::block_name(chunk.block_state(lx, ly, lz));
                    let biome = palette.names()[chunk.biome(lx / 4, ly / 4, lz / 4).to_index()].clone();
                    positions.push(serde_json::json!([x, y, z]));
                    expected.push((x, y, z, block, biome));
                }
            }
        }
    }

    let report = amulet::read_world(&world, positions);
    let read = report["positions"].as_array().expect("positions");
    assert_eq!(read.len(), expected.len());
    let mut kinds = std::collections::HashSet::new();
    for (got, (x, y, z, block, biome)) in read.iter().zip(&expected) {
        let at = format!("{x} {y} {z}");
        assert_eq!(got["error"], Value::Null, "{at}: {got}");
        // As stored, and as Amulet translates it to 1.20.1 (which would also catch a block
        // state Minecraft does not know).
        assert_eq!(got["raw_block"].as_str(), Some(block.as_str()), "block at {at}");
        assert_eq!(got["block"].as_str(), Some(block.as_str()), "block at {at}");
        assert_eq!(got["biome"].as_str(), Some(biome.as_str()), "biome at {at}");
        kinds.insert(block.clone());
    }
    // The sample must be varied enough to mean something: air, bedrock, rock, ground, plants…
    assert!(kinds.len() >= 6, "only {kinds:?}");
    let biomes: std::collections::HashSet<_> = expected.iter().map(|e| &e.4).collect();
    assert!(biomes.len() >= 2, "only {biomes:?}");
}

#[test]
fn a_full_disk_pauses_the_task_with_the_reason_and_a_rerun_finishes_it() {
    let dir = tempfile::tempdir().expect("temp dir");
    let config = write_config(dir.path(), 7);
    let world = dir.path().join("world");
    // One region file lives on a "disk" that is always full: Linux's /dev/full answers
    // every write with ENOSPC.
    std::fs::create_dir_all(world.join("region")).expect("mkdir");
    let full = world.join("region").join("r.0.0.mca");
    std::os::unix::fs::symlink("/dev/full", &full).expect("symlink");
    let out = Finished::run(pregen(&config, &world, 48));
    let stderr = out.stderr_text();
    assert_eq!(out.code(), Some(1), "{stderr}");
    assert!(stderr.contains("paused") && stderr.contains("r.0.0.mca"), "{stderr}");
    assert!(stderr.contains("No space left on device"), "{stderr}");
    let saved = Progress::load(&world.join("pregen.json")).expect("progress").expect("saved");
    assert_eq!(saved.state, State::Paused);
    assert!(saved.error.as_deref().is_some_and(|e| e.contains("No space left")), "{saved:?}");

    // Space is back: the same command finishes the task, every chunk readable.
    std::fs::remove_file(&full).expect("remove");
    let done = run_to_end(pregen(&config, &world, 48));
    assert!(done.contains("finished"), "{done}");
    let total = Plan::new(Task { center_x: 0, center_z: 0, radius: 48, shape: Shape::Square }, Shard::ALL).total();
    assert_eq!(saved_chunks(&world).len() as u64, total);
}

#[test]
fn shards_write_disjoint_region_files_that_together_equal_the_whole_task() {
    let dir = tempfile::tempdir().expect("temp dir");
    let config = write_config(dir.path(), 7);
    let (sharded, whole) = (dir.path().join("sharded"), dir.path().join("whole"));
    let mut files_of = Vec::new();
    for shard in ["0/2", "1/2"] {
        let before: Vec<_> = region_files(&sharded);
        let mut command = pregen(&config, &sharded, 300);
        command.args(["--shard", shard]);
        run_to_end(command);
        let after = region_files(&sharded);
        let new: Vec<_> = after.iter().filter(|f| !before.contains(f)).cloned().collect();
        assert!(!new.is_empty(), "shard {shard} wrote nothing");
        files_of.push(new);
    }
    assert!(sharded.join("pregen-0-of-2.json").is_file() && sharded.join("pregen-1-of-2.json").is_file());
    assert!(files_of[0].iter().all(|f| !files_of[1].contains(f)), "shards share a region file");
    run_to_end(pregen(&config, &whole, 300));
    assert!(saved_chunks(&sharded) == saved_chunks(&whole), "the shards' union differs from the whole task");
}

#[test]
fn amulet_finds_ores_at_vanilla_depths_dry_caves_and_lava_deep_down() {
    let dir = tempfile::tempdir().expect("temp dir");
    let config_path = write_config(dir.path(), 1);
    let world = dir.path().join("world");
    // Inland foothills of the default world (140 km east, 48 km north of the origin).
    let (x, z) = (140_000 / 40, -48_000 / 40);
    run_to_end(common::pregen::command(&config_path, &world, (x, z), 64));
    let (cx, cz) = ((x / 16) as i32, (z / 16) as i32);
    let c = amulet::census(&world, (cx - 3, cz - 3), (cx + 2, cz + 2));
    println!("census: {c}");
    let ores = &c["ores"];
    // Vanilla 1.20.1's ranges (Minecraft Wiki, "Ore"), a vein's reach (4 blocks) around them.
    for (ore, lo, hi) in [
        ("coal", 0, 320),
        ("iron", -64, 384),
        ("copper", -16, 112),
        ("gold", -64, 32),
        ("redstone", -64, 15),
        ("lapis", -64, 64),
        ("diamond", -64, 16),
    ] {
        let (plain, deep) = (&ores[format!("{ore}_ore")], &ores[format!("deepslate_{ore}_ore")]);
        let blocks = plain["blocks"].as_i64().unwrap_or(0) + deep["blocks"].as_i64().unwrap_or(0);
        assert!(blocks > 0, "no {ore} in 36 chunks: {ores}");
        for v in [plain, deep].into_iter().filter(|v| !v.is_null()) {
            let (min, max) = (v["min_y"].as_i64().expect("min_y"), v["max_y"].as_i64().expect("max_y"));
            assert!(min >= lo - 4 && max <= hi + 4, "{ore} at Y {min}..{max}, vanilla {lo}..{hi}");
        }
        // Deepslate variants in the deepslate: at and below Y 0, ragged up to Y 8 (vanilla's
        // gradient); plain ones above Y 0.
        assert!(deep.is_null() || deep["max_y"].as_i64() < Some(8), "{deep}");
        assert!(plain.is_null() || plain["min_y"].as_i64() > Some(0), "{plain}");
    }
    let (below, air) = (c["below_ground"].as_i64().expect("below"), c["cave_air"].as_i64().expect("air"));
    assert!(air * 100 > below && air * 5 < below, "cave air {air} of {below} blocks under the ground");
    assert!(c["lava"].as_i64() > Some(0), "no lava deep down");
    assert!(c["land_columns_away_from_sea"].as_i64() > Some(1000), "{c}");
    assert_eq!(c["water_below_ground_away_from_sea"], 0, "water under dry land: {c}");
}
