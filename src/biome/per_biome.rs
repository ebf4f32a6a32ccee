//! Tables keyed by biome that sit beside the rules (`[vegetation."minecraft:forest"]`,
//! `[surface."minecraft:desert"]`): reading them from every file in order, one table per
//! biome over all files, each checked by its own parser with `file:line` errors; and what
//! those parsers share (numbers, solid blocks).

use std::collections::BTreeMap;
use std::ops::Range;
use std::path::Path;

use toml::{Spanned, Value};
use valence::prelude::{BlockKind, BlockState};

use super::error::{line_of, BiomeError, Location, Problem};
use super::names::{overworld_biome, overworld_index, suggest_biome, OVERWORLD_BIOMES};

/// One file's tables of one kind, as TOML gives them (keys keep their places).
pub(crate) type RawTables = BTreeMap<Spanned<String>, Spanned<Body>>;

/// One biome's table: its keys and values with their places.
pub(crate) type Body = BTreeMap<Spanned<String>, Spanned<Value>>;

/// What a table's parser returns on a mistake: where (a span of the file) and what.
pub(crate) type Mistake = (Range<usize>, Problem);

/// A value per overworld biome, indexed like [`OVERWORLD_BIOMES`].
#[derive(Clone, Debug)]
pub(crate) struct Table<T> {
    by_biome: Vec<Option<T>>,
}

impl<T> Default for Table<T> {
    fn default() -> Self {
        Table { by_biome: Vec::new() }
    }
}

impl<T> Table<T> {
    /// The value for `biome`; `None` where no table names it.
    pub(crate) fn get(&self, biome: &str) -> Option<&T> {
        self.by_biome.get(overworld_index(biome)?)?.as_ref()
    }
}

/// Collects the tables of one kind from every file (in the order given), checking each.
pub(crate) struct Builder<T> {
    /// The key the tables are under (`vegetation`), for messages.
    kind: &'static str,
    parse: fn(&Body) -> Result<T, Mistake>,
    table: Table<T>,
    first: Vec<Option<Location>>,
}

impl<T: Clone> Builder<T> {
    /// A builder for the tables under `kind`, each read by `parse`.
    pub(crate) fn new(kind: &'static str, parse: fn(&Body) -> Result<T, Mistake>) -> Builder<T> {
        let n = OVERWORLD_BIOMES.len();
        Builder { kind, parse, table: Table { by_biome: vec![None; n] }, first: vec![None; n] }
    }

    /// Adds one file's tables; a biome given twice (in any files) is an error naming both.
    pub(crate) fn add(&mut self, file: &Path, text: &str, raw: &RawTables) -> Result<(), BiomeError> {
        let mut tables: Vec<_> = raw.iter().collect();
        tables.sort_by_key(|(name, _)| name.span().start);
        for (name, body) in tables {
            let at = |span: Range<usize>| Location { file: file.to_path_buf(), line: line_of(text, span.start) };
            let given = name.get_ref();
            let fail = |span: Range<usize>, problem: Problem| BiomeError::Table {
                at: at(span),
                kind: self.kind,
                biome: given.clone(),
                problem: Box::new(problem),
            };
            let Some(biome) = overworld_biome(given) else {
                let problem = Problem::UnknownBiome { biome: given.clone(), suggestion: suggest_biome(given) };
                return Err(fail(name.span(), problem));
            };
            let i = OVERWORLD_BIOMES.binary_search(&biome).expect("an overworld biome");
            if let Some(first) = &self.first[i] {
                return Err(fail(name.span(), Problem::TableTwice { first: first.clone() }));
            }
            let value = (self.parse)(body.get_ref()).map_err(|(span, problem)| fail(span, problem))?;
            self.first[i] = Some(at(name.span()));
            self.table.by_biome[i] = Some(value);
        }
        Ok(())
    }

    /// The finished table.
    pub(crate) fn finish(self) -> Table<T> {
        self.table
    }
}

/// A body's entries in file order.
pub(crate) fn in_order(body: &Body) -> Vec<(&Spanned<String>, &Spanned<Value>)> {
    let mut entries: Vec<_> = body.iter().collect();
    entries.sort_by_key(|(key, _)| key.span().start);
    entries
}

/// A whole, solid block by its 1.20.1 id (with or without `minecraft:`).
pub(crate) fn solid_block(name: &str) -> Result<BlockState, Problem> {
    let bare = name.strip_prefix("minecraft:").unwrap_or(name);
    let Some(kind) = BlockKind::from_str(bare) else {
        return Err(Problem::UnknownName { what: "block", name: name.to_string(), suggestion: None });
    };
    let block = kind.to_state();
    // Not air, a liquid or something thin or see-through a player falls into or sees through.
    if block.is_air() || block.is_liquid() || !block.is_opaque() {
        return Err(Problem::NotSolid { block: name.to_string() });
    }
    Ok(block)
}

/// A TOML number as `f64`.
pub(crate) fn number(v: &Value) -> Option<f64> {
    match v {
        Value::Integer(i) => Some(*i as f64),
        Value::Float(f) => Some(*f),
        _ => None,
    }
}

/// Rules of a fallback alone (`a.toml`) with `text` as a second file (`b.toml`), as the
/// tables' tests load them; errors as their messages.
#[cfg(test)]
pub(crate) fn load_beside_a_fallback(text: &str) -> Result<super::BiomeRules, String> {
    super::BiomeRules::from_sources(&[
        (std::path::PathBuf::from("a.toml"), "fallback = \"minecraft:plains\"\n".to_string()),
        (std::path::PathBuf::from("b.toml"), text.to_string()),
    ])
    .map_err(|e| e.to_string())
}
