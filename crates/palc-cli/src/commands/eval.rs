//! `palc eval`: runs an evaluation config (the paper's reproduction by
//! default) through `palc-eval` and shows its progress.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use clap::{Args, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use palc_eval::shard::Shard;
use palc_eval::{EvalOptions, MergeOptions, Outcome, Progress, RunRow, evaluate, merge};

use crate::console::say;

/// Arguments of `palc eval` (and of `cargo xtask reproduce-paper`).
#[derive(Debug, Args)]
#[command(args_conflicts_with_subcommands = true)]
pub struct EvalArgs {
    #[command(subcommand)]
    command: Option<EvalCommand>,
    /// Run the config's small `[quick]` subset (about a minute on two cores).
    #[arg(long)]
    quick: bool,
    /// Output directory.
    #[arg(long, default_value = "target/reproduce-paper")]
    out: PathBuf,
    /// Worker threads (default: every core; at most 1024).
    #[arg(long)]
    jobs: Option<usize>,
    /// The evaluation config.
    #[arg(long, default_value = "configs/reproduce.toml")]
    config: PathBuf,
    /// Run only part `i` of `n` (from 0) of the evaluation and write its runs to
    /// `OUT/shard.json`, for `palc eval merge` (see docs/scale-out.md).
    #[arg(long, value_name = "i/n")]
    shard: Option<Shard>,
}

#[derive(Debug, Subcommand)]
enum EvalCommand {
    /// Merge the shards of an evaluation (`palc eval --shard i/n`) into the
    /// results one machine would have written.
    Merge(MergeArgs),
}

/// Arguments of `palc eval merge`.
#[derive(Debug, Args)]
struct MergeArgs {
    /// The evaluation config the shards ran.
    #[arg(long, default_value = "configs/reproduce.toml")]
    config: PathBuf,
    /// The shards ran the config's `[quick]` subset.
    #[arg(long)]
    quick: bool,
    /// Output directory of the merged results.
    #[arg(long, default_value = "target/reproduce-paper")]
    out: PathBuf,
    /// The shards' output directories, every one of them.
    #[arg(required = true)]
    shards: Vec<PathBuf>,
}

/// Shows progress: a bar with ETA on a terminal, a plain line every 5 % otherwise.
struct Shown {
    bar: Option<ProgressBar>,
    total: AtomicUsize,
    done: AtomicUsize,
    start: Instant,
}

impl Shown {
    fn new() -> Shown {
        let bar = std::io::stdout().is_terminal().then(|| {
            let bar = ProgressBar::new(0);
            bar.set_style(
                ProgressStyle::with_template(
                    "{elapsed_precise} [{bar:40}] {pos}/{len} runs, ETA {eta} {msg}",
                )
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
            );
            bar
        });
        Shown {
            bar,
            total: AtomicUsize::new(0),
            done: AtomicUsize::new(0),
            start: Instant::now(),
        }
    }
}

impl Progress for Shown {
    fn started(&self, total: usize) {
        self.total.store(total, Ordering::Relaxed);
        match &self.bar {
            Some(bar) => bar.set_length(total as u64),
            None => say!("{total} runs"),
        }
    }

    fn finished(&self, row: &RunRow) {
        let done = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        if let Some(bar) = &self.bar {
            bar.set_message(format!("{} {}", row.spec.method.name(), row.status.name()));
            bar.inc(1);
            return;
        }
        let total = self.total.load(Ordering::Relaxed).max(1);
        let step = (total / 20).max(1);
        if done % step == 0 || done == total {
            let elapsed = self.start.elapsed().as_secs_f64();
            let eta = elapsed / done as f64 * total.saturating_sub(done) as f64;
            say!("[{done}/{total}] {elapsed:.0} s elapsed, about {eta:.0} s left");
        }
    }

    fn done(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_with_message("done");
        }
    }
}

/// Runs `palc eval`.
pub fn run(args: EvalArgs) -> anyhow::Result<()> {
    if let Some(EvalCommand::Merge(args)) = args.command {
        return run_merge(args);
    }
    let options = EvalOptions {
        config: args.config,
        out: args.out,
        quick: args.quick,
        jobs: args.jobs,
        shard: args.shard,
    };
    say!(
        "evaluating {}{} on {} threads",
        options.config.display(),
        if options.quick { " (quick subset)" } else { "" },
        options
            .jobs
            .map_or_else(|| "all".to_owned(), |j| j.to_string())
    );
    let outcome = evaluate(&options, &Shown::new())?;
    if let Some(shard) = options.shard {
        say!(
            "shard {shard}: {} runs in {:.1} s written to {}",
            outcome.runs,
            outcome.wall_s,
            outcome.report.display()
        );
        return Ok(());
    }
    finish(&outcome)
}

/// Runs `palc eval merge`.
fn run_merge(args: MergeArgs) -> anyhow::Result<()> {
    let options = MergeOptions {
        config: args.config,
        quick: args.quick,
        shards: args.shards,
        out: args.out,
    };
    say!(
        "merging {} shards of {}",
        options.shards.len(),
        options.config.display()
    );
    finish(&merge(&options)?)
}

/// Says what an evaluation wrote, and fails when one of its experiments
/// measured nothing.
fn finish(outcome: &Outcome) -> anyhow::Result<()> {
    say!(
        "{} runs in {:.1} s; report: {}",
        outcome.runs,
        outcome.wall_s,
        outcome.report.display()
    );
    if !outcome.idle.is_empty() {
        let experiments: Vec<String> = outcome.idle.iter().map(|e| e.to_string()).collect();
        anyhow::bail!(
            "the results are written, but {} measured nothing:\n  {}\n(a scene built to refuse \
             lists its refusal kinds in the config's `expected_refusals`)",
            if experiments.len() == 1 {
                "one experiment"
            } else {
                "some experiments"
            },
            experiments.join("\n  ")
        );
    }
    Ok(())
}
