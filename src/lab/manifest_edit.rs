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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_left_alone_keep_their_floats_to_the_last_digit() {
        // Gains a calibration once wrote; serde_json's default float parser reads some of them
        // one unit in the last place off, so a rewrite changed numbers nobody edited.
        let text = "{\n  \"gains\": [\n    0.9880082275194835,\n    0.9665533279319569,\n    1.1697618301393617\n  ],\n  \"n\": 1\n}\n";
        let path = std::env::temp_dir().join(format!("infiniterra-manifest-edit-{}.json", std::process::id()));
        std::fs::write(&path, text).unwrap();
        edit_manifest(&path, |object| {
            object.insert("n".into(), 2.into());
            Ok(())
        })
        .unwrap();
        let after = std::fs::read_to_string(&path).unwrap();
        let _ = std::fs::remove_file(&path);
        assert_eq!(after, text.replace("\"n\": 1", "\"n\": 2"));
    }
}
