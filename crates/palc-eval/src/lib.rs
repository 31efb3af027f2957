//! The evaluation of palc (paper Section III, Figs. 6-13) as a library: the
//! experiment config, the plan of runs, the parallel runner, the results
//! (`runs.json`, `runs.csv`), the statistics, the paper's claims as data,
//! REPORT.md and, with the default `plot` feature, the figures.
//!
//! `cargo xtask reproduce-paper` and `palc eval` both call [`evaluate`]; an
//! embedder can run any evaluation config from Rust the same way, or take the
//! pieces: [`Evaluation::load`] reads and checks the configs, [`Evaluation::plan`]
//! expands them into runs, [`runner::execute`] runs them through the harness
//! ([`HarnessRuns`]) on a fixed number of threads, and [`stats`], [`claims`],
//! [`targets`] and [`report`] turn the rows into numbers and text. Every run is
//! named in the outputs by a [`run_id`], a hash of what it runs.
//!
//! ```no_run
//! use palc_eval::{EvalOptions, NoProgress, evaluate};
//!
//! let options = EvalOptions {
//!     quick: true,
//!     out: "target/my-eval".into(),
//!     ..EvalOptions::default()
//! };
//! let outcome = evaluate(&options, &NoProgress)?;
//! println!("{} runs, report at {}", outcome.runs, outcome.report.display());
//! # Ok::<(), palc_eval::EvalError>(())
//! ```
//!
//! Results do not depend on the number of threads: runs are collected by index,
//! and every random draw comes from a seed of the config. The crate prints
//! nothing; progress goes to a [`Progress`] that the caller supplies.
#![deny(missing_docs)]
#![warn(clippy::print_stdout, clippy::print_stderr)]
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

pub mod ablation;
pub mod claims;
pub mod config;
pub mod drive;
pub mod drive_report;
mod error;
#[cfg(feature = "plot")]
mod experiments;
#[cfg(feature = "plot")]
pub mod figures;
pub mod harness_runs;
pub mod idle;
pub mod manifest;
pub mod plan;
pub mod recorded_drivers;
pub mod report;
pub mod results;
pub mod run_id;
pub mod runner;
pub mod scenes;
pub mod schedule;
pub mod shard;
pub mod shared_runs;
pub mod stats;
pub mod targets;
pub mod views;

use std::path::{Path, PathBuf};
use std::time::Instant;

pub use config::{EvalConfig, Selection};
pub use error::EvalError;
pub use harness_runs::{ExampleTrace, HarnessRuns};
pub use idle::IdleExperiment;
pub use plan::{Experiment, RunPlan, RunSpec};
pub use results::{Iteration, RunRow, Status};
pub use runner::{NoProgress, Progress};

use manifest::Manifest;
use palc_aggregator::output::{self, Staging};
use recorded_drivers::RecordedDrivers;

/// What to evaluate and where to write it; the defaults are the paper's
/// reproduction, run from the workspace root.
#[derive(Debug, Clone, PartialEq)]
pub struct EvalOptions {
    /// The evaluation config (TOML).
    pub config: PathBuf,
    /// Output directory.
    pub out: PathBuf,
    /// Run the config's `[quick]` subset.
    pub quick: bool,
    /// Worker threads, at most [`runner::MAX_JOBS`]; every core when `None`.
    pub jobs: Option<usize>,
    /// Run only this part of the plan and write its rows to `out/shard.json`
    /// ([`shard`]); the whole plan when `None`.
    pub shard: Option<shard::Shard>,
}

/// What [`merge`] reads and writes.
#[derive(Debug, Clone, PartialEq)]
pub struct MergeOptions {
    /// The evaluation config the shards ran.
    pub config: PathBuf,
    /// Whether the shards ran its `[quick]` subset.
    pub quick: bool,
    /// The shards' output directories, one per shard.
    pub shards: Vec<PathBuf>,
    /// Output directory of the merged results.
    pub out: PathBuf,
}

impl Default for EvalOptions {
    fn default() -> Self {
        EvalOptions {
            config: PathBuf::from("configs/reproduce.toml"),
            out: PathBuf::from("target/reproduce-paper"),
            quick: false,
            jobs: None,
            shard: None,
        }
    }
}

/// What an evaluation wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    /// Path of REPORT.md.
    pub report: PathBuf,
    /// Runs made.
    pub runs: usize,
    /// Wall time of the runs (s).
    pub wall_s: f64,
    /// The experiments none of whose runs ran ([`idle`]), with the most common
    /// reason; the results are written all the same, and `palc eval` exits
    /// non-zero when this is not empty.
    pub idle: Vec<IdleExperiment>,
}

/// An evaluation config read and checked with its base learning config.
#[derive(Debug)]
pub struct Evaluation {
    config_path: PathBuf,
    base_path: PathBuf,
    texts: [String; 2],
    selection: Selection,
    harness: HarnessRuns,
    quick: bool,
    max_runs: usize,
    expected_refusals: Vec<String>,
}

/// Reads a config, at most `palc_aggregator::input::MAX_INPUT_BYTES`.
fn read(path: &Path) -> Result<String, EvalError> {
    palc_aggregator::input::read_to_string(path).map_err(|e| EvalError::Io {
        action: "read",
        path: path.to_owned(),
        source: e.into_io(),
    })
}

impl Evaluation {
    /// Reads the evaluation config at `config_path` and the base learning config
    /// it names, and checks both; `quick` selects the `[quick]` subset. Every
    /// error names the file it is in.
    pub fn load(config_path: &Path, quick: bool) -> Result<Evaluation, EvalError> {
        let text = read(config_path)?;
        let config = EvalConfig::from_toml_str(&text).map_err(|e| e.in_file(config_path))?;
        let max_runs = config.max_runs.unwrap_or(plan::DEFAULT_MAX_RUNS);
        let base_path = config.base_path(config_path);
        let base_text = read(&base_path)?;
        let base = palc_harness::LearnConfig::from_toml_str(&base_text)
            .map_err(|e| EvalError::from(e).in_file(&base_path))?;
        let harness = HarnessRuns::new(base).map_err(|e| e.in_file(&base_path))?;
        let selection =
            (config.select(quick, harness.testbed())).map_err(|e| e.in_file(config_path))?;
        let rungs = (selection.ablation.resolve()).map_err(|e| e.in_file(config_path))?;
        let mut selection = selection;
        let mut recorded = Vec::new();
        let config_dir = config_path.parent().unwrap_or_else(|| Path::new("."));
        for kind in &selection.users {
            let drivers =
                (RecordedDrivers::load(kind, config_dir)).map_err(|e| e.in_file(config_path))?;
            recorded.extend(drivers);
        }
        for drivers in &recorded {
            let ids = drivers.accepted.iter().map(|d| d.id.clone()).collect();
            selection.drivers.insert(drivers.kind.clone(), ids);
        }
        let harness = harness.with_rungs(rungs).with_recorded(recorded);
        Ok(Evaluation {
            config_path: config_path.to_owned(),
            base_path,
            texts: [text, base_text],
            selection,
            harness,
            quick,
            max_runs,
            expected_refusals: config.expected_refusals,
        })
    }

    /// The runs of this evaluation, in output order; refused past the config's
    /// `max_runs` ([`plan::DEFAULT_MAX_RUNS`] by default).
    pub fn plan(&self) -> Result<RunPlan, EvalError> {
        plan::expand_bounded(&self.selection, self.harness.testbed(), self.max_runs)
            .map_err(|e| e.in_file(&self.config_path))
    }

    /// What is run: grid, users, transfer, timing and example.
    pub fn selection(&self) -> &Selection {
        &self.selection
    }

    /// The runner of this evaluation's runs.
    pub fn harness(&self) -> &HarnessRuns {
        &self.harness
    }

    /// The qualitative example's run (Fig. 6).
    pub fn example_spec(&self) -> Result<RunSpec, EvalError> {
        let example = &self.selection.example;
        let speed_case = config::speed_case(
            self.harness.testbed(),
            &example.speed_case,
            "example.speed_case",
        )
        .map_err(|e| e.in_file(&self.config_path))?;
        Ok(RunSpec {
            id: usize::MAX,
            experiment: Experiment::Grid,
            method: example.method,
            user: config::UserKind::deterministic(),
            style: example.style,
            speed_case,
            headway_m: example.headway_m,
            seed: example.seed,
            dt: None,
            horizon_margin_s: None,
            experience_from: None,
            rung: None,
        })
    }
}

/// Runs the whole evaluation described by `options` and writes its outputs:
/// `runs.json`, `runs.csv`, `example.json`, `manifest.json`, the figures (with
/// the `plot` feature) and `REPORT.md`. Nothing is written before both configs
/// are read and checked and the runs are planned; the outputs are written into a
/// staging directory next to `options.out`, which takes its place in one atomic
/// exchange when all are written ([`Staging::commit`]), so `options.out` holds
/// either all of the previous results or all of the new ones.
pub fn evaluate(options: &EvalOptions, progress: &dyn Progress) -> Result<Outcome, EvalError> {
    let jobs = match options.jobs {
        Some(jobs) => runner::check_jobs(jobs)?,
        None => manifest::cores().clamp(1, runner::MAX_JOBS),
    };
    let evaluation = Evaluation::load(&options.config, options.quick)?;
    let plan = evaluation.plan()?;
    let example_spec = evaluation.example_spec()?;
    if let Some(shard) = options.shard {
        return run_shard(&evaluation, &plan, shard, jobs, &options.out, progress);
    }
    // Everything is written into a staging directory next to `--out`, swapped with it
    // at the end: a run that fails leaves the previous results as they were. An
    // `--out` that exists and is not a directory is refused here, before the runs.
    let staging = Staging::new(&options.out)?;
    let start = Instant::now();
    let rows = runner::execute(&plan, &evaluation.harness, jobs, progress)?;
    let wall_s = start.elapsed().as_secs_f64();
    write_results(
        &evaluation,
        &example_spec,
        rows,
        (wall_s, jobs),
        staging,
        &options.out,
    )
}

/// Merges the shards of an evaluation ([`shard`]) and writes its outputs as
/// [`evaluate`] does, as if one machine had made every run.
///
/// # Errors
/// As [`Evaluation::load`], and [`EvalError::Shard`] naming the shard file and
/// the mismatch, or the runs or shards missing or given twice.
pub fn merge(options: &MergeOptions) -> Result<Outcome, EvalError> {
    let evaluation = Evaluation::load(&options.config, options.quick)?;
    let plan = evaluation.plan()?;
    let example_spec = evaluation.example_spec()?;
    let version = manifest::palc_version();
    let hash = manifest::config_hash(&[&evaluation.texts[0], &evaluation.texts[1]]);
    let expected = shard::Expected {
        palc_version: &version,
        config_sha256: &hash,
        quick: evaluation.quick,
    };
    let (rows, wall_s, threads) = shard::merge_rows(&options.shards, &plan, &expected)?;
    let staging = Staging::new(&options.out)?;
    write_results(
        &evaluation,
        &example_spec,
        rows,
        (wall_s, threads),
        staging,
        &options.out,
    )
}

/// Makes the runs of `shard` and writes them, with what a merge checks, to
/// `out/shard.json` (the directory created if needed).
fn run_shard(
    evaluation: &Evaluation,
    plan: &RunPlan,
    shard: shard::Shard,
    jobs: usize,
    out: &Path,
    progress: &dyn Progress,
) -> Result<Outcome, EvalError> {
    let path = out.join(shard::SHARD_FILE);
    std::fs::create_dir_all(out).map_err(|source| EvalError::Io {
        action: "create",
        path: out.to_owned(),
        source,
    })?;
    output::check_writable(&path)?;
    let executor = shard::ShardExecutor::new(&evaluation.harness, plan, shard);
    let start = Instant::now();
    let rows = runner::execute(plan, &executor, jobs, progress)?;
    let wall_s = start.elapsed().as_secs_f64();
    let rows: Vec<RunRow> = (rows.into_iter())
        .filter(|row| executor.is_member(row.spec.id))
        .collect();
    let file = shard::ShardFile {
        format_version: shard::SHARD_FORMAT_VERSION,
        palc_version: manifest::palc_version(),
        config_sha256: manifest::config_hash(&[&evaluation.texts[0], &evaluation.texts[1]]),
        quick: evaluation.quick,
        shard,
        plan_runs: plan.len(),
        threads: jobs,
        wall_s,
        rows,
    };
    write(&path, &serde_json::to_string(&file)?)?;
    Ok(Outcome {
        report: path,
        runs: file.rows.len(),
        wall_s,
        idle: Vec::new(),
    })
}

/// Writes every output of an evaluation's `rows` into `staging` and commits it
/// over `out`; `(wall_s, threads)` are the runs' wall time and threads.
fn write_results(
    evaluation: &Evaluation,
    example_spec: &RunSpec,
    rows: Vec<RunRow>,
    (wall_s, jobs): (f64, usize),
    staging: Staging,
    out_dir: &Path,
) -> Result<Outcome, EvalError> {
    let out = staging.path();
    let example = evaluation
        .harness
        .example(example_spec)
        .map_err(|e| e.to_string());

    let idle = idle::idle_experiments(&rows, &evaluation.expected_refusals);
    let selection = &evaluation.selection;
    let (git_commit, git_dirty) = manifest::git_state();
    let manifest = Manifest {
        palc_version: manifest::palc_version(),
        git_commit,
        git_dirty,
        config_sha256: manifest::config_hash(&[&evaluation.texts[0], &evaluation.texts[1]]),
        config_path: evaluation.config_path.display().to_string(),
        base_path: evaluation.base_path.display().to_string(),
        quick: evaluation.quick,
        seeds: selection.grid.seeds.clone(),
        threads: jobs,
        cores: manifest::cores(),
        machine: manifest::machine(),
        runs: rows.len(),
        wall_s,
    };

    results::write(&rows, &out.join("runs.json"), &out.join("runs.csv"))?;
    results::write_refusals(&rows, &out.join("refusals.csv"))?;
    if let Ok(trace) = &example {
        write(
            &out.join("example.json"),
            &serde_json::to_string_pretty(trace)?,
        )?;
    }
    write(
        &out.join("manifest.json"),
        &serde_json::to_string_pretty(&manifest)?,
    )?;
    // The paper's user kinds get a section and figures each; the families one
    // table together.
    let user_names: Vec<String> = (selection.users.iter())
        .filter(|u| !u.is_family())
        .map(|u| u.name.clone())
        .collect();
    #[cfg(feature = "plot")]
    let figures = experiments::draw_all(
        &rows,
        &selection.grid.methods,
        &user_names,
        example.as_ref().ok(),
        out,
    )?;
    #[cfg(not(feature = "plot"))]
    let figures = Vec::new();
    let report = report::render(&report::ReportInput {
        rows: &rows,
        methods: &selection.grid.methods,
        users: &user_names,
        user_kinds: &selection.users,
        example: example.as_ref().map_err(Clone::clone),
        figures: &figures,
        manifest: &manifest,
        ablation: (evaluation.harness.rungs(), &selection.ablation.users),
        recorded: evaluation.harness.recorded(),
        idle: &idle,
    });
    write(&out.join("REPORT.md"), &report.text)?;
    for table in &report.tables {
        let rows = table.rows.iter();
        results::write_csv(&out.join(table.file), Some(table.header), rows)?;
    }
    // The example's files and the report's tables of an earlier run are not carried
    // over when this one has none.
    let mut obsolete = vec!["example.json", "fig06-example.svg", "fig06-example.png"];
    obsolete.extend(report::TABLE_FILES);
    staging.commit(&obsolete)?;
    let report = out_dir.join("REPORT.md");
    Ok(Outcome {
        report,
        runs: rows.len(),
        wall_s,
        idle,
    })
}

fn write(path: &Path, text: &str) -> Result<(), EvalError> {
    Ok(output::write(path, text.as_bytes())?)
}
