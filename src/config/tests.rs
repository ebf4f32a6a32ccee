use std::path::Path;

use super::*;

fn parse(text: &str) -> Result<Config, ConfigError> {
    Config::parse(text, Path::new("config/test.toml"))
}

#[test]
fn the_shipped_config_is_valid_and_matches_the_defaults_it_documents() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(DEFAULT_PATH);
    let shipped = Config::load(&path).expect("config/server.toml must load");
    assert_eq!(shipped.layout, LayoutSettings::default());
    assert_eq!(shipped.climate, ClimateSettings::default());
    // The one deliberate difference: the shipped file turns the shipped learned core on
    // (left out, `learned` is empty: tests and tools stay procedural unless they ask).
    assert_eq!(shipped.engine.learned, ["core"]);
    assert_eq!(EngineSettings { learned: Vec::new(), ..shipped.engine.clone() }, EngineSettings::default());
    assert_eq!(shipped.server, ServerSettings::default());
    assert_eq!(shipped.world, WorldSettings::default());
}

#[test]
fn an_out_of_range_value_names_file_line_key_and_range() {
    let err = parse("[world]\nseed = 3\n\n[layout]\n# comment\nocean_fraction = 1.7\n").unwrap_err().to_string();
    assert_eq!(err, "config/test.toml:6: layout.ocean_fraction = 1.7 is out of range (allowed 0..=0.95)");
}

#[test]
fn a_cache_too_small_for_one_chunk_is_refused() {
    let err = parse("[engine]\ncache_mib = 4\n").unwrap_err().to_string();
    assert_eq!(err, "config/test.toml:2: engine.cache_mib = 4 is out of range (allowed 32..=65536)");
}

#[test]
fn unknown_keys_and_wrong_types_are_errors_with_lines() {
    let err = parse("[climate]\nlapse_rate = 6.5\n").unwrap_err().to_string();
    assert!(err.starts_with("config/test.toml:2:") && err.contains("lapse_rate"), "{err}");
    let err = parse("[engine]\n\ncache_mib = \"lots\"\n").unwrap_err().to_string();
    assert!(err.starts_with("config/test.toml:3:") && err.contains("\"lots\""), "{err}");
    let err = parse("[server\nbind = 1").unwrap_err().to_string();
    assert!(err.starts_with("config/test.toml:1:"), "{err}");
}

#[test]
fn structural_world_values_are_checked() {
    let err = parse("[world]\nmin_y = -60\n").unwrap_err().to_string();
    assert!(err.contains("world.min_y = -60") && err.contains("multiple of 16"), "{err}");
    let err = parse("[world]\nsea_level_y = 400\n").unwrap_err().to_string();
    assert!(err.contains("config/test.toml:2: world.sea_level_y = 400"), "{err}");
    let err = parse("[server]\nbind = \"localhost\"\n").unwrap_err().to_string();
    assert!(err.contains("server.bind") && err.contains("IP address and port"), "{err}");
}

#[test]
fn an_empty_file_means_every_default() {
    assert_eq!(parse("").unwrap(), Config::default());
}

#[test]
fn learned_stage_names_and_backends_are_checked() {
    let err = parse("[engine]\nlearned = [\"core\", \"canyon\"]\n").unwrap_err().to_string();
    assert!(err.starts_with("config/test.toml:2: engine.learned = \"canyon\"") && err.contains("detail"), "{err}");
    let err = parse("[engine]\nlearned = [\"detail\"]\n").unwrap_err().to_string();
    assert!(err.starts_with("config/test.toml:2: engine.learned") && err.contains("together with \"core\""), "{err}");
    let both = parse("[engine]\nlearned = [\"core\", \"detail\"]\n").unwrap().engine.learned;
    assert_eq!(both, vec!["core".to_string(), "detail".to_string()]);
    let err = parse("[engine]\nbackend = \"cuda\"\n").unwrap_err().to_string();
    assert!(err.contains("engine.backend = \"cuda\"") && err.contains("\"wgpu\""), "{err}");
    assert_eq!(parse("[engine]\nlearned = [\"core\"]\n").unwrap().engine.learned, vec!["core".to_string()]);
}

#[test]
fn the_game_mode_is_parsed_once_and_a_bad_one_names_file_line_key_and_values() {
    let mode = |text: &str| parse(text).map(|c| c.server.gamemode);
    assert_eq!(mode("[server]\ngamemode = \"survival\"\n").unwrap(), GameMode::Survival);
    assert_eq!(mode("").unwrap(), GameMode::Creative);
    let err = mode("[server]\nmax_players = 3\ngamemode = \"flying\"\n").unwrap_err().to_string();
    assert_eq!(
        err,
        "config/test.toml:3: server.gamemode = \"flying\" is out of range (allowed \"creative\", \"survival\", \
         \"adventure\" or \"spectator\")"
    );
    let numbers: Vec<i32> = GameMode::ALL.iter().map(|m| m.game_type()).collect();
    assert_eq!(numbers, [1, 0, 2, 3]);
}

#[test]
fn the_built_in_config_is_the_shipped_file() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(DEFAULT_PATH);
    assert_eq!(shipped::CONFIG, std::fs::read_to_string(&path).expect("the shipped file"));
    assert_eq!(Config::built_in(), Config::load(&path).expect("the shipped file loads"));
}

#[test]
fn a_missing_file_is_named_once_with_the_reason_once() {
    let err = Config::load(Path::new("no/such/config.toml")).unwrap_err();
    let shown = format!("{:#}", anyhow::Error::from(err));
    assert!(shown.starts_with("no/such/config.toml: cannot read the configuration file: "), "{shown}");
    assert_eq!(shown.matches("No such file").count(), 1, "{shown}");
    let named = Config::find(Some(Path::new("no/such/config.toml"))).unwrap_err().to_string();
    assert!(named.contains("no/such/config.toml"), "{named}");
}
