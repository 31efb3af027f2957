//! `palc import`: recorded traffic into palc.
//!
//! `palc import commonroad SCENARIO.xml... --out lane-changes.json` reads CommonRoad 2020a
//! scenarios with `palc_commonroad::import`, writes the recorded lane changes as one JSON
//! file (atomically) and prints a summary. A scenario without lane changes is not a
//! failure: the file is still written (with zero lane changes and the counts of what was
//! seen), and a warning says so, because an empty result is a fact about the recording.

use std::path::PathBuf;

use anyhow::Context;
use clap::{Args, Subcommand};
use palc_aggregator::output;
use palc_commonroad::import::{self, RecordedLaneChanges};

use crate::console::{say, warning};

/// Arguments of `palc import`.
#[derive(Debug, Args)]
pub struct ImportArgs {
    #[command(subcommand)]
    command: ImportCommand,
}

#[derive(Debug, Subcommand)]
enum ImportCommand {
    /// Find the lane changes of the vehicles recorded in CommonRoad 2020a scenarios and
    /// write them as JSON (lateral traces, speeds, lane widths, gaps at the start).
    Commonroad(CommonroadArgs),
}

/// Arguments of `palc import commonroad`.
#[derive(Debug, Args)]
pub struct CommonroadArgs {
    /// The scenario files (CommonRoad 2020a XML), read in this order.
    #[arg(required = true)]
    scenarios: Vec<PathBuf>,
    /// The JSON file to write.
    #[arg(long)]
    out: PathBuf,
}

/// Runs `palc import`.
pub fn run(args: ImportArgs) -> anyhow::Result<()> {
    match args.command {
        ImportCommand::Commonroad(args) => commonroad(args),
    }
}

fn commonroad(args: CommonroadArgs) -> anyhow::Result<()> {
    output::check_writable(&args.out)?;
    let mut file = RecordedLaneChanges::new();
    for path in &args.scenarios {
        let scenario = import::import_file(path)?;
        if scenario.source.counts.lane_changes == 0 {
            warning!(
                "{}: no lane change found ({} vehicles, {} cut by the recording)",
                path.display(),
                scenario.source.counts.vehicles,
                scenario.source.counts.cut_by_recording
            );
        }
        file.push(scenario);
    }
    output::write(&args.out, file.to_json().as_bytes())
        .with_context(|| format!("cannot write {}", args.out.display()))?;
    let c = &file.counts;
    let skipped = c.skipped_time_gap + c.skipped_non_finite + c.skipped_incomplete;
    say!(
        "{} scenario(s), {} vehicles ({} skipped: {} with gaps in their time steps, {} with non-finite numbers, \
         {} incomplete): {} lane changes ({} merges), {} cut by the recording, {} slow and {} repeated crossings, \
         {} unlinked lanelet changes; {} lanelet centres from the traffic; written to {}",
        file.sources.len(),
        c.vehicles,
        skipped,
        c.skipped_time_gap,
        c.skipped_non_finite,
        c.skipped_incomplete,
        c.lane_changes,
        c.merges,
        c.cut_by_recording,
        c.slow_crossings,
        c.repeated_crossings,
        c.unlinked_transitions,
        c.traffic_centres,
        args.out.display()
    );
    Ok(())
}
