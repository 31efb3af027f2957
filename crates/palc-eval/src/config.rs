//! The evaluation config (`configs/reproduce.toml`): the whole evaluation in one file.
//!
//! The file names a base learning config (`configs/learn.toml`: traffic,
//! planning, standard ALC, planner, loop) and says which runs to make from it:
//! the grid of Section III (speed case x headway x style x seed), the methods,
//! the users, the experience-transfer and timing experiments, the qualitative
//! example and a `[quick]` subset. Every run overrides only its cell, user and
//! method (and, in the timing experiment, the step and horizon margin).
//!
//! The grid has one definition: the speed cases, adjacent headways and seeds of
//! `[grid]` default to the base config's `[traffic.testbed]`, which defines them;
//! `[grid]` only narrows them (the `[quick]` subset does).

use std::path::{Path, PathBuf};

use palc_harness::user::ParameterSpread;
use palc_harness::{Method, StylePreset, user::Family};
use palc_traffic::{SpeedCaseConfig, TestbedConfig};
use serde::{Deserialize, Serialize};

use crate::EvalError;
use crate::ablation::AblationConfig;
use crate::drive::{DriveConfig, DriveScene};

/// The parsed evaluation config.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EvalConfig {
    /// Path of the base learning config, relative to this file.
    pub base: PathBuf,
    /// The grid of runs.
    pub grid: GridConfig,
    /// The users every grid cell is run with.
    pub users: Vec<UserKind>,
    /// Experience accumulation (Fig. 11).
    pub transfer: TransferConfig,
    /// Closed-loop execution: grid cells run again with re-planning on; none if absent.
    #[serde(default)]
    pub closed_loop: ClosedLoopRuns,
    /// Compute time against horizon and step (Fig. 13).
    pub timing: TimingConfig,
    /// The qualitative example (Fig. 6).
    pub example: ExampleConfig,
    /// The ablation ladder from `paper` to `palc`; none if absent.
    #[serde(default)]
    pub ablation: AblationConfig,
    /// A drive of varied scenes; none if absent.
    #[serde(default, skip_serializing_if = "DriveConfig::is_empty")]
    pub drive: DriveConfig,
    /// The `--quick` subset.
    pub quick: QuickConfig,
    /// The most runs the evaluation may expand to, checked before any run
    /// ([`crate::plan::DEFAULT_MAX_RUNS`], 100 000, when left out; the full
    /// reproduction is about 24 000): raise it for a larger study.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_runs: Option<usize>,
    /// Refusal kinds (as in `refusals.csv`, e.g. `standard-gaps-unsafe`) that may
    /// account for every run of an experiment, in a scene built to have no lane
    /// change to learn (the dense stress scene); none by default. An experiment
    /// none of whose runs ran for another reason is idle ([`crate::idle`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub expected_refusals: Vec<String>,
}

/// Closed-loop execution (`[closed_loop]`): every grid cell of these users run
/// again, for every method, with the base config's `[planning.closed_loop]`
/// turned on, against the same cell in open loop.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClosedLoopRuns {
    /// Names of the user kinds to run it for.
    pub users: Vec<String>,
}

/// The grid of Section III: every combination is one run.
///
/// Speed cases, headways and seeds left out are those of the base config's
/// `[traffic.testbed]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridConfig {
    /// Methods, `paper` and/or `palc`.
    pub methods: Vec<Method>,
    /// Names of speed cases of the base config's `[traffic.testbed]`; all by default.
    #[serde(default)]
    pub speed_cases: Option<Vec<String>>,
    /// Adjacent headways (m); the test bed's by default.
    #[serde(default)]
    pub headways_m: Option<Vec<f64>>,
    /// Driving styles.
    pub styles: Vec<StylePreset>,
    /// Scene seeds (with spread, the user's draws use the same seed); the test
    /// bed's by default.
    #[serde(default)]
    pub seeds: Option<Vec<u64>>,
}

/// A grid with every list given: what a selection runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Grid {
    /// Methods.
    pub methods: Vec<Method>,
    /// Speed cases, with their speeds.
    pub speed_cases: Vec<SpeedCaseConfig>,
    /// Adjacent headways (m).
    pub headways_m: Vec<f64>,
    /// Driving styles.
    pub styles: Vec<StylePreset>,
    /// Scene seeds.
    pub seeds: Vec<u64>,
}

/// One kind of simulated user.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UserKind {
    /// Name in reports, e.g. `deterministic`.
    pub name: String,
    /// Relative spread of the user's headway and duration per lane change; none
    /// for a deterministic user.
    #[serde(default)]
    pub spread_relative: Option<f64>,
    /// Spread of other parameters (`palc_harness::user::ParameterSpread`); the
    /// draws are seeded with the scene's seed.
    #[serde(default)]
    pub spread_parameters: Option<ParameterSpread>,
    /// The family that refines each style (`palc_harness::user::Family`: start rule,
    /// reaction, lateral profile, speed, perceived-safety takeover); the paper's
    /// user when left out.
    #[serde(default)]
    pub family: Option<Family>,
    /// A file of recorded lane changes (`palc import commonroad`), relative to
    /// the evaluation config: every lane change becomes a driver with its own
    /// shape, duration and start context, run in place of the grid's styles
    /// (`recorded_drivers` says how).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub recorded: Option<PathBuf>,
    /// The recorded driver of one run (its lane change's id), set by the plan;
    /// never in a config.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub driver: Option<String>,
}

impl UserKind {
    /// The paper's user: the style's parameters in every lane change.
    pub fn deterministic() -> UserKind {
        UserKind {
            name: "deterministic".to_owned(),
            spread_relative: None,
            spread_parameters: None,
            family: None,
            recorded: None,
            driver: None,
        }
    }

    /// Whether this kind departs from the paper's user model beyond the spread
    /// of headway and duration: a family, or spread on other parameters. The
    /// report gives such kinds one row each in its user-family table, and the
    /// paper's kinds a section each.
    pub fn is_family(&self) -> bool {
        self.family.is_some() || self.spread_parameters.is_some() || self.recorded.is_some()
    }

    /// Whether the kind's decision to start is outside the one-cue rules palc's
    /// simulated users were built around: a recorded driver, or a family that
    /// starts on MOBIL's incentive or on two cues at once.
    pub fn is_out_of_class(&self) -> bool {
        self.recorded.is_some()
            || (self.family.as_ref()).is_some_and(|f| {
                matches!(
                    f.start,
                    palc_harness::user::StartRule::Incentive { .. }
                        | palc_harness::user::StartRule::HeadwayOrTtc { .. }
                )
            })
    }

    /// Whether the kind has a family or spread of its own (besides recorded drivers).
    fn is_family_of_its_own(&self) -> bool {
        self.family.is_some() || self.has_spread()
    }

    /// Whether any parameter is drawn per lane change.
    pub fn has_spread(&self) -> bool {
        self.spread_relative.is_some() || self.spread_parameters.is_some()
    }
}

/// Which run's experience a transfer run starts from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TransferSource {
    /// The same user, method and seed in the next speed case of the grid (cyclic).
    NextSpeedCase,
    /// The same user, method and seed in the next headway of the grid (cyclic).
    NextHeadway,
}

/// Experience accumulation: each grid cell run again from experience learned elsewhere.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TransferConfig {
    /// Where the experience comes from.
    pub source: TransferSource,
    /// Names of the user kinds to run it for.
    pub users: Vec<String>,
    /// User kinds for which every grid cell is run again from the experience of
    /// every other speed case (same headway) and every other headway (same speed
    /// case): the transfer matrix. Default none.
    #[serde(default)]
    pub matrix_users: Vec<String>,
    /// User kinds who drive the grid's speed cases in sequence (and, separately,
    /// its headways), each scene started from the experience of the one before.
    /// Default none.
    #[serde(default)]
    pub accumulation_users: Vec<String>,
}

/// Compute time against the step `dt` and the horizon `K`.
///
/// The harness derives `K` from the scenario (the standard ALC's end plus a
/// margin, over `dt`), so the experiment varies `dt` and the margin and reports
/// the `K` each run used.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimingConfig {
    /// Methods to time.
    pub methods: Vec<Method>,
    /// Steps (s).
    pub dts: Vec<f64>,
    /// Horizon margins after the standard ALC's end (s).
    pub horizon_margins_s: Vec<f64>,
    /// Driving styles.
    pub styles: Vec<StylePreset>,
    /// Speed case of the timed runs.
    pub speed_case: String,
    /// Adjacent headway of the timed runs (m).
    pub headway_m: f64,
    /// Seed of the timed runs.
    pub seed: u64,
}

/// The qualitative example of Fig. 6: one run whose every lane change is kept.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExampleConfig {
    /// Method.
    pub method: Method,
    /// Driving style (the paper shows an aggressive user).
    pub style: StylePreset,
    /// Speed case.
    pub speed_case: String,
    /// Adjacent headway (m).
    pub headway_m: f64,
    /// Seed.
    pub seed: u64,
}

/// The `--quick` subset: its own grid, users and timing; transfer and example as above.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QuickConfig {
    /// The quick grid.
    pub grid: GridConfig,
    /// Names of the user kinds of the quick run.
    pub users: Vec<String>,
    /// The quick timing experiment.
    pub timing: TimingConfig,
    /// The quick closed-loop experiment (on the quick grid); none if absent.
    #[serde(default)]
    pub closed_loop: ClosedLoopRuns,
    /// The quick drive (around the quick grid); none if absent.
    #[serde(default, skip_serializing_if = "DriveConfig::is_empty")]
    pub drive: DriveConfig,
}

/// What one invocation runs: the full evaluation or the quick subset.
#[derive(Debug, Clone, PartialEq)]
pub struct Selection {
    /// The grid.
    pub grid: Grid,
    /// The users.
    pub users: Vec<UserKind>,
    /// The transfer experiment.
    pub transfer: TransferConfig,
    /// The closed-loop experiment.
    pub closed_loop: ClosedLoopRuns,
    /// The timing experiment.
    pub timing: TimingConfig,
    /// The example.
    pub example: ExampleConfig,
    /// The ablation ladder's users and rungs.
    pub ablation: AblationConfig,
    /// The accepted drivers of each recorded user kind, by kind name: each runs
    /// in place of the grid's styles. Filled when the recorded files are read.
    pub drivers: std::collections::BTreeMap<String, Vec<String>>,
    /// The drive of varied scenes: its users and its scenes, in driving order.
    pub drive: Drive,
}

/// The drive of a selection ([`crate::drive`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Drive {
    /// Names of the user kinds that drive.
    pub users: Vec<String>,
    /// The methods that drive.
    pub methods: Vec<Method>,
    /// The scenes, in driving order.
    pub scenes: Vec<DriveScene>,
}

/// Parses TOML text; an error names the dotted path of the field it is in (e.g.
/// `planning.standard_alc.time_headway_s`) besides the line and column that `toml` reports.
fn from_toml<'de, T: Deserialize<'de>>(text: &'de str) -> Result<T, EvalError> {
    palc_traffic::parse_toml(text)
        .map_err(|palc_traffic::TomlParseError { path, error }| EvalError::Toml { path, error })
}

impl EvalConfig {
    /// Parses and checks the config text.
    pub fn from_toml_str(text: &str) -> Result<EvalConfig, EvalError> {
        let config: EvalConfig = from_toml(text)?;
        config.validate()?;
        Ok(config)
    }

    /// The base learning config's path, resolved against the directory of `config_path`.
    pub fn base_path(&self, config_path: &Path) -> PathBuf {
        config_path
            .parent()
            .unwrap_or_else(|| Path::new("."))
            .join(&self.base)
    }

    /// The full evaluation or, with `quick`, the quick subset, with the grid's
    /// lists completed from the base config's test bed.
    pub fn select(&self, quick: bool, testbed: &TestbedConfig) -> Result<Selection, EvalError> {
        if !quick {
            let grid = self.grid.resolve("grid", testbed)?;
            let drive = Drive {
                users: self.drive.users.clone(),
                methods: (self.drive.methods.clone()).unwrap_or_else(|| grid.methods.clone()),
                scenes: self.drive.scenes("drive", grid.cells_to_draw())?,
            };
            return Ok(Selection {
                grid,
                users: self.users.clone(),
                transfer: self.transfer.clone(),
                closed_loop: self.closed_loop.clone(),
                timing: self.timing.clone(),
                example: self.example.clone(),
                ablation: self.ablation.clone(),
                drivers: Default::default(),
                drive,
            });
        }
        let users = (self.quick.users.iter())
            .map(|name| self.user(name, "quick.users").cloned())
            .collect::<Result<Vec<_>, _>>()?;
        let quick = |names: &[String]| -> Vec<String> {
            (names.iter())
                .filter(|name| self.quick.users.contains(name))
                .cloned()
                .collect()
        };
        let transfer = TransferConfig {
            users: quick(&self.transfer.users),
            matrix_users: quick(&self.transfer.matrix_users),
            accumulation_users: quick(&self.transfer.accumulation_users),
            ..self.transfer.clone()
        };
        let grid = self.quick.grid.resolve("quick.grid", testbed)?;
        let drive = Drive {
            users: self.quick.drive.users.clone(),
            methods: (self.quick.drive.methods.clone()).unwrap_or_else(|| grid.methods.clone()),
            scenes: self
                .quick
                .drive
                .scenes("quick.drive", grid.cells_to_draw())?,
        };
        Ok(Selection {
            grid,
            users,
            transfer,
            closed_loop: self.quick.closed_loop.clone(),
            timing: self.quick.timing.clone(),
            example: self.example.clone(),
            ablation: AblationConfig {
                users: quick(&self.ablation.users),
                ..self.ablation.clone()
            },
            drivers: Default::default(),
            drive,
        })
    }

    fn user(&self, name: &str, field: &str) -> Result<&UserKind, EvalError> {
        self.users
            .iter()
            .find(|u| u.name == name)
            .ok_or_else(|| EvalError::Unknown {
                kind: "user kind",
                name: name.to_owned(),
                field: field.to_owned(),
                known: self.users.iter().map(|u| u.name.clone()).collect(),
            })
    }

    /// Checks every list is non-empty, every number in range and every name defined.
    pub fn validate(&self) -> Result<(), EvalError> {
        if self.max_runs == Some(0) {
            return Err(EvalError::invalid(
                "max_runs",
                0,
                "at least 1 (leave it out for the default)",
            ));
        }
        for (i, kind) in self.expected_refusals.iter().enumerate() {
            let well_formed = !kind.is_empty()
                && (kind.bytes()).all(|b| b.is_ascii_lowercase() || b == b'-' || b == b'/');
            if !well_formed {
                return Err(EvalError::invalid(
                    format!("expected_refusals[{i}]"),
                    format_args!("{kind:?}"),
                    "a refusal kind as in refusals.csv (lower-case words joined by `-`, `user/` before a user's)",
                ));
            }
        }
        self.grid.validate("grid")?;
        self.quick.grid.validate("quick.grid")?;
        if self.users.is_empty() {
            return Err(EvalError::invalid(
                "users",
                "empty",
                "at least one user kind",
            ));
        }
        for (i, user) in self.users.iter().enumerate() {
            if let Some(driver) = &user.driver {
                return Err(EvalError::invalid(
                    format!("users[{i}].driver"),
                    driver,
                    "nothing: the plan sets each recorded run's driver",
                ));
            }
            if user.recorded.is_some() && user.is_family_of_its_own() {
                return Err(EvalError::invalid(
                    format!("users[{i}].recorded"),
                    user.name.as_str(),
                    "a kind without family or spread: recorded drivers bring their own style and profile",
                ));
            }
            if let Some(spread) = user.spread_relative {
                if !(spread.is_finite() && (0.0..0.5).contains(&spread)) {
                    return Err(EvalError::invalid(
                        format!("users[{i}].spread_relative"),
                        format_args!("{spread:e}"),
                        "a value in [0, 0.5)",
                    ));
                }
            }
            if let Some(family) = &user.family {
                family
                    .validate(&format!("users[{i}].family"))
                    .map_err(|e| EvalError::invalid_user(e.into()))?;
            }
            if let Some(parameters) = &user.spread_parameters {
                parameters
                    .validate(&format!("users[{i}].spread_parameters"))
                    .map_err(|e| EvalError::invalid_user(e.into()))?;
            }
            if self.users[..i].iter().any(|u| u.name == user.name) {
                return Err(EvalError::invalid(
                    format!("users[{i}].name"),
                    format_args!("`{}`", user.name),
                    "a name not defined before",
                ));
            }
        }
        for (field, names) in [
            ("transfer.users", &self.transfer.users),
            ("transfer.matrix_users", &self.transfer.matrix_users),
            (
                "transfer.accumulation_users",
                &self.transfer.accumulation_users,
            ),
            ("ablation.users", &self.ablation.users),
        ] {
            for name in names {
                self.user(name, field)?;
            }
        }
        for name in &self.quick.users {
            self.user(name, "quick.users")?;
        }
        for name in &self.closed_loop.users {
            self.user(name, "closed_loop.users")?;
        }
        for name in &self.quick.closed_loop.users {
            if !self.quick.users.contains(name) {
                return Err(EvalError::invalid(
                    "quick.closed_loop.users",
                    format_args!("`{name}`"),
                    "a user kind of quick.users",
                ));
            }
        }
        if self.quick.users.is_empty() {
            return Err(EvalError::invalid(
                "quick.users",
                "empty",
                "at least one user kind",
            ));
        }
        self.drive.validate("drive")?;
        self.quick.drive.validate("quick.drive")?;
        for name in &self.drive.users {
            self.user(name, "drive.users")?;
        }
        for name in &self.quick.drive.users {
            if !self.quick.users.contains(name) {
                return Err(EvalError::invalid(
                    "quick.drive.users",
                    format_args!("`{name}`"),
                    "a user kind of quick.users",
                ));
            }
        }
        self.ablation.resolve()?;
        self.timing.validate("timing")?;
        self.quick.timing.validate("quick.timing")?;
        check_headway("example.headway_m", self.example.headway_m)
    }
}

impl GridConfig {
    fn validate(&self, table: &str) -> Result<(), EvalError> {
        let optional_len = |list: &Option<Vec<_>>| list.as_ref().map(Vec::len);
        for (field, len) in [
            ("methods", Some(self.methods.len())),
            ("speed_cases", self.speed_cases.as_ref().map(Vec::len)),
            ("headways_m", optional_len(&self.headways_m)),
            ("styles", Some(self.styles.len())),
            ("seeds", self.seeds.as_ref().map(Vec::len)),
        ] {
            if len == Some(0) {
                return Err(EvalError::invalid(
                    format!("{table}.{field}"),
                    "empty",
                    "at least one entry (leave it out for the test bed's)",
                ));
            }
        }
        for &headway in self.headways_m.iter().flatten() {
            check_headway(&format!("{table}.headways_m"), headway)?;
        }
        Ok(())
    }

    /// This grid with every list given, from `testbed` where it is left out.
    pub fn resolve(&self, table: &str, testbed: &TestbedConfig) -> Result<Grid, EvalError> {
        let speed_cases = match &self.speed_cases {
            None => testbed.speed_cases.clone(),
            Some(names) => names
                .iter()
                .map(|name| speed_case(testbed, name, &format!("{table}.speed_cases")))
                .collect::<Result<_, _>>()?,
        };
        Ok(Grid {
            methods: self.methods.clone(),
            speed_cases,
            headways_m: (self.headways_m.clone())
                .unwrap_or_else(|| testbed.adjacent_headways_m.clone()),
            styles: self.styles.clone(),
            seeds: self.seeds.clone().unwrap_or_else(|| testbed.seeds.clone()),
        })
    }
}

impl Grid {
    /// The cells a drive is drawn around.
    pub fn cells_to_draw(&self) -> crate::drive::GridCells<'_> {
        crate::drive::GridCells {
            speed_cases: &self.speed_cases,
            headways_m: &self.headways_m,
            seeds: &self.seeds,
        }
    }

    /// Number of cells per method and user.
    pub fn cells(&self) -> usize {
        self.speed_cases.len() * self.headways_m.len() * self.styles.len() * self.seeds.len()
    }
}

/// The speed case `name` of the test bed; the error names `field` and the cases defined.
pub fn speed_case(
    testbed: &TestbedConfig,
    name: &str,
    field: &str,
) -> Result<SpeedCaseConfig, EvalError> {
    (testbed.speed_cases.iter())
        .find(|case| case.name == name)
        .cloned()
        .ok_or_else(|| EvalError::Unknown {
            kind: "speed case",
            name: name.to_owned(),
            field: field.to_owned(),
            known: testbed.speed_cases.iter().map(|c| c.name.clone()).collect(),
        })
}

impl TimingConfig {
    fn validate(&self, table: &str) -> Result<(), EvalError> {
        for (field, empty) in [
            ("methods", self.methods.is_empty()),
            ("dts", self.dts.is_empty()),
            ("styles", self.styles.is_empty()),
            ("horizon_margins_s", self.horizon_margins_s.is_empty()),
        ] {
            if empty {
                return Err(EvalError::invalid(
                    format!("{table}.{field}"),
                    "empty",
                    "at least one entry",
                ));
            }
        }
        for &dt in &self.dts {
            if !(dt.is_finite() && dt > 0.0 && dt <= 0.5) {
                return Err(EvalError::invalid(
                    format!("{table}.dts"),
                    format_args!("{dt:e}"),
                    "a step in (0, 0.5] s",
                ));
            }
        }
        for &margin in &self.horizon_margins_s {
            if !(margin.is_finite() && margin >= 0.0) {
                return Err(EvalError::invalid(
                    format!("{table}.horizon_margins_s"),
                    format_args!("{margin:e}"),
                    "a finite value >= 0 s",
                ));
            }
        }
        check_headway(&format!("{table}.headway_m"), self.headway_m)
    }
}

fn check_headway(field: &str, headway: f64) -> Result<(), EvalError> {
    if headway.is_finite() && headway > 0.0 {
        Ok(())
    } else {
        Err(EvalError::invalid(
            field,
            format_args!("{headway:e}"),
            "a finite headway > 0 m",
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const PROJECT_CONFIG: &str = include_str!("../../../configs/reproduce.toml");

    fn project_config() -> EvalConfig {
        EvalConfig::from_toml_str(PROJECT_CONFIG).expect("the project's config is valid")
    }

    fn testbed() -> TestbedConfig {
        let text = include_str!("../../../configs/learn.toml");
        let base = palc_harness::LearnConfig::from_toml_str(text).unwrap();
        base.traffic.testbed.unwrap()
    }

    #[test]
    fn the_project_config_parses_and_covers_the_paper_grid() {
        let config = project_config();
        let full = config.select(false, &testbed()).unwrap();
        assert_eq!(full.grid.speed_cases.len(), 4);
        assert_eq!(full.grid.headways_m, vec![50.0, 45.0, 40.0, 35.0, 30.0]);
        assert_eq!(full.grid.seeds, vec![1, 2]);
        assert_eq!(full.grid.styles.len(), 3);
        assert_eq!(full.grid.methods, vec![Method::Paper, Method::Palc]);
        assert!(config.users.iter().any(|u| u.spread_relative.is_none()));
        assert!(config.users.iter().any(|u| u.spread_relative.is_some()));
        assert!(config.timing.dts.contains(&0.05));
        let quick = config.select(true, &testbed()).unwrap();
        assert!(quick.grid.cells() < full.grid.cells());
    }

    #[test]
    fn drive_users_are_known_and_the_quick_ones_run_in_the_quick_subset() {
        let config = project_config();
        let full = config.select(false, &testbed()).unwrap();
        assert_eq!(full.drive.scenes.len(), config.drive.lane_changes());
        assert_eq!(full.drive.users, config.drive.users);
        let quick = config.select(true, &testbed()).unwrap();
        assert!(
            quick
                .drive
                .users
                .iter()
                .all(|u| config.quick.users.contains(u))
        );
        let mut bad = project_config();
        bad.drive.users = vec!["nobody".into()];
        let error = bad.validate().unwrap_err().to_string();
        assert!(
            error.contains("drive.users") && error.contains("nobody"),
            "{error}"
        );
        let mut bad = project_config();
        bad.quick.drive.users = vec!["spread-5%".into()];
        let error = bad.validate().unwrap_err().to_string();
        assert!(error.contains("quick.drive.users"), "{error}");
        let mut bad = project_config();
        bad.quick.drive.lane_changes = Some(0);
        let error = bad.validate().unwrap_err().to_string();
        assert!(error.contains("quick.drive.lane_changes"), "{error}");
    }

    #[test]
    fn closed_loop_users_are_known_and_the_quick_ones_run_in_the_quick_subset() {
        let config = project_config();
        assert_eq!(config.closed_loop.users, vec!["deterministic".to_owned()]);
        let quick = config.select(true, &testbed()).unwrap();
        assert_eq!(quick.closed_loop.users, vec!["deterministic".to_owned()]);
        let mut bad = project_config();
        bad.closed_loop.users = vec!["nobody".into()];
        let error = bad.validate().unwrap_err().to_string();
        assert!(error.contains("closed_loop.users"), "{error}");
        let mut bad = project_config();
        bad.quick.closed_loop.users = vec!["spread-2%".into()];
        bad.quick.users = vec!["deterministic".into()];
        let error = bad.validate().unwrap_err().to_string();
        assert!(error.contains("quick.closed_loop.users"), "{error}");
        // A config without the table runs no closed-loop run.
        let without = PROJECT_CONFIG
            .replace("[closed_loop]\nusers = [\"deterministic\"]\n", "")
            .replace("[quick.closed_loop]\nusers = [\"deterministic\"]\n", "");
        assert_ne!(without, PROJECT_CONFIG);
        let config = EvalConfig::from_toml_str(&without).unwrap();
        assert!(config.closed_loop.users.is_empty());
    }

    #[test]
    fn a_bad_value_is_named() {
        let error = EvalConfig::from_toml_str(&PROJECT_CONFIG.replace(
            "methods = [\"paper\", \"palc\"]",
            "methods = [\"paper\", \"magic\"]",
        ))
        .unwrap_err()
        .to_string();
        assert!(error.contains("magic"), "{error}");

        let mut config = project_config();
        config.timing.dts = vec![0.0];
        let error = config.validate().unwrap_err().to_string();
        assert!(
            error.contains("timing.dts") && error.contains("0e0"),
            "{error}"
        );

        let mut config = project_config();
        config.quick.users = vec!["nobody".to_owned()];
        let error = config.validate().unwrap_err().to_string();
        assert!(
            error.contains("nobody") && error.contains("quick.users"),
            "{error}"
        );

        let mut config = project_config();
        config.users[0].spread_relative = Some(0.7);
        let error = config.validate().unwrap_err().to_string();
        assert!(
            error.contains("spread_relative") && error.contains("7e-1"),
            "{error}"
        );
    }

    #[test]
    fn an_unknown_speed_case_is_named_with_the_defined_ones() {
        let mut config = project_config();
        config.grid.speed_cases = Some(vec!["autobahn".to_owned()]);
        let error = config.select(false, &testbed()).unwrap_err().to_string();
        assert!(
            error.contains("autobahn")
                && error.contains("grid.speed_cases")
                && error.contains("collector-high"),
            "{error}"
        );
    }

    #[test]
    fn an_unknown_style_is_refused_naming_the_field_path() {
        let error = EvalConfig::from_toml_str(&PROJECT_CONFIG.replace(
            "styles = [\"aggressive\", \"neutral\", \"cautious\"]",
            "styles = [\"reckless\"]",
        ))
        .unwrap_err();
        assert!(
            matches!(&error, EvalError::Toml { path, .. } if path == "grid.styles[0]"),
            "{error:?}"
        );
        let error = error.to_string();
        assert!(
            error.contains("`grid.styles[0]`")
                && error.contains("reckless")
                && error.contains("line"),
            "{error}"
        );
    }

    #[test]
    fn a_wrong_type_in_a_nested_field_names_its_path() {
        let error = EvalConfig::from_toml_str(
            &PROJECT_CONFIG.replace("spread_relative = 0.02", "spread_relative = \"2%\""),
        )
        .unwrap_err()
        .to_string();
        assert!(
            error.contains("`users[1].spread_relative`") && error.contains("line"),
            "{error}"
        );
    }

    #[test]
    fn an_unknown_field_is_refused() {
        let error = EvalConfig::from_toml_str("base = \"learn.toml\"\nbogus = 1\n")
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("bogus") || error.contains("missing"),
            "{error}"
        );
    }
}
