//! Loading, validation messages and lookup semantics, on small hand-written rule files.

use std::path::{Path, PathBuf};

use super::*;

const FALLBACK: &str = "fallback = \"minecraft:plains\"\n";

fn sources(files: &[(&str, &str)]) -> Vec<(PathBuf, String)> {
    files.iter().map(|(name, text)| (PathBuf::from(name), text.to_string())).collect()
}

fn load(files: &[(&str, &str)]) -> BiomeRules {
    BiomeRules::from_sources(&sources(files)).unwrap_or_else(|e| panic!("should load: {e}"))
}

/// The error message of a load that must fail.
fn error(files: &[(&str, &str)]) -> String {
    match BiomeRules::from_sources(&sources(files)) {
        Ok(rules) => panic!("should fail, loaded {} rules", rules.rule_count()),
        Err(e) => e.to_string(),
    }
}

fn one_file_error(text: &str) -> String {
    error(&[("biomes/default.toml", text)])
}

fn cell(temperature_c: f32, precipitation_mm: f32) -> Conditions {
    Conditions {
        temperature_c,
        seasonality_c: 5.0,
        precipitation_mm,
        variability_pct: 15.0,
        elevation_m: 200.0,
        surface_m: 200.0,
        slope_deg: 2.0,
        water: WaterBody::None,
        river_distance_m: 640.0,
    }
}

#[test]
fn the_first_matching_rule_wins_and_the_fallback_catches_the_rest() {
    let text = format!(
        "{FALLBACK}
[[rule]]
name = \"cold\"
biome = \"minecraft:taiga\"
override = true
temperature_c = [-inf, 5]

[[rule]]
name = \"wet\"
biome = \"minecraft:jungle\"
precipitation_mm = [2000, inf]
"
    );
    let rules = load(&[("a.toml", &text)]);
    assert_eq!(rules.biome(&cell(0.0, 2500.0)), "minecraft:taiga", "both match: the earlier wins");
    assert_eq!(rules.matching_rule(&cell(0.0, 2500.0)), Some("cold"));
    assert_eq!(rules.biome(&cell(20.0, 2500.0)), "minecraft:jungle");
    assert_eq!(rules.biome(&cell(20.0, 500.0)), "minecraft:plains", "nothing matches");
    assert_eq!(rules.matching_rule(&cell(20.0, 500.0)), None);
    // Broken input (NaN anywhere) matches no rule, not some arbitrary one.
    assert_eq!(rules.biome(&cell(f32::NAN, 2500.0)), "minecraft:plains");
    assert_eq!(rules.biome(&Conditions { slope_deg: f32::NAN, ..cell(0.0, 2500.0) }), "minecraft:plains");
    assert_eq!(rules.rule_count(), 2);
    assert_eq!(rules.fallback(), "minecraft:plains");
    assert_eq!(rules.biome_names(), ["minecraft:jungle", "minecraft:plains", "minecraft:taiga"]);
}

#[test]
fn range_ends_are_min_included_max_excluded() {
    let text = format!(
        "{FALLBACK}
[[rule]]
name = \"cool\"
biome = \"minecraft:taiga\"
temperature_c = [0, 10]

[[rule]]
name = \"warm\"
biome = \"minecraft:forest\"
temperature_c = [10, 20]
"
    );
    let rules = load(&[("a.toml", &text)]);
    assert_eq!(rules.biome(&cell(0.0, 0.0)), "minecraft:taiga");
    assert_eq!(rules.biome(&cell(10.0, 0.0)), "minecraft:forest", "touching ranges do not overlap");
    assert_eq!(rules.biome(&cell(20.0, 0.0)), "minecraft:plains");
}

#[test]
fn depth_is_surface_measured_downwards() {
    let text = format!(
        "{FALLBACK}
[[rule]]
name = \"deep\"
biome = \"minecraft:deep_ocean\"
depth_m = [2000, inf]

[[rule]]
name = \"shallow\"
biome = \"minecraft:ocean\"
surface_m = [-2000, 0]
"
    );
    let rules = load(&[("a.toml", &text)]);
    let sea = |surface_m| Conditions { surface_m, ..cell(10.0, 1000.0) };
    assert_eq!(rules.biome(&sea(-3000.0)), "minecraft:deep_ocean");
    assert_eq!(rules.biome(&sea(-1000.0)), "minecraft:ocean");
    assert_eq!(rules.biome(&sea(10.0)), "minecraft:plains");
}

#[test]
fn files_are_joined_in_the_order_given() {
    let first = format!(
        "{FALLBACK}[[rule]]\nname = \"a\"\nbiome = \"minecraft:desert\"\noverride = true\ntemperature_c = [20, inf]\n"
    );
    let second = "[[rule]]\nname = \"b\"\nbiome = \"minecraft:jungle\"\ntemperature_c = [10, inf]\n";
    let rules = load(&[("00-mine.toml", &first), ("default.toml", second)]);
    assert_eq!(rules.biome(&cell(25.0, 0.0)), "minecraft:desert");
    assert_eq!(rules.biome(&cell(15.0, 0.0)), "minecraft:jungle");
}

#[test]
fn unknown_biome_names_file_line_rule_and_a_suggestion() {
    let text = format!("{FALLBACK}\n[[rule]]\nname = \"jungle\"\nbiome = \"minecraft:jungel\"\n");
    assert_eq!(
        one_file_error(&text),
        "biomes/default.toml:5: rule \"jungle\": unknown biome \"minecraft:jungel\" (did you mean \"minecraft:jungle\"?)"
    );
    let text = format!("{FALLBACK}[[rule]]\nname = \"j\"\nbiome = \"jungle\"\n");
    assert!(one_file_error(&text).ends_with("unknown biome \"jungle\" (did you mean \"minecraft:jungle\"?)"));
    let text = format!("{FALLBACK}[[rule]]\nname = \"n\"\nbiome = \"minecraft:nether_wastes\"\n");
    assert_eq!(
        one_file_error(&text),
        "biomes/default.toml:4: rule \"n\": unknown biome \"minecraft:nether_wastes\"",
        "not an overworld biome, nothing close"
    );
}

#[test]
fn bad_ranges_name_the_key_and_why() {
    let rule = |range: &str| format!("{FALLBACK}[[rule]]\nname = \"r\"\nbiome = \"minecraft:taiga\"\n{range}\n");
    let cases = [
        ("temperature_c = [5, 5]", "bad range `temperature_c`: min 5 is not below max 5"),
        ("temperature_c = [10, -10]", "bad range `temperature_c`: min 10 is not below max -10"),
        ("temperature_c = [inf, inf]", "bad range `temperature_c`: min inf is not below max inf"),
        ("precipitation_mm = [nan, 5]", "bad range `precipitation_mm`: nan is not a bound"),
        ("temperature_c = [-200, 0]", "bad range `temperature_c`: min -200 is below the lowest possible value -100"),
        ("slope_deg = [10, 95]", "bad range `slope_deg`: max 95 is above the highest possible value 90"),
        ("precipitation_mm = [-1, 100]", "bad range `precipitation_mm`: min -1 is below the lowest possible value 0"),
        ("depth_m = [0, 20000]", "bad range `depth_m`: max 20000 is above the highest possible value 12000"),
        ("temperature_c = [0, 1e-50]", "bad range `temperature_c`: min 0 is not below max"),
    ];
    for (range, expected) in cases {
        let message = one_file_error(&rule(range));
        assert!(message.starts_with("biomes/default.toml:5: rule \"r\": "), "{message}");
        assert!(message.contains(expected), "{range}: {message}");
    }
    let shapes = ["temperature_c = [0, 1, 2]", "temperature_c = 5", "temperature_c = [\"-inf\", 0]", "slope_deg = []"];
    for range in shapes {
        let message = one_file_error(&rule(range));
        assert!(message.starts_with("biomes/default.toml:5: rule \"r\": `"), "{message}");
        assert!(message.contains("must be [min, max]: two numbers"), "{range}: {message}");
    }
}

#[test]
fn water_conditions_name_kinds_and_lists_must_be_gapless() {
    let text = format!(
        "{FALLBACK}[[rule]]\nname = \"river\"\nbiome = \"minecraft:river\"\noverride = true\nwater = \"river\"\n\
         [[rule]]\nname = \"fresh\"\nbiome = \"minecraft:swamp\"\nwater = [\"river\", \"lake\"]\n"
    );
    let rules = BiomeRules::from_sources(&[(PathBuf::from("biomes/default.toml"), text)]).unwrap();
    let with = |water| rules.biome(&Conditions { water, ..cell(10.0, 800.0) });
    assert_eq!(with(WaterBody::River), "minecraft:river");
    assert_eq!(with(WaterBody::Lake), "minecraft:swamp");
    assert_eq!(with(WaterBody::None), "minecraft:plains");
    assert_eq!(with(WaterBody::Sea), "minecraft:plains");

    let rule = |water: &str| format!("{FALLBACK}[[rule]]\nname = \"r\"\nbiome = \"minecraft:river\"\n{water}\n");
    let cases = [
        (
            "water = \"stream\"",
            "bad range `water`: unknown water kind \"stream\" (known: sea, lake, river, none, dry_lake)",
        ),
        ("water = [\"sea\", \"river\"]", "must be neighbours in the order sea, lake, river, none, dry_lake"),
        ("water = 3", "`water` must be a water kind"),
        ("water = []", "`water` must be a water kind"),
    ];
    for (water, expected) in cases {
        let message = one_file_error(&rule(water));
        assert!(message.starts_with("biomes/default.toml:5: rule \"r\": "), "{message}");
        assert!(message.contains(expected), "{water}: {message}");
    }
}

#[test]
fn river_distance_is_a_range_in_metres_from_the_bank() {
    let text =
        format!("{FALLBACK}[[rule]]\nname = \"banks\"\nbiome = \"minecraft:forest\"\nriver_distance_m = [0, 160]\n");
    let rules = BiomeRules::from_sources(&[(PathBuf::from("biomes/default.toml"), text)]).unwrap();
    let at = |river_distance_m| rules.biome(&Conditions { river_distance_m, ..cell(10.0, 400.0) });
    assert_eq!(
        (at(0.0), at(159.0), at(160.0), at(640.0)),
        ("minecraft:forest", "minecraft:forest", "minecraft:plains", "minecraft:plains")
    );
    let message = one_file_error(&format!(
        "{FALLBACK}[[rule]]\nname = \"r\"\nbiome = \"minecraft:forest\"\nriver_distance_m = [-5, 100]\n"
    ));
    assert!(message.starts_with("biomes/default.toml:5: rule \"r\": "), "{message}");
    assert!(message.contains("`river_distance_m`: min -5 is below the lowest possible value 0"), "{message}");
}

#[test]
fn duplicate_names_point_at_both_rules_across_files() {
    let a = format!("{FALLBACK}[[rule]]\nname = \"forest\"\nbiome = \"minecraft:forest\"\ntemperature_c = [0, 10]\n");
    let b = "# more\n[[rule]]\nname = \"forest\"\nbiome = \"minecraft:forest\"\ntemperature_c = [10, 20]\n";
    assert_eq!(
        error(&[("biomes/a.toml", &a), ("biomes/b.toml", b)]),
        "biomes/b.toml:2: rule \"forest\": the name is already used by the rule at biomes/a.toml:2"
    );
}

#[test]
fn a_rule_inside_an_earlier_rule_is_unreachable() {
    let text = format!(
        "{FALLBACK}
[[rule]]
name = \"warm\"
biome = \"minecraft:forest\"
temperature_c = [10, 30]

[[rule]]
name = \"warm and wet\"
biome = \"minecraft:forest\"
temperature_c = [15, 20]
precipitation_mm = [1000, inf]
"
    );
    assert_eq!(
        one_file_error(&text),
        "biomes/default.toml:8: rule \"warm and wet\": unreachable: the earlier rule \"warm\" \
         (biomes/default.toml:3) already matches everything this rule matches"
    );
    // `override` does not help: the rule still can never match.
    let text = text.replace("name = \"warm\"\n", "name = \"warm\"\noverride = true\n");
    assert!(one_file_error(&text).contains("unreachable"));
}

#[test]
fn overlapping_rules_of_different_biomes_need_override_on_the_earlier_one() {
    let text = |flag: &str, biome: &str| {
        format!(
            "{FALLBACK}
[[rule]]
name = \"swamp\"
biome = \"minecraft:swamp\"
{flag}slope_deg = [0, 1]
precipitation_mm = [800, inf]

[[rule]]
name = \"forest\"
biome = \"minecraft:{biome}\"
temperature_c = [5, 18]
precipitation_mm = [600, inf]
"
        )
    };
    assert_eq!(
        one_file_error(&text("", "forest")),
        "biomes/default.toml:9: rule \"forest\": overlaps the earlier rule \"swamp\" (biomes/default.toml:3, \
         minecraft:swamp) where temperature_c in [5, 18), precipitation_mm in [800, inf), slope_deg in [0, 1): \
         make the ranges disjoint, or set `override = true` on \"swamp\" if it is meant to win there"
    );
    let rules = load(&[("a.toml", &text("override = true\n", "forest"))]);
    let flat = Conditions { slope_deg: 0.5, ..cell(10.0, 1000.0) };
    assert_eq!(rules.biome(&flat), "minecraft:swamp");
    assert_eq!(rules.biome(&cell(10.0, 1000.0)), "minecraft:forest");
    // Overlapping rules of one biome give the same answer in any order: allowed.
    load(&[("a.toml", &text("", "swamp"))]);
    // `override` on the later rule cannot make it win, so it does not excuse the overlap.
    let later = text("", "forest").replace("name = \"forest\"\n", "name = \"forest\"\noverride = true\n");
    assert!(one_file_error(&later).contains("overlaps the earlier rule \"swamp\""));
}

#[test]
fn overlap_messages_show_depth_when_the_rule_uses_depth() {
    let text = format!(
        "{FALLBACK}[[rule]]\nname = \"a\"\nbiome = \"minecraft:ocean\"\nsurface_m = [-1000, 0]\n\
         [[rule]]\nname = \"b\"\nbiome = \"minecraft:deep_ocean\"\ndepth_m = [500, inf]\n"
    );
    assert!(one_file_error(&text).contains("where depth_m in (500, 1000]:"), "{}", one_file_error(&text));
}

#[test]
fn syntax_and_type_errors_carry_the_line() {
    let message = one_file_error(&format!("{FALLBACK}\n[[rule]]\nname = \"a\"\ntemperature_c = [1, \n"));
    assert!(message.starts_with("biomes/default.toml:5: "), "{message}");
    let message = one_file_error("fallback = \"minecraft:plains\"\nfalback = 1\n");
    assert!(message.starts_with("biomes/default.toml:2: unknown field `falback`"), "{message}");
    let message = one_file_error("fallback = 5\n");
    assert!(message.starts_with("biomes/default.toml:1: "), "{message}");
    let message = one_file_error(&format!("{FALLBACK}[rule]\nname = \"a\"\n"));
    assert!(message.starts_with("biomes/default.toml:2: "), "{message}");
    assert!(message.ends_with("(write each rule as [[rule]], with double brackets)"), "{message}");
}

#[test]
fn unknown_keys_in_a_rule_name_the_rule_and_suggest_the_key() {
    let text = format!("{FALLBACK}[[rule]]\nname = \"t\"\nbiome = \"minecraft:taiga\"\ntemprature_c = [0, 5]\n");
    assert_eq!(
        one_file_error(&text),
        "biomes/default.toml:5: rule \"t\": unknown key `temprature_c` (did you mean `temperature_c`?)"
    );
    let text = format!("{FALLBACK}[[rule]]\nname = \"t\"\nbiome = \"minecraft:taiga\"\ncolour = \"green\"\n");
    assert_eq!(one_file_error(&text), "biomes/default.toml:5: rule \"t\": unknown key `colour`");
}

#[test]
fn rules_need_a_name_and_a_biome_of_the_right_types() {
    let message = one_file_error(&format!("{FALLBACK}[[rule]]\nbiome = \"minecraft:taiga\"\n"));
    assert_eq!(message, "biomes/default.toml:2: rule \"#1\": missing `name`");
    let message = one_file_error(&format!("{FALLBACK}[[rule]]\nname = \"x\"\n[[rule]]\nname = 3\n"));
    assert_eq!(message, "biomes/default.toml:2: rule \"x\": missing `biome`", "the first problem in file order");
    let message = one_file_error(&format!("{FALLBACK}[[rule]]\nname = \"\"\nbiome = \"minecraft:taiga\"\n"));
    assert_eq!(message, "biomes/default.toml:3: rule \"#1\": `name` must be a non-empty string");
    let message =
        one_file_error(&format!("{FALLBACK}[[rule]]\nname = \"o\"\nbiome = \"minecraft:taiga\"\noverride = 1\n"));
    assert_eq!(message, "biomes/default.toml:5: rule \"o\": `override` must be true or false");
    let message = one_file_error(&format!(
        "{FALLBACK}[[rule]]\nname = \"s\"\nbiome = \"minecraft:ocean\"\nsurface_m = [-9, 0]\ndepth_m = [0, 9]\n"
    ));
    assert!(
        message.starts_with("biomes/default.toml:6: rule \"s\": set `surface_m` or `depth_m`, not both"),
        "{message}"
    );
}

#[test]
fn exactly_one_file_sets_a_known_fallback() {
    let rule = "[[rule]]\nname = \"a\"\nbiome = \"minecraft:taiga\"\n";
    assert_eq!(
        error(&[("biomes/a.toml", rule)]),
        "biomes/a.toml:1: no rule file sets `fallback = \"minecraft:...\"`: exactly one must name the biome used \
         where no rule matches"
    );
    assert_eq!(
        error(&[("biomes/a.toml", FALLBACK), ("biomes/b.toml", &format!("# b\n{FALLBACK}"))]),
        "biomes/b.toml:2: fallback: set again; it is already set at biomes/a.toml:1 (exactly one file may set it)"
    );
    assert_eq!(
        error(&[("biomes/a.toml", "fallback = \"minecraft:plain\"\n")]),
        "biomes/a.toml:1: fallback: unknown biome \"minecraft:plain\" (did you mean \"minecraft:plains\"?)"
    );
    let fallback_only = load(&[("a.toml", FALLBACK)]);
    assert_eq!((fallback_only.rule_count(), fallback_only.biome(&cell(0.0, 0.0))), (0, "minecraft:plains"));
}

#[test]
fn errors_expose_their_location() {
    let e = BiomeRules::from_sources(&sources(&[("x.toml", "fallback = \"minecraft:nope\"\n")]))
        .expect_err("unknown fallback");
    assert_eq!(e.location(), Some(&Location { file: PathBuf::from("x.toml"), line: 1 }));
}

/// An empty scratch folder, removed when dropped.
fn scratch() -> tempfile::TempDir {
    tempfile::tempdir().expect("create a scratch folder")
}

#[test]
fn load_dir_reads_toml_files_in_name_order_only() {
    let scratch_dir = scratch();
    let dir = scratch_dir.path();
    let write = |name: &str, text: &str| std::fs::write(dir.join(name), text).expect("write");
    write("b.toml", "[[rule]]\nname = \"b\"\nbiome = \"minecraft:jungle\"\ntemperature_c = [10, inf]\n");
    write("a.toml", &format!("{FALLBACK}[[rule]]\nname = \"a\"\nbiome = \"minecraft:desert\"\noverride = true\ntemperature_c = [20, inf]\n"));
    write("notes.txt", "not rules");
    write("c.toml.bak", "not rules either");
    let rules = BiomeRules::load_dir(dir).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(rules.rule_count(), 2);
    assert_eq!(rules.biome(&cell(25.0, 0.0)), "minecraft:desert", "a.toml comes first");

    let message = BiomeRules::load_dir(scratch().path()).expect_err("empty").to_string();
    assert!(message.ends_with("no *.toml biome rule files in this folder"), "{message}");
    let missing = dir.join("missing");
    let message = BiomeRules::load_dir(&missing).expect_err("missing").to_string();
    assert!(message.starts_with(&format!("{}: cannot read: ", missing.display())), "{message}");
}

#[test]
fn a_failed_reload_leaves_the_rules_in_use_untouched() {
    // What the console's `reload` does: load afresh, swap only on success.
    let scratch_dir = scratch();
    let dir = scratch_dir.path();
    let rules_file = dir.join("default.toml");
    let version = |biome: &str| format!("{FALLBACK}[[rule]]\nname = \"all\"\nbiome = \"minecraft:{biome}\"\n");
    std::fs::write(&rules_file, version("taiga")).expect("write");
    let mut current = BiomeRules::load_dir(dir).unwrap_or_else(|e| panic!("{e}"));

    std::fs::write(&rules_file, "fallback = \"minecraft:plains\"\n[[rule]\nname = ").expect("write");
    let reloaded = BiomeRules::load_dir(dir);
    let message = reloaded.as_ref().map(|_| ()).expect_err("broken TOML").to_string();
    assert!(message.starts_with(&format!("{}:2: ", rules_file.display())), "{message}");
    if let Ok(new) = reloaded {
        current = new;
    }
    assert_eq!(current.biome(&cell(0.0, 0.0)), "minecraft:taiga", "old rules still answer");

    std::fs::write(&rules_file, version("jungle")).expect("write");
    current = BiomeRules::load_dir(dir).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(current.biome(&cell(0.0, 0.0)), "minecraft:jungle", "new rules after a good reload");
}

#[test]
fn rules_can_be_shared_between_threads() {
    fn shareable<T: Clone + Send + Sync + 'static>() {}
    shareable::<BiomeRules>();
}

#[test]
fn a_hundred_thousand_lookups_stay_linear() {
    // Not a timing assertion (machines vary): only proof that lookup is a plain scan of the
    // compiled table, run enough times that an accidental quadratic cost would show.
    let rules =
        BiomeRules::load_dir(&Path::new(env!("CARGO_MANIFEST_DIR")).join("biomes")).unwrap_or_else(|e| panic!("{e}"));
    let mut counts = std::collections::HashMap::new();
    for i in 0..100_000u32 {
        let c = Conditions {
            temperature_c: (i % 61) as f32 - 30.0,
            seasonality_c: (i % 17) as f32,
            precipitation_mm: (i % 37) as f32 * 100.0,
            variability_pct: 15.0,
            elevation_m: (i % 41) as f32 * 100.0 - 1000.0,
            surface_m: (i % 41) as f32 * 100.0 - 1000.0,
            slope_deg: (i % 13) as f32,
            water: WaterBody::None,
            river_distance_m: (i % 7) as f32 * 100.0,
        };
        *counts.entry(rules.biome(&c)).or_insert(0u32) += 1;
    }
    assert_eq!(counts.values().sum::<u32>(), 100_000);
    assert!(counts.len() > 20, "{counts:?}");
}

#[test]
fn a_column_of_cells_gets_the_biomes_the_whole_table_gives() {
    let rules = BiomeRules::load_dir(&Path::new(env!("CARGO_MANIFEST_DIR")).join("biomes")).unwrap();
    let mut h = 3u64;
    let mut unit = move || {
        h = h.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (h >> 40) as f32 / (1u64 << 24) as f32
    };
    let (mut cells, mut biomes) = (0, std::collections::BTreeSet::new());
    for _ in 0..3000 {
        let ground = Conditions {
            temperature_c: -30.0 + 65.0 * unit(),
            seasonality_c: 40.0 * unit(),
            precipitation_mm: 3000.0 * unit(),
            variability_pct: 60.0 * unit(),
            elevation_m: -500.0 + 4500.0 * unit(),
            surface_m: -500.0 + 4500.0 * unit(),
            slope_deg: 40.0 * unit(),
            water: WaterBody::ALL[(unit() * WaterBody::ALL.len() as f32) as usize % WaterBody::ALL.len()],
            river_distance_m: 700.0 * unit(),
        };
        let column = rules.over(&ground);
        // Up the air over it: higher and colder.
        for k in 0..40 {
            let c = Conditions {
                elevation_m: ground.elevation_m + 150.0 * k as f32,
                temperature_c: ground.temperature_c - 0.9 * k as f32,
                ..ground
            };
            assert_eq!(column.biome(&c), rules.biome(&c), "{c:?}");
            biomes.insert(rules.biome(&c));
            cells += 1;
        }
    }
    assert!(cells == 120_000 && biomes.len() > 20, "{} biomes met", biomes.len());
}
