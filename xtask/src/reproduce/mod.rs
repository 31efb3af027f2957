//! `cargo xtask reproduce-paper`: the paper's evaluation (Section III, Figs. 6-13)
//! regenerated from `configs/reproduce.toml`, both methods side by side.
//!
//! The task only orchestrates: [`plan`] expands the config into runs, [`runner`]
//! executes them in parallel through the harness ([`harness_runs`]), [`stats`]
//! aggregates, [`experiments`] and [`figures`] draw, [`report`] writes REPORT.md
//! with the [`manifest`]. All learning happens in `palc-harness`.

mod config;
mod experiments;
mod figures;
mod harness_runs;
mod manifest;
mod plan;
mod report;
mod results;
mod runner;
mod stats;

#[cfg(test)]
mod golden;

use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::Parser;

use config::ReproduceConfig;
use harness_runs::HarnessRuns;
use manifest::Manifest;
use runner::Progress;

/// Command-line options of `cargo xtask reproduce-paper`.
#[derive(Debug, Parser)]
#[command(
    name = "cargo xtask reproduce-paper",
    about = "Regenerate the paper's evaluation"
)]
pub struct Args {
    /// Run the small `[quick]` subset (about a minute on two cores).
    #[arg(long)]
    pub quick: bool,
    /// Output directory.
    #[arg(long, default_value = "target/reproduce-paper")]
    pub out: PathBuf,
    /// Worker threads (default: every core).
    #[arg(long)]
    pub jobs: Option<usize>,
    /// The reproduction config.
    #[arg(long, default_value = "configs/reproduce.toml")]
    pub config: PathBuf,
}

/// Runs the task with the arguments after `reproduce-paper`.
pub fn main(args: impl IntoIterator<Item = String>) -> anyhow::Result<()> {
    let args = Args::parse_from(std::iter::once("reproduce-paper".to_owned()).chain(args));
    let outcome = reproduce(&args, false)?;
    println!(
        "{} runs in {:.1} s; report: {}",
        outcome.runs,
        outcome.wall_s,
        outcome.report.display()
    );
    Ok(())
}

/// What a reproduction wrote.
pub struct Outcome {
    /// Path of REPORT.md.
    pub report: PathBuf,
    /// Runs made.
    pub runs: usize,
    /// Wall time of the runs (s).
    pub wall_s: f64,
}

fn read(path: &Path) -> anyhow::Result<String> {
    std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))
}

/// Runs the whole reproduction described by `args`; `quiet` prints nothing.
pub fn reproduce(args: &Args, quiet: bool) -> anyhow::Result<Outcome> {
    let text = read(&args.config)?;
    let config = ReproduceConfig::from_toml_str(&text)
        .with_context(|| format!("in {}", args.config.display()))?;
    let base_path = config.base_path(&args.config);
    let base_text = read(&base_path)?;
    let harness = HarnessRuns::from_toml_str(&base_text)
        .with_context(|| format!("in {}", base_path.display()))?;
    let selection = config.select(args.quick)?;
    let plan = plan::expand(&selection, &harness.speed_cases()?)
        .with_context(|| format!("in {}", args.config.display()))?;
    let jobs = args.jobs.unwrap_or_else(manifest::cores).max(1);
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;

    if !quiet {
        println!(
            "reproduce-paper: {} runs ({} grid cells x {} methods x {} users, transfer, timing) on {jobs} threads",
            plan.len(),
            selection.grid.cells(),
            selection.grid.methods.len(),
            selection.users.len()
        );
    }
    let progress = Progress::new(plan.len(), quiet);
    let rows = runner::execute(&plan, &harness, jobs, &progress)?;
    let wall_s = progress.elapsed().as_secs_f64();

    let example_spec = plan::RunSpec {
        id: usize::MAX,
        experiment: plan::Experiment::Grid,
        method: selection.example.method.clone(),
        user: config::UserKind {
            name: "deterministic".into(),
            spread_relative: None,
        },
        style: selection.example.style.clone(),
        speed_case: (harness.speed_cases()?.into_iter())
            .find(|c| c.name == selection.example.speed_case)
            .with_context(|| {
                format!(
                    "unknown speed case `{}` in `example`",
                    selection.example.speed_case
                )
            })?,
        headway_m: selection.example.headway_m,
        seed: selection.example.seed,
        dt: None,
        horizon_margin_s: None,
        experience_from: None,
    };
    let example = harness.example(&example_spec).map_err(|e| format!("{e:#}"));

    let (git_commit, git_dirty) = manifest::git_state();
    let manifest = Manifest {
        palc_version: manifest::palc_version(),
        git_commit,
        git_dirty,
        config_sha256: manifest::config_hash(&[&text, &base_text]),
        config_path: args.config.display().to_string(),
        base_path: base_path.display().to_string(),
        quick: args.quick,
        seeds: selection.grid.seeds.clone(),
        threads: jobs,
        cores: manifest::cores(),
        machine: manifest::machine(),
        runs: rows.len(),
        wall_s,
    };

    let out = &args.out;
    results::write(&rows, &out.join("runs.json"), &out.join("runs.csv"))?;
    if let Ok(trace) = &example {
        let text = serde_json::to_string_pretty(trace)?;
        std::fs::write(out.join("example.json"), text).context("cannot write example.json")?;
    }
    std::fs::write(
        out.join("manifest.json"),
        serde_json::to_string_pretty(&manifest)?,
    )
    .context("cannot write manifest.json")?;
    let user_names: Vec<String> = selection.users.iter().map(|u| u.name.clone()).collect();
    let figures = experiments::draw_all(
        &rows,
        &selection.grid.methods,
        &user_names,
        example.as_ref().ok(),
        out,
    )?;
    let report_text = report::render(&report::ReportInput {
        rows: &rows,
        methods: &selection.grid.methods,
        users: &user_names,
        example: example.as_ref().map_err(Clone::clone),
        figures: &figures,
        manifest: &manifest,
    });
    let report = out.join("REPORT.md");
    std::fs::write(&report, report_text)
        .with_context(|| format!("cannot write {}", report.display()))?;
    Ok(Outcome {
        report,
        runs: rows.len(),
        wall_s,
    })
}
