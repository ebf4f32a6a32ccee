//! What a measured step needed from the pipeline: the windows each window function evaluated
//! during it and the seconds they took (summed over threads, inclusive: a function that
//! queries another counts the time it waited for it), summed over the runs.

use super::Measurement;
use crate::terrain::infinite::FunctionStats;

/// Windows and seconds per window function, over the runs so far.
#[derive(Debug, Default)]
pub struct Needed {
    /// Per function: name, windows over all runs, seconds per run.
    functions: Vec<(String, f64, Vec<f64>)>,
    runs: usize,
}

impl Needed {
    /// Adds one run: the engine's counters `before` and `after` it.
    pub fn add(&mut self, before: &[FunctionStats], after: &[FunctionStats]) {
        self.runs += 1;
        for f in after {
            let earlier = before.iter().find(|b| b.name == f.name);
            let windows = f.windows - earlier.map_or(0, |b| b.windows);
            let seconds = f.seconds - earlier.map_or(0.0, |b| b.seconds);
            if windows == 0 {
                continue;
            }
            match self.functions.iter_mut().find(|n| n.0 == f.name) {
                Some(n) => {
                    n.1 += windows as f64;
                    n.2.push(seconds);
                }
                None => self.functions.push((f.name.clone(), windows as f64, vec![seconds])),
            }
        }
    }

    /// The table's rows: windows per run and seconds, per function.
    pub fn measurements(self) -> Vec<Measurement> {
        let runs = self.runs.max(1) as f64;
        let mut out = Vec::new();
        for (name, windows, seconds) in self.functions {
            out.push(Measurement::new(&format!("  windows of {name} it evaluated"), "windows", vec![windows / runs]));
            out.push(Measurement::new(&format!("  seconds in {name}, inclusive"), "s", seconds));
        }
        out
    }
}
