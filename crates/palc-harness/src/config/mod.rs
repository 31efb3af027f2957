//! The configuration of a learning run, as read from TOML (`configs/learn.toml`),
//! with its tables: the planning set-up ([`PlanningConfig`]) and closed loop
//! ([`ClosedLoopConfig`]).

mod closed_loop;
mod planning;

pub use crate::acc::AccConfig;
pub use crate::safety::SafetyConfig;
pub use crate::standard_alc::StandardWeights;
pub use closed_loop::ClosedLoopConfig;
pub use planning::PlanningConfig;

use palc_planner::PlannerConfig;
use palc_traffic::{ScenarioConfig, TestbedCell};
use serde::{Deserialize, Serialize};

use crate::HarnessError;
use crate::method::Method;

use palc_user::{Family, SimulatedUser, Spread, Style, StylePreset};

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

/// The simulated user: a preset or custom style, the family of rules that
/// refines it, and an optional spread.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UserConfig {
    /// `aggressive`, `neutral`, `cautious` or `custom`.
    pub style: UserStyle,
    /// The style when `style = "custom"`.
    #[serde(default)]
    pub custom: Option<Style>,
    /// The family's rules (`[user.family]`): start rule, reaction, lateral profile,
    /// speed, perceived-safety takeover; the paper's user by default.
    #[serde(default)]
    pub family: Option<Family>,
    /// Spread of the user's parameters between lane changes; none by default.
    #[serde(default)]
    pub spread: Option<Spread>,
}

/// A file holding only a `[user]` table (`palc learn --user FILE`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct UserFile {
    user: UserConfig,
}

impl UserConfig {
    /// Parses and checks a TOML text holding one `[user]` table (and nothing
    /// else), e.g. a user family kept in its own file; errors name the field path.
    pub fn from_toml_str(text: &str, deviation_m: f64) -> Result<UserConfig, HarnessError> {
        let file: UserFile = from_toml(text)?;
        file.user.simulated(deviation_m)?;
        Ok(file.user)
    }

    /// A deterministic user of one of the paper's styles.
    pub fn preset(preset: StylePreset) -> UserConfig {
        UserConfig {
            style: UserStyle::Preset(preset),
            custom: None,
            family: None,
            spread: None,
        }
    }

    /// The simulated user of this config, taking over beyond `deviation_m`.
    ///
    /// # Errors
    /// [`HarnessError::InvalidConfig`] naming the field of a parameter out of bound.
    pub fn simulated(&self, deviation_m: f64) -> Result<SimulatedUser, HarnessError> {
        let family = self.family.clone().unwrap_or_default();
        let name = match &self.family {
            Some(family) if *family != Family::default() => {
                format!("{} ({})", self.style, family.describe())
            }
            _ => self.style.to_string(),
        };
        Ok(SimulatedUser::new(
            name,
            self.style()?,
            family,
            deviation_m,
            self.spread,
        )?)
    }

    /// The nominal style of this user.
    ///
    /// # Errors
    /// [`HarnessError::InvalidConfig`] for `custom` without a valid `[user.custom]` table.
    pub fn style(&self) -> Result<Style, HarnessError> {
        match (self.style, self.custom) {
            (UserStyle::Preset(preset), _) => Ok(preset.style()),
            (UserStyle::Custom, Some(style)) => {
                style.validate("user.custom")?;
                Ok(style)
            }
            (UserStyle::Custom, None) => Err(HarnessError::MissingTable {
                table: "user.custom",
                reason: "`user.style` is \"custom\"",
            }),
        }
    }
}

/// The style a [`UserConfig`] names: one of the paper's presets, or `custom` for
/// the `[user.custom]` table.
///
/// Reads and writes as a name (`style = "neutral"`, `style = "custom"`); any other
/// name is refused when the config is parsed, with the list of valid names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub enum UserStyle {
    /// One of the paper's three styles.
    Preset(StylePreset),
    /// The style of `[user.custom]`.
    Custom,
}

impl UserStyle {
    /// The name in configs and reports.
    pub const fn name(self) -> &'static str {
        match self {
            UserStyle::Preset(preset) => preset.name(),
            UserStyle::Custom => "custom",
        }
    }
}

impl From<StylePreset> for UserStyle {
    fn from(preset: StylePreset) -> Self {
        UserStyle::Preset(preset)
    }
}

impl std::str::FromStr for UserStyle {
    type Err = HarnessError;

    /// A preset's name or `custom`; [`HarnessError::UnknownStyle`] lists the valid names.
    fn from_str(name: &str) -> Result<Self, Self::Err> {
        match name {
            "custom" => Ok(UserStyle::Custom),
            _ => name
                .parse::<StylePreset>()
                .map(UserStyle::Preset)
                .map_err(|_| HarnessError::UnknownStyle {
                    name: name.to_owned(),
                    expected: format!("{}, `custom`", StylePreset::quoted_names()),
                }),
        }
    }
}

impl TryFrom<String> for UserStyle {
    type Error = HarnessError;

    fn try_from(name: String) -> Result<Self, Self::Error> {
        name.parse()
    }
}

impl From<UserStyle> for String {
    fn from(style: UserStyle) -> Self {
        style.name().to_owned()
    }
}

impl std::fmt::Display for UserStyle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// How far `planning.target_l` may lie from the target lane's centre (m).
pub const TARGET_L_TOLERANCE_M: f64 = 1e-6;

/// Checks `[aggregator]`, naming each field by its path in the config.
pub(crate) fn validate_aggregator(
    options: &palc_aggregator::AggregatorOptions,
) -> Result<(), HarnessError> {
    let in_table = |table: &str, error: palc_zone_filter::ZoneError| match error {
        palc_zone_filter::ZoneError::InvalidConfig {
            field,
            value,
            bound,
        } => HarnessError::InvalidConfig {
            field: format!("aggregator.{table}.{field}"),
            value,
            bound: bound.to_owned(),
        },
        other => HarnessError::Zone(other),
    };
    options.zone.validate().map_err(|e| in_table("zone", e))?;
    options
        .bounds
        .validate()
        .map_err(|e| in_table("bounds", e))?;
    options.validate().map_err(|error| match error {
        palc_aggregator::AggregatorError::InvalidOption {
            field,
            value,
            bound,
        } => HarnessError::InvalidConfig {
            field: format!("aggregator.{field}"),
            value,
            bound: bound.to_owned(),
        },
        other => HarnessError::Aggregator(other),
    })
}

/// Largest `loop.max_takeovers`: a run keeps a record of every lane change, so the
/// caps on a run's length bound its memory.
pub const MAX_TAKEOVERS: usize = 1_000;
/// Largest `loop.success_streak` (the paper's is 3).
pub const MAX_SUCCESS_STREAK: usize = 100;
/// Largest `loop.max_lane_changes` and `loop.spread_window`.
pub const MAX_LANE_CHANGES: usize = 1_000;

/// When a run stops.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StoppingConfig {
    /// Takeovers after which the run is reported as a failure.
    pub max_takeovers: usize,
    /// Consecutive takeover-free lane changes that count as success (paper: 3).
    pub success_streak: usize,
    /// Users with spread: lane changes in the window over which the takeover rate
    /// is measured. Default `20`.
    pub spread_window: usize,
    /// Users with spread: personalized when the window's takeover rate is at most the
    /// ceiling (the nominal plan's rate on the same draws) plus this margin.
    /// Default `0.05`: one takeover more than the nominal plan in 20 lane changes.
    /// (A window of 10 within 0.1 stopped runs whose plan, frozen, was then taken
    /// over 5 times more than the nominal plan in 50 lane changes:
    /// docs/experiments/0050-users-with-spread-averaging-and-window.md.)
    pub spread_margin: f64,
    /// Users with spread: lane changes after which the run stops in any case.
    pub max_lane_changes: usize,
    /// Users with spread: lane changes driven after the run has ended, with
    /// learning frozen, each judged by the drawn user against the nominal plan on
    /// the same draw ([`crate::record::FrozenEvaluation`]); `0` for none. Default `50`.
    pub frozen_lane_changes: usize,
}

impl Default for StoppingConfig {
    fn default() -> Self {
        Self {
            max_takeovers: 30,
            success_streak: 3,
            spread_window: 20,
            spread_margin: 0.05,
            max_lane_changes: 60,
            frozen_lane_changes: 50,
        }
    }
}

/// Parses TOML text; an error names the dotted path of the field it is in (e.g.
/// `planning.standard_alc.time_headway_s`) besides the line and column that `toml` reports.
fn from_toml<'de, T: Deserialize<'de>>(text: &'de str) -> Result<T, HarnessError> {
    palc_traffic::parse_toml(text)
        .map_err(|palc_traffic::TomlParseError { path, error }| HarnessError::Toml { path, error })
}

impl LearnConfig {
    /// This config for another cell of the test bed. Checked by
    /// [`LearnConfig::validate`] and when the run starts, like a parsed config.
    pub fn with_cell(mut self, cell: CellChoice) -> Self {
        self.cell = cell;
        self
    }

    /// This config for another simulated user.
    pub fn with_user(mut self, user: UserConfig) -> Self {
        self.user = user;
        self
    }

    /// This config for another learning method.
    pub fn with_method(mut self, method: Method) -> Self {
        self.method = method;
        self
    }

    /// Parses and validates a TOML config.
    pub fn from_toml_str(text: &str) -> Result<LearnConfig, HarnessError> {
        let config: LearnConfig = from_toml(text)?;
        config.validate()?;
        Ok(config)
    }

    /// Checks the parts that can be checked without building the scene.
    pub fn validate(&self) -> Result<(), HarnessError> {
        self.traffic.validate()?;
        self.planning.validate()?;
        self.standard_weights.validate()?;
        self.user.simulated(self.planning.takeover_threshold_m)?;
        self.validate_target_l()?;
        if let Some(options) = &self.aggregator {
            validate_aggregator(options)?;
        }
        let s = &self.stopping;
        for (field, value, max) in [
            ("loop.max_takeovers", s.max_takeovers, MAX_TAKEOVERS),
            ("loop.success_streak", s.success_streak, MAX_SUCCESS_STREAK),
            ("loop.spread_window", s.spread_window, MAX_LANE_CHANGES),
            (
                "loop.max_lane_changes",
                s.max_lane_changes,
                MAX_LANE_CHANGES,
            ),
        ] {
            if !(1..=max).contains(&value) {
                return Err(HarnessError::InvalidConfig {
                    field: field.to_owned(),
                    value: value as f64,
                    bound: format!("a whole number in [1, {max}]"),
                });
            }
        }
        if s.frozen_lane_changes > MAX_LANE_CHANGES {
            return Err(HarnessError::InvalidConfig {
                field: "loop.frozen_lane_changes".to_owned(),
                value: s.frozen_lane_changes as f64,
                bound: format!("a whole number in [0, {MAX_LANE_CHANGES}]"),
            });
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

    /// `planning.target_l` is the centre of the target lane: lane 1, one lane
    /// width from the ego's lane 0 (a lane change of the test bed).
    fn validate_target_l(&self) -> Result<(), HarnessError> {
        let road = &self.traffic.road;
        let target_l = self.planning.target_l;
        if road.lanes < 2 {
            return Err(HarnessError::InvalidConfig {
                field: "planning.target_l".to_owned(),
                value: target_l,
                bound: format!(
                    "the centre of a target lane, but `traffic.road.lanes` = {} has none",
                    road.lanes
                ),
            });
        }
        if (target_l - road.lane_width_m).abs() > TARGET_L_TOLERANCE_M {
            return Err(HarnessError::InvalidConfig {
                field: "planning.target_l".to_owned(),
                value: target_l,
                bound: format!(
                    "the centre of the target lane, `traffic.road.lane_width_m` = {:?} m (within {TARGET_L_TOLERANCE_M:?} m)",
                    road.lane_width_m
                ),
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
                HarnessError::UnknownSpeedCase {
                    name: self.cell.speed_case.clone(),
                    defined: names.join(", "),
                }
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

#[cfg(test)]
mod tests {
    use super::*;

    const DEFAULT: &str = include_str!("../../../../configs/learn.toml");

    fn user(text: &str) -> Result<UserConfig, toml::de::Error> {
        toml::from_str(text)
    }

    #[test]
    fn user_styles_read_and_write_as_names() {
        for preset in StylePreset::ALL {
            let parsed = user(&format!("style = \"{}\"", preset.name())).unwrap();
            assert_eq!(parsed, UserConfig::preset(preset));
            assert_eq!(parsed.style().unwrap(), preset.style());
            let written = toml::to_string(&parsed).unwrap();
            assert!(
                written.contains(&format!("style = \"{}\"", preset.name())),
                "{written}"
            );
        }
        let custom = user(
            "style = \"custom\"\n[custom]\ntime_headway_s = 1.3\nlane_change_duration_s = 2.0",
        )
        .unwrap();
        assert_eq!(custom.style, UserStyle::Custom);
        assert_eq!(custom.style().unwrap().time_headway_s, 1.3);
        let preset: StylePreset =
            toml::from_str::<std::collections::BTreeMap<String, StylePreset>>("p = \"cautious\"")
                .unwrap()["p"];
        assert_eq!(preset, StylePreset::Cautious);
    }

    #[test]
    fn an_unknown_style_is_refused_when_parsed_listing_the_valid_names() {
        let err = user("style = \"reckless\"").unwrap_err().to_string();
        for name in [
            "reckless",
            "`aggressive`",
            "`neutral`",
            "`cautious`",
            "`custom`",
        ] {
            assert!(err.contains(name), "{err}");
        }
        let text = DEFAULT.replace("style = \"neutral\"", "style = \"Neutral\"");
        let err = LearnConfig::from_toml_str(&text).unwrap_err().to_string();
        assert!(err.contains("`Neutral`"), "{err}");
        let err = "reckless".parse::<UserStyle>().unwrap_err().to_string();
        assert!(err.contains("`custom`"), "{err}");
    }

    #[test]
    fn custom_without_its_table_is_refused_naming_the_field() {
        let err = user("style = \"custom\"").unwrap().style().unwrap_err();
        assert!(err.to_string().contains("user.custom"), "{err}");
    }

    #[test]
    fn builders_replace_only_their_part() {
        let base = LearnConfig::from_toml_str(DEFAULT).unwrap();
        let cell = CellChoice {
            speed_case: "arterial-slow".to_owned(),
            headway_m: 35.0,
            seed: 9,
        };
        let user = UserConfig::preset(StylePreset::Cautious);
        let built = (base.clone())
            .with_cell(cell.clone())
            .with_user(user.clone())
            .with_method(Method::Paper);
        assert_eq!(built.cell, cell);
        assert_eq!(built.user, user);
        assert_eq!(built.method, Method::Paper);
        let restored = (built.clone())
            .with_cell(base.cell.clone())
            .with_user(base.user.clone())
            .with_method(base.method);
        assert_eq!(restored, base);
        assert_eq!(built.label(), "arterial-slow / 35 m / seed 9 / cautious");
        built.validate().unwrap();
        assert_eq!(built.cell().unwrap().adjacent_headway, 35.0);
    }
}
