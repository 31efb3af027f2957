//! Expanding the config into a list of runs, in a fixed order.
//!
//! The order of the list is the order of every output, whatever the number of
//! threads: runs are executed in parallel but collected by index.

use palc_harness::{Method, StylePreset};
use palc_traffic::{SpeedCaseConfig, TestbedConfig};
use serde::{Deserialize, Serialize};

use crate::EvalError;
use crate::config::{Grid, Selection, TransferSource, UserKind, speed_case};

/// The experiment a run belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Experiment {
    /// The grid, started without experience (Figs. 7-10, 12).
    Grid,
    /// A grid cell started with experience from another scenario (Fig. 11).
    Transfer,
    /// Compute time against step and horizon (Fig. 13).
    Timing,
    /// A grid cell driven in closed loop (`[planning.closed_loop]` on).
    ClosedLoop,
    /// A grid cell started with experience from one other speed case or headway
    /// of the grid (`transfer.matrix_users`): every ordered pair.
    Matrix,
    /// A scene of a sequence one user drives, each started with the experience
    /// of the scene before (`transfer.accumulation_users`).
    Accumulation,
    /// A grid cell run with a rung of the ablation ladder (`[ablation]`), from scratch.
    Ablation,
    /// An ablation cell started with the experience of the same rung in the
    /// cell's other scene (`transfer.source`).
    AblationTransfer,
    /// One lane change of a drive of varied scenes (`[drive]`, [`crate::drive`]),
    /// started with the experience of the drive's lane change before it.
    Drive,
    /// A scene of a drive driven once without experience: the drive's baseline.
    DriveFromScratch,
}

impl Experiment {
    /// Name in CSV and reports.
    pub fn name(self) -> &'static str {
        match self {
            Experiment::Grid => "grid",
            Experiment::Transfer => "transfer",
            Experiment::Timing => "timing",
            Experiment::ClosedLoop => "closed-loop",
            Experiment::Matrix => "transfer-matrix",
            Experiment::Accumulation => "accumulation",
            Experiment::Ablation => "ablation",
            Experiment::AblationTransfer => "ablation-transfer",
            Experiment::Drive => "drive",
            Experiment::DriveFromScratch => "drive-from-scratch",
        }
    }
}

impl Experiment {
    /// Whether a run of this experiment is one lane change of a drive ([`crate::drive`]).
    pub fn is_drive(self) -> bool {
        matches!(self, Experiment::Drive | Experiment::DriveFromScratch)
    }
}

/// One run of the loop: everything that differs from the base config.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunSpec {
    /// Index in the run list.
    pub id: usize,
    /// Which experiment.
    pub experiment: Experiment,
    /// The learning method.
    pub method: Method,
    /// The user kind.
    pub user: UserKind,
    /// Style name.
    pub style: StylePreset,
    /// Speed case, with its speeds.
    pub speed_case: SpeedCaseConfig,
    /// Adjacent headway (m).
    pub headway_m: f64,
    /// Scene seed (and seed of the user's draws).
    pub seed: u64,
    /// Step override (timing experiment).
    pub dt: Option<f64>,
    /// Horizon margin override (timing experiment).
    pub horizon_margin_s: Option<f64>,
    /// Index of the run whose learned experience this run starts from.
    pub experience_from: Option<usize>,
    /// The ablation rung this run uses (its label rule and aggregator options;
    /// `method` is the rung's label rule); none outside the ablation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rung: Option<String>,
}

/// What identifies a scenario and user apart from the experiment: a transfer
/// run and the grid run of the same cell share it.
pub type CellKey = (&'static str, String, String, String, u64, u64);

impl RunSpec {
    /// The cell of this run: method, user, style, speed case, headway bits, seed.
    pub fn experiment_cell(&self) -> CellKey {
        (
            self.method.name(),
            self.user.name.clone(),
            self.style_name().to_owned(),
            self.speed_case.name.clone(),
            self.headway_m.to_bits(),
            self.seed,
        )
    }

    /// The style in reports: the preset's name, or a recorded run's driver (who
    /// drives with its own style).
    pub fn style_name(&self) -> &str {
        match &self.user.driver {
            Some(driver) => driver,
            None => self.style.name(),
        }
    }

    /// A short label for progress lines and error lists.
    pub fn label(&self) -> String {
        let method = match &self.rung {
            Some(rung) => format!("[{rung}]"),
            None => self.method.name().to_owned(),
        };
        let mut label = format!(
            "{} {} {} {} / {} m / seed {} / {}",
            self.experiment.name(),
            method,
            self.user.name,
            self.style_name(),
            self.headway_m,
            self.seed,
            self.speed_case.name
        );
        if let Some(dt) = self.dt {
            label.push_str(&format!(" / dt {dt}"));
        }
        if let Some(margin) = self.horizon_margin_s {
            label.push_str(&format!(" / margin {margin} s"));
        }
        label
    }
}

/// The runs of a selection, in two phases: runs without experience first (grid,
/// timing, closed loop), then the runs that start from experience (transfer,
/// transfer matrix, accumulation), which the runner starts as soon as the run
/// they learn from has ended.
#[derive(Debug, Clone, PartialEq)]
pub struct RunPlan {
    /// Grid and timing runs.
    pub first: Vec<RunSpec>,
    /// Runs with experience; `experience_from` points into `first` or to an
    /// earlier run of this list (accumulation, drive). A drive's first lane
    /// change has none: it starts from scratch.
    pub transfer: Vec<RunSpec>,
}

impl RunPlan {
    /// Every run, phase one first.
    pub fn all(&self) -> impl Iterator<Item = &RunSpec> {
        self.first.iter().chain(&self.transfer)
    }

    /// Number of runs.
    pub fn len(&self) -> usize {
        self.first.len() + self.transfer.len()
    }

    /// Whether there is no run.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Expands a selection; the timing runs' speed case is looked up in `testbed`.
pub fn expand(selection: &Selection, testbed: &TestbedConfig) -> Result<RunPlan, EvalError> {
    expand_bounded(selection, testbed, DEFAULT_MAX_RUNS)
}

/// The bound on the runs of an evaluation when its config sets no `max_runs`.
pub const DEFAULT_MAX_RUNS: usize = 100_000;

/// Refuses a run past `max_runs` (`len` runs are planned already).
fn room(len: usize, max_runs: usize) -> Result<(), EvalError> {
    if len < max_runs {
        Ok(())
    } else {
        Err(EvalError::TooManyRuns { max_runs })
    }
}

/// [`expand`] with at most `max_runs` runs: the expansion stops with
/// [`EvalError::TooManyRuns`] as soon as it would plan one more, so a config that
/// would expand to millions of runs is refused before they are even listed.
pub fn expand_bounded(
    selection: &Selection,
    testbed: &TestbedConfig,
    max_runs: usize,
) -> Result<RunPlan, EvalError> {
    let grid = &selection.grid;
    let drivers = |user: &UserKind| -> &[String] {
        (selection.drivers.get(&user.name)).map_or(&[], Vec::as_slice)
    };
    let mut first = Vec::new();
    for method in &grid.methods {
        for user in &selection.users {
            let drivers = drivers(user);
            grid_cells(
                &mut first,
                grid,
                Experiment::Grid,
                *method,
                user,
                drivers,
                None,
                max_runs,
            )?;
        }
    }
    let timing = &selection.timing;
    let timing_case = speed_case(testbed, &timing.speed_case, "timing.speed_case")?;
    let deterministic = UserKind::deterministic();
    for method in &timing.methods {
        for &dt in &timing.dts {
            for &margin in &timing.horizon_margins_s {
                for style in &timing.styles {
                    room(first.len(), max_runs)?;
                    first.push(RunSpec {
                        id: first.len(),
                        experiment: Experiment::Timing,
                        method: *method,
                        user: deterministic.clone(),
                        style: *style,
                        speed_case: timing_case.clone(),
                        headway_m: timing.headway_m,
                        seed: timing.seed,
                        dt: Some(dt),
                        horizon_margin_s: Some(margin),
                        experience_from: None,
                        rung: None,
                    });
                }
            }
        }
    }
    let closed_loop: Vec<RunSpec> = (first.iter())
        .filter(|s| {
            s.experiment == Experiment::Grid && selection.closed_loop.users.contains(&s.user.name)
        })
        .cloned()
        .collect();
    for spec in closed_loop {
        room(first.len(), max_runs)?;
        first.push(RunSpec {
            id: first.len(),
            experiment: Experiment::ClosedLoop,
            ..spec
        });
    }
    // The ablation ladder: every grid cell of its users, once per rung.
    let rungs = selection.ablation.resolve()?;
    for rung in &rungs {
        for user in (selection.users.iter()).filter(|u| selection.ablation.users.contains(&u.name))
        {
            let name = Some(rung.name.clone());
            grid_cells(
                &mut first,
                grid,
                Experiment::Ablation,
                rung.labels,
                user,
                drivers(user),
                name,
                max_runs,
            )?;
        }
    }
    let mut transfer = Vec::new();
    let with_experience = |s: &RunSpec| match s.experiment {
        Experiment::Grid => Some(Experiment::Transfer),
        Experiment::Ablation => Some(Experiment::AblationTransfer),
        _ => None,
    };
    for target in &first {
        let Some(experiment) = with_experience(target) else {
            continue;
        };
        if experiment == Experiment::Transfer
            && !selection.transfer.users.contains(&target.user.name)
        {
            continue;
        }
        let source = transfer_source(selection, target, &first);
        let Some(source) = source else { continue };
        room(first.len() + transfer.len(), max_runs)?;
        transfer.push(RunSpec {
            id: first.len() + transfer.len(),
            experiment,
            experience_from: Some(source),
            ..target.clone()
        });
    }
    let grid_runs: Vec<RunSpec> = (first.iter())
        .filter(|s| s.experiment == Experiment::Grid)
        .cloned()
        .collect();
    let same = |a: &RunSpec, b: &RunSpec| {
        a.method == b.method && a.user == b.user && a.style == b.style && a.seed == b.seed
    };
    let id = |first: &[RunSpec], transfer: &[RunSpec]| first.len() + transfer.len();
    // Transfer matrix: every ordered pair of speed cases (same headway), then of
    // headways (same speed case).
    for target in grid_runs
        .iter()
        .filter(|s| selection.transfer.matrix_users.contains(&s.user.name))
    {
        let sources = grid_runs.iter().filter(|s| {
            same(s, target)
                && ((s.headway_m == target.headway_m
                    && s.speed_case.name != target.speed_case.name)
                    || (s.speed_case.name == target.speed_case.name
                        && s.headway_m != target.headway_m))
        });
        for source in sources {
            room(id(&first, &transfer), max_runs)?;
            transfer.push(RunSpec {
                id: id(&first, &transfer),
                experiment: Experiment::Matrix,
                experience_from: Some(source.id),
                ..target.clone()
            });
        }
    }
    // Accumulation: each chain starts at the grid run of the grid's first speed
    // case (first headway) and goes through the others in grid order.
    for start in grid_runs
        .iter()
        .filter(|s| selection.transfer.accumulation_users.contains(&s.user.name))
    {
        let first_case = grid.speed_cases.first().map(|c| c.name.as_str());
        let first_headway = grid.headways_m.first().copied();
        let chains: [Vec<RunSpec>; 2] = [
            if Some(start.speed_case.name.as_str()) == first_case {
                (grid.speed_cases.iter().skip(1))
                    .filter_map(|case| {
                        grid_runs.iter().find(|s| {
                            same(s, start)
                                && s.headway_m == start.headway_m
                                && s.speed_case.name == case.name
                        })
                    })
                    .cloned()
                    .collect()
            } else {
                Vec::new()
            },
            if Some(start.headway_m) == first_headway {
                (grid.headways_m.iter().skip(1))
                    .filter_map(|&headway| {
                        grid_runs.iter().find(|s| {
                            same(s, start)
                                && s.speed_case.name == start.speed_case.name
                                && s.headway_m == headway
                        })
                    })
                    .cloned()
                    .collect()
            } else {
                Vec::new()
            },
        ];
        for chain in chains {
            let mut previous = start.id;
            for scene in chain {
                let next = id(&first, &transfer);
                room(next, max_runs)?;
                transfer.push(RunSpec {
                    id: next,
                    experiment: Experiment::Accumulation,
                    experience_from: Some(previous),
                    ..scene
                });
                previous = next;
            }
        }
    }
    drives(selection, &mut transfer, first.len(), max_runs)?;
    Ok(RunPlan { first, transfer })
}

/// Appends a run of `experiment` for every cell of `grid` (speed case x headway x
/// style x seed, in that order) with this method, user and rung. A recorded
/// user kind runs its `drivers` in place of the styles (each with its own
/// style; the run's preset is the grid's first, unused).
fn grid_cells(
    runs: &mut Vec<RunSpec>,
    grid: &Grid,
    experiment: Experiment,
    method: Method,
    user: &UserKind,
    drivers: &[String],
    rung: Option<String>,
    max_runs: usize,
) -> Result<(), EvalError> {
    let users = styled(grid, user, drivers);
    for case in &grid.speed_cases {
        for &headway_m in &grid.headways_m {
            for (style, user) in &users {
                for &seed in &grid.seeds {
                    room(runs.len(), max_runs)?;
                    runs.push(RunSpec {
                        id: runs.len(),
                        experiment,
                        method,
                        user: user.clone(),
                        style: *style,
                        speed_case: case.clone(),
                        headway_m,
                        seed,
                        dt: None,
                        horizon_margin_s: None,
                        experience_from: None,
                        rung: rung.clone(),
                    });
                }
            }
        }
    }
    Ok(())
}

/// The users of `user`'s runs: one per style of the grid, or, for a recorded
/// kind, one per driver (each with its own style; the preset is the grid's
/// first, unused).
fn styled(grid: &Grid, user: &UserKind, drivers: &[String]) -> Vec<(StylePreset, UserKind)> {
    match &user.recorded {
        Some(_) => (drivers.iter())
            .map(|driver| {
                let user = UserKind {
                    driver: Some(driver.clone()),
                    ..user.clone()
                };
                (grid.styles[0], user)
            })
            .collect(),
        None => (grid.styles.iter())
            .map(|&style| (style, user.clone()))
            .collect(),
    }
}

/// Appends the drives of `selection` to `transfer` (whose first id is
/// `offset`): per method, drive user and style (or recorded driver), one chain
/// of runs through the drive's scenes, each but the first starting from the one
/// before it; then every scene of each drive once without experience, the
/// drive's baseline (in `transfer` too, so that no earlier run's id moves).
fn drives(
    selection: &Selection,
    transfer: &mut Vec<RunSpec>,
    offset: usize,
    max_runs: usize,
) -> Result<(), EvalError> {
    let grid = &selection.grid;
    let drive = &selection.drive;
    for (experiment, method) in [Experiment::Drive, Experiment::DriveFromScratch]
        .into_iter()
        .flat_map(|e| drive.methods.iter().map(move |m| (e, m)))
    {
        for user in (selection.users.iter()).filter(|u| drive.users.contains(&u.name)) {
            let drivers = (selection.drivers.get(&user.name)).map_or(&[][..], Vec::as_slice);
            for (style, user) in styled(grid, user, drivers) {
                let mut previous = None;
                for scene in &drive.scenes {
                    let id = offset + transfer.len();
                    room(id, max_runs)?;
                    transfer.push(RunSpec {
                        id,
                        experiment,
                        method: *method,
                        user: user.clone(),
                        style,
                        speed_case: scene.speed_case.clone(),
                        headway_m: scene.headway_m,
                        seed: scene.seed,
                        dt: None,
                        horizon_margin_s: None,
                        experience_from: previous,
                        rung: None,
                    });
                    previous = (experiment == Experiment::Drive).then_some(id);
                }
            }
        }
    }
    Ok(())
}

/// The phase-one run (of `target`'s experiment and rung) whose experience
/// `target` starts from; `None` when the grid has a single speed case (or
/// headway), so that there is no other scenario.
fn transfer_source(selection: &Selection, target: &RunSpec, first: &[RunSpec]) -> Option<usize> {
    let grid = &selection.grid;
    let next = |len: usize, index: usize| (index + 1) % len;
    let (case, headway) = match selection.transfer.source {
        TransferSource::NextSpeedCase => {
            let cases = &grid.speed_cases;
            let i = cases
                .iter()
                .position(|c| c.name == target.speed_case.name)?;
            let case = &cases[next(cases.len(), i)];
            (case.name.as_str(), target.headway_m)
        }
        TransferSource::NextHeadway => {
            let headways = &grid.headways_m;
            let i = headways.iter().position(|&h| h == target.headway_m)?;
            (
                target.speed_case.name.as_str(),
                headways[next(headways.len(), i)],
            )
        }
    };
    let source = first.iter().find(|s| {
        s.experiment == target.experiment
            && s.rung == target.rung
            && s.method == target.method
            && s.user == target.user
            && s.style == target.style
            && s.seed == target.seed
            && s.speed_case.name == case
            && s.headway_m == headway
    })?;
    // A single speed case (or headway) has no other scenario to learn from.
    (source.id != target.id).then_some(source.id)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::config::{
        ClosedLoopRuns, ExampleConfig, Grid, TimingConfig, TransferConfig, TransferSource,
    };

    /// The paper's four speed cases (Section III.A).
    pub(crate) fn testbed() -> TestbedConfig {
        let speed_cases = [
            ("collector-high", 45.0, 40.0),
            ("collector-slow", 45.0, 35.0),
            ("arterial-high", 65.0, 60.0),
            ("arterial-slow", 65.0, 55.0),
        ]
        .into_iter()
        .map(|(name, ego_mph, others_mph)| SpeedCaseConfig {
            name: name.to_owned(),
            ego_mph,
            others_mph,
        })
        .collect();
        let text = include_str!("../../../configs/learn.toml");
        let mut testbed = (palc_harness::LearnConfig::from_toml_str(text).unwrap())
            .traffic
            .testbed
            .unwrap();
        testbed.speed_cases = speed_cases;
        testbed
    }

    pub(crate) fn selection() -> Selection {
        let testbed = testbed();
        let case = |name: &str| speed_case(&testbed, name, "test").unwrap();
        Selection {
            grid: Grid {
                methods: vec![Method::Paper, Method::Palc],
                speed_cases: vec![case("collector-high"), case("arterial-slow")],
                headways_m: vec![50.0, 30.0],
                styles: StylePreset::ALL.to_vec(),
                seeds: vec![1, 2],
            },
            users: vec![
                UserKind::deterministic(),
                UserKind {
                    name: "spread".into(),
                    spread_relative: Some(0.02),
                    ..UserKind::deterministic()
                },
            ],
            transfer: TransferConfig {
                source: TransferSource::NextSpeedCase,
                users: vec!["deterministic".into()],
                matrix_users: Vec::new(),
                accumulation_users: Vec::new(),
            },
            closed_loop: ClosedLoopRuns::default(),
            timing: TimingConfig {
                methods: vec![Method::Palc],
                dts: vec![0.1, 0.05],
                horizon_margins_s: vec![0.0, 1.0],
                styles: vec![StylePreset::Neutral],
                speed_case: "collector-high".into(),
                headway_m: 40.0,
                seed: 1,
            },
            example: ExampleConfig {
                method: Method::Palc,
                style: StylePreset::Aggressive,
                speed_case: "collector-high".into(),
                headway_m: 40.0,
                seed: 1,
            },
            ablation: crate::ablation::AblationConfig::default(),
            drivers: Default::default(),
            drive: Default::default(),
        }
    }

    #[test]
    fn a_config_past_its_run_bound_is_refused_before_its_runs_are_listed() {
        let selection = selection();
        let all = expand(&selection, &testbed()).unwrap().len();
        assert!(all < DEFAULT_MAX_RUNS);
        assert_eq!(
            expand_bounded(&selection, &testbed(), all).unwrap().len(),
            all
        );
        for max_runs in [1, 10, all - 1] {
            let error = expand_bounded(&selection, &testbed(), max_runs).unwrap_err();
            let message = error.to_string();
            assert!(
                matches!(error, EvalError::TooManyRuns { max_runs: m } if m == max_runs)
                    && message.contains("max_runs")
                    && message.contains(&max_runs.to_string()),
                "{message}"
            );
        }
        // A million seeds stop at the bound, not after a million runs are listed.
        let mut huge = selection.clone();
        huge.grid.seeds = (0..1_000_000).collect();
        assert!(matches!(
            expand(&huge, &testbed()),
            Err(EvalError::TooManyRuns { .. })
        ));
    }

    #[test]
    fn a_recorded_kind_runs_its_drivers_in_place_of_the_styles_and_transfers_per_driver() {
        let mut selection = selection();
        selection.users = vec![UserKind {
            name: "recorded".into(),
            recorded: Some("lane-changes.json".into()),
            ..UserKind::deterministic()
        }];
        selection.transfer.users = vec!["recorded".into()];
        selection
            .drivers
            .insert("recorded".into(), vec!["a:1:10".into(), "b:2:20".into()]);
        let plan = expand(&selection, &testbed()).unwrap();
        let grid: Vec<&RunSpec> = (plan.first.iter())
            .filter(|s| s.experiment == Experiment::Grid)
            .collect();
        // 2 methods x 2 speed cases x 2 headways x 2 drivers x 2 seeds.
        assert_eq!(grid.len(), 32);
        assert!(grid.iter().all(|s| s.user.driver.is_some()));
        assert_eq!(
            (grid.iter()).filter(|s| s.style_name() == "b:2:20").count(),
            16
        );
        for target in plan.transfer.iter() {
            let source = &plan.first[target.experience_from.unwrap()];
            assert_eq!(source.user.driver, target.user.driver);
            assert_ne!(source.speed_case, target.speed_case);
        }
    }

    #[test]
    fn the_grid_expands_to_every_combination_with_dense_ids() {
        let plan = expand(&selection(), &testbed()).unwrap();
        let grid = plan
            .first
            .iter()
            .filter(|s| s.experiment == Experiment::Grid)
            .count();
        assert_eq!(grid, 2 * 2 * 2 * 2 * 3 * 2);
        let timing = plan
            .first
            .iter()
            .filter(|s| s.experiment == Experiment::Timing)
            .count();
        assert_eq!(timing, 4);
        // Transfer: deterministic users only, every grid cell once.
        assert_eq!(plan.transfer.len(), grid / 2);
        for (i, spec) in plan.all().enumerate() {
            assert_eq!(spec.id, i);
        }
    }

    #[test]
    fn a_transfer_run_takes_the_same_user_from_the_next_speed_case() {
        let plan = expand(&selection(), &testbed()).unwrap();
        for target in &plan.transfer {
            let source = &plan.first[target.experience_from.unwrap()];
            assert_eq!(source.experiment, Experiment::Grid);
            assert_eq!(
                (
                    source.method,
                    &source.user,
                    &source.style,
                    source.seed,
                    source.headway_m
                ),
                (
                    target.method,
                    &target.user,
                    &target.style,
                    target.seed,
                    target.headway_m
                )
            );
            assert_ne!(source.speed_case, target.speed_case);
        }
    }

    #[test]
    fn the_matrix_pairs_every_other_scene_and_accumulation_chains_follow_the_grid() {
        let mut selection = selection();
        selection.grid.speed_cases = testbed().speed_cases[..3].to_vec();
        selection.transfer.users.clear();
        selection.transfer.matrix_users = vec!["deterministic".into()];
        selection.transfer.accumulation_users = vec!["deterministic".into()];
        let plan = expand(&selection, &testbed()).unwrap();
        assert!(plan.all().enumerate().all(|(i, s)| s.id == i));
        let cells = (plan.first.iter())
            .filter(|s| s.experiment == Experiment::Grid && s.user.name == "deterministic")
            .count();
        let same_run = |a: &RunSpec, b: &RunSpec| {
            (a.method, &a.user, a.style, a.seed) == (b.method, &b.user, b.style, b.seed)
        };
        // Every cell from each of the 2 other speed cases and the 1 other headway.
        let matrix: Vec<&RunSpec> = (plan.transfer.iter())
            .filter(|s| s.experiment == Experiment::Matrix)
            .collect();
        assert_eq!(matrix.len(), cells * 3);
        for target in matrix {
            let source = &plan.first[target.experience_from.unwrap()];
            assert_eq!(source.experiment, Experiment::Grid);
            assert!(same_run(source, target));
            let case = source.speed_case.name != target.speed_case.name;
            let headway = source.headway_m != target.headway_m;
            assert!(
                case != headway,
                "{} from {}",
                target.label(),
                source.label()
            );
        }
        // Chains: 2 speed cases after the first, per headway; 1 headway after the
        // first, per speed case; each scene from the one before it.
        let chained: Vec<&RunSpec> = (plan.transfer.iter())
            .filter(|s| s.experiment == Experiment::Accumulation)
            .collect();
        let starts_per_axis = cells / (3 * 2);
        assert_eq!(chained.len(), starts_per_axis * 2 * 2 + starts_per_axis * 3);
        for scene in &chained {
            let from = scene.experience_from.unwrap();
            assert!(from < scene.id);
            let source = plan.all().find(|s| s.id == from).unwrap();
            assert!(same_run(source, scene));
            assert!(matches!(
                source.experiment,
                Experiment::Grid | Experiment::Accumulation
            ));
        }
        assert!((chained.iter()).any(|s| {
            plan.transfer.iter().any(|t| {
                Some(t.id) == s.experience_from && t.experiment == Experiment::Accumulation
            })
        }));
    }

    #[test]
    fn the_ablation_runs_every_cell_once_per_rung_and_transfers_within_its_rung() {
        let mut selection = selection();
        selection.transfer.users.clear();
        selection.ablation = toml::from_str(
            r#"
            users = ["deterministic"]
            [[rungs]]
            name = "paper"
            change = "the printed method"
            method = "paper"
            [[rungs]]
            name = "labels"
            change = "palc's label rule"
            method = "palc"
            "#,
        )
        .unwrap();
        let plan = expand(&selection, &testbed()).unwrap();
        assert!(plan.all().enumerate().all(|(i, s)| s.id == i));
        let cells = selection.grid.cells();
        for (rung, labels) in [("paper", Method::Paper), ("labels", Method::Palc)] {
            let of_rung = |experiment: Experiment| -> Vec<&RunSpec> {
                (plan.all())
                    .filter(|s| s.experiment == experiment && s.rung.as_deref() == Some(rung))
                    .collect()
            };
            let scratch = of_rung(Experiment::Ablation);
            assert_eq!(scratch.len(), cells);
            assert!(
                scratch
                    .iter()
                    .all(|s| s.method == labels && s.experience_from.is_none())
            );
            let with = of_rung(Experiment::AblationTransfer);
            assert_eq!(with.len(), cells);
            for target in with {
                let source = &plan.first[target.experience_from.unwrap()];
                assert_eq!(source.experiment, Experiment::Ablation);
                assert_eq!(source.rung, target.rung);
                assert_ne!(source.speed_case, target.speed_case);
                assert_eq!(source.headway_m, target.headway_m);
            }
        }
        // The grid's own transfer runs are not made for users outside `transfer.users`.
        assert!(
            plan.transfer
                .iter()
                .all(|s| s.experiment != Experiment::Transfer)
        );
    }

    #[test]
    fn a_single_speed_case_has_no_transfer_run() {
        let mut selection = selection();
        selection.grid.speed_cases.truncate(1);
        let plan = expand(&selection, &testbed()).unwrap();
        assert!(plan.transfer.is_empty());
    }

    #[test]
    fn an_unknown_timing_speed_case_is_named() {
        let mut selection = selection();
        selection.timing.speed_case = "autobahn".into();
        let error = expand(&selection, &testbed()).unwrap_err().to_string();
        assert!(
            error.contains("autobahn") && error.contains("timing.speed_case"),
            "{error}"
        );
    }

    #[test]
    fn closed_loop_runs_repeat_the_grid_cells_of_their_users_in_phase_one() {
        let mut selection = selection();
        selection.closed_loop.users = vec!["deterministic".into()];
        let plan = expand(&selection, &testbed()).unwrap();
        let grid: Vec<&RunSpec> = (plan.first.iter())
            .filter(|s| s.experiment == Experiment::Grid && s.user.name == "deterministic")
            .collect();
        let closed: Vec<&RunSpec> = (plan.first.iter())
            .filter(|s| s.experiment == Experiment::ClosedLoop)
            .collect();
        assert_eq!(closed.len(), grid.len());
        for (open, closed) in grid.iter().zip(&closed) {
            assert_eq!(open.experiment_cell(), closed.experiment_cell());
        }
        assert!(plan.all().enumerate().all(|(i, s)| s.id == i));
    }
}
