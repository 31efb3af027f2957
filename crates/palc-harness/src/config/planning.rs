//! The planning set-up's parameters (`[planning]`): the step, the trigger, the
//! horizon's margin, the search window, the standard ALC, the takeover
//! threshold, and the tables of the ACC, the safety layer and closed loop.

use serde::{Deserialize, Serialize};

use crate::HarnessError;
use crate::acc::AccConfig;
use crate::config::closed_loop::ClosedLoopConfig;
use crate::error::invalid;
use crate::safety::SafetyConfig;
use palc_user::Style;

/// Parameters of the planning set-up; defaults in `configs/learn.toml`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PlanningConfig {
    /// Step of the plan and of the simulation (s).
    pub dt: f64,
    /// Time headway to the preceding vehicle at which planning starts (s); must be
    /// larger than every user's, so that planning starts before any user would.
    pub trigger_time_headway_s: f64,
    /// Time after the standard ALC's end that the horizon still covers (s).
    pub horizon_margin_s: f64,
    /// Longest approach before the trigger (s); a scenario that never triggers is refused.
    pub max_approach_s: f64,
    /// How far after the trigger users' starts are searched (s).
    pub search_window_s: f64,
    /// The standard ALC before learning: conservative, later and slower than every style.
    pub standard_alc: Style,
    /// The standard ALC starts no earlier than this long after the latest of the
    /// paper's three styles (s): a conservative system waits until every style would
    /// have gone, also when a user's start is set by a gap on the target lane.
    /// With `safety.enforce`, it also waits until both target-lane gaps stay at least
    /// the safe distance over its whole lane change, as predicted with the ego
    /// keeping its lane.
    pub standard_alc_min_delay_s: f64,
    /// Lateral position of the target lane's centre (m).
    pub target_l: f64,
    /// Deviation beyond which the user takes over (m); the paper's 0.3 m.
    pub takeover_threshold_m: f64,
    /// The ego's ACC whenever no lane-change plan drives it (the approach, the
    /// lane-keeping prediction, the user after a takeover).
    pub acc: AccConfig,
    /// The safe distance of the safety layer and of the safety measures.
    pub safety: SafetyConfig,
    /// Closed-loop execution: re-planning while the lane change is driven.
    pub closed_loop: ClosedLoopConfig,
}

impl Default for PlanningConfig {
    fn default() -> Self {
        Self {
            dt: 0.1,
            trigger_time_headway_s: 2.2,
            horizon_margin_s: 1.0,
            max_approach_s: 60.0,
            search_window_s: 60.0,
            standard_alc: Style {
                time_headway_s: 1.0,
                lane_change_duration_s: 3.5,
                min_lead_gap_s: 0.8,
                min_lag_gap_s: 0.0,
            },
            standard_alc_min_delay_s: 0.5,
            target_l: 3.5,
            takeover_threshold_m: 0.3,
            acc: AccConfig::default(),
            safety: SafetyConfig::default(),
            closed_loop: ClosedLoopConfig::default(),
        }
    }
}

impl PlanningConfig {
    /// Checks every field against its bound.
    pub fn validate(&self) -> Result<(), HarnessError> {
        let positive = [
            ("planning.dt", self.dt),
            (
                "planning.trigger_time_headway_s",
                self.trigger_time_headway_s,
            ),
            ("planning.max_approach_s", self.max_approach_s),
            ("planning.search_window_s", self.search_window_s),
            ("planning.takeover_threshold_m", self.takeover_threshold_m),
        ];
        for (field, value) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err(invalid(field, value, "a finite value > 0"));
            }
        }
        // The step an experience may be stored at: a plan at another step could
        // not be saved or carried.
        let (dt_low, dt_high) = palc_aggregator::EXPERIENCE_DT_BOUNDS_S;
        if !(dt_low..=dt_high).contains(&self.dt) {
            return Err(invalid(
                "planning.dt",
                self.dt,
                &format!("a step in [{dt_low}, {dt_high}] s"),
            ));
        }
        if !(self.standard_alc_min_delay_s.is_finite() && self.standard_alc_min_delay_s >= 0.0) {
            return Err(invalid(
                "planning.standard_alc_min_delay_s",
                self.standard_alc_min_delay_s,
                "a finite value >= 0",
            ));
        }
        if !(self.horizon_margin_s.is_finite() && self.horizon_margin_s >= 0.0) {
            return Err(invalid(
                "planning.horizon_margin_s",
                self.horizon_margin_s,
                "a finite value >= 0",
            ));
        }
        if !self.target_l.is_finite() {
            return Err(invalid("planning.target_l", self.target_l, "finite"));
        }
        // Each of these becomes a number of steps of `dt` the set-up allocates and
        // walks through: bounded like a prediction (`palc_traffic::MAX_HORIZON_STEPS`).
        let longest_s = palc_traffic::MAX_HORIZON_STEPS as f64 * self.dt;
        let durations = [
            ("planning.max_approach_s", self.max_approach_s),
            ("planning.search_window_s", self.search_window_s),
            (
                "planning.standard_alc_min_delay_s",
                self.standard_alc_min_delay_s,
            ),
            ("planning.horizon_margin_s", self.horizon_margin_s),
        ];
        for (field, value) in durations {
            if value > longest_s {
                return Err(invalid(
                    field,
                    value,
                    &format!(
                        "at most {longest_s:?} s ({} steps of planning.dt)",
                        palc_traffic::MAX_HORIZON_STEPS
                    ),
                ));
            }
        }
        self.standard_alc.validate("planning.standard_alc")?;
        self.acc.validate("planning.acc")?;
        self.safety.validate("planning.safety")?;
        self.closed_loop.validate("planning.closed_loop", self.dt)
    }
}
