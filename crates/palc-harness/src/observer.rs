//! What the loop tells its observers (progress bars, printers, recorders, the
//! evaluation's traces): every lane change, what each lesson produced, and the
//! summary at the end. The loop knows them only through [`Observer`].

use palc_aggregator::{AggregatorError, Lesson, StepOutcome};

use crate::record::{LaneChangeRecord, RunSummary};
use crate::safety::Violation;

/// What one lesson produced (paper Fig. 2, the learning branch after a takeover).
#[derive(Debug, Clone, Copy)]
pub enum LessonEvent<'a> {
    /// The aggregator learned from the lesson: `outcome` holds the expert
    /// trajectory `ψ^E` (Eqs. 24-26 or the lesson expert), the zone's lateral bounds
    /// (Eqs. 27-32, when the zone is used), the correction report (Eqs. 33-36 or
    /// the incremental rule), the timings of each part and the next plan `ψ^(t)`.
    Learned {
        /// Index of the taken-over lane change the lesson came from.
        lane_change: usize,
        /// The lesson: the plan, what was driven, the takeover step and the labelled samples.
        lesson: &'a Lesson,
        /// What the learning step produced.
        outcome: &'a StepOutcome,
    },
    /// The method could not learn from the lesson (e.g. the paper's zone-centre
    /// expert infeasible in a hard zone); the experience stays as it was and the
    /// next lane change repeats the plan.
    Failed {
        /// Index of the taken-over lane change the lesson came from.
        lane_change: usize,
        /// The lesson the method could not learn from.
        lesson: &'a Lesson,
        /// Why the learning step failed.
        error: &'a AggregatorError,
    },
}

impl LessonEvent<'_> {
    /// Index of the taken-over lane change the lesson came from.
    pub fn lane_change(&self) -> usize {
        match *self {
            LessonEvent::Learned { lane_change, .. } | LessonEvent::Failed { lane_change, .. } => {
                lane_change
            }
        }
    }

    /// Whether the method learned from the lesson.
    pub fn is_learned(&self) -> bool {
        matches!(self, LessonEvent::Learned { .. })
    }
}

/// Watches the loop; every method has a default that does nothing.
///
/// For each lane change the loop calls [`Observer::lane_change`]; when that lane
/// change was taken over and the takeover cap is not reached, it then calls
/// [`Observer::lesson`] once, learned or failed. [`Observer::finished`] comes once,
/// after the last lane change.
pub trait Observer {
    /// Called before lane change `lane_change` when the safety layer refuses the
    /// learned plan (the standard ALC's plan is driven instead); the record of the
    /// lane change keeps the violation too.
    fn safety_refusal(&mut self, _lane_change: usize, _violation: &Violation) {}
    /// Called after each lane change, before its lesson (if any) is learned.
    fn lane_change(&mut self, _record: &LaneChangeRecord) {}
    /// Called after each lesson, whether the method learned from it or not.
    fn lesson(&mut self, _event: &LessonEvent<'_>) {}
    /// Called once when the run ends.
    fn finished(&mut self, _summary: &RunSummary) {}
}

/// An observer that watches nothing.
#[derive(Debug, Default, Clone, Copy)]
pub struct NoObserver;

impl Observer for NoObserver {}
