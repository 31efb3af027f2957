//! `configs/reproduce.toml`: the whole reproduction in one file.
//!
//! The file names a base learning config (`configs/learn.toml`: traffic,
//! planning, standard ALC, planner, loop) and says which runs to make from it:
//! the grid of Section III (speed case x headway x style x seed), the methods,
//! the users, the experience-transfer and timing experiments, the qualitative
//! example and a `[quick]` subset. Every run overrides only its cell, user and
//! method (and, in the timing experiment, the step and horizon margin).

use std::path::{Path, PathBuf};

use anyhow::{Context, bail, ensure};
use serde::{Deserialize, Serialize};

/// The parsed `configs/reproduce.toml`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReproduceConfig {
    /// Path of the base learning config, relative to this file.
    pub base: PathBuf,
    /// The grid of runs.
    pub grid: GridConfig,
    /// The users every grid cell is run with.
    pub users: Vec<UserKind>,
    /// Experience accumulation (Fig. 11).
    pub transfer: TransferConfig,
    /// Compute time against horizon and step (Fig. 13).
    pub timing: TimingConfig,
    /// The qualitative example (Fig. 6).
    pub example: ExampleConfig,
    /// The `--quick` subset.
    pub quick: QuickConfig,
}

/// The grid of Section III: every combination is one run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridConfig {
    /// Methods, `paper` and/or `palc`.
    pub methods: Vec<String>,
    /// Names of speed cases of the base config's `[traffic.testbed]`.
    pub speed_cases: Vec<String>,
    /// Adjacent headways (m).
    pub headways_m: Vec<f64>,
    /// Style names.
    pub styles: Vec<String>,
    /// Scene seeds; with spread, the user's draws use the same seed.
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
    pub methods: Vec<String>,
    /// Steps (s).
    pub dts: Vec<f64>,
    /// Horizon margins after the standard ALC's end (s).
    pub horizon_margins_s: Vec<f64>,
    /// Styles.
    pub styles: Vec<String>,
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
    pub method: String,
    /// Style (the paper shows an aggressive user).
    pub style: String,
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
}

/// What one invocation runs: the full reproduction or the quick subset.
#[derive(Debug, Clone, PartialEq)]
pub struct Selection {
    /// The grid.
    pub grid: GridConfig,
    /// The users.
    pub users: Vec<UserKind>,
    /// The transfer experiment.
    pub transfer: TransferConfig,
    /// The timing experiment.
    pub timing: TimingConfig,
    /// The example.
    pub example: ExampleConfig,
}

impl ReproduceConfig {
    /// Parses and checks the config text.
    pub fn from_toml_str(text: &str) -> anyhow::Result<ReproduceConfig> {
        let config: ReproduceConfig = toml::from_str(text).context("cannot parse the config")?;
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

    /// The full reproduction or, with `quick`, the quick subset.
    pub fn select(&self, quick: bool) -> anyhow::Result<Selection> {
        if !quick {
            return Ok(Selection {
                grid: self.grid.clone(),
                users: self.users.clone(),
                transfer: self.transfer.clone(),
                timing: self.timing.clone(),
                example: self.example.clone(),
            });
        }
        let users = self
            .quick
            .users
            .iter()
            .map(|name| self.user(name).cloned())
            .collect::<anyhow::Result<Vec<_>>>()?;
        let transfer = TransferConfig {
            users: (self.transfer.users.iter())
                .filter(|name| self.quick.users.contains(name))
                .cloned()
                .collect(),
            ..self.transfer.clone()
        };
        Ok(Selection {
            grid: self.quick.grid.clone(),
            users,
            transfer,
            timing: self.quick.timing.clone(),
            example: self.example.clone(),
        })
    }

    fn user(&self, name: &str) -> anyhow::Result<&UserKind> {
        self.users.iter().find(|u| u.name == name).with_context(|| {
            let names: Vec<&str> = self.users.iter().map(|u| u.name.as_str()).collect();
            format!("unknown user kind `{name}`: `[[users]]` defines {names:?}")
        })
    }

    /// Checks every list is non-empty, every number in range and every name defined.
    pub fn validate(&self) -> anyhow::Result<()> {
        self.grid.validate("grid")?;
        self.quick.grid.validate("quick.grid")?;
        ensure!(
            !self.users.is_empty(),
            "`users` is empty, expected at least one user kind"
        );
        for (i, user) in self.users.iter().enumerate() {
            if let Some(spread) = user.spread_relative {
                ensure!(
                    spread.is_finite() && (0.0..0.5).contains(&spread),
                    "`users[{i}].spread_relative` is {spread}, expected a value in [0, 0.5)"
                );
            }
            ensure!(
                !self.users[..i].iter().any(|u| u.name == user.name),
                "`users[{i}].name` `{}` is defined twice",
                user.name
            );
        }
        for name in self.transfer.users.iter().chain(&self.quick.users) {
            self.user(name)?;
        }
        ensure!(!self.quick.users.is_empty(), "`quick.users` is empty");
        self.timing.validate("timing")?;
        self.quick.timing.validate("quick.timing")?;
        check_method("example.method", &self.example.method)?;
        check_headway("example.headway_m", self.example.headway_m)?;
        Ok(())
    }
}

impl GridConfig {
    fn validate(&self, table: &str) -> anyhow::Result<()> {
        for (field, len) in [
            ("methods", self.methods.len()),
            ("speed_cases", self.speed_cases.len()),
            ("headways_m", self.headways_m.len()),
            ("styles", self.styles.len()),
            ("seeds", self.seeds.len()),
        ] {
            ensure!(
                len > 0,
                "`{table}.{field}` is empty, expected at least one entry"
            );
        }
        for method in &self.methods {
            check_method(&format!("{table}.methods"), method)?;
        }
        for &headway in &self.headways_m {
            check_headway(&format!("{table}.headways_m"), headway)?;
        }
        Ok(())
    }

    /// Number of cells per method and user.
    pub fn cells(&self) -> usize {
        self.speed_cases.len() * self.headways_m.len() * self.styles.len() * self.seeds.len()
    }
}

impl TimingConfig {
    fn validate(&self, table: &str) -> anyhow::Result<()> {
        ensure!(!self.methods.is_empty(), "`{table}.methods` is empty");
        ensure!(!self.dts.is_empty(), "`{table}.dts` is empty");
        ensure!(!self.styles.is_empty(), "`{table}.styles` is empty");
        ensure!(
            !self.horizon_margins_s.is_empty(),
            "`{table}.horizon_margins_s` is empty"
        );
        for method in &self.methods {
            check_method(&format!("{table}.methods"), method)?;
        }
        for &dt in &self.dts {
            ensure!(
                dt.is_finite() && dt > 0.0 && dt <= 0.5,
                "`{table}.dts` holds {dt}, expected a step in (0, 0.5] s"
            );
        }
        for &margin in &self.horizon_margins_s {
            ensure!(
                margin.is_finite() && margin >= 0.0,
                "`{table}.horizon_margins_s` holds {margin}, expected a finite value >= 0"
            );
        }
        check_headway(&format!("{table}.headway_m"), self.headway_m)
    }
}

fn check_method(field: &str, method: &str) -> anyhow::Result<()> {
    if palc_harness::Method::named(method).is_none() {
        bail!("`{field}` holds `{method}`, expected `paper` or `palc`");
    }
    Ok(())
}

fn check_headway(field: &str, headway: f64) -> anyhow::Result<()> {
    ensure!(
        headway.is_finite() && headway > 0.0,
        "`{field}` holds {headway}, expected a finite headway > 0 m"
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn project_config() -> ReproduceConfig {
        let text = std::fs::read_to_string(crate::project_root().join("configs/reproduce.toml"))
            .expect("configs/reproduce.toml exists");
        ReproduceConfig::from_toml_str(&text).expect("the project's config is valid")
    }

    #[test]
    fn the_project_config_parses_and_covers_the_paper_grid() {
        let config = project_config();
        assert_eq!(config.grid.speed_cases.len(), 4);
        assert_eq!(config.grid.headways_m, vec![50.0, 45.0, 40.0, 35.0, 30.0]);
        assert_eq!(config.grid.styles.len(), 3);
        assert_eq!(config.grid.methods, vec!["paper", "palc"]);
        assert!(config.users.iter().any(|u| u.spread_relative.is_none()));
        assert!(config.users.iter().any(|u| u.spread_relative.is_some()));
        assert!(config.timing.dts.contains(&0.05));
        let quick = config.select(true).unwrap();
        assert!(quick.grid.cells() < config.grid.cells());
    }

    #[test]
    fn a_bad_value_is_named() {
        let mut config = project_config();
        config.grid.methods.push("magic".to_owned());
        let error = config.validate().unwrap_err().to_string();
        assert!(
            error.contains("grid.methods") && error.contains("magic"),
            "{error}"
        );

        let mut config = project_config();
        config.timing.dts = vec![0.0];
        let error = config.validate().unwrap_err().to_string();
        assert!(
            error.contains("timing.dts") && error.contains('0'),
            "{error}"
        );

        let mut config = project_config();
        config.quick.users = vec!["nobody".to_owned()];
        let error = config.validate().unwrap_err().to_string();
        assert!(error.contains("nobody"), "{error}");

        let mut config = project_config();
        config.users[0].spread_relative = Some(0.7);
        let error = config.validate().unwrap_err().to_string();
        assert!(
            error.contains("spread_relative") && error.contains("0.7"),
            "{error}"
        );
    }

    #[test]
    fn an_unknown_field_is_refused() {
        let error = ReproduceConfig::from_toml_str("base = \"learn.toml\"\nbogus = 1\n")
            .unwrap_err()
            .root_cause()
            .to_string();
        assert!(
            error.contains("bogus") || error.contains("missing"),
            "{error}"
        );
    }
}
