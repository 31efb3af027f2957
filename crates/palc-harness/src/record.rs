//! What the loop reports: one record per lane change and a summary per run.

use serde::{Deserialize, Serialize};

/// Compute time of one iteration, split by part (seconds).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct PartTimes {
    /// Updating the zone model with the lesson's samples.
    pub zone_fit_s: f64,
    /// Projecting the zone onto lateral bounds.
    pub bounds_s: f64,
    /// Planning the expert trajectory.
    pub expert_s: f64,
    /// Correcting the weights (including its inner solves).
    pub correction_s: f64,
    /// Planning the next lane change.
    pub plan_s: f64,
}

impl PartTimes {
    /// The sum of all parts.
    pub fn total_s(&self) -> f64 {
        self.zone_fit_s + self.bounds_s + self.expert_s + self.correction_s + self.plan_s
    }
}

/// Where and how the user took over.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Takeover {
    /// Planning step of the takeover.
    pub step: usize,
    /// Time from the start of the plan (s).
    pub time_s: f64,
    /// Longitudinal distance from the start of the plan (m).
    pub distance_m: f64,
    /// `|planned − expected|` at the takeover (m).
    pub deviation_m: f64,
}

/// One lane change of the loop.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LaneChangeRecord {
    /// 0-based index of the lane change in the run.
    pub index: usize,
    /// Number of takeovers before this lane change.
    pub takeovers_before: usize,
    /// The takeover, if the user took over.
    pub takeover: Option<Takeover>,
    /// Largest `|planned − expected|` over the whole plan (m).
    pub max_deviation_m: f64,
    /// Perceived safety distance ratio (paper, Section III.A): distance covered
    /// before the takeover over the distance of the whole lane change; 1 without takeover.
    pub perceived_safety_ratio: f64,
    /// Compute time of the learning step that followed (zero without takeover),
    /// plus the time of planning this lane change.
    pub times: PartTimes,
    /// Step of the plan (s).
    pub dt: f64,
    /// Planned lateral positions, steps `0..=K` (m).
    pub planned_l: Vec<f64>,
    /// Lateral positions the user expected (m).
    pub expected_l: Vec<f64>,
    /// Lateral positions driven: the plan up to the takeover, the user after (m).
    pub driven_l: Vec<f64>,
    /// Whether the user's parameters in this lane change were drawn with spread.
    pub with_spread: bool,
    /// Whether the user's *nominal* trajectory, used as the plan, would have been
    /// taken over against this lane change's draw (the ceiling of a user with spread).
    pub nominal_plan_taken_over: bool,
    /// Why the learning step after this lane change failed, if it did; the
    /// experience then stays as it was.
    pub learning_error: Option<String>,
}

/// How a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    /// The success criterion was met.
    Personalized,
    /// The takeover cap was reached first.
    CapReached,
}

/// The summary of one run of the loop.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunSummary {
    /// How the run ended.
    pub outcome: Outcome,
    /// Takeovers before success, or the cap when it was reached (paper's N_lc).
    pub takeovers: usize,
    /// Lane changes driven in all.
    pub lane_changes: usize,
    /// Largest `|planned − expected|` of the last lane change (m).
    pub final_max_deviation_m: f64,
    /// Takeover rate over the last window of lane changes (users with spread).
    pub final_takeover_rate: f64,
    /// Takeover rate of the user's nominal trajectory against the same draws.
    pub ceiling_takeover_rate: f64,
}
