//! `infiniterra pregen` as owners and batch engines run it: the real binary writing real
//! region files, killed with SIGKILL and resumed, and read back by Amulet (PyPI
//! `amulet-core`), an Anvil reader that shares no code with ours.
//!
//! Every wait is for a line or an exit; nothing sleeps to synchronise.

use std::collections::BTreeMap;
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Arc;

use infiniterra::biome::BiomeRules;
use infiniterra::config::Config;
use infiniterra::fill::{BiomePalette, Generator};
use infiniterra::pregen::{Plan, Progress, Shape, Shard, State, Task};
use infiniterra::terrain::Pipeline;
use infiniterra::world::find_spawn;
use infiniterra::world::region::{RegionFile, RegionPos};
use serde_json::Value;
use valence::prelude::{BlockState, Chunk};
use valence::registry::RegistryIdx;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A configuration with `seed`, written into `dir`.
fn config(dir: &Path, seed: u64) -> PathBuf {
    let path = dir.join("server.toml");
    std::fs::write(&path, format!("[world]\nseed = {seed}\n")).expect("write config");
    path
}

/// `infiniterra pregen` for the square of `radius` blocks around 0, 0 into `world`.
fn pregen(config: &Path, world: &Path, radius: i64) -> Command {
    pregen_at(config, world, (0, 0), radius)
}

/// `infiniterra pregen` for the square of `radius` blocks around `center` into `world`.
fn pregen_at(config: &Path, world: &Path, center: (i64, i64), radius: i64) -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_infiniterra"));
    command
        .arg("pregen")
        .args(["--config".as_ref(), config.as_os_str()])
        .args(["--world".as_ref(), world.as_os_str()])
        .args(["--center", &format!("{},{}", center.0, center.1)])
        .args(["--radius", &radius.to_string(), "--threads", "2"])
        .arg("--biomes")
        .arg(repo().join("biomes"))
        .stdin(Stdio::null());
    command
}

fn run_to_end(mut command: Command) -> String {
    let out = command.output().expect("run infiniterra pregen");
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "pregen failed: {:?}\n{stdout}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

/// Every saved chunk of a world: (chunk x, z) → its uncompressed NBT.
fn saved_chunks(world: &Path) -> BTreeMap<(i32, i32), Vec<u8>> {
    let mut chunks = BTreeMap::new();
    for entry in std::fs::read_dir(world.join("region")).expect("region folder") {
        let path = entry.expect("entry").path();
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or_default().to_string();
        let region = RegionPos::parse_file_name(&name).unwrap_or_else(|| panic!("stray file {name}"));
        let mut file = RegionFile::open(&path, false).expect("open region");
        for (lx, lz) in file.chunks() {
            let nbt = file.read(lx, lz).expect("readable").expect("present");
            chunks.insert((region.x * 32 + lx as i32, region.z * 32 + lz as i32), nbt);
        }
    }
    chunks
}

#[test]
fn a_killed_pregen_resumes_and_ends_identical_to_an_uninterrupted_one() {
    let dir = tempfile::tempdir().expect("temp dir");
    let config = config(dir.path(), 7);
    // ≈ 6,400 chunks: several seconds even in an optimised build, so the kill lands mid-run.
    let radius = 640;
    let task = Task { center_x: 0, center_z: 0, radius, shape: Shape::Square };
    let total = Plan::new(task, Shard::ALL).total();

    // Run, and SIGKILL it as soon as it has saved some progress (the progress line is
    // printed right after a checkpoint).
    let killed = dir.path().join("killed");
    let mut first = pregen(&config, &killed, radius);
    first.args(["--report-every", "0"]);
    let mut child = first.stdout(Stdio::piped()).spawn().expect("start pregen");
    let stdout = BufReader::new(child.stdout.take().expect("stdout"));
    let mut seen = Vec::new();
    for line in stdout.lines().map_while(Result::ok) {
        let progressed = line.starts_with("pregen: ") && line.contains(" chunks (") && !line.starts_with("pregen: 0/");
        seen.push(line);
        if progressed {
            break;
        }
    }
    child.kill().expect("SIGKILL");
    let status = child.wait().expect("wait");
    assert!(!status.success(), "it finished before it could be killed: {seen:#?}");
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
    let config = config(dir.path(), 7);
    let world = dir.path().join("world");
    run_to_end(pregen(&config, &world, 16));
    // An unfinished task (as a crash leaves it) blocks a different one; a finished one does not.
    let mut unfinished = Progress::load(&world.join("pregen.json")).expect("load").expect("saved");
    unfinished.state = State::Running;
    unfinished.done = 0;
    unfinished.save(&world.join("pregen.json")).expect("save");
    let out = pregen(&config, &world, 48).output().expect("run");
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("pregen.json") && stderr.contains("another task"), "{stderr}");

    unfinished.state = State::Finished;
    unfinished.save(&world.join("pregen.json")).expect("save");
    run_to_end(pregen(&config, &world, 48));

    // A world made with another seed is refused too: its chunks would not match.
    let other = self::config(&dir.path().join("x").tap_mkdir(), 8);
    let out = pregen(&other, &world, 16).output().expect("run");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("seed 7") && stderr.contains("level.dat"), "{stderr}");
}

trait TapMkdir {
    fn tap_mkdir(self) -> PathBuf;
}

impl TapMkdir for PathBuf {
    fn tap_mkdir(self) -> PathBuf {
        std::fs::create_dir_all(&self).expect("mkdir");
        self
    }
}

/// The Python with Amulet that `scripts/test` installs (or the same install, done here when
/// this test runs alone).
fn amulet_python() -> PathBuf {
    if let Some(python) = std::env::var_os("INFINITERRA_PYTHON") {
        return PathBuf::from(python);
    }
    let out = Command::new("bash").arg(repo().join("scripts/pyenv")).output().expect("run scripts/pyenv");
    assert!(out.status.success(), "scripts/pyenv failed: {}", String::from_utf8_lossy(&out.stderr));
    PathBuf::from(String::from_utf8_lossy(&out.stdout).trim())
}

/// "minecraft:name[key=value,…]" with properties sorted, as the Amulet script prints blocks.
fn block_name(state: BlockState) -> String {
    let kind = state.to_kind();
    let mut props: Vec<(String, String)> = kind
        .props()
        .iter()
        .filter_map(|&p| state.get(p).map(|v| (p.to_str().to_string(), v.to_str().to_string())))
        .collect();
    props.sort();
    let mut name = format!("minecraft:{}", kind.to_str());
    if !props.is_empty() {
        let list: Vec<String> = props.into_iter().map(|(k, v)| format!("{k}={v}")).collect();
        name.push_str(&format!("[{}]", list.join(",")));
    }
    name
}

#[test]
fn amulet_reads_the_blocks_and_biomes_we_generate() {
    let dir = tempfile::tempdir().expect("temp dir");
    let config_path = config(dir.path(), 7);
    let world = dir.path().join("world");
    let config = Config::load(&config_path).expect("config");
    let generator = Generator::new(Arc::new(Pipeline::new(7, &config.terrain())), &config);
    let rules = BiomeRules::load_dir(&repo().join("biomes")).expect("rules");
    let palette = BiomePalette::vanilla();
    let min_y = config.world.min_y as i32;
    // Around the spawn, on land (the origin of this seed is open sea): 8×8 chunks.
    let spawn = find_spawn(&generator, &rules);
    let (sx, sz) = (i64::from(spawn.block.x), i64::from(spawn.block.z));
    run_to_end(pregen_at(&config_path, &world, (sx, sz), 64));
    let plan = Plan::new(Task { center_x: sx, center_z: sz, radius: 64, shape: Shape::Square }, Shard::ALL);
    let chunks: Vec<(i32, i32)> = (0..plan.regions().len()).flat_map(|i| plan.region_chunks(i)).collect();
    assert_eq!(chunks.len(), 64);

    // Sampled positions: in every chunk, two columns, each at the surface, just above it
    // (plants, snow, water), a few blocks below it, and at the floor and near the top.
    let mut expected = Vec::new();
    let mut positions = Vec::new();
    for &(cx, cz) in &chunks {
        {
            let chunk = generator.chunk(&rules, &palette, cx, cz);
            for (i, (lx, lz)) in [(3u32, 11u32), (12, 5)].into_iter().enumerate() {
                let (lx, lz) = ((lx + (cx + cz).rem_euclid(4) as u32) % 16, (lz + i as u32) % 16);
                let (x, z) = (cx * 16 + lx as i32, cz * 16 + lz as i32);
                let surface = generator.surface(&rules, x.into(), z.into()).y;
                for y in [min_y, surface - 5, surface, surface + 1, surface + 2, 300] {
                    let ly = (y - min_y) as u32;
                    let block = block_name(chunk.block_state(lx, ly, lz));
                    let biome = palette.names()[chunk.biome(lx / 4, ly / 4, lz / 4).to_index()].clone();
                    positions.push(serde_json::json!([x, y, z]));
                    expected.push((x, y, z, block, biome));
                }
            }
        }
    }

    let mut child = Command::new(amulet_python())
        .arg(repo().join("tests/anvil/read_world.py"))
        .arg(&world)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run the Amulet reader");
    child
        .stdin
        .take()
        .expect("stdin")
        .write_all(Value::Array(positions).to_string().as_bytes())
        .expect("send positions");
    let out = child.wait_with_output().expect("Amulet reader");
    assert!(out.status.success(), "Amulet reader failed: {}", String::from_utf8_lossy(&out.stderr));
    let report: Value = serde_json::from_slice(&out.stdout).expect("JSON from the Amulet reader");
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
    let config = config(dir.path(), 7);
    let world = dir.path().join("world");
    // One region file lives on a "disk" that is always full: Linux's /dev/full answers
    // every write with ENOSPC.
    std::fs::create_dir_all(world.join("region")).expect("mkdir");
    let full = world.join("region").join("r.0.0.mca");
    std::os::unix::fs::symlink("/dev/full", &full).expect("symlink");
    let out = pregen(&config, &world, 48).output().expect("run");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
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
    let config = config(dir.path(), 7);
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

fn region_files(world: &Path) -> Vec<String> {
    let Ok(entries) = std::fs::read_dir(world.join("region")) else { return Vec::new() };
    let mut names: Vec<String> =
        entries.map(|e| e.expect("entry").file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    names
}
