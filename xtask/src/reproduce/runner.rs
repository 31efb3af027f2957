//! Running the plan in parallel: rayon on `--jobs` threads, results collected by
//! run index so that every output is the same whatever the number of threads.

use std::collections::HashMap;
use std::io::IsTerminal;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;

use super::plan::{RunPlan, RunSpec};
use super::results::{RunRow, Status};

/// Runs one spec. The harness implements it (`harness_runs.rs`); tests use
/// synthetic executors.
pub trait Executor: Sync {
    /// What a run learned, to start another run from.
    type Experience: Send + Sync;

    /// Runs `spec`, from `experience` if given; returns the row and, when the
    /// run produced one, its experience.
    fn run(
        &self,
        spec: &RunSpec,
        experience: Option<&Self::Experience>,
    ) -> (RunRow, Option<Self::Experience>);

    /// The takeover cap, for rows of runs that could not start.
    fn cap(&self) -> usize;
}

/// Shows progress: a bar with ETA on a terminal, a plain line every 5 % otherwise.
pub struct Progress {
    bar: Option<ProgressBar>,
    total: usize,
    done: AtomicUsize,
    start: Instant,
    quiet: bool,
}

impl Progress {
    /// Progress over `total` runs; `quiet` prints nothing (tests).
    pub fn new(total: usize, quiet: bool) -> Progress {
        let bar = (!quiet && std::io::stdout().is_terminal()).then(|| {
            let bar = ProgressBar::new(total as u64);
            bar.set_style(
                ProgressStyle::with_template(
                    "{elapsed_precise} [{bar:40}] {pos}/{len} runs, ETA {eta} {msg}",
                )
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
            );
            bar
        });
        Progress {
            bar,
            total,
            done: AtomicUsize::new(0),
            start: Instant::now(),
            quiet,
        }
    }

    fn finished(&self, row: &RunRow) {
        let done = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        if let Some(bar) = &self.bar {
            bar.set_message(format!("{} {}", row.spec.method, row.status.name()));
            bar.inc(1);
            return;
        }
        if self.quiet {
            return;
        }
        let step = (self.total / 20).max(1);
        if done % step == 0 || done == self.total {
            let elapsed = self.start.elapsed().as_secs_f64();
            let eta = elapsed / done as f64 * (self.total - done) as f64;
            println!(
                "[{done}/{total}] {elapsed:.0} s elapsed, about {eta:.0} s left",
                total = self.total
            );
        }
    }

    /// Ends the bar.
    pub fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_with_message("done");
        }
    }

    /// Time since the start.
    pub fn elapsed(&self) -> Duration {
        self.start.elapsed()
    }
}

/// Runs every spec of `plan` on `jobs` threads; the rows are in plan order.
pub fn execute<E: Executor>(
    plan: &RunPlan,
    executor: &E,
    jobs: usize,
    progress: &Progress,
) -> anyhow::Result<Vec<RunRow>> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs)
        .build()
        .context("cannot start the thread pool")?;
    let sources: Vec<usize> = plan
        .transfer
        .iter()
        .filter_map(|s| s.experience_from)
        .collect();
    let (mut rows, experiences): (Vec<RunRow>, HashMap<usize, E::Experience>) =
        pool.install(|| {
            let done: Vec<(RunRow, Option<E::Experience>)> = plan
                .first
                .par_iter()
                .map(|spec| {
                    let (row, experience) = executor.run(spec, None);
                    progress.finished(&row);
                    let keep = sources.contains(&spec.id);
                    (row, experience.filter(|_| keep))
                })
                .collect();
            let mut experiences = HashMap::new();
            let rows = done
                .into_iter()
                .map(|(row, experience)| {
                    if let Some(experience) = experience {
                        experiences.insert(row.spec.id, experience);
                    }
                    row
                })
                .collect();
            (rows, experiences)
        });
    let transfer: Vec<RunRow> = pool.install(|| {
        plan.transfer
            .par_iter()
            .map(|spec| {
                let source = spec.experience_from.and_then(|id| experiences.get(&id));
                let row = match source {
                    Some(experience) => executor.run(spec, Some(experience)).0,
                    None => {
                        let from = spec
                            .experience_from
                            .and_then(|id| rows.get(id))
                            .map_or_else(|| "none".to_owned(), RunSpec::label_of);
                        let reason = format!("no experience to start from: source run {from}");
                        RunRow::without_result(
                            spec.clone(),
                            Status::Refused { reason },
                            executor.cap(),
                            0.0,
                        )
                    }
                };
                progress.finished(&row);
                row
            })
            .collect()
    });
    rows.extend(transfer);
    progress.finish();
    for (index, row) in rows.iter().enumerate() {
        anyhow::ensure!(
            row.spec.id == index,
            "run {} came back as {}",
            index,
            row.spec.id
        );
    }
    Ok(rows)
}

impl RunSpec {
    fn label_of(row: &RunRow) -> String {
        format!("`{}` ({})", row.spec.label(), row.status.name())
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::super::plan::{self, Experiment};
    use super::super::results::Iteration;
    use super::*;

    /// A deterministic stand-in for the harness: the outcome is a function of
    /// the spec (and of whether experience was given), never of the thread.
    pub(crate) struct Synthetic;

    impl Executor for Synthetic {
        type Experience = usize;

        fn run(&self, spec: &RunSpec, experience: Option<&usize>) -> (RunRow, Option<usize>) {
            let style = match spec.style.as_str() {
                "aggressive" => 2,
                "neutral" => 4,
                _ => 6,
            };
            let base = style + (spec.seed as usize % 3) + (spec.headway_m < 40.0) as usize;
            let takeovers = if spec.method == "paper" { 30 } else { base };
            let takeovers = match experience {
                Some(_) => takeovers * 3 / 4,
                None => takeovers,
            };
            let status = if spec.speed_case.name == "arterial-slow" && spec.style == "cautious" {
                return (
                    RunRow::without_result(
                        spec.clone(),
                        Status::Refused {
                            reason: "the standard ALC is not conservative".into(),
                        },
                        30,
                        0.0,
                    ),
                    None,
                );
            } else if takeovers >= 30 {
                Status::CapReached
            } else {
                Status::Personalized
            };
            let lane_changes = takeovers + 3;
            let iterations = (0..lane_changes)
                .map(|i| Iteration {
                    takeover: i < takeovers,
                    perceived_safety_ratio: if i < takeovers {
                        0.2 + 0.5 * i as f64 / lane_changes as f64
                    } else {
                        1.0
                    },
                    max_deviation_m: 0.1,
                    times_s: [
                        0.001,
                        0.002,
                        0.01,
                        0.02,
                        0.005 * spec.dt.unwrap_or(0.1) * 10.0,
                    ],
                })
                .collect();
            let dt = spec.dt.unwrap_or(0.1);
            let row = RunRow {
                spec: spec.clone(),
                status,
                takeovers,
                cap: 30,
                lane_changes,
                final_max_deviation_m: Some(0.05),
                final_takeover_rate: Some(0.0),
                ceiling_takeover_rate: Some(0.0),
                horizon: (8.0 / dt) as usize,
                dt: Some(dt),
                wall_s: 0.01,
                iterations,
            };
            (row, Some(spec.id))
        }

        fn cap(&self) -> usize {
            30
        }
    }

    pub(crate) fn synthetic_rows() -> Vec<RunRow> {
        let plan = plan::expand(&plan::tests::selection(), &plan::tests::speed_cases()).unwrap();
        execute(&plan, &Synthetic, 2, &Progress::new(plan.len(), true)).unwrap()
    }

    #[test]
    fn results_do_not_depend_on_the_number_of_threads() {
        let plan = plan::expand(&plan::tests::selection(), &plan::tests::speed_cases()).unwrap();
        let one = execute(&plan, &Synthetic, 1, &Progress::new(plan.len(), true)).unwrap();
        let three = execute(&plan, &Synthetic, 3, &Progress::new(plan.len(), true)).unwrap();
        assert_eq!(one, three);
        assert_eq!(one.len(), plan.len());
    }

    #[test]
    fn a_transfer_run_gets_its_sources_experience_or_is_named_as_refused() {
        let rows = synthetic_rows();
        let transfer: Vec<&RunRow> = rows
            .iter()
            .filter(|r| r.spec.experiment == Experiment::Transfer)
            .collect();
        assert!(!transfer.is_empty());
        for row in transfer {
            let source = &rows[row.spec.experience_from.unwrap()];
            if !source.status.counted() {
                let Status::Refused { reason } = &row.status else {
                    panic!("{:?}", row.status)
                };
                assert!(reason.contains(&source.spec.label()), "{reason}");
            } else if row.status.counted() {
                // The synthetic executor needs a quarter fewer takeovers with experience.
                let without = rows
                    .iter()
                    .find(|r| {
                        r.spec.experiment == Experiment::Grid
                            && r.spec.experiment_cell() == row.spec.experiment_cell()
                    })
                    .unwrap();
                assert!(row.takeovers <= without.takeovers);
            }
        }
    }
}
