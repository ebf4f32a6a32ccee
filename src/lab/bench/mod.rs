//! `infiniterra bench`: numbers for this machine — the engine's own overhead per window
//! with a trivial Φ, the pipeline's throughput, and pre-generation and joining the whole way
//! to region files (chunks/s, first region cold, join latency, peak memory), as a table, as
//! JSON and as a PNG chart against the goals.
//!
//! Every figure is the median of several runs at different places of the world (fresh
//! pipelines, so "cold" really is cold). Speed targets live here, never in timed tests.

mod chart;
mod engine;
mod light;
mod needed;
mod pipeline;
mod pregen;

use serde::Serialize;

use crate::config::Config;

/// What `infiniterra bench` measures and where it writes.
#[derive(Debug, Clone)]
pub struct BenchOptions {
    /// Print JSON instead of a table.
    pub json: bool,
    /// Runs per measurement (the median is reported).
    pub runs: usize,
    /// Chunks in the long pre-generation run (throughput and peak memory); 0 skips it.
    pub pregen_chunks: u64,
    /// Where to write the chart.
    pub out: std::path::PathBuf,
}

/// One measured quantity.
#[derive(Debug, Clone, Serialize)]
pub struct Measurement {
    /// What was measured.
    pub name: String,
    /// Median over the runs.
    pub value: f64,
    /// Unit of `value`.
    pub unit: &'static str,
    /// Every run's value.
    pub runs: Vec<f64>,
}

impl Measurement {
    /// Builds a measurement from the runs' values.
    pub fn new(name: &str, unit: &'static str, mut runs: Vec<f64>) -> Measurement {
        let mut sorted = runs.clone();
        sorted.sort_by(f64::total_cmp);
        let value = sorted.get(sorted.len() / 2).copied().unwrap_or(f64::NAN);
        runs.shrink_to_fit();
        Measurement { name: name.to_string(), value, unit, runs }
    }
}

/// Runs the suite and prints it.
pub fn run(config: &Config, args: &BenchOptions) -> anyhow::Result<()> {
    let runs = args.runs.max(1);
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut all = engine::measure(runs);
    all.extend(pipeline::measure(config, runs)?);
    all.extend(pregen::measure(config, runs, args.pregen_chunks)?);
    if args.json {
        let doc = serde_json::json!({ "machine_threads": threads, "seed": config.world.seed, "measurements": all });
        println!("{}", serde_json::to_string_pretty(&doc)?);
    } else {
        println!("infiniterra bench — {threads} hardware threads, seed {}, median of {runs} runs", config.world.seed);
        println!("{:<58} {:>14}  unit", "measurement", "median");
        for m in &all {
            println!("{:<58} {:>14.3}  {}", m.name, m.value, m.unit);
        }
    }
    let bars: Vec<chart::Bar> = all.iter().map(|m| chart::Bar { measurement: m, goal: goal(config, m) }).collect();
    let title = format!("infiniterra bench: {threads} hardware threads, seed {}, median of {runs}", config.world.seed);
    chart::save(&args.out, &title, &bars)?;
    if !args.json {
        println!("wrote {}", args.out.display());
    }
    Ok(())
}

/// The goal a measurement is judged against, where the project has one (issues #4, #6 and #24).
fn goal(config: &Config, m: &Measurement) -> Option<chart::Goal> {
    let at_least = |value| Some(chart::Goal { value, higher_is_better: true });
    let at_most = |value| Some(chart::Goal { value, higher_is_better: false });
    match m.name.as_str() {
        n if n.starts_with("pregen:") && m.unit == "chunks/s" => at_least(1_000.0),
        n if n.starts_with("pregen: peak resident memory") => at_most(config.engine.cache_mib as f64 + 300.0),
        "pipeline: first 512×512-block region, cold start" => at_most(1.5),
        n if n.starts_with("join: all 441 chunks") => at_most(2.0),
        "pipeline: steady exploration, chunk-sized queries" => at_least(256_000.0),
        _ => None,
    }
}
