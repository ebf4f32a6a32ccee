//! The biome identifiers a rule may name, and "did you mean" suggestions for typos.

/// Every overworld biome of Minecraft 1.20.1 (protocol 763), sorted.
///
/// Taken from the registry codec valence 0.2.0-alpha.1 sends to clients, minus the nether,
/// the end and `minecraft:the_void`. 53 entries: 1.20.1 has 64 biomes in all, 5 nether,
/// 5 end and the void. A rule naming anything else is rejected at load, because the client
/// would be sent a biome it has no registry entry for.
pub const OVERWORLD_BIOMES: &[&str] = &[
    "minecraft:badlands",
    "minecraft:bamboo_jungle",
    "minecraft:beach",
    "minecraft:birch_forest",
    "minecraft:cherry_grove",
    "minecraft:cold_ocean",
    "minecraft:dark_forest",
    "minecraft:deep_cold_ocean",
    "minecraft:deep_dark",
    "minecraft:deep_frozen_ocean",
    "minecraft:deep_lukewarm_ocean",
    "minecraft:deep_ocean",
    "minecraft:desert",
    "minecraft:dripstone_caves",
    "minecraft:eroded_badlands",
    "minecraft:flower_forest",
    "minecraft:forest",
    "minecraft:frozen_ocean",
    "minecraft:frozen_peaks",
    "minecraft:frozen_river",
    "minecraft:grove",
    "minecraft:ice_spikes",
    "minecraft:jagged_peaks",
    "minecraft:jungle",
    "minecraft:lukewarm_ocean",
    "minecraft:lush_caves",
    "minecraft:mangrove_swamp",
    "minecraft:meadow",
    "minecraft:mushroom_fields",
    "minecraft:ocean",
    "minecraft:old_growth_birch_forest",
    "minecraft:old_growth_pine_taiga",
    "minecraft:old_growth_spruce_taiga",
    "minecraft:plains",
    "minecraft:river",
    "minecraft:savanna",
    "minecraft:savanna_plateau",
    "minecraft:snowy_beach",
    "minecraft:snowy_plains",
    "minecraft:snowy_slopes",
    "minecraft:snowy_taiga",
    "minecraft:sparse_jungle",
    "minecraft:stony_peaks",
    "minecraft:stony_shore",
    "minecraft:sunflower_plains",
    "minecraft:swamp",
    "minecraft:taiga",
    "minecraft:warm_ocean",
    "minecraft:windswept_forest",
    "minecraft:windswept_gravelly_hills",
    "minecraft:windswept_hills",
    "minecraft:windswept_savanna",
    "minecraft:wooded_badlands",
];

/// The namespace every vanilla biome lives in.
const NAMESPACE: &str = "minecraft:";

/// The index of `name` in [`OVERWORLD_BIOMES`], if it is an overworld biome. The names the
/// rules hand out are the list's own strings, so they are found by address (integer
/// comparisons); other strings by comparing their text. Chunk generation looks a biome's
/// tables up for every column, and comparing text was a twentieth of its time.
pub fn overworld_index(name: &str) -> Option<usize> {
    /// Slots of an open-addressed table by address: (address, index), 0 for empty.
    const SLOTS: usize = 256;
    static BY_ADDRESS: std::sync::LazyLock<[(usize, usize); SLOTS]> = std::sync::LazyLock::new(|| {
        let mut table = [(0, 0); SLOTS];
        for (i, name) in OVERWORLD_BIOMES.iter().enumerate() {
            let mut slot = slot_of(name.as_ptr() as usize);
            while table[slot].0 != 0 {
                slot = (slot + 1) % SLOTS;
            }
            table[slot] = (name.as_ptr() as usize, i);
        }
        table
    });
    fn slot_of(address: usize) -> usize {
        ((address as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 56) as usize
    }
    let address = name.as_ptr() as usize;
    let mut slot = slot_of(address);
    // The list fills a quarter of the table: a probe or two.
    loop {
        let (a, i) = BY_ADDRESS[slot];
        if a == 0 {
            break;
        }
        // The same address and length are the same text.
        if a == address && OVERWORLD_BIOMES[i].len() == name.len() {
            return Some(i);
        }
        slot = (slot + 1) % SLOTS;
    }
    OVERWORLD_BIOMES.binary_search(&name).ok()
}

/// The registry's own `&'static str` for `name`, if it is an overworld biome.
pub(crate) fn overworld_biome(name: &str) -> Option<&'static str> {
    OVERWORLD_BIOMES.binary_search(&name).ok().map(|i| OVERWORLD_BIOMES[i])
}

/// The overworld biome closest to a mistyped `given`, compared without the `minecraft:`
/// namespace so that a forgotten namespace ("jungle") is an exact hit.
pub(crate) fn suggest_biome(given: &str) -> Option<&'static str> {
    let bare = |s: &str| s.strip_prefix(NAMESPACE).unwrap_or(s).to_ascii_lowercase();
    let given = bare(given.trim());
    closest(&given, OVERWORLD_BIOMES.iter().map(|&name| (bare(name), name)))
}

/// The candidate closest to a mistyped key.
pub(crate) fn suggest_key(given: &str, keys: &[&'static str]) -> Option<&'static str> {
    closest(&given.to_ascii_lowercase(), keys.iter().map(|&k| (k.to_string(), k)))
}

/// The candidate at the smallest edit distance from `given`, if close enough to be a typo:
/// at most a quarter of the word's length (and at least 2), so that "jungel" finds "jungle"
/// but a different word ("snowy_tundra", renamed in 1.18) suggests nothing rather than
/// something misleading ("snowy_taiga").
fn closest(given: &str, candidates: impl Iterator<Item = (String, &'static str)>) -> Option<&'static str> {
    let limit = (given.chars().count() / 4).max(2);
    candidates
        .map(|(compared, name)| (edit_distance(given, &compared), name))
        .filter(|&(d, _)| d <= limit)
        .min_by_key(|&(d, _)| d)
        .map(|(_, name)| name)
}

/// Levenshtein distance in characters.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let substitute = diagonal + usize::from(ca != cb);
            diagonal = row[j + 1];
            row[j + 1] = substitute.min(row[j] + 1).min(diagonal + 1);
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overworld_list_is_sorted_unique_and_complete() {
        assert!(OVERWORLD_BIOMES.windows(2).all(|w| w[0] < w[1]), "sorted and unique (binary search relies on it)");
        assert_eq!(OVERWORLD_BIOMES.len(), 53);
        assert!(OVERWORLD_BIOMES.iter().all(|b| b.starts_with(NAMESPACE)));
        for gone in ["minecraft:the_void", "minecraft:nether_wastes", "minecraft:the_end", "minecraft:mountains"] {
            assert_eq!(overworld_biome(gone), None, "{gone}");
        }
        assert_eq!(overworld_biome("minecraft:cherry_grove"), Some("minecraft:cherry_grove"));
        // By address or by text, the same index; and nothing for other names.
        for (i, name) in OVERWORLD_BIOMES.iter().enumerate() {
            assert_eq!(overworld_index(name), Some(i));
            let copy: String = name.chars().collect();
            assert_eq!(overworld_index(&copy), Some(i), "a copy elsewhere in memory");
            assert_eq!(overworld_index(&name[..name.len() - 1]), None, "{name}");
        }
    }

    #[test]
    fn suggestions_catch_typos_and_missing_namespaces_only() {
        assert_eq!(suggest_biome("minecraft:jungel"), Some("minecraft:jungle"));
        assert_eq!(suggest_biome("jungle"), Some("minecraft:jungle"));
        assert_eq!(suggest_biome("minecraft:snowy_tundra"), None, "renamed in 1.18; nothing close");
        assert_eq!(suggest_biome("minecraft:savana_plateau"), Some("minecraft:savanna_plateau"));
        assert_eq!(suggest_key("temprature_c", &["temperature_c", "slope_deg"]), Some("temperature_c"));
        assert_eq!(suggest_key("colour", &["temperature_c", "slope_deg"]), None);
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("", "abc"), 3);
    }
}
