//! Where the learned stages' files (`<stage>.json` manifests and their weights) are read
//! from: a folder on disk, or files compiled into the binary (the shipped models, so an
//! installed binary runs from any directory). Always built, so callers can name a source
//! whether or not the learned-model code is.

use std::borrow::Cow;
use std::fmt;
use std::io;
use std::path::{Path, PathBuf};

/// A read-only set of model files, addressed by paths relative to its root.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ModelFiles {
    /// A folder on disk.
    Dir(PathBuf),
    /// Files compiled into the binary: (path relative to the models folder, contents).
    Embedded(&'static [(&'static str, &'static [u8])]),
}

impl ModelFiles {
    /// The contents of `rel` (a `NotFound` error when there is no such file).
    pub fn read(&self, rel: &Path) -> io::Result<Cow<'static, [u8]>> {
        match self {
            ModelFiles::Dir(dir) => std::fs::read(dir.join(rel)).map(Cow::Owned),
            ModelFiles::Embedded(files) => files
                .iter()
                .find(|(name, _)| Path::new(name) == normalise(rel))
                .map(|&(_, bytes)| Cow::Borrowed(bytes))
                .ok_or_else(|| io::Error::new(io::ErrorKind::NotFound, "not built into this binary")),
        }
    }

    /// True when `rel` exists.
    pub fn has(&self, rel: &Path) -> bool {
        match self {
            ModelFiles::Dir(dir) => dir.join(rel).is_file(),
            ModelFiles::Embedded(files) => files.iter().any(|(name, _)| Path::new(name) == normalise(rel)),
        }
    }

    /// How messages name `rel`: its path on disk, or `built-in models/<rel>`.
    pub fn shown(&self, rel: &Path) -> PathBuf {
        match self {
            ModelFiles::Dir(dir) => dir.join(rel),
            ModelFiles::Embedded(_) => Path::new("built-in models").join(normalise(rel)),
        }
    }
}

impl fmt::Display for ModelFiles {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ModelFiles::Dir(dir) => write!(f, "{}", dir.display()),
            ModelFiles::Embedded(_) => f.write_str("the models built into this binary"),
        }
    }
}

/// `rel` without `.` components (a guide named `./guide/core.json` is `guide/core.json`).
fn normalise(rel: &Path) -> PathBuf {
    rel.components().filter(|c| !matches!(c, std::path::Component::CurDir)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn embedded_files_are_found_by_relative_path_and_named_as_built_in() {
        static FILES: [(&str, &[u8]); 2] = [("core.json", b"{}"), ("guide/core.json", b"[]")];
        let files = ModelFiles::Embedded(&FILES);
        assert_eq!(&*files.read(Path::new("core.json")).unwrap(), b"{}");
        assert_eq!(&*files.read(&Path::new(".").join("guide").join("core.json")).unwrap(), b"[]");
        assert_eq!(files.read(Path::new("detail.json")).unwrap_err().kind(), io::ErrorKind::NotFound);
        assert!(files.has(Path::new("guide/core.json")) && !files.has(Path::new("x")));
        assert_eq!(files.shown(Path::new("core.json")), Path::new("built-in models/core.json"));
    }
}
