//! Scenario configs as read from TOML.
//!
//! Every field name carries its unit (`_m`, `_s`, `_mph`, `_mps2`); a field in another unit
//! is an unknown field and is refused (`deny_unknown_fields`). Speeds are given in mph, as in
//! the paper, and converted to SI when a scene is built.

use crate::error::ConfigError;
use crate::idm::{DesiredGap, IdmParams};
use crate::road::Road;
use crate::validate::{in_range, non_negative, out_of_range, positive};
use serde::{Deserialize, Serialize};

/// Parses TOML text; an error names the dotted path of the field it is in (e.g.
/// `road.lanes`) besides the line and column that `toml` reports.
fn from_toml<'de, T: Deserialize<'de>>(text: &'de str) -> Result<T, ConfigError> {
    parse_toml(text).map_err(|TomlParseError { path, error }| ConfigError::Toml { path, error })
}

/// A TOML parse error and the dotted path of the field it is in.
#[derive(Debug)]
pub struct TomlParseError {
    /// Dotted path of the field (`a.b[2].c`); empty for a syntax error, which has no field.
    pub path: String,
    /// The parse error, with its line and column.
    pub error: Box<toml::de::Error>,
}

/// Parses TOML text into `T`, keeping the path of the field an error is in: the one
/// TOML reader of every config of palc (scenario, learning and evaluation configs),
/// each of which maps the error into its own type.
pub fn parse_toml<'de, T: Deserialize<'de>>(text: &'de str) -> Result<T, TomlParseError> {
    let deserializer = toml::de::Deserializer::parse(text).map_err(|source| TomlParseError {
        path: String::new(),
        error: Box::new(source),
    })?;
    serde_path_to_error::deserialize(deserializer).map_err(|error| TomlParseError {
        path: field_path(error.path()),
        error: Box::new(error.into_inner()),
    })
}

/// The dotted path of a field (`a.b[2].c`), or an empty string when nothing of it is known.
fn field_path(path: &serde_path_to_error::Path) -> String {
    if path
        .iter()
        .all(|segment| matches!(segment, serde_path_to_error::Segment::Unknown))
    {
        String::new()
    } else {
        path.to_string()
    }
}

/// A whole scenario config: road, vehicles, IDM and exactly one of `testbed` or `platoon`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScenarioConfig {
    /// The road section.
    #[serde(default)]
    pub road: RoadConfig,
    /// Vehicle dimensions, shared by all vehicles.
    #[serde(default)]
    pub vehicle: VehicleConfig,
    /// IDM parameters of the background vehicles (the desired speed comes from the scenario).
    #[serde(default)]
    pub idm: IdmConfig,
    /// The paper's test bed and its grid of cells.
    pub testbed: Option<TestbedConfig>,
    /// A platoon on one lane behind a scripted leader.
    pub platoon: Option<PlatoonConfig>,
}

/// `[road]`: the road section.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RoadConfig {
    /// Length of the section where vehicles are placed at the start (m); the paper's 200 m.
    pub length_m: f64,
    /// Lane width (m); the paper's 3.5 m.
    pub lane_width_m: f64,
    /// Number of lanes.
    pub lanes: u32,
}

impl Default for RoadConfig {
    fn default() -> Self {
        RoadConfig {
            length_m: 200.0,
            lane_width_m: 3.5,
            lanes: 2,
        }
    }
}

/// `[vehicle]`: dimensions of every vehicle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct VehicleConfig {
    /// Length (m); 5 m as in Treiber et al. (2000).
    pub length_m: f64,
    /// Width (m), used by the lateral occupancy rule.
    pub width_m: f64,
}

impl Default for VehicleConfig {
    fn default() -> Self {
        VehicleConfig {
            length_m: 5.0,
            width_m: 1.8,
        }
    }
}

/// `[idm]`: IDM parameters except the desired speed, with Treiber et al. (2000) as defaults.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct IdmConfig {
    /// T, desired time gap (s).
    pub t_s: f64,
    /// s0, minimum net gap (m).
    pub s0_m: f64,
    /// a, maximum acceleration (m/s^2).
    pub a_mps2: f64,
    /// b, comfortable deceleration (m/s^2), positive.
    pub b_mps2: f64,
    /// delta, acceleration exponent.
    pub delta: f64,
    /// Physical braking limit that clips the IDM's deceleration (m/s^2), positive.
    pub max_braking_mps2: f64,
    /// Test bed only: desired speed of target-lane followers as a multiple of the background
    /// speed, above 1 so that a finite gap can hold the background speed.
    pub desired_speed_ratio: f64,
    /// The form of the desired gap `s*`: `"clamped"` (default, SUMO's convention, used by
    /// the test bed) or `"treiber2000"` (the formula as printed); see [`DesiredGap`].
    pub desired_gap: DesiredGap,
}

impl Default for IdmConfig {
    fn default() -> Self {
        let p = IdmParams::treiber_2000(1.0);
        IdmConfig {
            t_s: p.t,
            s0_m: p.s0,
            a_mps2: p.a,
            b_mps2: p.b,
            delta: p.delta,
            max_braking_mps2: 9.0,
            desired_speed_ratio: 1.2,
            desired_gap: DesiredGap::Clamped,
        }
    }
}

impl IdmConfig {
    /// The IDM parameters with desired speed `v0` (m/s).
    pub fn params(&self, v0: f64) -> IdmParams {
        IdmParams {
            v0,
            t: self.t_s,
            s0: self.s0_m,
            a: self.a_mps2,
            b: self.b_mps2,
            delta: self.delta,
            desired_gap: self.desired_gap,
        }
    }
}

/// `[testbed]`: the paper's test bed (Section III.A) and its grid of cells.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TestbedConfig {
    /// Front position of the ego at the start (m).
    #[serde(default = "default_ego_start")]
    pub ego_start_s_m: f64,
    /// Initial time headway of the ego to the preceding vehicle, front to front over the ego speed (s).
    #[serde(default = "default_initial_time_headway")]
    pub initial_time_headway_s: f64,
    /// Range of the adjacent vehicle's initial lead over the ego, as a fraction of the adjacent
    /// headway, `[min, max]` within `[0, 1]`; the seed draws the value.
    #[serde(default = "default_adjacent_phase")]
    pub adjacent_phase: [f64; 2],
    /// Half-width of the uniform jitter added to every background vehicle's initial position (m).
    #[serde(default = "default_jitter")]
    pub position_jitter_m: f64,
    /// Front-to-front headway of a background vehicle behind the ego on lane 0 (m); none if absent.
    pub follower_headway_m: Option<f64>,
    /// The speed cases (paper: 45/40, 45/35, 65/60, 65/55 mph).
    pub speed_cases: Vec<SpeedCaseConfig>,
    /// Front-to-front headways on the target lane (m) (paper: 50, 45, 40, 35, 30).
    pub adjacent_headways_m: Vec<f64>,
    /// Seeds; each cell of the grid is one (speed case, headway, seed).
    pub seeds: Vec<u64>,
    /// A stress scene: the preceding vehicle brakes hard during the approach instead
    /// of following the IDM. None (the paper's test bed) if absent.
    #[serde(default)]
    pub preceding_braking: Option<PrecedingBrakingConfig>,
    /// A stress scene: the target lane's lag vehicle accelerates into the gap when
    /// the ego starts its lane change. None (the paper's test bed) if absent.
    #[serde(default)]
    pub lag_accelerating: Option<LagAcceleratingConfig>,
}

/// `[testbed.preceding_braking]`: the preceding vehicle holds the background speed,
/// then brakes at a constant deceleration down to a fraction of it, and holds that.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PrecedingBrakingConfig {
    /// Time from the start of the scene at which the braking starts (s).
    pub start_s: f64,
    /// Deceleration (m/s^2), e.g. 4 for a hard brake.
    pub deceleration_mps2: f64,
    /// Speed after braking, as a fraction of the background speed, in [0, 1).
    pub final_speed_ratio: f64,
}

/// Largest `testbed.lag_accelerating.acceleration_mps2` (m/s^2): a hard
/// acceleration of a passenger car.
pub const MAX_LAG_ACCELERATION_MPS2: f64 = 6.0;

/// `[testbed.lag_accelerating]`: the target lane's lag vehicle accelerates into the
/// gap when the ego starts its lane change.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LagAcceleratingConfig {
    /// The ego's lateral offset from the centre of its start lane, towards the
    /// target lane, at which the lag vehicle starts accelerating (m), in (0, lane width].
    pub trigger_lateral_m: f64,
    /// The lag vehicle's maximum acceleration after the trigger (m/s^2), in
    /// \[0.1, [`MAX_LAG_ACCELERATION_MPS2`]\].
    pub acceleration_mps2: f64,
    /// The lag vehicle's desired speed after the trigger, as a multiple of its speed
    /// at the trigger, in (1, 2].
    pub speed_ratio: f64,
}

impl LagAcceleratingConfig {
    /// Checks every field against its bound; `lane_width` is the road's (m).
    ///
    /// # Errors
    /// [`ConfigError::OutOfRange`] naming `testbed.lag_accelerating.<field>`.
    pub fn validate(&self, lane_width: f64) -> Result<(), ConfigError> {
        let field = |name: &str| format!("testbed.lag_accelerating.{name}");
        let trigger = self.trigger_lateral_m;
        if !(trigger > 0.0 && trigger <= lane_width) {
            return Err(out_of_range(
                &field("trigger_lateral_m"),
                trigger,
                &format!("in (0, {lane_width:?}] m, within one lane width"),
            ));
        }
        in_range(
            &field("acceleration_mps2"),
            self.acceleration_mps2,
            0.1,
            MAX_LAG_ACCELERATION_MPS2,
            &format!("in [0.1, {MAX_LAG_ACCELERATION_MPS2:?}] m/s^2"),
        )?;
        let ratio = self.speed_ratio;
        if !(ratio > 1.0 && ratio <= 2.0) {
            return Err(out_of_range(&field("speed_ratio"), ratio, "in (1, 2]"));
        }
        Ok(())
    }
}

fn default_ego_start() -> f64 {
    50.0
}
fn default_initial_time_headway() -> f64 {
    3.0
}
fn default_adjacent_phase() -> [f64; 2] {
    [0.2, 0.8]
}
fn default_jitter() -> f64 {
    0.5
}

/// One speed case of the test bed, in mph as in the paper.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpeedCaseConfig {
    /// Name used in reports, e.g. `collector-high`.
    pub name: String,
    /// Ego speed (mph).
    pub ego_mph: f64,
    /// Speed of the surrounding vehicles (mph).
    pub others_mph: f64,
}

/// `[platoon]`: vehicles on one lane behind a scripted leader, the usual way to compare IDM
/// implementations.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlatoonConfig {
    /// Number of vehicles including the leader.
    pub vehicles: u32,
    /// Lane of the platoon.
    #[serde(default)]
    pub lane: u32,
    /// Front position of the leader at the start (m).
    pub leader_start_s_m: f64,
    /// Front-to-front headway between consecutive vehicles at the start (m).
    pub headway_m: f64,
    /// Initial speed of the followers (mph); the leader starts at its profile's speed.
    pub initial_speed_mph: f64,
    /// IDM desired speed v0 of the followers (mph).
    pub desired_speed_mph: f64,
    /// The leader's speed profile: piecewise linear between points, constant outside.
    pub leader_profile: Vec<ProfilePointConfig>,
    /// Per-follower initial states, front to back (`[[platoon.followers]]`): empty (the
    /// default) places every follower `headway_m` behind the vehicle ahead at
    /// `initial_speed_mph`; otherwise exactly `vehicles - 1` entries, each overriding both,
    /// so that a platoon can start away from equilibrium.
    #[serde(default)]
    pub followers: Vec<FollowerConfig>,
}

/// The initial state of one platoon follower.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FollowerConfig {
    /// Front-to-front headway to the vehicle ahead at the start (m), positive.
    pub headway_m: f64,
    /// Initial speed (mph), at most the platoon's `desired_speed_mph`.
    pub speed_mph: f64,
}

/// One point of a scripted speed profile.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProfilePointConfig {
    /// Time (s).
    pub time_s: f64,
    /// Speed (mph).
    pub speed_mph: f64,
}

impl ScenarioConfig {
    /// Parses a TOML config and validates the parts that do not depend on a grid cell.
    pub fn from_toml_str(text: &str) -> Result<ScenarioConfig, ConfigError> {
        let config: ScenarioConfig = from_toml(text)?;
        config.validate()?;
        Ok(config)
    }

    /// Checks the road, vehicle and IDM tables and that exactly one scenario is given.
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.road()?;
        positive("vehicle.length_m", self.vehicle.length_m)?;
        positive("vehicle.width_m", self.vehicle.width_m)?;
        // A vehicle wider than its lane touches the next one from any position.
        if self.vehicle.width_m > self.road.lane_width_m {
            return Err(out_of_range(
                "vehicle.width_m",
                self.vehicle.width_m,
                &format!(
                    "at most `road.lane_width_m` = {:?} m, to fit its lane",
                    self.road.lane_width_m
                ),
            ));
        }
        let idm = &self.idm;
        positive("idm.t_s", idm.t_s)?;
        non_negative("idm.s0_m", idm.s0_m)?;
        positive("idm.a_mps2", idm.a_mps2)?;
        positive("idm.b_mps2", idm.b_mps2)?;
        positive("idm.delta", idm.delta)?;
        in_range(
            "idm.max_braking_mps2",
            idm.max_braking_mps2,
            idm.b_mps2,
            f64::INFINITY,
            "at least idm.b_mps2",
        )?;
        if !(idm.desired_speed_ratio > 1.0 && idm.desired_speed_ratio.is_finite()) {
            return Err(out_of_range(
                "idm.desired_speed_ratio",
                idm.desired_speed_ratio,
                "above 1",
            ));
        }
        if let Some(testbed) = &self.testbed {
            for (i, case) in testbed.speed_cases.iter().enumerate() {
                if let Some(first) =
                    (testbed.speed_cases[..i].iter()).position(|c| c.name == case.name)
                {
                    return Err(ConfigError::DuplicateName {
                        field: format!("testbed.speed_cases[{i}].name"),
                        name: case.name.clone(),
                        first: format!("testbed.speed_cases[{first}]"),
                    });
                }
            }
        }
        if let Some(lag) = self.testbed.as_ref().and_then(|t| t.lag_accelerating) {
            lag.validate(self.road.lane_width_m)?;
        }
        match (&self.testbed, &self.platoon) {
            (None, None) => Err(ConfigError::ScenarioKind { found: "neither" }),
            (Some(_), Some(_)) => Err(ConfigError::ScenarioKind { found: "both" }),
            _ => Ok(()),
        }
    }

    /// The road of this config, validated.
    pub fn road(&self) -> Result<Road, ConfigError> {
        let r = &self.road;
        positive("road.length_m", r.length_m)?;
        positive("road.lane_width_m", r.lane_width_m)?;
        if r.lanes == 0 || r.lanes > crate::road::MAX_LANES {
            let bound = format!("in [1, {}]", crate::road::MAX_LANES);
            return Err(out_of_range("road.lanes", f64::from(r.lanes), &bound));
        }
        Ok(Road {
            length: r.length_m,
            lane_width: r.lane_width_m,
            lanes: r.lanes,
        })
    }
}
