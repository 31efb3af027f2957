//! `palc`: the command line of palc, a thin layer over the library crates.
//!
//! Each subcommand lives in its own module under `commands/`; this file only
//! parses arguments and dispatches. Every output file is written through
//! `palc_aggregator::output` (nothing is truncated in place), and every line for the
//! user goes through `console` (a closed stdout ends the command quietly, with its
//! files saved).

use std::process::ExitCode;

use clap::{Parser, Subcommand};

mod commands;
mod console;
#[cfg(test)]
mod fuzz;
mod parse;

/// Personalized automated lane change that learns from the driver's takeovers.
#[derive(Debug, Parser)]
#[command(name = "palc", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Run an evaluation config: the paper's reproduction by default (runs, statistics,
    /// REPORT.md, figures).
    Eval(commands::eval::EvalArgs),
    /// A browser driving study: a person drives, palc learns from their takeovers.
    Drive(commands::drive::DriveArgs),
    /// Learn a user's lane changes from takeovers (the lesson-learning loop).
    Learn(commands::learn::LearnArgs),
    /// Background traffic on its own (IDM scenes, platoons).
    Traffic(commands::traffic::TrafficArgs),
    /// Plan one lane change (the MPC as a QP) from a JSON problem.
    Plan(commands::plan::PlanArgs),
    /// The perceived safe zone filter: fit on labelled samples, classify points.
    Zone(commands::zone::ZoneArgs),
    /// Simulated users: the lane change a user expects, before learning starts.
    User(commands::user::UserArgs),
    /// Bring recorded traffic into palc (`palc import commonroad SCENARIO.xml...`).
    Import(commands::import::ImportArgs),
    /// Write palc's scenes and learned lane changes for other tools
    /// (`palc export commonroad`).
    Export(commands::export::ExportArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Eval(args) => commands::eval::run(args),
        Command::Drive(args) => commands::drive::run(args),
        Command::Learn(args) => commands::learn::run_learn(args),
        Command::Traffic(args) => commands::traffic::run(args),
        Command::Plan(args) => commands::plan::run(args),
        Command::Zone(args) => commands::zone::run(args),
        Command::User(args) => commands::user::run(args),
        Command::Import(args) => commands::import::run(args),
        Command::Export(args) => commands::export::run(args),
    };
    let result = result.and_then(|()| match console::failure() {
        Some(error) => Err(anyhow::Error::new(error).context("cannot write to the terminal")),
        None => Ok(()),
    });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // The reader of our output has gone away (`palc ... | head`): not a failure.
        Err(error) if console::is_broken_pipe(&error) => ExitCode::SUCCESS,
        Err(error) => {
            console::report(&error);
            ExitCode::FAILURE
        }
    }
}
