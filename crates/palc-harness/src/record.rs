//! What the loop reports: one record per lane change (with what closed loop did
//! and the compute time by part, [`Timings`]) and a summary per run.

pub use palc_aggregator::Timings;

use palc_aggregator::Experience;
use serde::{Deserialize, Serialize};

use crate::driver::CarriedBelief;
use crate::method::Method;
use crate::safety::{SafetyMetrics, Violation};
use palc_user::TakeoverCause;

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
    /// Why the user took over; the lateral deviation unless recorded otherwise.
    #[serde(default)]
    pub cause: TakeoverCause,
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
    /// Compute time of the learning step that produced this lane change's plan
    /// (zero for the first lane change, after a takeover-free one and after a
    /// failed lesson), plus the time of planning it.
    pub times: Timings,
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
    /// Safety of the steps the system drove (the plan, up to a takeover).
    pub safety: SafetyMetrics,
    /// Safety of the steps the user drove after a takeover (all `None` and zero
    /// without one): the simulated user's own choices, which no plan controls.
    pub user_safety: SafetyMetrics,
    /// Safety of the driven plan as the safety layer predicted it, driven to its end.
    pub planned_safety: SafetyMetrics,
    /// Why the safety layer refused the learned plan, if it did; the standard ALC's
    /// plan was driven instead. In closed loop, the first refusal of the lane
    /// change, at its start or at a re-plan.
    pub safety_refusal: Option<Violation>,
    /// What the closed loop did (`[planning.closed_loop]`); `None` in open loop.
    /// The planned lateral positions are then those the system drove, re-plans
    /// included.
    #[serde(default)]
    pub closed_loop: Option<ClosedLoopStats>,
    /// Why the learning step after this lane change failed, if it did, as a
    /// message for `--record` files; the experience then stays as it was.
    /// Observers see the typed error in [`crate::LessonEvent::Failed`].
    pub learning_error: Option<String>,
}

/// How a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    /// The success criterion was met.
    Personalized,
    /// The takeover cap (or, for a user with spread, the lane-change cap) was
    /// reached first.
    CapReached,
}

impl Outcome {
    /// The takeovers a run counts for in every statistic (the paper's N_lc,
    /// Section III.B): a personalized run counts its `takeovers`; a run that
    /// did not personalize counts as a failure at the `cap`, or at its own
    /// takeovers if it took over more often than that.
    pub fn counted_takeovers(self, takeovers: usize, cap: usize) -> usize {
        match self {
            Outcome::Personalized => takeovers,
            Outcome::CapReached => cap.max(takeovers),
        }
    }
}

/// The summary of one run of the loop.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunSummary {
    /// How the run ended.
    pub outcome: Outcome,
    /// Takeovers that happened in the run; see [`RunSummary::counted_takeovers`]
    /// for the number the statistics use.
    pub takeovers: usize,
    /// The takeover cap of the run (`loop.max_takeovers`).
    pub cap: usize,
    /// Lane changes driven in all.
    pub lane_changes: usize,
    /// Lessons the method could not learn from (each left the experience as it
    /// was; observers saw each as [`crate::LessonEvent::Failed`]).
    pub learning_failures: usize,
    /// Largest `|planned − expected|` of the last lane change (m).
    pub final_max_deviation_m: f64,
    /// Takeover rate over the last window of lane changes (users with spread).
    pub final_takeover_rate: f64,
    /// Takeover rate of the user's nominal trajectory against the same draws.
    pub ceiling_takeover_rate: f64,
    /// Users with spread: the lane changes driven after the run ended, learning
    /// frozen (`loop.frozen_lane_changes`); `None` for a deterministic user.
    #[serde(default)]
    pub frozen: Option<FrozenEvaluation>,
}

/// The evaluation phase of a user with spread: the plan the run ended with, driven
/// `lane_changes` more times without learning, each time against a new draw of the
/// user, and the user's nominal plan judged on the same draws (the ceiling).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct FrozenEvaluation {
    /// Lane changes driven.
    pub lane_changes: usize,
    /// Of them, taken over.
    pub takeovers: usize,
    /// Of them, those in which the user would have taken over the nominal plan.
    pub ceiling_takeovers: usize,
}

impl FrozenEvaluation {
    /// Share of the lane changes taken over.
    pub fn takeover_rate(&self) -> f64 {
        self.takeovers as f64 / self.lane_changes.max(1) as f64
    }

    /// Share of the lane changes in which the nominal plan would have been taken over.
    pub fn ceiling_rate(&self) -> f64 {
        self.ceiling_takeovers as f64 / self.lane_changes.max(1) as f64
    }
}

impl RunSummary {
    /// Takeovers before success, or the cap when the run did not personalize
    /// (the paper's N_lc; the rule of [`Outcome::counted_takeovers`]).
    pub fn counted_takeovers(&self) -> usize {
        self.outcome.counted_takeovers(self.takeovers, self.cap)
    }
}

/// What the closed loop did in one lane change (recorded as
/// [`crate::LaneChangeRecord::closed_loop`]).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct ClosedLoopStats {
    /// Re-plans solved and checked (refused ones included).
    pub replans: usize,
    /// Re-plans the planner could not solve; the ego kept its current plan.
    pub replan_failures: usize,
    /// Re-plans the safety layer refused.
    pub refusals: usize,
    /// Step from which the standard ALC's weights drove the lane change, if the
    /// safety layer fell back to them (0 when the first plan was refused).
    pub fallback_step: Option<usize>,
    /// The first refusal.
    pub first_refusal: Option<Violation>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn a_personalized_run_counts_its_takeovers_a_failed_one_the_cap() {
        assert_eq!(Outcome::Personalized.counted_takeovers(4, 30), 4);
        assert_eq!(Outcome::Personalized.counted_takeovers(0, 30), 0);
        assert_eq!(Outcome::CapReached.counted_takeovers(30, 30), 30);
        // A user with spread can stop at the lane-change cap with fewer takeovers.
        assert_eq!(Outcome::CapReached.counted_takeovers(12, 30), 30);
        assert_eq!(Outcome::CapReached.counted_takeovers(31, 30), 31);
        let summary = RunSummary {
            outcome: Outcome::CapReached,
            takeovers: 12,
            cap: 30,
            lane_changes: 60,
            learning_failures: 0,
            final_max_deviation_m: 0.5,
            final_takeover_rate: 0.2,
            ceiling_takeover_rate: 0.1,
            frozen: None,
        };
        assert_eq!(summary.counted_takeovers(), 30);
        let summary = RunSummary {
            outcome: Outcome::Personalized,
            ..summary
        };
        assert_eq!(summary.counted_takeovers(), 12);
    }

    proptest! {
        /// A run that did not personalize never counts fewer takeovers than one
        /// that did with the same takeovers, nor fewer than the cap.
        #[test]
        fn a_failure_never_counts_less_than_a_success(takeovers in 0usize..100, cap in 1usize..60) {
            let failed = Outcome::CapReached.counted_takeovers(takeovers, cap);
            prop_assert!(failed >= Outcome::Personalized.counted_takeovers(takeovers, cap));
            prop_assert!(failed >= cap);
        }
    }
}

/// Everything a run produced.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RunResult {
    /// The scenario, e.g. `collector-high / 40 m / seed 1 / neutral`.
    pub label: String,
    /// The method.
    pub method: Method,
    /// Planning horizon K of this scenario.
    pub horizon: usize,
    /// Step (s).
    pub dt: f64,
    /// How the run ended.
    pub summary: RunSummary,
    /// One record per lane change.
    pub records: Vec<LaneChangeRecord>,
    /// What was learned, to be saved or carried into another scenario.
    pub experience: Experience,
    /// What the driver estimate believed when the experience this run started
    /// from was carried in: `None` from scratch, for a method that carries in
    /// the weights' own time base, and below two recorded scenes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub carried_belief: Option<CarriedBelief>,
}
