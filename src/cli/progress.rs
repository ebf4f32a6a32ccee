//! Progress bars for long work: a bar with rate and ETA on a terminal, a plain progress
//! line every few seconds otherwise (CI logs, pipes).

use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};

/// Reports `done / total` of some unit of work.
pub struct Progress {
    bar: Option<ProgressBar>,
    label: String,
    unit: &'static str,
    started: Instant,
    last_line: Instant,
}

impl Progress {
    /// A new progress report for work measured in `unit`s.
    pub fn new(label: &str, unit: &'static str) -> Progress {
        let bar = std::io::IsTerminal::is_terminal(&std::io::stderr()).then(|| {
            let bar = ProgressBar::new(0);
            let template = format!("{label} [{{bar:40}}] {{pos}}/{{len}} {unit} ({{per_sec}}, ETA {{eta}})");
            if let Ok(style) = ProgressStyle::with_template(&template) {
                bar.set_style(style.progress_chars("=> "));
            }
            bar
        });
        let now = Instant::now();
        Progress { bar, label: label.to_string(), unit, started: now, last_line: now }
    }

    /// Records progress.
    pub fn update(&mut self, done: u64, total: u64) {
        if let Some(bar) = &self.bar {
            bar.set_length(total);
            bar.set_position(done);
        } else if self.last_line.elapsed() >= Duration::from_secs(3) || done == total {
            self.last_line = Instant::now();
            let secs = self.started.elapsed().as_secs_f64().max(1e-6);
            let rate = done as f64 / secs;
            let eta = if rate > 0.0 { (total.saturating_sub(done)) as f64 / rate } else { f64::INFINITY };
            eprintln!(
                "{}: {done}/{total} {} ({:.0}%), {rate:.0} {}/s, ETA {eta:.0} s",
                self.label,
                self.unit,
                100.0 * done as f64 / total.max(1) as f64,
                self.unit
            );
        }
    }

    /// Ends the bar.
    pub fn finish(self) {
        if let Some(bar) = self.bar {
            bar.finish_and_clear();
        }
    }
}
