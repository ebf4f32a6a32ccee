//! Biome rules: which Minecraft biome a 4×4×4 cell gets, from its climate and terrain in
//! physical units, as written by the server owner in `biomes/*.toml`.
//!
//! Owns: the rule file format (documented at the top of `biomes/default.toml`), its
//! validation and error messages, the compiled first-match table and the list of 1.20.1
//! overworld biomes. Must not touch: the terrain pipeline (it receives numbers, not tiles),
//! the server's reload command (it only offers a load that either fully succeeds or changes
//! nothing), Minecraft registries beyond names.
//!
//! Beside the rules, tables keyed by biome say what each biome looks like: `[vegetation."…"]`
//! (shipped in `biomes/vegetation.toml`) how wooded it is, which tree species in what shares
//! and the chance of each ground plant; `[surface."…"]` (`biomes/surface.toml`) the blocks of
//! its ground; and `[[vein]]`s (`biomes/underground.toml`) the ore and rock placements under
//! every biome. Each file documents its keys at its top.
//!
//! Semantics in one paragraph: files are read in file-name order and their rules
//! concatenated; a rule is a box of half-open ranges `[min, max)`, one per quantity it names;
//! the first rule whose box holds the conditions gives the biome, and the configured
//! `fallback` is used where none does, so a lookup never fails. At load, a rule that an
//! earlier rule entirely covers is an error (it could never apply), and so is an overlap
//! between rules of different biomes unless the earlier rule says `override = true`.

mod error;
mod load;
mod names;
mod per_biome;
mod rules;
mod surface;
mod underground;
mod vegetation;

#[cfg(test)]
mod default_tests;
#[cfg(test)]
mod tests;

use std::path::{Path, PathBuf};

pub use error::{BiomeError, Location, Problem};
pub use names::{overworld_index, OVERWORLD_BIOMES};
pub use surface::Surface;
pub use underground::{Vein, VeinHeight, MAX_SIZE as MAX_VEIN_SIZE};
pub use vegetation::{Species, Vegetation, PLANTS, WATER_PLANTS};

/// What a rule sees for one 4×4×4 biome cell.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conditions {
    /// Annual mean air temperature at the cell's altitude, °C (the caller applies the lapse
    /// rate for cells above the surface).
    pub temperature_c: f32,
    /// Temperature seasonality: standard deviation of the monthly means, °C.
    pub seasonality_c: f32,
    /// Annual precipitation, mm.
    pub precipitation_mm: f32,
    /// Inter-annual precipitation variability (coefficient of variation), %.
    pub variability_pct: f32,
    /// The cell's altitude, metres above sea level (negative under water); for cells at or
    /// below the surface, the surface elevation.
    pub elevation_m: f32,
    /// The column's ground or sea-floor elevation, metres; below 0 the column is sea.
    pub surface_m: f32,
    /// Surface slope, degrees (0 flat .. 90).
    pub slope_deg: f32,
    /// The water the cell's columns hold.
    pub water: WaterBody,
    /// Distance from the cell's sample column to the nearest river's bank, metres: 0 in a
    /// river, at most 640 (what every column farther away reads).
    pub river_distance_m: f32,
}

/// The water body of a biome cell, for a rule's `water` condition.
///
/// The order is the one a rule's list must follow without gaps (`water = ["lake", "river"]`
/// is fine, `["sea", "river"]` is two rules): it puts together the sets rules want — any
/// water (`sea` … `river`), fresh water (`lake`, `river`), land with or without a dry lake
/// bed (`none`, `dry_lake`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[repr(u8)]
pub enum WaterBody {
    /// The sea (the column's ground is under sea level).
    Sea,
    /// A lake above sea level.
    Lake,
    /// A river.
    River,
    /// No water: dry land.
    #[default]
    None,
    /// A dry lake bed: a closed basin too dry to hold a lake (salt or clay flat).
    DryLake,
}

impl WaterBody {
    /// Every kind, in code order.
    pub const ALL: [WaterBody; 5] =
        [WaterBody::Sea, WaterBody::Lake, WaterBody::River, WaterBody::None, WaterBody::DryLake];

    /// How a rule file names it.
    pub fn key(self) -> &'static str {
        match self {
            WaterBody::Sea => "sea",
            WaterBody::Lake => "lake",
            WaterBody::River => "river",
            WaterBody::None => "none",
            WaterBody::DryLake => "dry_lake",
        }
    }
}

/// A validated, compiled set of biome rules.
///
/// Cheap to share: `Clone + Send + Sync`, immutable once loaded. To reload, load a new value
/// and swap it in; a failed load returns an error and leaves nothing half-applied.
#[derive(Clone, Debug)]
pub struct BiomeRules {
    table: rules::Table,
    /// Names of the rules, parallel to the table (for [`BiomeRules::matching_rule`]).
    names: Vec<String>,
    /// What grows in each biome.
    vegetation: per_biome::Table<Vegetation>,
    /// The ground of each biome's dry land.
    surface: per_biome::Table<Surface>,
    /// The veins of ore and rock, in file order.
    veins: Vec<Vein>,
}

/// The rules that can decide the cells of one column (see [`BiomeRules::over`]).
pub struct CellColumn<'r> {
    rules: &'r BiomeRules,
    ground: Conditions,
    candidates: Vec<usize>,
}

impl<'r> CellColumn<'r> {
    /// The biome for `c`, as [`BiomeRules::biome`] gives it; `c` must equal the column's
    /// ground conditions on every lane but temperature and elevation.
    #[inline]
    pub fn biome(&self, c: &Conditions) -> &'r str {
        debug_assert!(
            Conditions { temperature_c: self.ground.temperature_c, elevation_m: self.ground.elevation_m, ..*c }
                .lanes()
                .iter()
                .zip(self.ground.lanes())
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "{c:?} is not a cell over {:?}",
            self.ground
        );
        self.rules.table.biome_among(&self.candidates, c)
    }
}

impl BiomeRules {
    /// Loads every `*.toml` file of `dir`, in file-name order.
    ///
    /// Either every file reads and validates and a fresh value is returned, or the first
    /// problem (in file order) is returned and nothing else happens: a server reloading its
    /// rules keeps the old value on error.
    pub fn load_dir(dir: &Path) -> Result<BiomeRules, BiomeError> {
        let read_error = |source| BiomeError::Read { path: dir.to_path_buf(), source };
        let mut paths = Vec::new();
        for entry in std::fs::read_dir(dir).map_err(read_error)? {
            let path = entry.map_err(read_error)?.path();
            if path.extension().is_some_and(|e| e == "toml") && path.is_file() {
                paths.push(path);
            }
        }
        if paths.is_empty() {
            return Err(BiomeError::NoFiles { dir: dir.to_path_buf() });
        }
        paths.sort_by(|a, b| a.file_name().cmp(&b.file_name()));
        let mut files = Vec::with_capacity(paths.len());
        for path in paths {
            let text =
                std::fs::read_to_string(&path).map_err(|source| BiomeError::Read { path: path.clone(), source })?;
            files.push((path, text));
        }
        BiomeRules::from_sources(&files)
    }

    /// Builds rules from `(name, contents)` pairs, in the order given (tests, embedded rules).
    pub fn from_sources(files: &[(PathBuf, String)]) -> Result<BiomeRules, BiomeError> {
        let loaded = load::load(files)?;
        Ok(BiomeRules {
            table: loaded.table,
            names: loaded.rules.into_iter().map(|r| r.name).collect(),
            vegetation: loaded.vegetation,
            surface: loaded.surface,
            veins: loaded.veins,
        })
    }

    /// The biome for `c`, e.g. `"minecraft:plains"`: the first matching rule's, else the
    /// fallback. Never fails (a NaN in any quantity matches no rule: the fallback) and does
    /// not allocate: it runs for every biome cell of every chunk.
    #[inline]
    pub fn biome(&self, c: &Conditions) -> &str {
        self.table.biome(c)
    }

    /// The biomes of a column of cells whose conditions differ from `ground`'s only in
    /// temperature and elevation (the air over a ground, cooling with height): the rules
    /// that fail on another lane are set aside once for the whole column. The columns pass
    /// asks for some 80 cells over each cell column of a chunk, and scanning every rule for
    /// each was a twentieth of a chunk's time.
    pub fn over(&self, ground: &Conditions) -> CellColumn<'_> {
        CellColumn { rules: self, ground: *ground, candidates: self.table.candidates_varying_height(ground) }
    }

    /// The name of the rule that decides `c`, or `None` where the fallback does (for
    /// debugging a map or answering "why is this a desert?").
    pub fn matching_rule(&self, c: &Conditions) -> Option<&str> {
        self.table.first_match(c).map(|i| self.names[i].as_str())
    }

    /// Every biome the rules can produce, the fallback included: sorted, without repeats
    /// (for palettes and registries).
    pub fn biome_names(&self) -> Vec<&str> {
        let mut names: Vec<&str> = self.table.biomes.iter().copied().chain([self.table.fallback]).collect();
        names.sort_unstable();
        names.dedup();
        names
    }

    /// What grows in `biome` (trees, their species, ground plants), or `None` where no
    /// `[vegetation."…"]` table names it: nothing grows there.
    pub fn vegetation(&self, biome: &str) -> Option<&Vegetation> {
        self.vegetation.get(biome)
    }

    /// The ground of `biome`'s dry, gentle land: its `[surface."…"]` table, else
    /// [`Surface::DEFAULT`] (grass over dirt).
    pub fn surface(&self, biome: &str) -> Surface {
        self.surface.get(biome).copied().unwrap_or(Surface::DEFAULT)
    }

    /// Every `[[vein]]` of ore or rock, in file order (the order keys their random draws).
    pub fn veins(&self) -> &[Vein] {
        &self.veins
    }

    /// The biome used where no rule matches.
    pub fn fallback(&self) -> &str {
        self.table.fallback
    }

    /// How many rules were loaded, over all files.
    pub fn rule_count(&self) -> usize {
        self.table.bounds.len()
    }
}
