//! End to end: a real `infiniterra serve` process, real Minecraft 1.20.1 clients (mineflayer,
//! in `tests/e2e/`), and the same world computed in this process to compare with.
//!
//! Every wait is for a line or an exit, bounded by a timeout; nothing sleeps to synchronise.

mod common;

use std::path::Path;
use std::time::Instant;

use common::config::{self, VIEW};
use common::fixtures::{self, find_spawn, generator, short, BiomeRules, Config, Generator};
use common::process::{self, Finished};
use common::server::{Server, LINE_TIMEOUT, START_TIMEOUT};
use common::{free_port, repo};
use serde_json::Value;
use valence::prelude::{BlockState, ChunkPos, ChunkView};

/// Asserts every column the surveyor reported is what `generator` computes with `rules` (top
/// block, its Y, biome, sky light); returns how many were land.
fn assert_surveyed_columns(report: &Value, columns: &[(i64, i64)], generator: &Generator, rules: &BiomeRules) -> usize {
    let v = *generator.vertical();
    let seen = report["columns"].as_array().expect("columns");
    assert_eq!(seen.len(), columns.len());
    let mut land = 0;
    for (c, &(x, z)) in seen.iter().zip(columns) {
        let s = generator.surface(rules, x, z);
        let y = c["y"].as_i64().expect("y");
        if s.y >= v.water_top_y() {
            land += 1;
        }
        if let Some(water) = s.water_y {
            assert!(water > s.y, "water over the ground at ({x}, {z}): {c}");
            if c["covered"] == true && y < i64::from(water) {
                // Mangrove roots (a tree part, which the probe looks through) stand in the
                // water from its surface down, waterlogged: under them is more water or the bed.
                assert!(y >= i64::from(s.y), "under the roots at ({x}, {z}): {c}");
                if y == i64::from(s.y) {
                    assert_eq!(c["block"], s.top, "the bed under the roots at ({x}, {z})");
                } else {
                    assert!(matches!(c["block"].as_str(), Some("water" | "ice")), "{c}");
                }
                continue;
            }
            // Sea, river or lake: the water's surface is the top (a river may have cut its bed
            // below sea level near the coast, its surface still above it).
            assert_eq!(y, i64::from(water), "water surface at ({x}, {z}): {c}");
            assert!(matches!(c["block"].as_str(), Some("water" | "ice")), "{c}");
            // One level less per block of water or ice; under one block of water the block
            // below its surface is the (dark) bed.
            assert_eq!(c["sky_light_above"], 15, "{c}");
            assert_eq!(c["sky_light_at"], 14, "{c}");
            let below = if s.y < water - 1 { 13 } else { 0 };
            assert_eq!(c["sky_light_below"], below, "{c}");
        } else {
            assert!(s.y >= v.water_top_y(), "a column under sea level holds water: ({x}, {z}): {c}");
            assert_eq!(y, i64::from(s.y), "top of column ({x}, {z}): {c}");
            assert_eq!(c["block"], s.top, "ground block of ({x}, {z})");
            assert_eq!(c["biome"], short(&s.biome), "biome at ({x}, {}, {z})", s.y);
            // Sky light: open sky above the ground (unless a tree shades it), dark inside it.
            if c["covered"] == false {
                assert_eq!(c["sky_light_above"], 15, "{c}");
            }
            assert_eq!(c["sky_light_at"], 0, "{c}");
        }
    }
    land
}

/// Columns every 7 blocks in a 43×43 square around a spawn, and their `--columns` argument.
fn columns_around(spawn: (i64, i64)) -> (Vec<(i64, i64)>, String) {
    let mut columns = Vec::new();
    for dz in (-21..=21).step_by(7) {
        for dx in (-21..=21).step_by(7) {
            columns.push((spawn.0 + dx, spawn.1 + dz));
        }
    }
    let list = columns.iter().map(|(x, z)| format!("{x},{z}")).collect::<Vec<_>>().join(";");
    (columns, list)
}

#[test]
fn the_shipped_learned_core_stage_serves_the_terrain_this_process_computes() {
    // The engine section of the shipped configuration, with the shipped weights.
    let shipped = fixtures::shipped_config();
    assert!(shipped.engine.learned.iter().any(|s| s == "core"), "the shipped config runs the learned core");
    let biomes = fixtures::shipped_biomes();
    let keep = tempfile::tempdir().expect("temp dir");
    let world = config::world_directory(&keep.path().join("world"))
        + &config::learned_engine(&["core"], &fixtures::shipped_models());
    let mut server = Server::start_with(&biomes, 7, &world);
    let rules = fixtures::rules(&biomes);
    assert!(
        server.stdout_seen(|l| l.starts_with("terrain: learned stages core from")),
        "the start-up log says the learned core runs"
    );
    // Built here with one engine thread (the server runs two): the same bits whatever the
    // thread count.
    let pipeline = fixtures::learned_pipeline(&server.config, &["core"], 1);
    assert!(pipeline.active_stages().iter().any(|s| s == "core"), "{:?}", pipeline.active_stages());
    let generator = fixtures::generator_with(pipeline, &server.config);
    let spawn = find_spawn(&generator, &rules);
    let (columns, list) = columns_around((i64::from(spawn.block.x), i64::from(spawn.block.z)));
    let expected_chunks = ChunkView::new(ChunkPos::new(0, 0), VIEW).iter().count();
    let report =
        server.probe("surveyor", &["--columns".into(), list, "--expect-chunks".into(), expected_chunks.to_string()]);
    assert_eq!(report["spawn"]["y"].as_f64(), Some(spawn.feet.y), "{report}");
    let land = assert_surveyed_columns(&report, &columns, &generator, &rules);
    assert!(land > 0, "no land column sampled around the spawn");
    server.expect_line(|l| l == "surveyor left", LINE_TIMEOUT);
    assert!(server.stop().success());
}

#[test]
fn a_player_spawns_on_land_and_sees_the_terrain_the_pipeline_describes() {
    let biomes = fixtures::shipped_biomes();
    let mut server = Server::start(&biomes, 1);
    assert!(
        server.stdout_seen(|l| l.starts_with("terrain: procedural layout only")),
        "no [engine] learned: procedural"
    );
    let rules = fixtures::rules(&biomes);
    let generator = generator(&server.config);
    let v = *generator.vertical();
    let spawn = find_spawn(&generator, &rules);

    let (columns, list) = columns_around((i64::from(spawn.block.x), i64::from(spawn.block.z)));
    let expected_chunks = ChunkView::new(ChunkPos::new(0, 0), VIEW).iter().count();
    let report =
        server.probe("surveyor", &["--columns".into(), list, "--expect-chunks".into(), expected_chunks.to_string()]);
    println!(
        "join: spawned after {} ms, all {expected_chunks} chunks of view distance {VIEW} after {} ms",
        report["spawn_ms"], report["all_chunks_ms"]
    );

    // (a) spawned where the server said, landed on solid ground above the sea.
    assert_eq!(report["spawn"]["x"].as_f64(), Some(spawn.feet.x), "{report}");
    assert_eq!(report["spawn"]["z"].as_f64(), Some(spawn.feet.z), "{report}");
    assert_eq!(report["spawn"]["y"].as_f64(), Some(spawn.feet.y), "{report}");
    assert_eq!(report["game_mode"], "creative");
    assert_eq!(report["min_y"].as_i64(), Some(i64::from(v.min_y)));
    assert_eq!(report["height"].as_i64(), Some(i64::from(v.height)));
    assert_eq!(report["on_ground"], true);
    let below = report["below"].as_str().unwrap_or("");
    assert!(!matches!(below, "water" | "air" | "ice" | "powder_snow" | "lava"), "landed on {below}");
    assert_eq!(report["below_y"].as_i64(), Some(i64::from(spawn.block.y)), "{report}");
    assert!(spawn.block.y >= v.sea_level_y, "spawn ground Y {} is below the sea", spawn.block.y);
    // On the ground block (mud and the like are a little lower than a full block).
    let feet = report["position"]["y"].as_f64().unwrap_or(f64::NAN);
    let ground_top = f64::from(spawn.block.y) + 1.0;
    assert!(feet > ground_top - 0.5 && feet <= ground_top, "feet at {feet}, ground block top at {ground_top}");

    // (b) every sampled column is what the pipeline + vertical mapping + rules say (the
    // ground under any tree).
    let land = assert_surveyed_columns(&report, &columns, &generator, &rules);
    assert!(land > 0, "no land column sampled around the spawn");

    server.expect_line(|l| l == "surveyor left", LINE_TIMEOUT);
    server.command("status");
    let players = server.expect_line(|l| l.starts_with("players:"), LINE_TIMEOUT);
    assert!(players.starts_with("players: 0"), "{players}");
    server.expect_line(|l| l.starts_with("chunks:") && l.contains("generated/s"), LINE_TIMEOUT);
    server.expect_line(|l| l.starts_with("queue:") && l.contains("cached"), LINE_TIMEOUT);
    server.expect_line(|l| l.starts_with("memory:") && l.contains("MiB"), LINE_TIMEOUT);
    server.command("seed");
    server.expect_line(|l| l == "seed 1", LINE_TIMEOUT);
    server.command("frobnicate");
    server.expect_line(|l| l.contains("unknown command") && l.contains("help"), LINE_TIMEOUT);
    assert!(server.stop().success());
}

#[test]
fn a_player_by_a_river_sees_its_water_and_the_river_biome() {
    let biomes = fixtures::shipped_biomes();
    let rules = fixtures::rules(&biomes);
    // The first seed whose spawn has a river within 40 blocks (rivers follow the terrain, so
    // the test looks for one rather than naming a place).
    let (seed, generator, river) = (1..=40u64)
        .find_map(|seed| {
            let generator = generator(&fixtures::seeded_config(seed));
            let spawn = find_spawn(&generator, &rules);
            let river =
                fixtures::river_columns_near(&generator, (i64::from(spawn.block.x), i64::from(spawn.block.z)), 40);
            (river.len() >= 8).then_some((seed, generator, river))
        })
        .expect("no seed of 1..=40 has a river within 40 blocks of its spawn");
    // Every fourth river column, at most 24.
    let sample: Vec<(i64, i64, i32)> = river.iter().step_by((river.len() / 24).max(1)).copied().take(24).collect();
    let list: String = sample.iter().map(|(x, z, _)| format!("{x},{z};")).collect();
    let mut server = Server::start(&biomes, seed);
    let report = server.probe("wader", &["--columns".into(), list]);
    let columns = report["columns"].as_array().unwrap_or_else(|| panic!("no columns: {report}"));
    assert_eq!(columns.len(), sample.len(), "{report}");
    for (column, &(x, z, top)) in columns.iter().zip(&sample) {
        assert_eq!((column["x"].as_i64(), column["z"].as_i64()), (Some(x), Some(z)), "{column}");
        let block = column["block"].as_str().unwrap_or("");
        assert!(block == "water" || block == "ice", "({x}, {z}) river column shows {block}: {column}");
        assert_eq!(column["y"].as_i64(), Some(i64::from(top)), "({x}, {z}) water top: {column}");
        let biome = column["biome"].as_str().unwrap_or("");
        assert!(biome == "river" || biome == "frozen_river", "({x}, {z}) biome {biome}: {column}");
    }
    println!("seed {seed}: {} river columns by the spawn, {} checked", river.len(), sample.len());
    drop(generator);
    assert!(server.stop().success());
}

#[test]
fn garbage_and_wrong_versions_are_refused_and_players_still_join() {
    let mut server = Server::start(&fixtures::shipped_biomes(), 2);
    let report = server.node("garbage.js", &[]);
    for probe in ["varint_overflow", "http_request", "random_bytes"] {
        assert_eq!(report[probe]["closed"], true, "{probe}: {report}");
    }
    assert_eq!(report["wrong_version"]["kicked"], true, "{report}");
    assert_eq!(report["wrong_version"]["reached_play"], false, "{report}");
    assert!(report["wrong_version"]["reason"].to_string().contains("1.20.1"), "{report}");

    let player = server.probe("after_garbage", &[]);
    assert_eq!(player["on_ground"], true);
    // A second player after the first left: the server survived a disconnect too.
    server.probe("second", &[]);
    assert!(server.stop().success());
}

#[test]
fn reload_keeps_the_old_rules_on_error_and_applies_good_rules_to_new_chunks() {
    let dir = tempfile::tempdir().expect("temp dir");
    let biomes = dir.path().join("biomes");
    common::copy_files(&fixtures::shipped_biomes(), &biomes);
    // Saved chunks keep the rules they were made with; with saving off, a revisited place is
    // generated again and so follows the new rules, which is what this test looks at.
    let mut server = Server::start_with(&biomes, 3, "save_chunks = false\n");
    let generator = generator(&server.config);
    let rules = fixtures::rules(&biomes);
    let spawn = find_spawn(&generator, &rules);
    let (x, z) = (i64::from(spawn.block.x), i64::from(spawn.block.z));
    let column = vec!["--columns".to_string(), format!("{x},{z}")];
    let before = generator.surface(&rules, x, z);
    assert_ne!(before.biome, "minecraft:desert", "pick a seed whose spawn is not already desert");

    let report = server.probe("first", &column);
    assert_eq!(report["columns"][0]["biome"], short(&before.biome));

    // A broken file: the old rules stay, and say why.
    std::fs::write(biomes.join("zz_broken.toml"), "[[rule]]\nname = \"oops\"\nbiome = \n").expect("write");
    server.command("reload");
    let failed = server.expect_line(|l| l.starts_with("reload"), LINE_TIMEOUT);
    assert!(failed.contains("failed") && failed.contains("zz_broken.toml"), "{failed}");
    // A broken vegetation table is refused the same way, naming its line and biome.
    std::fs::write(biomes.join("zz_broken.toml"), "\n[vegetation.\"minecraft:stony_peaks\"]\ntrees = 2\n")
        .expect("write");
    server.command("reload");
    let failed = server.expect_line(|l| l.starts_with("reload"), LINE_TIMEOUT);
    let said = "zz_broken.toml:3: vegetation for \"minecraft:stony_peaks\": `trees` must be from 0 to 1, not 2";
    assert!(failed.contains("failed") && failed.contains(said), "{failed}");
    let report = server.probe("second", &column);
    assert_eq!(report["columns"][0]["biome"], short(&before.biome));
    // Chunks on screen keep the rules they were built with: let them go first.
    server.expect_line(|l| l == "second left", LINE_TIMEOUT);

    // Good rules that make everything desert: new chunks follow them.
    for entry in std::fs::read_dir(&biomes).expect("read") {
        std::fs::remove_file(entry.expect("entry").path()).expect("remove");
    }
    std::fs::write(biomes.join("all.toml"), "fallback = \"minecraft:desert\"\n").expect("write");
    server.command("reload");
    let reloaded = server.expect_line(|l| l.starts_with("reload"), LINE_TIMEOUT);
    assert!(reloaded.starts_with("reloaded"), "{reloaded}");
    let report = server.probe("third", &column);
    assert_eq!(report["columns"][0]["biome"], "desert", "{report}");
    assert!(server.stop().success());
}

#[test]
fn start_up_problems_exit_with_a_message_and_the_documented_code() {
    let dir = tempfile::tempdir().expect("temp dir");
    let run_with = |text: &str, biomes: &Path| {
        let config = config::write(dir.path(), text);
        let args = ["serve".as_ref(), "--config".as_ref(), config.as_os_str(), "--biomes".as_ref(), biomes.as_os_str()];
        let out = Finished::run(process::infiniterra(&repo(), args));
        (out.code(), out.stderr_text())
    };
    let run = |bind: &str, biomes: &Path| run_with(&format!("[server]\nbind = \"{bind}\"\n"), biomes);
    let biomes = fixtures::shipped_biomes();

    let (code, stderr) = run("127.0.0.1:25565", &dir.path().join("no-such-dir"));
    assert_eq!(code, Some(2), "{stderr}");
    assert!(stderr.contains("no-such-dir"), "{stderr}");

    let (code, stderr) = run("127.0.0.1:0", &biomes);
    assert_eq!(code, Some(2), "{stderr}");
    assert!(stderr.contains("port 0"), "{stderr}");

    let taken = std::net::TcpListener::bind("127.0.0.1:0").expect("bind");
    let address = taken.local_addr().expect("address").to_string();
    let (code, stderr) = run(&address, &biomes);
    assert_eq!(code, Some(1), "{stderr}");
    assert!(stderr.contains("cannot listen on") && stderr.contains(&address), "{stderr}");
    drop(taken);

    // A learned stage without its weights (or without the learned-model code in this build):
    // refused at start-up, naming what is missing.
    let none = dir.path().join("none").display().to_string();
    let text =
        format!("[server]\nbind = \"127.0.0.1:{}\"\n[engine]\nlearned = [\"core\"]\nmodels = {none:?}\n", free_port());
    let (code, stderr) = run_with(&text, &biomes);
    assert_eq!(code, Some(2), "{stderr}");
    assert!(
        stderr.contains("core") && (stderr.contains("--no-default-features") || stderr.contains("core.json")),
        "{stderr}"
    );
}

#[test]
fn a_flying_player_has_every_chunk_of_its_final_view() {
    let mut server = Server::start(&fixtures::shipped_biomes(), 4);
    let started = Instant::now();
    // The client asks for more than the server's cap: the view it gets is the cap's.
    let args = ["--name", "flyer", "--view", "6", "--cap", &VIEW.to_string(), "--distance", "500", "--speed", "25"];
    let report = server.node("fly.js", &args.iter().map(|s| s.to_string()).collect::<Vec<_>>());
    println!(
        "flight: {} ms for 500 blocks, {} chunks during it, {} missing on arrival, all in view {} ms later; \
         {} ms in all",
        report["flight_ms"],
        report["flight_packets"],
        report["missing_on_arrival"],
        report["settle_ms"],
        started.elapsed().as_millis()
    );
    if report["ok"] != Value::Bool(true) {
        server.fail(&format!("the flight failed: {report}"));
    }
    let start_x = report["start"]["x"].as_f64().expect("start x");
    let final_x = report["final"]["x"].as_f64().expect("final x");
    assert!((final_x - start_x - 500.0).abs() < 1e-6, "flew from {start_x} to {final_x}");
    // The script waited until no position of the capped view was missing; check it here against
    // valence's own view too.
    let chunk = &report["final"]["chunk"];
    let centre = ChunkPos::new(chunk[0].as_i64().expect("x") as i32, chunk[1].as_i64().expect("z") as i32);
    assert_eq!(centre.x, (final_x / 16.0).floor() as i32);
    let view = ChunkView::new(centre, VIEW);
    assert_eq!(report["final_view"].as_u64(), Some(view.iter().count() as u64), "{report}");
    // Nothing beyond the capped view is held (the server unloaded what the flight left behind).
    assert!(report["loaded"].as_u64() >= Some(view.iter().count() as u64), "{report}");
    assert!(report["loaded"].as_u64() <= Some(ChunkView::new(centre, VIEW + 1).iter().count() as u64), "{report}");
    // 500 blocks is 31 chunks: the view was refilled along the way.
    assert!(report["ever_loaded"].as_u64() > Some(view.iter().count() as u64 + 31 * 9), "{report}");
    server.expect_line(|l| l == "flyer left", LINE_TIMEOUT);
    assert!(server.stop().success());
}

#[test]
fn twenty_players_joining_and_leaving_repeatedly_leave_no_chunks_behind() {
    const BOTS: usize = 20;
    const ROUNDS: usize = 3;
    let mut server = Server::start(&fixtures::shipped_biomes(), 5);
    let (_, _, baseline, _) = server.queue();
    assert_eq!(baseline, 0, "chunks loaded before anyone joined");

    let started = Instant::now();
    let args = ["--bots", &BOTS.to_string(), "--rounds", &ROUNDS.to_string(), "--view", "2", "--stagger", "50"];
    let report = server.node("churn.js", &args.iter().map(|s| s.to_string()).collect::<Vec<_>>());
    println!("churn: {report} in {} ms", started.elapsed().as_millis());
    if report["ok"] != Value::Bool(true) {
        server.fail(&format!("churn failed: {report}"));
    }
    for _ in 0..BOTS * ROUNDS {
        server.expect_line(|l| l.starts_with("churn_") && l.ends_with(" left"), LINE_TIMEOUT);
    }

    // Everyone left: the tick after the last leaves, their chunks are unloaded. Ask until the
    // loaded count is back to the baseline (each answer is a line; the wait is bounded).
    let deadline = Instant::now() + LINE_TIMEOUT;
    let (mut waiting, mut loaded, mut cached);
    loop {
        (waiting, _, loaded, cached) = server.queue();
        if loaded == baseline || Instant::now() > deadline {
            break;
        }
    }
    assert_eq!(loaded, baseline, "chunks still loaded after every player left");
    assert_eq!(waiting, 0, "chunks still wanted after every player left");
    assert!(
        cached <= server.config.server.chunk_cache,
        "{cached} cached, the cap is {}",
        server.config.server.chunk_cache
    );
    assert!(cached > 0, "the chunks players saw were not kept for revisits");

    // Still serving: one more player joins, and the process is alive.
    server.probe("after_churn", &[]);
    assert!(server.process.running(), "the server exited");
    assert!(server.stop().success());
}

/// Runs `infiniterra pregen` (the batch command) with `config`'s seed around `center`.
fn batch_pregen(config: &Config, world: &Path, center: (i64, i64), radius: i64) {
    let dir = tempfile::tempdir().expect("temp dir");
    let config_path = config::write(dir.path(), &config::seed_only(config.world.seed));
    common::pregen::run_to_end(common::pregen::command(&config_path, world, center, radius));
}

/// Sets block (`at`, `y`) of saved chunk `chunk` to `block`, as an editor such as Amulet would.
fn edit_block(world: &Path, generator: &Generator, chunk: (i32, i32), at: (i64, i64), y: i32, block: BlockState) {
    use fixtures::{BiomePalette, Light};
    use infiniterra::world::codec::{Decoder, Encoder};
    use infiniterra::world::region::{compress, local, RegionFile, RegionPos};
    use valence::prelude::Chunk;
    let v = generator.vertical();
    let palette = std::sync::Arc::new(BiomePalette::vanilla());
    let path = world.join("region").join(RegionPos::of_chunk(chunk.0, chunk.1).file_name());
    let mut file = RegionFile::open(&path, false).expect("open region");
    let (lx, lz) = local(chunk.0, chunk.1);
    let nbt = file.read(lx, lz).expect("readable").expect("saved");
    let mut blocks =
        Decoder::new(v.min_y, v.height as u32, palette.clone()).decode(chunk.0, chunk.1, &nbt).expect("decode");
    let (bx, bz) = (at.0.rem_euclid(16) as u32, at.1.rem_euclid(16) as u32);
    blocks.set_block_state(bx, (y - v.min_y) as u32, bz, block);
    let nbt =
        Encoder::new(v.min_y, palette.names().to_vec()).encode(chunk.0, chunk.1, &blocks, Some(&Light::of(&blocks)));
    file.write(lx, lz, &compress(&nbt), 0).expect("write");
    file.sync().expect("sync");
}

#[test]
fn saved_chunks_are_loaded_and_a_corrupt_one_is_reported_and_served_regenerated() {
    use infiniterra::world::region::{local, RegionFile, RegionPos};
    let seed = 6;
    let keep = tempfile::tempdir().expect("temp dir");
    let world = keep.path().join("world");
    let config = fixtures::seeded_config(seed);
    let rules = fixtures::shipped_rules();
    let generator = generator(&config);
    let spawn = find_spawn(&generator, &rules);
    let (sx, sz) = (i64::from(spawn.block.x), i64::from(spawn.block.z));
    batch_pregen(&config, &world, (sx, sz), 96);

    // Garbage over the compressed bytes of the spawn chunk, length and header left alone.
    let (cx, cz) = (spawn.block.x.div_euclid(16), spawn.block.z.div_euclid(16));
    let path = world.join("region").join(RegionPos::of_chunk(cx, cz).file_name());
    let (lx, lz) = local(cx, cz);
    let original = RegionFile::open(&path, false).expect("open").read(lx, lz).expect("readable").expect("saved");
    let mut bytes = std::fs::read(&path).expect("read region");
    let entry = 4 * (lx + lz * 32);
    let sector = u32::from_be_bytes(bytes[entry..entry + 4].try_into().expect("4 bytes")) >> 8;
    let data = sector as usize * 4096 + 5;
    bytes[data..data + 200].fill(0xAB);
    std::fs::write(&path, &bytes).expect("write region");
    assert!(RegionFile::open(&path, false).expect("open").read(lx, lz).is_err(), "the chunk still reads");

    // And an edit by another tool in the chunk east of it: a gold block on top of one column.
    // Seeing it proves saved chunks are loaded, not generated again.
    let (ex, ez) = (cx + 1, cz);
    let edited = (i64::from(ex) * 16 + 5, i64::from(ez) * 16 + 9);
    let gold_y = generator.surface(&rules, edited.0, edited.1).y.max(generator.vertical().water_top_y()) + 1;
    edit_block(&world, &generator, (ex, ez), edited, gold_y, BlockState::GOLD_BLOCK);

    let mut server = Server::start_with(&fixtures::shipped_biomes(), seed, &config::world_directory(&world));
    let mut columns: Vec<(i64, i64)> = (0..16).map(|i| (cx as i64 * 16 + i, cz as i64 * 16 + 15 - i)).collect();
    columns.push(edited);
    let list = columns.iter().map(|(x, z)| format!("{x},{z}")).collect::<Vec<_>>().join(";");
    let report = server.probe("inspector", &["--columns".into(), list]);
    let seen = report["columns"].as_array().expect("columns");
    let gold = seen.last().expect("the edited column");
    assert_eq!((gold["block"].as_str(), gold["y"].as_i64()), (Some("gold_block"), Some(i64::from(gold_y))), "{gold}");
    columns.pop();
    let line = server.expect_line(|l| l.starts_with("corrupt chunk"), LINE_TIMEOUT);
    assert!(line.starts_with(&format!("corrupt chunk {cx}, {cz}:")) && line.contains("regenerated"), "{line}");
    assert!(line.contains(&RegionPos::of_chunk(cx, cz).file_name()), "{line}");
    let v = *generator.vertical();
    for (c, &(x, z)) in seen.iter().zip(&columns) {
        let s = generator.surface(&rules, x, z);
        let expected_y = if s.y >= v.water_top_y() { s.y } else { v.water_top_y() };
        assert_eq!(c["y"].as_i64(), Some(i64::from(expected_y)), "column ({x}, {z}): {c}");
        if s.y >= v.water_top_y() {
            assert_eq!(c["block"], s.top, "ground block of ({x}, {z})");
        }
    }
    assert!(server.stop().success());
    // The regenerated chunk was saved over the broken one, identical to the original.
    let repaired = RegionFile::open(&path, false).expect("open").read(lx, lz).expect("readable").expect("saved");
    assert!(repaired == original, "the regenerated chunk differs from the one first saved");
}

#[test]
fn console_pregen_starts_pauses_continues_cancels_finishes_and_resumes_after_a_restart() {
    use infiniterra::pregen::{Plan, Progress, Shape, Shard, State, Task};
    use infiniterra::world::region::{local, RegionFile, RegionPos};
    let seed = 9;
    let keep = tempfile::tempdir().expect("temp dir");
    let world = keep.path().join("world");
    let biomes = fixtures::shipped_biomes();
    let mut server = Server::start_with(&biomes, seed, &config::world_directory(&world));
    // A running task also reports its progress every few seconds, unasked ("pregen: 1,351/141,376
    // chunks (1.0%), 568 chunks/s, ETA …"): a command's answer is the next pregen line that is not
    // such a report.
    let running_report = |l: &str| {
        l.strip_prefix("pregen: ").is_some_and(|r| r.starts_with(|c: char| c.is_ascii_digit()))
            && l.contains(" chunks/s")
            && !l.contains(", paused")
            && !l.contains(", finished")
    };
    let pregen_line = |l: &str| l.starts_with("pregen") && !running_report(l);

    server.command("pregen progress");
    assert_eq!(server.expect_line(pregen_line, LINE_TIMEOUT), "pregen: no task");
    server.command("pregen start 0 0 lots");
    let line = server.expect_line(pregen_line, LINE_TIMEOUT);
    assert!(line.contains("radius \"lots\" is not a whole number"), "{line}");

    // A small task runs to the end, and every chunk of it is in the region files.
    server.command("pregen start 40 -40 100 circle");
    let line = server.expect_line(pregen_line, LINE_TIMEOUT);
    assert!(line.starts_with("pregen: circle of radius 100 around 40, -40:"), "{line}");
    let finished = server.expect_line(|l| l.starts_with("pregen:") && l.contains("finished"), START_TIMEOUT);
    let small = Plan::new(Task { center_x: 40, center_z: -40, radius: 100, shape: Shape::Circle }, Shard::ALL);
    assert!(finished.contains(&format!("{}/{} chunks (100.0%)", small.total(), small.total())), "{finished}");
    for i in 0..small.regions().len() {
        for (x, z) in small.region_chunks(i) {
            let path = world.join("region").join(RegionPos::of_chunk(x, z).file_name());
            let (lx, lz) = local(x, z);
            assert!(RegionFile::open(&path, false).expect("region").contains(lx, lz), "chunk {x}, {z} not saved");
        }
    }

    // A big task: players still get their chunks while it runs; pause, continue, cancel.
    server.command("pregen start 0 0 3000");
    server.expect_line(|l| l.starts_with("pregen: square of radius 3000"), LINE_TIMEOUT);
    let expected_chunks = ChunkView::new(ChunkPos::new(0, 0), VIEW).iter().count();
    let report = server.probe("visitor", &["--expect-chunks".into(), expected_chunks.to_string()]);
    assert!(report["all_chunks_ms"].as_f64().is_some(), "the player's view did not arrive: {report}");
    server.command("pregen pause");
    assert_eq!(server.expect_line(pregen_line, LINE_TIMEOUT), "pregen: paused; `pregen continue` resumes");
    server.command("pregen progress");
    let line = server.expect_line(pregen_line, LINE_TIMEOUT);
    assert!(line.contains("paused") && line.contains("chunks ("), "{line}");
    server.command("pregen continue");
    assert_eq!(server.expect_line(pregen_line, LINE_TIMEOUT), "pregen: continuing");
    server.command("pregen cancel");
    let line = server.expect_line(pregen_line, LINE_TIMEOUT);
    assert!(line.contains("Type `pregen confirm`"), "{line}");
    server.command("seed"); // Any other command keeps the task.
    server.command("pregen confirm");
    assert_eq!(server.expect_line(pregen_line, LINE_TIMEOUT), "pregen: nothing to confirm (`pregen cancel` first)");
    server.command("pregen cancel");
    server.expect_line(|l| l.contains("Type `pregen confirm`"), LINE_TIMEOUT);
    server.command("pregen confirm");
    server.expect_line(|l| l == "pregen: cancelled", LINE_TIMEOUT);
    assert!(!world.join("pregen.json").exists(), "a cancelled task leaves its progress file");

    // A running task survives a restart: the next server resumes it where it was saved.
    server.command("pregen start 0 0 3000");
    server.expect_line(|l| l.starts_with("pregen: square of radius 3000"), LINE_TIMEOUT);
    server.expect_line(|l| l.starts_with("pregen: ") && l.contains(" chunks (") && l.contains("ETA"), START_TIMEOUT);
    assert!(server.stop().success());
    let saved = Progress::load(&world.join("pregen.json")).expect("progress").expect("saved at stop");
    assert_eq!(saved.state, State::Running);
    assert!(saved.done > 0, "{saved:?}");
    let mut server = Server::start_with(&biomes, seed, &config::world_directory(&world));
    // (It said "resuming" during start-up; the task is active again, from where it was saved.)
    server.command("pregen progress");
    let line = server.expect_line(|l| l == "pregen: no task" || l.contains(" chunks ("), LINE_TIMEOUT);
    let done: u64 = line
        .strip_prefix("pregen: ")
        .and_then(|l| l.split('/').next())
        .map(|n| n.replace(',', ""))
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no progress in {line:?}"));
    assert!(done >= saved.done, "resumed at {done}, saved {}: {line}", saved.done);
    server.command("pregen cancel");
    server.expect_line(|l| l.contains("Type `pregen confirm`"), LINE_TIMEOUT);
    server.command("pregen confirm");
    server.expect_line(|l| l == "pregen: cancelled", LINE_TIMEOUT);
    assert!(server.stop().success());
}

/// Two dry columns near `spawn` with nothing growing on them (a broken block must not leave
/// a floating plant; a placed one needs a clear spot), a few blocks apart: a bare dry column
/// (no plant, no tree over it, no water beside it, where sugar cane may grow on the bank) 2–3
/// blocks east of the spawn and one west, if there are.
fn bare_columns(generator: &Generator, rules: &BiomeRules, spawn: (i64, i64)) -> Option<((i64, i64), (i64, i64))> {
    let v = *generator.vertical();
    let bare = |&(x, z): &(i64, i64)| {
        let here = generator.surface(rules, x, z);
        here.y > v.water_top_y()
            && here.water_y.is_none()
            && [(1, 0), (-1, 0), (0, 1), (0, -1)]
                .iter()
                .all(|&(dx, dz)| generator.surface(rules, x + dx, z + dz).water_y.is_none())
            && generator.plant_blocks(rules, x, z).is_empty()
            && generator.clear_of_trees(rules, x, z)
    };
    let east: Vec<(i64, i64)> = (2..4).flat_map(|dx| (-2..=2).map(move |dz| (spawn.0 + dx, spawn.1 + dz))).collect();
    let west: Vec<(i64, i64)> = (2..4).flat_map(|dx| (-2..=2).map(move |dz| (spawn.0 - dx, spawn.1 + dz))).collect();
    let pick = |list: Vec<(i64, i64)>| list.into_iter().find(bare);
    Some((pick(east)?, pick(west)?))
}

#[test]
fn a_players_edits_are_seen_by_others_and_kept_after_a_reconnect_and_a_restart() {
    let keep = tempfile::tempdir().expect("temp dir");
    let world = keep.path().join("world");
    let rules = fixtures::shipped_rules();
    // A world with bare ground on both sides of its spawn (woods leave few columns clear of
    // every crown).
    let (seed, generator, (broken, placed_on)) = (6..=40)
        .find_map(|seed| {
            let generator = generator(&fixtures::seeded_config(seed));
            let spawn = find_spawn(&generator, &rules);
            let bare = bare_columns(&generator, &rules, (i64::from(spawn.block.x), i64::from(spawn.block.z)))?;
            Some((seed, generator, bare))
        })
        .expect("a seed in 6..=40 with bare ground beside its spawn");
    let (by, py) =
        (generator.surface(&rules, broken.0, broken.1).y, generator.surface(&rules, placed_on.0, placed_on.1).y);
    let at = |(x, z): (i64, i64), y: i32| format!("{x},{y},{z}");

    let mut server = Server::start_with(&fixtures::shipped_biomes(), seed, &config::world_directory(&world));
    let args = ["--break", &at(broken, by), "--place-on", &at(placed_on, py), "--block", "gold_block"];
    let report = server.node("edit.js", &args.map(String::from));
    assert_eq!(report["ok"], true, "{report}");
    assert_eq!(report["game_mode"], "creative", "{report}");
    assert_eq!(report["before"]["placed"], "air", "{report}");
    assert_eq!(report["observer_saw"]["broken"], "air", "{report}");
    assert_eq!(report["observer_saw"]["placed"], "gold_block", "{report}");

    // What a player joining later sees, after a reconnect and after a restart: the broken
    // column one block lower, open to the sky where the block was (its light recomputed), and
    // the gold block on the other column.
    let list = format!("{},{};{},{}", broken.0, broken.1, placed_on.0, placed_on.1);
    let check = |report: &Value, when: &str| {
        let columns = report["columns"].as_array().expect("columns");
        let (b, p) = (&columns[0], &columns[1]);
        assert_eq!(b["y"].as_i64(), Some(i64::from(by - 1)), "{when}: broken column {b}");
        assert_eq!(b["sky_light_above"], 15, "{when}: the light of the broken block's place: {b}");
        assert_eq!(
            (p["block"].as_str(), p["y"].as_i64()),
            (Some("gold_block"), Some(i64::from(py + 1))),
            "{when}: {p}"
        );
    };
    check(&server.probe("returning", &["--columns".into(), list.clone()]), "after a reconnect");
    assert!(server.stop().success());
    let mut server = Server::start_with(&fixtures::shipped_biomes(), seed, &config::world_directory(&world));
    check(&server.probe("after_restart", &["--columns".into(), list]), "after a restart");
    assert!(server.stop().success());
}

#[test]
fn a_survival_player_digs_by_hand_and_picks_up_what_the_block_drops() {
    // A world whose spawn stands on a grass block (mineflayer's physics sinks through mud).
    let rules = fixtures::shipped_rules();
    let (seed, ground) = (1..=40)
        .find_map(|seed| {
            let generator = generator(&fixtures::seeded_config(seed));
            let spawn = find_spawn(&generator, &rules);
            let ground = generator.surface(&rules, i64::from(spawn.block.x), i64::from(spawn.block.z));
            (ground.top == "grass_block").then_some((seed, ground))
        })
        .expect("a seed in 1..=40 that spawns on a grass block");
    let keep = tempfile::tempdir().expect("temp dir");
    let world = config::world_directory(&keep.path().join("world"));
    let mut server =
        Server::start_with_server_keys(&fixtures::shipped_biomes(), seed, "gamemode = \"survival\"", &world);
    let report = server.node("drop.js", &[]);
    assert_eq!(report["ok"], true, "{report}");
    assert_eq!(report["game_mode"], "survival", "{report}");
    // The grass block under the spawn, dug by hand, gives dirt.
    assert_eq!(report["dug"]["name"], ground.top, "seed {seed}: {report}");
    let expected = "dirt";
    assert_eq!(report["before"], serde_json::json!([]), "{report}");
    assert_eq!(report["after"], serde_json::json!([{ "name": expected, "count": 1 }]), "{report}");
    // The drop lay where the block was.
    let (x, y, z) = (&report["dug"]["x"], &report["dug"]["y"], &report["dug"]["z"]);
    let at = &report["drop_at"];
    assert_eq!(at["x"].as_f64().map(f64::floor), x.as_f64(), "{report}");
    assert_eq!(at["z"].as_f64().map(f64::floor), z.as_f64(), "{report}");
    assert_eq!(at["y"].as_f64().map(f64::floor), y.as_f64(), "{report}");
    assert!(server.stop().success());
}
