//! Reading rule files: TOML into rules that remember where they were written, each checked
//! on its own (keys, types, biome, ranges), then the checks across rules (unique names, no
//! unreachable rule, no unacknowledged overlap) and the fallback.

use std::collections::{BTreeMap, HashMap};
use std::ops::Range;
use std::path::{Path, PathBuf};

use serde::Deserialize;
use toml::{Spanned, Value};

use super::error::{line_of, BiomeError, Location, Problem};
use super::names::{overworld_biome, suggest_biome, suggest_key};
use super::per_biome::{self, number};
use super::rules::{Axis, Bounds, Table};
use super::surface::{self, Surface};
use super::underground::{self, Vein};
use super::vegetation::{self, Vegetation};
use super::WaterBody;

/// Shorthand for `surface_m` measured downwards, so ocean rules read like ocean charts.
const DEPTH_KEY: &str = "depth_m";

/// Every key a `[[rule]]` understands (for "did you mean").
pub(crate) const RULE_KEYS: &[&str] = &[
    "name",
    "biome",
    "override",
    "temperature_c",
    "seasonality_c",
    "precipitation_mm",
    "variability_pct",
    "elevation_m",
    "surface_m",
    DEPTH_KEY,
    "slope_deg",
    "water",
    "river_distance_m",
];

/// What a range key must hold.
const RANGE_SHAPE: &str = "[min, max]: two numbers, with inf or -inf (no quotes) for an open end";

/// A file as TOML sees it. Rules stay generic tables so that an unknown key or a wrong type
/// inside one can be reported with the rule's name, which serde's own errors cannot do.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFile {
    fallback: Option<Spanned<String>>,
    #[serde(default)]
    rule: Vec<Spanned<BTreeMap<Spanned<String>, Spanned<Value>>>>,
    #[serde(default)]
    vegetation: per_biome::RawTables,
    #[serde(default)]
    surface: per_biome::RawTables,
    #[serde(default)]
    vein: Vec<Spanned<per_biome::Body>>,
}

/// A rule as loaded: its box and what messages need to point at it.
#[derive(Clone, Debug)]
pub(crate) struct Rule {
    pub(crate) name: String,
    pub(crate) biome: &'static str,
    pub(crate) bounds: Bounds,
    /// Wins, by design, wherever it overlaps a later rule (see the overlap check).
    pub(crate) overrides: bool,
    /// Written with `depth_m`: messages show its surface range as depth.
    pub(crate) as_depth: bool,
    /// The `[[rule]]` header.
    pub(crate) at: Location,
}

/// The rules in match order (for names and messages) and their compiled table.
pub(crate) struct Loaded {
    pub(crate) rules: Vec<Rule>,
    pub(crate) table: Table,
    pub(crate) vegetation: per_biome::Table<Vegetation>,
    pub(crate) surface: per_biome::Table<Surface>,
    pub(crate) veins: Vec<Vein>,
}

/// Parses and checks `files` in the order given (the caller sorts by name).
pub(crate) fn load(files: &[(PathBuf, String)]) -> Result<Loaded, BiomeError> {
    let mut rules = Vec::new();
    let mut fallback: Option<(&'static str, Location)> = None;
    let mut vegetation = per_biome::Builder::new("vegetation", vegetation::parse);
    let mut surfaces = per_biome::Builder::new("surface", surface::parse);
    let mut veins = Vec::new();
    for (file, text) in files {
        let raw: RawFile = toml::from_str(text).map_err(|e| BiomeError::Syntax {
            at: Location { file: file.clone(), line: e.span().map_or(1, |s| line_of(text, s.start)) },
            message: syntax_message(e.message()),
        })?;
        if let Some(given) = raw.fallback {
            let at = Location { file: file.clone(), line: line_of(text, given.span().start) };
            if let Some((_, first)) = fallback {
                return Err(BiomeError::Fallback { at, problem: Box::new(Problem::FallbackTwice { first }) });
            }
            let biome = overworld_biome(given.get_ref()).ok_or_else(|| BiomeError::Fallback {
                at: at.clone(),
                problem: Box::new(Problem::UnknownBiome {
                    biome: given.get_ref().clone(),
                    suggestion: suggest_biome(given.get_ref()),
                }),
            })?;
            fallback = Some((biome, at));
        }
        for (index, table) in raw.rule.iter().enumerate() {
            rules.push(parse_rule(file, text, index, table)?);
        }
        vegetation.add(file, text, &raw.vegetation)?;
        surfaces.add(file, text, &raw.surface)?;
        for (index, table) in raw.vein.iter().enumerate() {
            veins.push(parse_vein(file, text, index, table)?);
        }
    }
    let Some((fallback, _)) = fallback else {
        return Err(BiomeError::NoFallback { file: files.first().map(|(f, _)| f.clone()).unwrap_or_default() });
    };
    check_names(&rules)?;
    check_order(&rules)?;
    let table = Table {
        bounds: rules.iter().map(|r| r.bounds).collect(),
        biomes: rules.iter().map(|r| r.biome).collect(),
        fallback,
    };
    Ok(Loaded { rules, table, vegetation: vegetation.finish(), surface: surfaces.finish(), veins })
}

/// The parser's message, with a hint for the one mistake it words obscurely: `[rule]`
/// (a single table) where each rule must be `[[rule]]` (an entry of an array of tables).
fn syntax_message(message: &str) -> String {
    let message = message.trim();
    if message.contains("expected a sequence") {
        format!("{message} (write each rule as [[rule]], with double brackets)")
    } else {
        message.to_string()
    }
}

/// One `[[vein]]`, with its place and block in any message.
fn parse_vein(file: &Path, text: &str, index: usize, table: &Spanned<per_biome::Body>) -> Result<Vein, BiomeError> {
    underground::parse(table.get_ref(), table.span()).map_err(|(span, problem)| {
        let block = table.get_ref().iter().find(|(k, _)| k.get_ref() == "block");
        let vein = match block.map(|(_, v)| v.get_ref()) {
            Some(Value::String(name)) if !matches!(problem, Problem::UnknownName { .. }) => {
                format!("#{} ({name})", index + 1)
            }
            _ => format!("#{}", index + 1),
        };
        let at = Location { file: file.to_path_buf(), line: line_of(text, span.start) };
        BiomeError::Vein { at, vein, problem: Box::new(problem) }
    })
}

/// One `[[rule]]` table, checked key by key in file order.
fn parse_rule(
    file: &Path,
    text: &str,
    index: usize,
    table: &Spanned<BTreeMap<Spanned<String>, Spanned<Value>>>,
) -> Result<Rule, BiomeError> {
    let at = |span: Range<usize>| Location { file: file.to_path_buf(), line: line_of(text, span.start) };
    let header = at(table.span());
    let mut entries: Vec<_> = table.get_ref().iter().collect();
    entries.sort_by_key(|(key, _)| key.span().start);

    // The name first, so that every later message can carry it.
    let unnamed = format!("#{}", index + 1);
    let name = match entries.iter().find(|(key, _)| key.get_ref() == "name") {
        Some((_, value)) => match value.get_ref() {
            Value::String(s) if !s.trim().is_empty() => s.clone(),
            _ => {
                let problem = Problem::WrongType { key: "name".into(), expected: "a non-empty string" };
                return Err(BiomeError::Rule { at: at(value.span()), rule: unnamed, problem: Box::new(problem) });
            }
        },
        None => {
            let problem = Problem::MissingKey { key: "name" };
            return Err(BiomeError::Rule { at: header, rule: unnamed, problem: Box::new(problem) });
        }
    };
    let fail = |span: Range<usize>, problem: Problem| BiomeError::Rule {
        at: at(span),
        rule: name.clone(),
        problem: Box::new(problem),
    };

    let (mut bounds, mut biome, mut overrides) = (Bounds::ANY, None, false);
    let (mut surface_span, mut depth_span) = (None, None);
    for (key, value) in entries {
        let key_name = key.get_ref().as_str();
        match key_name {
            "name" => {}
            "biome" => {
                let Value::String(given) = value.get_ref() else {
                    let problem =
                        Problem::WrongType { key: "biome".into(), expected: "a string such as \"minecraft:plains\"" };
                    return Err(fail(value.span(), problem));
                };
                let found = overworld_biome(given).ok_or_else(|| {
                    let problem = Problem::UnknownBiome { biome: given.clone(), suggestion: suggest_biome(given) };
                    fail(value.span(), problem)
                })?;
                biome = Some(found);
            }
            "override" => {
                let Value::Boolean(flag) = value.get_ref() else {
                    let problem = Problem::WrongType { key: "override".into(), expected: "true or false" };
                    return Err(fail(value.span(), problem));
                };
                overrides = *flag;
            }
            DEPTH_KEY => {
                let (lo, hi) = parse_range(DEPTH_KEY, value.get_ref(), Axis::Surface.limits())
                    .map_err(|problem| fail(value.span(), problem))?;
                // depth ∈ [lo, hi) is surface ∈ (−hi, −lo]; stored half-open as [−hi, −lo),
                // which differs only on the boundary points themselves.
                bounds.lo[Axis::Surface.lane()] = -hi;
                bounds.hi[Axis::Surface.lane()] = -lo;
                depth_span = Some(key.span());
            }
            "water" => {
                let (lo, hi) = parse_water(value.get_ref()).map_err(|problem| fail(value.span(), problem))?;
                bounds.lo[Axis::Water.lane()] = lo;
                bounds.hi[Axis::Water.lane()] = hi;
            }
            other => {
                let Some(&axis) = Axis::ALL.iter().find(|a| a.key() == other) else {
                    let problem =
                        Problem::UnknownKey { key: other.to_string(), suggestion: suggest_key(other, RULE_KEYS) };
                    return Err(fail(key.span(), problem));
                };
                let (lo, hi) =
                    parse_range(axis.key(), value.get_ref(), axis.limits()).map_err(|p| fail(value.span(), p))?;
                bounds.lo[axis.lane()] = lo;
                bounds.hi[axis.lane()] = hi;
                if axis == Axis::Surface {
                    surface_span = Some(key.span());
                }
            }
        }
    }
    if let (Some(surface), Some(depth)) = (surface_span, depth_span.clone()) {
        // Point at whichever of the two comes second: that is the one that conflicts.
        let second = if surface.start > depth.start { surface } else { depth };
        return Err(fail(second, Problem::SurfaceAndDepth));
    }
    let Some(biome) = biome else {
        let problem = Box::new(Problem::MissingKey { key: "biome" });
        return Err(BiomeError::Rule { at: header, rule: name, problem });
    };
    Ok(Rule { name, biome, bounds, overrides, as_depth: depth_span.is_some(), at: header })
}

/// A `[min, max]` range of `key`, checked against the axis' physical `limits`.
fn parse_range(key: &'static str, value: &Value, limits: (f32, f32)) -> Result<(f32, f32), Problem> {
    let wrong = || Problem::WrongType { key: key.to_string(), expected: RANGE_SHAPE };
    let Value::Array(items) = value else { return Err(wrong()) };
    let [lo, hi] = items.as_slice() else { return Err(wrong()) };
    let (lo, hi) = (number(lo).ok_or_else(wrong)?, number(hi).ok_or_else(wrong)?);
    let bad = |why: String| Err(Problem::BadRange { key, why });
    if lo.is_nan() || hi.is_nan() {
        return bad("nan is not a bound".into());
    }
    let (floor, ceiling) = (f64::from(limits.0), f64::from(limits.1));
    for (what, v) in [("min", lo), ("max", hi)] {
        if v.is_finite() && v < floor {
            return bad(format!("{what} {v} is below the lowest possible value {floor} (use -inf for no lower limit)"));
        }
        if v.is_finite() && v > ceiling {
            return bad(format!(
                "{what} {v} is above the highest possible value {ceiling} (use inf for no upper limit)"
            ));
        }
    }
    // Compared after the cast to f32 (the type conditions arrive in), so two bounds that
    // round together are caught rather than making a rule that matches nothing.
    let (lo32, hi32) = (lo as f32, hi as f32);
    if lo32 >= hi32 {
        return bad(format!("min {lo} is not below max {hi} (ranges are [min, max): min included, max excluded)"));
    }
    Ok((lo32, hi32))
}

/// What `water` must hold.
const WATER_SHAPE: &str = "a water kind (\"sea\", \"lake\", \"river\", \"none\" or \"dry_lake\") or a list of them";

/// A `water` condition: one kind or a list of kinds, as the range of their codes. A list must
/// be gapless in [`WaterBody`]'s order, since a rule is one box.
fn parse_water(value: &Value) -> Result<(f32, f32), Problem> {
    let wrong = || Problem::WrongType { key: "water".into(), expected: WATER_SHAPE };
    let names: Vec<&Value> = match value {
        Value::Array(items) if !items.is_empty() => items.iter().collect(),
        Value::String(_) => vec![value],
        _ => return Err(wrong()),
    };
    let mut codes = Vec::with_capacity(names.len());
    for name in names {
        let Value::String(name) = name else { return Err(wrong()) };
        let Some(kind) = WaterBody::ALL.iter().find(|w| w.key() == name) else {
            let keys: Vec<&str> = WaterBody::ALL.iter().map(|w| w.key()).collect();
            let why = format!("unknown water kind \"{name}\" (known: {})", keys.join(", "));
            return Err(Problem::BadRange { key: "water", why });
        };
        codes.push(*kind as u8);
    }
    codes.sort_unstable();
    codes.dedup();
    let (lo, hi) = (codes[0], codes[codes.len() - 1]);
    if usize::from(hi - lo) + 1 != codes.len() {
        let order: Vec<&str> = WaterBody::ALL.iter().map(|w| w.key()).collect();
        let why = format!(
            "a rule's water kinds must be neighbours in the order {} (a rule is one range); write two rules",
            order.join(", ")
        );
        return Err(Problem::BadRange { key: "water", why });
    }
    Ok((f32::from(lo), f32::from(hi) + 1.0))
}

/// Names are unique across all files: messages and the overlap advice refer to rules by name.
fn check_names(rules: &[Rule]) -> Result<(), BiomeError> {
    let mut seen: HashMap<&str, &Location> = HashMap::new();
    for rule in rules {
        if let Some(first) = seen.insert(&rule.name, &rule.at) {
            let problem = Box::new(Problem::DuplicateName { first: first.clone() });
            return Err(BiomeError::Rule { at: rule.at.clone(), rule: rule.name.clone(), problem });
        }
    }
    Ok(())
}

/// Order checks, each rule against every earlier one (files concatenated in name order):
///
/// - unreachable: one earlier rule's box covers this rule's box, so this rule never matches.
///   Only single-rule cover is detected; a rule covered by the union of several earlier rules
///   (say, one for each half of its range) passes this check and is simply dead.
/// - overlap: the boxes share conditions, the biomes differ, and the earlier rule is not
///   marked `override = true`. Under first-match the earlier rule would win there silently;
///   `override` is the written statement that it is meant to (an exception carved out of the
///   broader rules after it). Overlaps between rules of the same biome are harmless.
fn check_order(rules: &[Rule]) -> Result<(), BiomeError> {
    for (j, later) in rules.iter().enumerate() {
        let earlier = &rules[..j];
        let fail =
            |problem| BiomeError::Rule { at: later.at.clone(), rule: later.name.clone(), problem: Box::new(problem) };
        if let Some(cover) = earlier.iter().find(|e| e.bounds.covers(&later.bounds)) {
            return Err(fail(Problem::Unreachable { earlier: cover.name.clone(), at: cover.at.clone() }));
        }
        for e in earlier.iter().filter(|e| !e.overrides && e.biome != later.biome) {
            if let Some(common) = e.bounds.intersection(&later.bounds) {
                return Err(fail(Problem::Overlap {
                    earlier: e.name.clone(),
                    earlier_biome: e.biome,
                    at: e.at.clone(),
                    region: common.describe(later.as_depth),
                }));
            }
        }
    }
    Ok(())
}
