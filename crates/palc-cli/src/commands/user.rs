//! `palc user`: what a simulated user expects, before learning starts.

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::Context;
use clap::{Args, Subcommand};
use palc_aggregator::output;

use crate::commands::learn::{ScenarioArgs, load_config};
use crate::console::say;

/// Arguments of `palc user`.
#[derive(Debug, Args)]
pub struct UserArgs {
    #[command(subcommand)]
    command: UserCommand,
}

#[derive(Debug, Subcommand)]
enum UserCommand {
    /// Write the lane change a user expects in a scenario as CSV (step, time, s,
    /// speed, lateral position, heading, phase).
    Expect(ExpectArgs),
}

/// Arguments of `palc user expect`.
#[derive(Debug, Args)]
pub struct ExpectArgs {
    #[command(flatten)]
    scenario: ScenarioArgs,
    /// The CSV file to write.
    #[arg(long)]
    out: PathBuf,
}

/// Runs `palc user`.
pub fn run(args: UserArgs) -> anyhow::Result<()> {
    match args.command {
        UserCommand::Expect(args) => expect(args),
    }
}

fn expect(args: ExpectArgs) -> anyhow::Result<()> {
    output::check_writable(&args.out)?;
    let config = load_config(&args.scenario)?;
    let (setup, expectation) =
        palc_harness::advanced::expectation(&config).with_context(|| args.scenario.whose_user())?;
    let lane_change = &expectation.lane_change;
    let mut csv = String::from("step,time_s,s_m,v_mps,l_m,phi_rad,phase\n");
    for (i, state) in expectation
        .states
        .iter()
        .enumerate()
        .take(setup.horizon + 1)
    {
        let t = i as f64 * setup.dt;
        let phase = if i < expectation.start_step {
            "keeping"
        } else if t <= lane_change.end_s() + 1e-9 {
            "changing"
        } else {
            "done"
        };
        let _ = writeln!(
            csv,
            "{i},{t:.3},{:.4},{:.4},{:.4},{:.6},{phase}",
            state.s, state.v, state.l, state.phi
        );
    }
    output::write(&args.out, csv.as_bytes())
        .with_context(|| format!("cannot write {}", args.out.display()))?;
    say!(
        "{}: decides at {:.1} s, starts at {:.1} s, ends at {:.2} s ({} profile); {} steps written to {}",
        config.label(),
        expectation.decision_step as f64 * setup.dt,
        lane_change.start_s,
        lane_change.end_s(),
        lane_change.profile.name(),
        setup.horizon + 1,
        args.out.display()
    );
    Ok(())
}
