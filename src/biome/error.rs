//! What can be wrong with a set of rule files, worded for the server owner who must fix it:
//! every message starts with `file:line:` and, inside a rule, the rule's name.

use std::fmt;
use std::path::PathBuf;

/// A place in a rule file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Location {
    /// The file, as it was given (e.g. `biomes/default.toml`).
    pub file: PathBuf,
    /// 1-based line.
    pub line: usize,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}", self.file.display(), self.line)
    }
}

/// 1-based line of byte `offset` of `text` (for a [`Location`] from a TOML span).
pub(crate) fn line_of(text: &str, offset: usize) -> usize {
    text.as_bytes()[..offset.min(text.len())].iter().filter(|&&b| b == b'\n').count() + 1
}

/// Rule files that cannot be used. Loading stops at the first one, in file order.
#[derive(Debug, thiserror::Error)]
pub enum BiomeError {
    /// A folder or file could not be read.
    #[error("{}: cannot read: {source}", path.display())]
    Read {
        /// The folder or file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The folder holds no `*.toml` file.
    #[error("{}: no *.toml biome rule files in this folder", dir.display())]
    NoFiles {
        /// The folder.
        dir: PathBuf,
    },
    /// Not valid TOML, a wrong type or an unknown key outside any rule.
    #[error("{at}: {message}")]
    Syntax {
        /// Where the parser stopped.
        at: Location,
        /// What the parser said.
        message: String,
    },
    /// Something wrong inside one rule.
    #[error("{at}: rule \"{rule}\": {problem}")]
    Rule {
        /// The `[[rule]]` header, or the offending key when one key is to blame.
        at: Location,
        /// The rule's name, or `#N` (its position in the file) when it has none.
        rule: String,
        /// What is wrong (boxed: it is the bulky part, and errors travel in `Result`s).
        problem: Box<Problem>,
    },
    /// `fallback` is set by more than one file, or names no overworld biome.
    #[error("{at}: fallback: {problem}")]
    Fallback {
        /// The offending `fallback` key.
        at: Location,
        /// What is wrong.
        problem: Box<Problem>,
    },
    /// Something wrong in one biome's table beside the rules (`[vegetation."…"]`,
    /// `[surface."…"]`).
    #[error("{at}: {kind} for \"{biome}\": {problem}")]
    Table {
        /// The table's header, or the offending key.
        at: Location,
        /// Which kind of table (`vegetation`, `surface`).
        kind: &'static str,
        /// The biome as the header names it.
        biome: String,
        /// What is wrong.
        problem: Box<Problem>,
    },
    /// Something wrong in one `[[vein]]`.
    #[error("{at}: vein {vein}: {problem}")]
    Vein {
        /// The `[[vein]]` header, or the offending key.
        at: Location,
        /// `#N` (its place in its file), with its block when it names one: `#3 (iron_ore)`.
        vein: String,
        /// What is wrong.
        problem: Box<Problem>,
    },
    /// No file sets `fallback`, so some conditions would have no biome.
    #[error(
        "{}:1: no rule file sets `fallback = \"minecraft:...\"`: exactly one must name the biome used where \
         no rule matches",
        file.display()
    )]
    NoFallback {
        /// The first rule file, where the setting would usually go.
        file: PathBuf,
    },
}

impl BiomeError {
    /// The location the message points at, when there is one (tests and tooling).
    pub fn location(&self) -> Option<&Location> {
        match self {
            BiomeError::Syntax { at, .. }
            | BiomeError::Rule { at, .. }
            | BiomeError::Fallback { at, .. }
            | BiomeError::Table { at, .. }
            | BiomeError::Vein { at, .. } => Some(at),
            BiomeError::Read { .. } | BiomeError::NoFiles { .. } | BiomeError::NoFallback { .. } => None,
        }
    }
}

/// What is wrong with a rule (or with the fallback).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum Problem {
    /// A key no rule understands (usually a typo).
    #[error("unknown key `{key}`{}", did_you_mean(.suggestion, "`"))]
    UnknownKey {
        /// The key as written.
        key: String,
        /// The closest known key.
        suggestion: Option<&'static str>,
    },
    /// `name` or `biome` is missing.
    #[error("missing `{key}`")]
    MissingKey {
        /// The missing key.
        key: &'static str,
    },
    /// A key has a value of the wrong type or shape.
    #[error("`{key}` must be {expected}")]
    WrongType {
        /// The key.
        key: String,
        /// What it must be.
        expected: &'static str,
    },
    /// A biome that is not a Minecraft 1.20.1 overworld biome.
    #[error("unknown biome \"{biome}\"{}", did_you_mean(.suggestion, "\""))]
    UnknownBiome {
        /// The biome as written.
        biome: String,
        /// The closest overworld biome.
        suggestion: Option<&'static str>,
    },
    /// A range that is empty, NaN or outside what is physically possible.
    #[error("bad range `{key}`: {why}")]
    BadRange {
        /// The key.
        key: &'static str,
        /// Why it is rejected.
        why: String,
    },
    /// `surface_m` and `depth_m` are the same axis; setting both is ambiguous.
    #[error("set `surface_m` or `depth_m`, not both (depth_m = [a, b] is surface_m = [-b, -a])")]
    SurfaceAndDepth,
    /// Two rules share a name, so messages and `override` reasoning could not tell them apart.
    #[error("the name is already used by the rule at {first}")]
    DuplicateName {
        /// The first rule of that name.
        first: Location,
    },
    /// An earlier rule matches everything this one would, so this one can never apply.
    #[error("unreachable: the earlier rule \"{earlier}\" ({at}) already matches everything this rule matches")]
    Unreachable {
        /// The covering rule.
        earlier: String,
        /// Where it is.
        at: Location,
    },
    /// Two rules with different biomes match the same conditions, and the earlier one is not
    /// marked `override`, so the answer would silently depend on their order.
    #[error(
        "overlaps the earlier rule \"{earlier}\" ({at}, {earlier_biome}) where {region}: make the ranges disjoint, \
         or set `override = true` on \"{earlier}\" if it is meant to win there"
    )]
    Overlap {
        /// The earlier rule.
        earlier: String,
        /// Its biome.
        earlier_biome: &'static str,
        /// Where it is.
        at: Location,
        /// The shared ranges.
        region: String,
    },
    /// `fallback` set again after another file set it.
    #[error("set again; it is already set at {first} (exactly one file may set it)")]
    FallbackTwice {
        /// The first setting.
        first: Location,
    },
    /// A species, plant or block name a table does not know.
    #[error("unknown {what} \"{name}\"{}", did_you_mean(.suggestion, "\""))]
    UnknownName {
        /// `species`, `plant` or `block`.
        what: &'static str,
        /// The name as written.
        name: String,
        /// The closest known name.
        suggestion: Option<&'static str>,
    },
    /// A block where a whole, solid one is needed (ground, a vein): not air, a liquid or a
    /// thin or see-through block.
    #[error("\"{block}\" is not a whole, solid block")]
    NotSolid {
        /// The block as written.
        block: String,
    },
    /// A vein given both height shapes.
    #[error("give `uniform` or `triangle`, not both")]
    TwoHeights,
    /// A biome's plant chances add up to more than one plant per column.
    #[error("the plant chances sum to {total:.2}, more than 1: a column grows one plant at most")]
    PlantsOverOne {
        /// Their sum.
        total: f64,
    },
    /// A chance outside `[0, 1]`.
    #[error("`{key}` must be from 0 to 1, not {value}")]
    BadChance {
        /// The key or plant.
        key: String,
        /// The value as written.
        value: f64,
    },
    /// Trees are asked for, but no species says which.
    #[error("`trees` above 0 needs `species`, such as species = {{ oak = 1 }}")]
    TreesWithoutSpecies,
    /// A biome's table of one kind given a second time.
    #[error("already given at {first} (one table per biome, over all files)")]
    TableTwice {
        /// The first table.
        first: Location,
    },
}

/// ` (did you mean "x"?)` or nothing.
fn did_you_mean(suggestion: &Option<&'static str>, quote: &str) -> String {
    suggestion.map_or(String::new(), |s| format!(" (did you mean {quote}{s}{quote}?)"))
}
