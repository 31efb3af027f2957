//! Running the plan in parallel: a fixed number of threads take the runs in the
//! order of [`crate::schedule`] (each run as soon as the runs it needs have
//! ended), and the results are collected by run index, so that every output is
//! the same whatever the number of threads and the order runs end in.
//!
//! The runner prints nothing: it reports each finished run to a [`Progress`],
//! which a binary turns into a progress bar or log lines.

use std::collections::HashMap;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::{Arc, Condvar, Mutex, MutexGuard, PoisonError};

use crate::EvalError;
use crate::plan::{Experiment, RunPlan, RunSpec};
use crate::results::{RunRow, Status};
use crate::schedule::Schedule;
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
/// are in plan order. Each run starts as soon as the runs it needs have ended
/// and a thread is free, the longest chain first ([`crate::schedule`]). A run
/// that repeats an earlier one ([`crate::shared_runs`]) is not computed again:
/// it takes the earlier run's row under its own spec.
pub fn execute<E: Executor>(
    plan: &RunPlan,
    executor: &E,
    jobs: usize,
    progress: &dyn Progress,
) -> Result<Vec<RunRow>, EvalError> {
    let jobs = check_jobs(jobs)?;
    progress.started(plan.len());
    let original = shared_runs::originals(plan, |spec| executor.identity(spec));
    // How many runs start from each run's experience: an experience is kept
    // until the last of them has started, then dropped.
    let mut uses: HashMap<usize, usize> = HashMap::new();
    for source in plan.all().filter_map(|s| s.experience_from) {
        *uses.entry(source).or_default() += 1;
    }
    let specs: Vec<&RunSpec> = plan.all().collect();
    let state = Mutex::new(State {
        schedule: Schedule::new(plan, &original),
        shared: Shared::new(&original),
        rows: vec![None; plan.len()],
        experiences: HashMap::new(),
        uses,
        running: 0,
    });
    let changed = Condvar::new();
    let work = Work {
        specs: &specs,
        original: &original,
        executor,
        progress,
        state: &state,
        changed: &changed,
    };
    // Fewer threads than asked still run every run; none is an error.
    let none_started = std::thread::scope(|scope| {
        let mut error = None;
        let mut started = 0;
        for _ in 0..jobs {
            let thread = std::thread::Builder::new().name("palc-eval".to_owned());
            match thread.spawn_scoped(scope, || work.run_until_done()) {
                Ok(_) => started += 1,
                Err(e) => error = Some(e),
            }
        }
        error.filter(|_| started == 0)
    });
    if let Some(error) = none_started {
        return Err(EvalError::Thread(error));
    }
    if progress.cancelled() {
        return Err(EvalError::Cancelled);
    }
    let rows = state
        .into_inner()
        .unwrap_or_else(PoisonError::into_inner)
        .rows;
    let rows: Vec<RunRow> = (rows.into_iter().zip(&specs))
        .map(|(row, spec)| row.unwrap_or_else(|| never_ready(spec, executor.cap())))
        .collect();
    progress.done();
    debug_assert!(rows.iter().enumerate().all(|(i, row)| row.spec.id == i));
    Ok(rows)
}

/// What the threads share: the schedule and every output so far.
struct State<X> {
    schedule: Schedule,
    /// Outputs of originals that repeats still wait for.
    shared: Shared<RunRow, Arc<X>>,
    /// The row of every run that has ended, by run index.
    rows: Vec<Option<RunRow>>,
    /// Experiences that runs not yet started will start from, by run index.
    experiences: HashMap<usize, Arc<X>>,
    /// How many runs not yet started will start from each run's experience.
    uses: HashMap<usize, usize>,
    /// Runs started and not ended.
    running: usize,
}

/// What a run starts with, taken from the [`State`] when it starts.
enum Start<X> {
    /// Compute the run, from the experience of its source if it has one.
    Compute { source: Option<Source<X>> },
    /// Take the output of the original it repeats.
    Repeat(Box<(RunRow, Option<Arc<X>>)>),
}

/// The run a run starts from: its experience, or its row when it left none.
enum Source<X> {
    Experience(Arc<X>),
    Nothing { label: String },
}

/// One evaluation's runs, worked on by every thread.
struct Work<'a, E: Executor> {
    specs: &'a [&'a RunSpec],
    original: &'a [usize],
    executor: &'a E,
    progress: &'a dyn Progress,
    state: &'a Mutex<State<E::Experience>>,
    changed: &'a Condvar,
}

impl<E: Executor> Work<'_, E> {
    /// Starts ready runs until none is left to start (or the evaluation is
    /// cancelled), waiting while runs that others need are running.
    fn run_until_done(&self) {
        while let Some((id, start)) = self.next_start() {
            let spec = self.specs[id];
            let (row, experience) = match start {
                Start::Repeat(output) => *output,
                Start::Compute { source } => self.compute(spec, source),
            };
            self.progress.finished(&row);
            self.end(id, row, experience);
        }
        // Wake the threads that wait, to see that nothing is left.
        self.changed.notify_all();
    }

    /// The next run to start, and what it starts with; `None` when every run
    /// has started and none is running, or when the evaluation is cancelled.
    fn next_start(&self) -> Option<(usize, Start<E::Experience>)> {
        let mut state = self.lock();
        let id = loop {
            if self.progress.cancelled() {
                return None;
            }
            if let Some(id) = state.schedule.next_ready() {
                break id;
            }
            if state.running == 0 {
                return None;
            }
            state = (self.changed.wait(state)).unwrap_or_else(PoisonError::into_inner);
        };
        state.running += 1;
        let spec = self.specs[id];
        let of = self.original[id];
        if of != id {
            let mut output = repeated(spec, of, &state.shared);
            state.shared.served(of);
            // A repeat refused for want of experience names its own source, as
            // computed on its own it would (a shard may not hold the original).
            if let (
                Status::Refused {
                    refusal: None,
                    reason,
                },
                Some(source),
            ) = (&mut output.0.status, spec.experience_from)
            {
                *reason = no_experience_reason(&source_label(&state.rows, source));
            }
            return Some((id, Start::Repeat(Box::new(output))));
        }
        let source = spec.experience_from.map(|source| {
            let experience = state.experiences.get(&source).cloned();
            if let Some(left) = state.uses.get_mut(&source) {
                *left -= 1;
                if *left == 0 {
                    state.uses.remove(&source);
                    state.experiences.remove(&source);
                }
            }
            match experience {
                Some(experience) => Source::Experience(experience),
                None => Source::Nothing {
                    label: source_label(&state.rows, source),
                },
            }
        });
        Some((id, Start::Compute { source }))
    }

    /// Computes `spec` from its source.
    fn compute(
        &self,
        spec: &RunSpec,
        source: Option<Source<E::Experience>>,
    ) -> (RunRow, Option<Arc<E::Experience>>) {
        // A run that panics fails alone: the other threads, waiting for it to
        // end, go on, and its row names the panic.
        let run = |experience: Option<&E::Experience>| match catch_unwind(AssertUnwindSafe(|| {
            self.executor.run(spec, experience)
        })) {
            Ok((row, learned)) => (row, learned.map(Arc::new)),
            Err(panic) => {
                let message = (panic.downcast_ref::<&str>().map(|m| (*m).to_owned()))
                    .or_else(|| panic.downcast_ref::<String>().cloned())
                    .unwrap_or_else(|| "no message".to_owned());
                let status = Status::Failed {
                    error: format!("the run panicked: {message}"),
                };
                let row = RunRow::without_result(spec.clone(), status, self.executor.cap(), 0.0);
                (row, None)
            }
        };
        match source {
            None => run(None),
            Some(Source::Experience(experience)) => {
                let (row, learned) = run(Some(&experience));
                (row, learned.or_else(|| passed_on(spec, &experience)))
            }
            // A drive that has learned nothing yet (its first scenes were
            // refused) starts from scratch.
            Some(Source::Nothing { .. }) if spec.experiment == Experiment::Drive => run(None),
            Some(Source::Nothing { label }) => {
                let status = Status::Refused {
                    reason: no_experience_reason(&label),
                    refusal: None,
                };
                let row = RunRow::without_result(spec.clone(), status, self.executor.cap(), 0.0);
                (row, None)
            }
        }
    }

    /// Records the output of run `id` and makes ready the runs that need it.
    fn end(&self, id: usize, row: RunRow, experience: Option<Arc<E::Experience>>) {
        let mut state = self.lock();
        let output = (row, experience);
        if self.original[id] == id {
            state.shared.keep(id, &output);
        }
        let (row, experience) = output;
        if let Some(experience) = experience.filter(|_| state.uses.contains_key(&id)) {
            state.experiences.insert(id, experience);
        }
        state.rows[id] = Some(row);
        state.schedule.ended(id);
        state.running -= 1;
        drop(state);
        self.changed.notify_all();
    }

    fn lock(&self) -> MutexGuard<'_, State<E::Experience>> {
        // A thread that panicked inside the lock left the state as it was
        // between two runs: the others go on.
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

/// The row of a run that never became ready. Unreachable: a run needs only
/// earlier runs of the plan, which all end.
fn never_ready(spec: &RunSpec, cap: usize) -> RunRow {
    let status = Status::Failed {
        error: "a run it needs never ended".to_owned(),
    };
    RunRow::without_result(spec.clone(), status, cap, 0.0)
}
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

/// The label of run `source` for a refusal that names it: its spec and status,
/// or "none" when it has no row.
fn source_label(rows: &[Option<RunRow>], source: usize) -> String {
    (rows.get(source).and_then(Option::as_ref)).map_or_else(|| "none".to_owned(), RunSpec::label_of)
}

/// Why a run whose source, `label`, handed on no experience is refused
/// ([`crate::results::NO_EXPERIENCE_SOURCE`]).
fn no_experience_reason(label: &str) -> String {
    format!("no experience to start from: source run {label}")
}

/// What a run that learned nothing hands on: a drive goes on through a scene it
/// could not drive (refused) with the experience it had; other runs hand on nothing.
fn passed_on<X: Clone>(spec: &RunSpec, experience: &X) -> Option<X> {
    (spec.experiment == Experiment::Drive).then(|| experience.clone())
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

    /// The ablation's `paper` rung repeats the grid's `paper` runs, and its
    /// transfer runs repeat the grid's transfer runs while learning from the
    /// rung's own runs: where that source is refused, the repeat's refusal names
    /// its own source, as computing it would (and as a shard that holds only the
    /// ablation does).
    #[test]
    fn a_repeat_refused_for_want_of_experience_names_its_own_source() {
        let mut selection = plan::tests::selection();
        selection.ablation = crate::ablation::AblationConfig {
            users: vec!["deterministic".into()],
            rungs: vec![crate::ablation::RungConfig {
                name: "paper".into(),
                change: "the printed method".into(),
                method: Some(palc_harness::Method::Paper),
                aggregator: Default::default(),
            }],
        };
        let plan = plan::expand(&selection, &plan::tests::testbed()).unwrap();
        let counting = |share| Counting {
            share,
            computed: Default::default(),
        };
        let all = execute(&plan, &counting(false), 2, &NoProgress).unwrap();
        let once = execute(&plan, &counting(true), 2, &NoProgress).unwrap();
        let ablation_refused = (once.iter())
            .filter(|row| row.spec.experiment == Experiment::AblationTransfer)
            .filter(|row| matches!(row.status, Status::Refused { refusal: None, .. }))
            .count();
        assert!(ablation_refused > 0, "the plan has such repeats");
        assert_eq!(all, once);
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

    /// [`Synthetic`], but panics in the first run of the transfer phase.
    struct PanicsOnce {
        at: usize,
    }

    impl Executor for PanicsOnce {
        type Experience = usize;

        fn run(&self, spec: &RunSpec, experience: Option<&usize>) -> (RunRow, Option<usize>) {
            assert!(spec.id != self.at, "a bug in run {}", spec.id);
            Synthetic.run(spec, experience)
        }

        fn cap(&self) -> usize {
            Synthetic.cap()
        }
    }

    #[test]
    fn a_run_that_panics_fails_alone_and_names_the_panic() {
        let plan = plan::expand(&plan::tests::selection(), &plan::tests::testbed()).unwrap();
        let at = plan.first.len();
        let rows = execute(&plan, &PanicsOnce { at }, 2, &NoProgress).unwrap();
        let every = execute(&plan, &Synthetic, 2, &NoProgress).unwrap();
        assert_eq!(rows.len(), plan.len());
        match &rows[at].status {
            Status::Failed { error } => {
                assert!(error.contains("panicked: a bug in run"), "{error}")
            }
            other => panic!("expected a failed run, got {other:?}"),
        }
        // Runs that do not learn from it, directly or down a chain, are as
        // without the panic.
        let mut affected = vec![false; plan.len()];
        affected[at] = true;
        for spec in plan.all() {
            affected[spec.id] |= spec.experience_from.is_some_and(|s| affected[s]);
        }
        assert!(affected.iter().filter(|&&a| !a).count() > plan.len() / 2);
        for (row, expected) in rows.iter().zip(&every) {
            if !affected[row.spec.id] {
                assert_eq!(row, expected);
            }
        }
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
