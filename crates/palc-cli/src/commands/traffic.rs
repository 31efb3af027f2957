//! `palc traffic ...`: background traffic on its own.
//!
//! `palc traffic simulate` builds a scene from a scenario config and writes one CSV row per
//! vehicle per step: `time,id,lane,s,l,v,a` (SI units), or with `--format json` an array
//! of objects with the same keys. Numbers are written in full precision (Rust's shortest
//! representation that reads back to the same `f64`), so that the output can be compared
//! with a reference at any tolerance. In a test-bed scene the ego has no planner here: it
//! keeps its lane and follows its stand-in IDM (`Scene::step_autonomous`).

use anyhow::{Context, bail};
use clap::{Args, Subcommand, ValueEnum};
use palc_aggregator::output;
use palc_traffic::{MAX_DT, ScenarioConfig, Scene};
use std::path::PathBuf;

/// Background traffic on its own.
#[derive(Debug, Args)]
pub struct TrafficArgs {
    #[command(subcommand)]
    command: TrafficCommand,
}

#[derive(Debug, Subcommand)]
enum TrafficCommand {
    /// Simulate a scenario config and write every vehicle's state per step as CSV.
    Simulate(SimulateArgs),
}

#[derive(Debug, Args)]
struct SimulateArgs {
    /// Scenario config (TOML), e.g. configs/testbed.toml or configs/platoon.toml.
    #[arg(long)]
    config: PathBuf,
    /// Simulated duration (s).
    #[arg(long, default_value_t = 20.0)]
    duration: f64,
    /// Time step (s).
    #[arg(long, default_value_t = 0.1)]
    dt: f64,
    /// Index of the test-bed cell to run (speed case, then headway, then seed); 0 for a platoon.
    #[arg(long, default_value_t = 0)]
    cell: usize,
    /// Output file.
    #[arg(long)]
    out: PathBuf,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Csv)]
    format: Format,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Format {
    /// One row per vehicle per step: `time,id,lane,s,l,v,a`.
    Csv,
    /// An array of `{time, id, lane, s, l, v, a}` objects.
    Json,
}

/// Largest number of steps one run may write (`--duration / --dt`), so that a typo cannot
/// fill the disk or the memory (a row per vehicle and step is held until the file is written).
const MAX_STEPS: f64 = 1e6;

/// Largest number of rows one run may hold (a row per vehicle and step), as many
/// as a samples CSV may have: 10^4 vehicles pass their bound and 10^6 steps
/// theirs, but not both at once.
const MAX_ROWS: f64 = 1e7;

pub fn run(args: TrafficArgs) -> anyhow::Result<()> {
    match args.command {
        TrafficCommand::Simulate(args) => simulate(&args),
    }
}

fn simulate(args: &SimulateArgs) -> anyhow::Result<()> {
    output::check_writable(&args.out)?;
    let text = palc_aggregator::input::read_to_string(&args.config)?;
    let config = ScenarioConfig::from_toml_str(&text)
        .with_context(|| format!("in {}", args.config.display()))?;
    let mut scene = Scene::from_config(&config, args.cell)
        .with_context(|| format!("in {}", args.config.display()))?;
    if !(args.duration >= 0.0 && args.duration.is_finite()) {
        bail!(
            "--duration {} is out of range: it must be finite and at least 0 s",
            args.duration
        );
    }
    if !(args.dt > 0.0 && args.dt <= MAX_DT) {
        bail!(
            "--dt {:e} s is out of range: it must be in (0, {MAX_DT}] s",
            args.dt
        );
    }
    let steps = (args.duration / args.dt).round();
    let valid = args.dt > 0.0 && steps <= MAX_STEPS;
    if !valid {
        bail!(
            "--duration / --dt = {steps} steps is out of range: at most {MAX_STEPS} steps with dt above 0 s"
        );
    }
    let vehicles = scene.vehicles().len();
    let row_count = (steps + 1.0) * vehicles as f64;
    if row_count > MAX_ROWS {
        bail!(
            "--duration / --dt = {steps} steps of {vehicles} vehicles make {row_count} rows (one per vehicle and step, the start included): at most {MAX_ROWS} rows"
        );
    }
    let mut rows = Vec::new();
    // `steps` is a whole number in [0, MAX_STEPS] here, so the cast is exact.
    for step in 0..=(steps as u64) {
        if step > 0 {
            scene.step_autonomous(args.dt)?;
        }
        for vehicle in scene.vehicles() {
            let state = &vehicle.state;
            rows.push(Row {
                time: scene.time(),
                id: vehicle.id.0,
                lane: vehicle.lane.0,
                s: state.s,
                l: state.l,
                v: state.v,
                a: state.a,
            });
        }
    }
    // The whole run is simulated before `--out` is touched, and written through a
    // temporary file: a failure leaves an existing `--out` as it was.
    output::write_with(&args.out, |out| match args.format {
        Format::Csv => {
            let mut writer = csv::Writer::from_writer(out);
            writer.write_record(["time", "id", "lane", "s", "l", "v", "a"])?;
            for r in &rows {
                // `{}` of an f64 is the shortest string that reads back to the same number.
                writer.write_record([
                    r.time.to_string(),
                    r.id.to_string(),
                    r.lane.to_string(),
                    r.s.to_string(),
                    r.l.to_string(),
                    r.v.to_string(),
                    r.a.to_string(),
                ])?;
            }
            writer.flush()
        }
        Format::Json => serde_json::to_writer(out, &rows).map_err(std::io::Error::other),
    })?;
    Ok(())
}

/// One vehicle at one step, as written.
#[derive(Debug, serde::Serialize)]
struct Row {
    time: f64,
    id: u32,
    lane: u32,
    s: f64,
    l: f64,
    v: f64,
    a: f64,
}
