//! Running the plan in parallel: rayon on a fixed number of threads, results
//! collected by run index so that every output is the same whatever the number
//! of threads.
//!
//! The runner prints nothing: it reports each finished run to a [`Progress`],
//! which a binary turns into a progress bar or log lines.

use std::collections::HashMap;

use rayon::prelude::*;

use crate::EvalError;
use crate::plan::{Experiment, RunPlan, RunSpec};
use crate::results::{RunRow, Status};
use crate::shared_runs::{self, Shared};

/// Runs one spec. The harness implements it (`harness_runs.rs`); tests use
/// synthetic executors.
pub trait Executor: Sync {
    /// What a run learned, to start another run from.
    type Experience: Send + Sync + Clone;

    /// Runs `spec`, from `experience` if given; returns the row and, when the
    /// run produced one, its experience.
    fn run(
        &self,
        spec: &RunSpec,
        experience: Option<&Self::Experience>,
    ) -> (RunRow, Option<Self::Experience>);

    /// The takeover cap, for rows of runs that could not start.
    fn cap(&self) -> usize;

    /// What determines the result of `spec` apart from the experience it starts
    /// from: two runs with equal identities and the same source give the same row
    /// (apart from the spec and the timing fields), so the runner computes one
    /// and shares it ([`crate::shared_runs`]). `None`, by default: always computed.
    fn identity(&self, _spec: &RunSpec) -> Option<String> {
        None
    }
}

/// Watches the runs of an evaluation; called from the worker threads.
pub trait Progress: Sync {
    /// Called once before the first run with the number of runs.
    fn started(&self, _total: usize) {}
    /// Called after each run, in the order runs finish.
    fn finished(&self, _row: &RunRow) {}
    /// Called once after the last run.
    fn done(&self) {}
    /// Whether the evaluation is to stop: asked before each run; once it answers
    /// yes, the runs not started are skipped and [`execute`] returns
    /// [`EvalError::Cancelled`] (no output is written). Never, by default.
    fn cancelled(&self) -> bool {
        false
    }
}

/// A [`Progress`] that shows nothing.
#[derive(Debug, Default, Clone, Copy)]
pub struct NoProgress;

impl Progress for NoProgress {}

/// The most worker threads an evaluation may start (`--jobs`).
pub const MAX_JOBS: usize = 1024;

/// `jobs` if it lies in `1..=MAX_JOBS`.
///
/// # Errors
/// [`EvalError::InvalidOption`] naming `--jobs`, the value and the bound.
pub fn check_jobs(jobs: usize) -> Result<usize, EvalError> {
    if (1..=MAX_JOBS).contains(&jobs) {
        Ok(jobs)
    } else {
        Err(EvalError::InvalidOption {
            option: "--jobs",
            value: jobs.to_string(),
            bound: format!("1 to {MAX_JOBS} threads"),
        })
    }
}

/// Runs every spec of `plan` on `jobs` threads (at most [`MAX_JOBS`]); the rows
/// are in plan order. A run that repeats an earlier one ([`crate::shared_runs`])
/// is not computed again: it takes the earlier run's row under its own spec.
pub fn execute<E: Executor>(
    plan: &RunPlan,
    executor: &E,
    jobs: usize,
    progress: &dyn Progress,
) -> Result<Vec<RunRow>, EvalError> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(check_jobs(jobs)?)
        .build()?;
    progress.started(plan.len());
    let original = shared_runs::originals(plan, |spec| executor.identity(spec));
    let mut shared: Shared<RunRow, E::Experience> = Shared::new(&original);
    // How many runs start from each run's experience: an experience is kept
    // until the last of them has started, then dropped.
    let mut uses: HashMap<usize, usize> = HashMap::new();
    for source in plan.transfer.iter().filter_map(|s| s.experience_from) {
        *uses.entry(source).or_default() += 1;
    }
    // An original's output, kept whole when a run repeats it.
    let keep = |id: usize, uses: &HashMap<usize, usize>, shared: &Shared<RunRow, E::Experience>| {
        uses.contains_key(&id) || shared.has_repeats(id)
    };
    let computed: Vec<Option<Output<E>>> = pool.install(|| {
        (plan.first.par_iter())
            .map(|spec| {
                if original[spec.id] != spec.id {
                    return None;
                }
                if progress.cancelled() {
                    return Some((skipped(spec, executor.cap()), None));
                }
                let (row, experience) = executor.run(spec, None);
                progress.finished(&row);
                Some((row, experience.filter(|_| keep(spec.id, &uses, &shared))))
            })
            .collect()
    });
    let mut experiences: HashMap<usize, E::Experience> = HashMap::new();
    let mut rows = Vec::with_capacity(plan.len());
    for (spec, output) in plan.first.iter().zip(computed) {
        let (row, experience) = match output {
            Some(output) => {
                shared.keep(spec.id, &output);
                output
            }
            // A cancelled evaluation reports no repeat as finished: its
            // original was skipped, and nothing is written.
            None if progress.cancelled() => (skipped(spec, executor.cap()), None),
            None => {
                let output = repeated(spec, original[spec.id], &shared);
                shared.served(original[spec.id]);
                progress.finished(&output.0);
                output
            }
        };
        if let Some(experience) = experience.filter(|_| uses.contains_key(&spec.id)) {
            experiences.insert(spec.id, experience);
        }
        rows.push(row);
    }
    // Runs with experience, in waves: each wave holds the runs whose source has
    // ended (a grid run, or an accumulation or drive run of an earlier wave) and,
    // for a repeat, whose original has ended.
    let mut transfer: Vec<Option<RunRow>> = vec![None; plan.transfer.len()];
    let offset = plan.first.len();
    let ended = |id: usize, transfer: &[Option<RunRow>]| {
        id < offset || transfer.get(id - offset).is_some_and(Option::is_some)
    };
    loop {
        let wave: Vec<&RunSpec> = (plan.transfer.iter())
            .filter(|s| transfer[s.id - offset].is_none())
            .filter(|s| s.experience_from.is_none_or(|id| ended(id, &transfer)))
            .filter(|s| original[s.id] == s.id || ended(original[s.id], &transfer))
            .collect();
        if wave.is_empty() || progress.cancelled() {
            break;
        }
        let done: Vec<Output<E>> = pool.install(|| {
            wave.par_iter()
                .map(|spec| {
                    let compute = |experience: Option<&E::Experience>| match original[spec.id] {
                        of if of == spec.id => executor.run(spec, experience),
                        of => repeated(spec, of, &shared),
                    };
                    let source = spec.experience_from.and_then(|id| experiences.get(&id));
                    let (row, experience) = match (spec.experience_from, source) {
                        (Some(_), Some(experience)) => {
                            let (row, learned) = compute(Some(experience));
                            (row, learned.or_else(|| passed_on(spec, experience)))
                        }
                        (None, _) => compute(None),
                        // A drive that has learned nothing yet (its first
                        // scenes were refused) starts from scratch.
                        (Some(_), None) if spec.experiment == Experiment::Drive => compute(None),
                        (Some(source), None) => {
                            let from = (match source.checked_sub(offset) {
                                None => rows.get(source),
                                Some(i) => transfer.get(i).and_then(Option::as_ref),
                            })
                            .map_or_else(|| "none".to_owned(), RunSpec::label_of);
                            let reason = format!("no experience to start from: source run {from}");
                            let row = RunRow::without_result(
                                (*spec).clone(),
                                Status::Refused {
                                    reason,
                                    refusal: None,
                                },
                                executor.cap(),
                                0.0,
                            );
                            (row, None)
                        }
                    };
                    progress.finished(&row);
                    (row, experience.filter(|_| keep(spec.id, &uses, &shared)))
                })
                .collect()
        });
        for spec in &wave {
            if let Some(source) = spec.experience_from {
                if let Some(left) = uses.get_mut(&source) {
                    *left -= 1;
                    if *left == 0 {
                        experiences.remove(&source);
                    }
                }
            }
            if original[spec.id] != spec.id {
                shared.served(original[spec.id]);
            }
        }
        for (row, experience) in done {
            let id = row.spec.id;
            let output = (row, experience);
            if original[id] == id {
                shared.keep(id, &output);
            }
            let (row, experience) = output;
            if let Some(experience) = experience.filter(|_| uses.contains_key(&id)) {
                experiences.insert(id, experience);
            }
            transfer[id - offset] = Some(row);
        }
    }
    if progress.cancelled() {
        return Err(EvalError::Cancelled);
    }
    rows.extend(transfer.into_iter().flatten());
    progress.done();
    debug_assert!(rows.iter().enumerate().all(|(i, row)| row.spec.id == i));
    Ok(rows)
}

/// A run's row and the experience it hands on.
type Output<E> = (RunRow, Option<<E as Executor>::Experience>);

/// The output of a run that repeats original `of`: the original's row under the
/// run's own spec, and the original's experience. The original has ended.
fn repeated<X: Clone>(
    spec: &RunSpec,
    of: usize,
    shared: &Shared<RunRow, X>,
) -> (RunRow, Option<X>) {
    match shared.output(of) {
        Some((row, experience)) => (
            RunRow {
                spec: spec.clone(),
                ..row.clone()
            },
            experience.clone(),
        ),
        // Unreachable: a repeat waits for its original, whose output is kept
        // until its last repeat is served.
        None => {
            let status = Status::Failed {
                error: format!("the run it repeats (index {of}) has no output"),
            };
            (RunRow::without_result(spec.clone(), status, 0, 0.0), None)
        }
    }
}

/// What a run that learned nothing hands on: a drive goes on through a scene it
/// could not drive (refused) with the experience it had; other runs hand on nothing.
fn passed_on<X: Clone>(spec: &RunSpec, experience: &X) -> Option<X> {
    (spec.experiment == Experiment::Drive).then(|| experience.clone())
}

/// The row of a run skipped because the evaluation was cancelled; never written.
fn skipped(spec: &RunSpec, cap: usize) -> RunRow {
    let status = Status::Failed {
        error: "cancelled".to_owned(),
    };
    RunRow::without_result(spec.clone(), status, cap, 0.0)
}

impl RunSpec {
    fn label_of(row: &RunRow) -> String {
        format!("`{}` ({})", row.spec.label(), row.status.name())
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::plan::{self, Experiment};
    use crate::results::Iteration;
    use palc_harness::{Method, StylePreset};

    /// A deterministic stand-in for the harness: the outcome is a function of
    /// the spec (and of whether experience was given), never of the thread.
    pub(crate) struct Synthetic;

    impl Executor for Synthetic {
        type Experience = usize;

        fn run(&self, spec: &RunSpec, experience: Option<&usize>) -> (RunRow, Option<usize>) {
            let style = match spec.style {
                StylePreset::Aggressive => 2,
                StylePreset::Neutral => 4,
                StylePreset::Cautious => 6,
            };
            let base = style + (spec.seed as usize % 3) + (spec.headway_m < 40.0) as usize;
            let takeovers = if spec.method == Method::Paper {
                30
            } else {
                base
            };
            let takeovers = match experience {
                Some(_) => takeovers * 3 / 4,
                None => takeovers,
            };
            let status =
                if spec.speed_case.name == "arterial-slow" && spec.style == StylePreset::Cautious {
                    return (
                        RunRow::without_result(
                            spec.clone(),
                            Status::refused(
                                "synthetic",
                                palc_harness::Refusal::StandardNotSlower {
                                    standard_duration_s: 3.5,
                                    style: "cautious".into(),
                                    user_duration_s: 3.5,
                                },
                            ),
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
                    perceived_safety_takeover: false,
                    perceived_safety_ratio: if i < takeovers {
                        0.2 + 0.5 * i as f64 / lane_changes as f64
                    } else {
                        1.0
                    },
                    max_deviation_m: 0.1,
                    times_s: palc_harness::record::Timings {
                        zone_fit_s: 0.001,
                        bounds_s: 0.002,
                        expert_s: 0.01,
                        correction_s: 0.02,
                        plan_s: 0.005 * spec.dt.unwrap_or(0.1) * 10.0,
                    },
                    learning_error: None,
                    safety: Default::default(),
                    user_safety: Default::default(),
                    safety_refusal: None,
                    closed_loop: None,
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
                frozen: None,
                horizon: (8.0 / dt) as usize,
                dt: Some(dt),
                wall_s: 0.01,
                iterations,
                driver_belief: None,
            };
            (row, Some(spec.id))
        }

        fn cap(&self) -> usize {
            30
        }
    }

    pub(crate) fn synthetic_rows() -> Vec<RunRow> {
        let plan = plan::expand(&plan::tests::selection(), &plan::tests::testbed()).unwrap();
        execute(&plan, &Synthetic, 2, &NoProgress).unwrap()
    }

    /// [`Synthetic`] with an experience that depends only on what the run computes,
    /// counting the runs it computes; with `share`, it names what determines a
    /// run, so that the runner shares repeats.
    struct Counting {
        share: bool,
        computed: std::sync::atomic::AtomicUsize,
    }

    impl Executor for Counting {
        type Experience = usize;

        fn run(&self, spec: &RunSpec, experience: Option<&usize>) -> (RunRow, Option<usize>) {
            self.computed
                .fetch_add(1, std::sync::atomic::Ordering::SeqCst);
            let (row, learned) = Synthetic.run(spec, experience);
            (row, learned.map(|_| 1))
        }

        fn cap(&self) -> usize {
            Synthetic.cap()
        }

        fn identity(&self, spec: &RunSpec) -> Option<String> {
            self.share.then(|| {
                let dt = spec.dt.map(f64::to_bits);
                format!("{:?}", (spec.experiment_cell(), &spec.speed_case.name, dt))
            })
        }
    }

    #[test]
    fn shared_repeats_give_the_rows_of_computing_every_run() {
        let plan = plan::expand(&plan::tests::selection(), &plan::tests::testbed()).unwrap();
        let counting = |share| Counting {
            share,
            computed: Default::default(),
        };
        let (every, shared) = (counting(false), counting(true));
        let all = execute(&plan, &every, 2, &NoProgress).unwrap();
        let once = execute(&plan, &shared, 2, &NoProgress).unwrap();
        assert_eq!(all, once);
        let computed = |e: &Counting| e.computed.load(std::sync::atomic::Ordering::SeqCst);
        assert!(
            computed(&shared) < computed(&every),
            "the plan repeats runs (transfer and matrix pairs), computed once"
        );
    }

    /// Cancels once `after` runs have finished, counting the runs finished.
    struct CancelAfter {
        after: usize,
        finished: std::sync::atomic::AtomicUsize,
    }

    impl Progress for CancelAfter {
        fn finished(&self, _row: &RunRow) {
            self.finished
                .fetch_add(1, std::sync::atomic::Ordering::SeqCst);
        }
        fn cancelled(&self) -> bool {
            self.finished.load(std::sync::atomic::Ordering::SeqCst) >= self.after
        }
    }

    #[test]
    fn a_cancelled_evaluation_stops_starting_runs_and_returns_cancelled() {
        let plan = plan::expand(&plan::tests::selection(), &plan::tests::testbed()).unwrap();
        assert!(
            plan.len() > 10,
            "the test needs more runs than it lets finish"
        );
        let progress = CancelAfter {
            after: 3,
            finished: Default::default(),
        };
        let result = execute(&plan, &Synthetic, 1, &progress);
        assert!(matches!(result, Err(EvalError::Cancelled)), "{result:?}");
        // On one thread, the run that made the count reach 3 is the last one started.
        let finished = progress.finished.load(std::sync::atomic::Ordering::SeqCst);
        assert_eq!(finished, 3);
    }

    /// Repeats every run of a cell (any experiment, step or margin) as its first.
    struct RepeatsCells;

    impl Executor for RepeatsCells {
        type Experience = usize;

        fn run(&self, spec: &RunSpec, experience: Option<&usize>) -> (RunRow, Option<usize>) {
            Synthetic.run(spec, experience)
        }

        fn cap(&self) -> usize {
            Synthetic.cap()
        }

        fn identity(&self, spec: &RunSpec) -> Option<String> {
            Some(format!("{:?}", spec.experiment_cell()))
        }
    }

    #[test]
    fn a_cancelled_evaluation_reports_no_repeat_as_finished() {
        let plan = plan::expand(&plan::tests::selection(), &plan::tests::testbed()).unwrap();
        let original = shared_runs::originals(&plan, |spec| RepeatsCells.identity(spec));
        let first = plan.first.len();
        assert!(
            (0..first).any(|i| original[i] != i),
            "the test needs a repeat among the runs without experience"
        );
        let progress = CancelAfter {
            after: 0,
            finished: Default::default(),
        };
        let result = execute(&plan, &RepeatsCells, 1, &progress);
        assert!(matches!(result, Err(EvalError::Cancelled)), "{result:?}");
        let finished = progress.finished.load(std::sync::atomic::Ordering::SeqCst);
        assert_eq!(finished, 0);
    }

    #[test]
    fn results_do_not_depend_on_the_number_of_threads() {
        let plan = plan::expand(&plan::tests::selection(), &plan::tests::testbed()).unwrap();
        let one = execute(&plan, &Synthetic, 1, &NoProgress).unwrap();
        let three = execute(&plan, &Synthetic, 3, &NoProgress).unwrap();
        assert_eq!(one, three);
        assert_eq!(one.len(), plan.len());
    }

    #[test]
    fn a_scene_of_a_sequence_starts_from_the_one_before_or_is_named_as_refused() {
        let mut selection = plan::tests::selection();
        selection.grid.speed_cases = plan::tests::testbed().speed_cases.to_vec();
        selection.transfer.accumulation_users = vec!["deterministic".into()];
        let plan = plan::expand(&selection, &plan::tests::testbed()).unwrap();
        let rows = execute(&plan, &Synthetic, 2, &NoProgress).unwrap();
        assert_eq!(rows.len(), plan.len());
        assert!(rows.iter().enumerate().all(|(i, r)| r.spec.id == i));
        let mut after_a_scene = 0;
        for row in rows
            .iter()
            .filter(|r| r.spec.experiment == Experiment::Accumulation)
        {
            let source = &rows[row.spec.experience_from.unwrap()];
            after_a_scene += usize::from(source.spec.experiment == Experiment::Accumulation);
            if source.status.counted() {
                // Started from experience: a quarter fewer takeovers (synthetic).
                let without = (rows.iter())
                    .find(|r| {
                        r.spec.experiment == Experiment::Grid
                            && r.spec.experiment_cell() == row.spec.experiment_cell()
                    })
                    .unwrap();
                assert_eq!(
                    row.takeovers,
                    without.takeovers * 3 / 4,
                    "{}",
                    row.spec.label()
                );
            } else {
                let Status::Refused { reason, .. } = &row.status else {
                    panic!("{:?}", row.status)
                };
                assert!(reason.contains(&source.spec.label()), "{reason}");
            }
        }
        assert!(after_a_scene > 0);
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
                let Status::Refused { reason, .. } = &row.status else {
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

    /// Refuses every scene whose seed is odd; a run's experience is its id, and
    /// its row's `takeovers` is the id of the run whose experience it started
    /// from (`usize::MAX`: from scratch).
    struct Chain;

    impl Executor for Chain {
        type Experience = usize;

        fn run(&self, spec: &RunSpec, experience: Option<&usize>) -> (RunRow, Option<usize>) {
            if spec.seed % 2 == 1 {
                let status = Status::Refused {
                    reason: "odd".into(),
                    refusal: None,
                };
                return (RunRow::without_result(spec.clone(), status, 1, 0.0), None);
            }
            let mut row = RunRow::without_result(spec.clone(), Status::Personalized, 1, 0.0);
            row.takeovers = experience.copied().unwrap_or(usize::MAX);
            (row, Some(spec.id))
        }

        fn cap(&self) -> usize {
            1
        }
    }

    #[test]
    fn a_drive_passes_its_experience_through_refused_scenes_and_starts_from_scratch_before_any() {
        let mut selection = plan::tests::selection();
        selection.users.truncate(1);
        selection.transfer.users.clear();
        selection.grid.methods = vec![Method::Palc];
        selection.grid.styles = vec![StylePreset::Neutral];
        let grid = selection.grid.clone();
        let config = crate::drive::DriveConfig {
            users: vec!["deterministic".into()],
            lane_changes: Some(6),
            grid_share: Some(1.0),
            ..Default::default()
        };
        let mut scenes = config.scenes("drive", grid.cells_to_draw()).unwrap();
        // Seeds: refused (odd), refused, driven, refused, driven, driven.
        for (scene, seed) in scenes.iter_mut().zip([1, 3, 2, 5, 4, 6]) {
            scene.seed = seed;
        }
        selection.drive = crate::config::Drive {
            users: config.users.clone(),
            methods: vec![Method::Palc],
            scenes,
        };
        let plan = plan::expand(&selection, &plan::tests::testbed()).unwrap();
        let rows = execute(&plan, &Chain, 2, &NoProgress).unwrap();
        let drive: Vec<&RunRow> = (rows.iter())
            .filter(|r| r.spec.experiment == Experiment::Drive)
            .collect();
        assert_eq!(drive.len(), 6);
        let id = |i: usize| drive[i].spec.id;
        assert_eq!(drive[0].spec.experience_from, None);
        for i in 1..6 {
            assert_eq!(drive[i].spec.experience_from, Some(id(i - 1)), "scene {i}");
        }
        let refused = |i: usize| matches!(drive[i].status, Status::Refused { .. });
        assert!(refused(0) && refused(1) && refused(3));
        // The first driven scene starts from scratch; the next from it, through the refused one.
        assert_eq!(drive[2].takeovers, usize::MAX);
        assert_eq!(drive[4].takeovers, id(2));
        assert_eq!(drive[5].takeovers, id(4));
    }

    #[test]
    fn jobs_past_the_bound_are_refused_naming_the_option_and_the_bound() {
        assert_eq!(check_jobs(1).unwrap(), 1);
        assert_eq!(check_jobs(MAX_JOBS).unwrap(), MAX_JOBS);
        for jobs in [0, MAX_JOBS + 1, 100_000] {
            let message = check_jobs(jobs).unwrap_err().to_string();
            assert!(
                message.contains("--jobs")
                    && message.contains(&jobs.to_string())
                    && message.contains("1024"),
                "{message}"
            );
        }
        let plan = RunPlan {
            first: Vec::new(),
            transfer: Vec::new(),
        };
        assert!(execute(&plan, &Synthetic, 100_000, &NoProgress).is_err());
    }
}
