//! The layers point one way (docs/architecture.md): reads the `crate::…` and `super::…` paths
//! of every module of both crates and checks that
//!
//! - nothing outside `cli/` imports `crate::cli` (domain code returns its own errors; only the
//!   command line maps them to exit codes),
//! - the product never imports the lab (`crate::lab`: train, eval, bench),
//! - the crate's top-level modules import each other without a cycle, and
//! - within every folder, sibling modules import each other without a cycle.
//!
//! A source scan rather than a compiler plug-in: the rules are about which names a module
//! mentions, which the text shows exactly (comments and string literals are skipped).

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// A module path inside one crate: `["server", "stream"]` for `src/server/stream/mod.rs`.
type ModPath = Vec<String>;

/// Every `.rs` file under `root` with its module path.
fn modules(root: &Path) -> Vec<(ModPath, PathBuf)> {
    let mut out = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
            let path = entry.expect("directory entry").path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let rel = path.strip_prefix(root).expect("under root").with_extension("");
                let mut parts: ModPath = rel.iter().map(|p| p.to_string_lossy().into_owned()).collect();
                if matches!(parts.last().map(String::as_str), Some("mod" | "lib" | "main")) {
                    parts.pop();
                }
                out.push((parts, path));
            }
        }
    }
    out.sort();
    out
}

/// The source without comments and string literals (so a doc line that says `crate::cli`
/// is not an import).
fn code_only(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let b = text.as_bytes();
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'/' && b.get(i + 1) == Some(&b'/') {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if b[i] == b'/' && b.get(i + 1) == Some(&b'*') {
            i += 2;
            while i + 1 < b.len() && !(b[i] == b'*' && b[i + 1] == b'/') {
                i += 1;
            }
            i += 2;
        } else if b[i] == b'"' {
            i += 1;
            while i < b.len() && b[i] != b'"' {
                i += if b[i] == b'\\' { 2 } else { 1 };
            }
            i += 1;
            out.push_str("\"\"");
        } else if b[i] == b'\'' && b.get(i + 2) == Some(&b'\'') {
            // A char literal such as '"' or '{'; lifetimes ('a) have no closing quote there.
            i += 3;
        } else {
            out.push(b[i] as char);
            i += 1;
        }
    }
    out
}

fn ident_at(s: &str) -> Option<&str> {
    let end = s.find(|c: char| !(c.is_alphanumeric() || c == '_')).unwrap_or(s.len());
    (end > 0).then(|| &s[..end])
}

/// The first path segments named after each `prefix` (`crate::` or `super::`), including each
/// name of a `prefix{a, b::c}` group.
fn names_after(code: &str, prefix: &str) -> BTreeSet<String> {
    let mut names = BTreeSet::new();
    for (at, _) in code.match_indices(prefix) {
        // Skip `foo_crate::` and `$crate::`.
        if code[..at].chars().last().is_some_and(|c| c.is_alphanumeric() || c == '_' || c == '$') {
            continue;
        }
        let rest = &code[at + prefix.len()..];
        if let Some(group) = rest.strip_prefix('{') {
            let mut depth = 0;
            let mut item_start = true;
            for (i, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => break,
                    '}' => depth -= 1,
                    ',' if depth == 0 => item_start = true,
                    c if c.is_whitespace() => {}
                    _ if item_start && depth == 0 => {
                        item_start = false;
                        if let Some(name) = ident_at(&group[i..]) {
                            names.insert(name.to_string());
                        }
                    }
                    _ => {}
                }
            }
        } else if let Some(name) = ident_at(rest) {
            names.insert(name.to_string());
        }
    }
    names
}

/// Unit-test modules in files of their own (`tests.rs`, `*_tests.rs`, anything in a `tests/`
/// folder): test code may build its fixtures from any layer, so it is not part of the graph.
fn is_test_file(path: &Path) -> bool {
    let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    name == "tests" || name.ends_with("_tests") || path.parent().is_some_and(|p| p.ends_with("tests"))
}

/// The code before an inline `#[cfg(test)] mod tests { … }` (the test module is last in a file
/// by the project's convention), for the same reason.
fn production_code(code: &str) -> &str {
    let mut at = 0;
    while let Some(i) = code[at..].find("#[cfg(test)]") {
        let start = at + i;
        if code[start + "#[cfg(test)]".len()..].trim_start().starts_with("mod tests {") {
            return &code[..start];
        }
        at = start + 1;
    }
    code
}

/// Edges `(from, to)` between modules of one crate, each edge as the two full paths.
fn references(root: &Path) -> Vec<(ModPath, ModPath)> {
    let mods = modules(root);
    let known: BTreeSet<&ModPath> = mods.iter().map(|(m, _)| m).collect();
    let mut edges = Vec::new();
    for (module, path) in &mods {
        if is_test_file(path) {
            continue;
        }
        let all = code_only(&fs::read_to_string(path).expect("readable source"));
        let code = production_code(&all);
        // `crate::a::b` targets module `a` (and `a::b` when that is a module).
        for name in names_after(code, "crate::") {
            let target = vec![name];
            if known.contains(&target) {
                edges.push((module.clone(), target));
            }
        }
        // `super::x` from module `p::m` targets sibling `p::x`. In a `mod.rs`, `super` is the
        // parent folder's module; non-`mod.rs` files `m.rs` hold module `m` whose parent is
        // the folder.
        if let Some((_, parent)) = module.split_last() {
            for name in names_after(code, "super::") {
                let mut target = parent.to_vec();
                target.push(name);
                if known.contains(&target) && &target != module {
                    edges.push((module.clone(), target));
                }
            }
        }
    }
    edges
}

/// A cycle in `graph`, if any, as the list of its nodes.
fn find_cycle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        n: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        stack: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(n.to_string(), 1);
        stack.push(n.to_string());
        for m in graph.get(n).into_iter().flatten() {
            match state.get(m.as_str()).copied().unwrap_or(0) {
                1 => {
                    let start = stack.iter().position(|s| s == m).expect("on the stack");
                    let mut cycle = stack[start..].to_vec();
                    cycle.push(m.clone());
                    return Some(cycle);
                }
                0 => {
                    if let Some(c) = visit(m, graph, state, stack) {
                        return Some(c);
                    }
                }
                _ => {}
            }
        }
        stack.pop();
        state.insert(n.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for n in graph.keys() {
        if state.get(n.as_str()).copied().unwrap_or(0) == 0 {
            let mut stack = Vec::new();
            if let Some(c) = visit(n, graph, &mut state, &mut stack) {
                return Some(c);
            }
        }
    }
    None
}

/// Cycles among the top-level modules, and among the siblings of every folder.
fn cycles(edges: &[(ModPath, ModPath)]) -> Vec<String> {
    let mut graphs: BTreeMap<ModPath, BTreeMap<String, BTreeSet<String>>> = BTreeMap::new();
    for (from, to) in edges {
        // The deepest folder holding both: the edge is between its children on each side.
        let common = from.iter().zip(to).take_while(|(a, b)| a == b).count();
        let (Some(a), Some(b)) = (from.get(common), to.get(common)) else { continue };
        graphs.entry(from[..common].to_vec()).or_default().entry(a.clone()).or_default().insert(b.clone());
    }
    graphs
        .iter()
        .filter_map(|(folder, g)| find_cycle(g).map(|c| format!("in {}/: {}", folder.join("/"), c.join(" → "))))
        .collect()
}

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn the_scanner_sees_grouped_and_super_imports_and_skips_comments() {
    let code =
        code_only("use crate::{a, b::{c, d}};\n// crate::hidden\nlet s = \"crate::str\";\nsuper::x::y(); crate::e::f;");
    assert_eq!(names_after(&code, "crate::"), ["a", "b", "e"].map(String::from).into());
    assert_eq!(names_after(&code, "super::"), ["x"].map(String::from).into());
    let g: BTreeMap<String, BTreeSet<String>> =
        [("a", "b"), ("b", "c"), ("c", "a")].iter().map(|(x, y)| (x.to_string(), [y.to_string()].into())).collect();
    assert_eq!(find_cycle(&g), Some(["a", "b", "c", "a"].map(String::from).to_vec()));
}

#[test]
fn nothing_outside_the_command_line_imports_it() {
    let offenders: Vec<String> = references(&repo().join("src"))
        .into_iter()
        .filter(|(from, to)| to == &["cli"] && from.first().map(String::as_str) != Some("cli"))
        .map(|(from, _)| from.join("::"))
        .collect();
    assert!(offenders.is_empty(), "domain modules import crate::cli: {offenders:?}");
}

#[test]
fn the_product_never_imports_the_lab() {
    let product = ["server", "pregen", "world", "chunkgen", "render", "export", "config", "biome", "draw", "npy"];
    let offenders: Vec<String> = references(&repo().join("src"))
        .into_iter()
        .filter(|(from, to)| {
            to.first().map(String::as_str) == Some("lab") && product.contains(&from.first().map_or("", String::as_str))
        })
        .map(|(from, _)| from.join("::"))
        .collect();
    assert!(offenders.is_empty(), "product modules import crate::lab: {offenders:?}");
}

#[test]
fn modules_import_each_other_without_cycles_in_both_crates() {
    let found: Vec<String> = ["src", "terrain/src"]
        .iter()
        .flat_map(|root| cycles(&references(&repo().join(root))).into_iter().map(move |c| format!("{root}: {c}")))
        .collect();
    assert!(found.is_empty(), "import cycles:\n{}", found.join("\n"));
}
