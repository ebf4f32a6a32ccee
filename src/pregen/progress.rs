//! The saved state of a pre-generation task (`<world>/pregen*.json`): which task, and how
//! many chunks of its order are known to be on disk. Written atomically (temporary file,
//! fsync, rename), so after any crash it holds either the previous or the new state.

use std::io::Write;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::plan::{Shard, Task};

/// Where the task stands.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum State {
    /// Generating (or was, when the process died: resume it).
    Running,
    /// Paused by the owner, or by an error such as a full disk.
    Paused,
    /// Every chunk is saved.
    Finished,
}

/// The file's contents.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Progress {
    /// The task.
    pub task: Task,
    /// The shard of it this file tracks.
    pub shard: Shard,
    /// The world seed (a task never continues under another seed).
    pub seed: u64,
    /// The first `done` chunks of the plan's order are saved and fsynced.
    pub done: u64,
    /// Chunks in the plan.
    pub total: u64,
    /// Running, paused or finished.
    pub state: State,
    /// Why it paused, when an error paused it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

/// The progress file of `shard` in `world_dir`.
pub fn path(world_dir: &Path, shard: Shard) -> PathBuf {
    if shard == Shard::ALL {
        world_dir.join("pregen.json")
    } else {
        world_dir.join(format!("pregen-{}-of-{}.json", shard.index, shard.count))
    }
}

impl Progress {
    /// Reads `path`; `Ok(None)` when there is no such file. A file that is not valid is an
    /// error naming it (it is never silently replaced: the owner may want to look).
    pub fn load(path: &Path) -> anyhow::Result<Option<Progress>> {
        let text = match std::fs::read_to_string(path) {
            Ok(text) => text,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => anyhow::bail!("{}: cannot read: {e}", path.display()),
        };
        serde_json::from_str(&text).map(Some).map_err(|e| {
            anyhow::anyhow!("{}: not a pre-generation progress file ({e}); move it away to start over", path.display())
        })
    }

    /// Writes `path` atomically.
    pub fn save(&self, path: &Path) -> std::io::Result<()> {
        let tmp = path.with_extension("json.tmp");
        let mut file = std::fs::File::create(&tmp)?;
        let text = serde_json::to_string_pretty(self).map_err(std::io::Error::other)?;
        file.write_all(text.as_bytes())?;
        file.write_all(b"\n")?;
        file.sync_all()?;
        std::fs::rename(&tmp, path)?;
        // The rename itself is durable only once the folder is synced.
        if let Some(dir) = path.parent() {
            std::fs::File::open(dir)?.sync_all()?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pregen::plan::Shape;

    #[test]
    fn progress_round_trips_and_a_broken_file_is_named() {
        let dir = tempfile::tempdir().expect("temp dir");
        let p = path(dir.path(), Shard { index: 1, count: 4 });
        assert!(p.ends_with("pregen-1-of-4.json"));
        assert!(Progress::load(&p).expect("absent is fine").is_none());
        let progress = Progress {
            task: Task { center_x: -5, center_z: 7, radius: 300, shape: Shape::Circle },
            shard: Shard { index: 1, count: 4 },
            seed: 42,
            done: 17,
            total: 99,
            state: State::Paused,
            error: Some("disk full".into()),
        };
        progress.save(&p).expect("save");
        assert_eq!(Progress::load(&p).expect("load"), Some(progress));
        assert!(!p.with_extension("json.tmp").exists());
        std::fs::write(&p, "{\"task\": 3").expect("write");
        let err = Progress::load(&p).unwrap_err().to_string();
        assert!(err.contains("pregen-1-of-4.json") && err.contains("move it away"), "{err}");
    }
}
