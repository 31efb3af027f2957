//! The configuration of a learning run, as read from TOML (`configs/learn.toml`).

use palc_planner::PlannerConfig;
use palc_traffic::{ScenarioConfig, TestbedCell};
use serde::{Deserialize, Serialize};

use crate::HarnessError;
use crate::method::Method;
use crate::setup::PlanningConfig;
use crate::standard_alc::StandardWeights;
use crate::user::{Spread, Style};

/// Everything that describes one run of the lesson-learning loop.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LearnConfig {
    /// The traffic: road, vehicles, IDM and the test-bed grid (`[traffic.*]`).
    pub traffic: ScenarioConfig,
    /// Which cell of the grid to run.
    pub cell: CellChoice,
    /// The simulated user.
    pub user: UserConfig,
    /// The learning method, `paper` or `palc`.
    #[serde(default)]
    pub method: Method,
    /// The planning set-up.
    #[serde(default)]
    pub planning: PlanningConfig,
    /// The standard ALC's weights before learning.
    #[serde(default)]
    pub standard_weights: StandardWeights,
    /// The planner (its horizon and step are set from `planning`).
    #[serde(default)]
    pub planner: PlannerConfig,
    /// When the loop stops.
    #[serde(default, rename = "loop")]
    pub stopping: StoppingConfig,
    /// The aggregator's options; by default the method's own
    /// ([`palc_aggregator::AggregatorOptions::paper`] or the defaults for `palc`).
    #[serde(default)]
    pub aggregator: Option<palc_aggregator::AggregatorOptions>,
}

/// A cell of the test-bed grid, by speed-case name, adjacent headway and seed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CellChoice {
    /// Name of a speed case of `[traffic.testbed]`.
    pub speed_case: String,
    /// Front-to-front headway on the target lane (m).
    pub headway_m: f64,
    /// Seed of the scene's random draws.
    pub seed: u64,
}

/// The simulated user: a preset or custom style, and an optional spread.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UserConfig {
    /// `aggressive`, `neutral`, `cautious` or `custom`.
    pub style: String,
    /// The style when `style = "custom"`.
    #[serde(default)]
    pub custom: Option<Style>,
    /// Spread of the user's parameters between lane changes; none by default.
    #[serde(default)]
    pub spread: Option<Spread>,
}

impl UserConfig {
    /// The nominal style of this user.
    pub fn style(&self) -> Result<Style, HarnessError> {
        match (self.style.as_str(), self.custom) {
            ("custom", Some(style)) => {
                style.validate("user.custom")?;
                Ok(style)
            }
            ("custom", None) => Err(HarnessError::InvalidConfig {
                field: "user.custom".to_owned(),
                value: f64::NAN,
                bound: "a [user.custom] table when style = \"custom\"".to_owned(),
            }),
            (name, _) => Style::named(name),
        }
    }
}

/// When a run stops.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StoppingConfig {
    /// Takeovers after which the run is reported as a failure.
    pub max_takeovers: usize,
    /// Consecutive takeover-free lane changes that count as success (paper: 3).
    pub success_streak: usize,
    /// Users with spread: lane changes in the window over which the takeover rate is measured.
    pub spread_window: usize,
    /// Users with spread: personalized when the window's takeover rate is at most the
    /// ceiling (the nominal plan's rate on the same draws) plus this margin.
    pub spread_margin: f64,
    /// Users with spread: lane changes after which the run stops in any case.
    pub max_lane_changes: usize,
}

impl Default for StoppingConfig {
    fn default() -> Self {
        Self {
            max_takeovers: 30,
            success_streak: 3,
            spread_window: 10,
            spread_margin: 0.1,
            max_lane_changes: 60,
        }
    }
}

impl LearnConfig {
    /// Parses and validates a TOML config.
    pub fn from_toml_str(text: &str) -> Result<LearnConfig, HarnessError> {
        let config: LearnConfig = toml::from_str(text)?;
        config.validate()?;
        Ok(config)
    }

    /// Checks the parts that can be checked without building the scene.
    pub fn validate(&self) -> Result<(), HarnessError> {
        self.traffic.validate()?;
        self.user.style()?;
        self.planning.validate()?;
        let s = &self.stopping;
        for (field, value) in [
            ("loop.max_takeovers", s.max_takeovers),
            ("loop.success_streak", s.success_streak),
            ("loop.spread_window", s.spread_window),
            ("loop.max_lane_changes", s.max_lane_changes),
        ] {
            if value == 0 {
                return Err(HarnessError::InvalidConfig {
                    field: field.to_owned(),
                    value: 0.0,
                    bound: "at least 1".to_owned(),
                });
            }
        }
        if !(s.spread_margin.is_finite() && (0.0..=1.0).contains(&s.spread_margin)) {
            return Err(HarnessError::InvalidConfig {
                field: "loop.spread_margin".to_owned(),
                value: s.spread_margin,
                bound: "a value in [0, 1]".to_owned(),
            });
        }
        Ok(())
    }

    /// The test-bed cell this config selects.
    pub fn cell(&self) -> Result<TestbedCell, HarnessError> {
        let cells = self.traffic.testbed_cells()?;
        let names: Vec<String> = cells.iter().map(|c| c.speed_case.name.clone()).collect();
        let case = cells
            .iter()
            .find(|c| c.speed_case.name == self.cell.speed_case)
            .ok_or_else(|| {
                let mut names = names.clone();
                names.dedup();
                HarnessError::UnknownSpeedCase(self.cell.speed_case.clone(), names.join(", "))
            })?;
        if !(self.cell.headway_m.is_finite() && self.cell.headway_m > 0.0) {
            return Err(HarnessError::InvalidConfig {
                field: "cell.headway_m".to_owned(),
                value: self.cell.headway_m,
                bound: "a finite value > 0".to_owned(),
            });
        }
        Ok(TestbedCell {
            speed_case: case.speed_case.clone(),
            adjacent_headway: self.cell.headway_m,
            seed: self.cell.seed,
        })
    }

    /// A short name of the scenario for messages and reports.
    pub fn label(&self) -> String {
        format!(
            "{} / {} m / seed {} / {}",
            self.cell.speed_case, self.cell.headway_m, self.cell.seed, self.user.style
        )
    }
}
