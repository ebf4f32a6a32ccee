//! Edits a model manifest (`models/<stage>.json`) in place: the one way `train` (relief-hint
//! fit and calibration) and `eval --record` change a shipped manifest, so every writer keeps
//! the keys it does not touch exactly as written and replaces the file atomically.

use std::path::Path;

use anyhow::{anyhow, Context};

/// Changes the JSON object in `path` through `edit` and writes it back through a temporary
/// file + rename; every key `edit` leaves alone is kept as written, floats included.
pub fn edit_manifest(
    path: &Path,
    edit: impl FnOnce(&mut serde_json::Map<String, serde_json::Value>) -> anyhow::Result<()>,
) -> anyhow::Result<()> {
    let text = std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let mut value: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("{} is not JSON", path.display()))?;
    let object = value.as_object_mut().ok_or_else(|| anyhow!("{} is not a JSON object", path.display()))?;
    edit(object)?;
    let tmp = path.with_extension("json.tmp");
    std::fs::write(&tmp, serde_json::to_string_pretty(&value)? + "\n")
        .and_then(|()| std::fs::rename(&tmp, path))
        .with_context(|| format!("writing {}", path.display()))
}
