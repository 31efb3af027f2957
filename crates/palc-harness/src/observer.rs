//! What the loop tells its observers (progress bars, printers, recorders, the
//! evaluation's traces): every lane change, what each lesson produced, and the
//! summary at the end. The loop knows them only through [`Observer`].

use palc_aggregator::{AggregatorError, Lesson, Onset, StepOutcome};

use crate::driver::DriverEstimate;
use crate::onset::GapAcceptanceSet;

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
        /// What the experience now knows of the driver's start, this lesson's included.
        driver: DriverEvidence<'a>,
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
        /// What the experience knows of the driver's start (unchanged by this lesson).
        driver: DriverEvidence<'a>,
    },
}

/// The starts an experience has observed, one per scene, each with what the
/// driver saw at every step: the evidence [`DriverEstimate`] reads. The estimate
/// is computed when asked ([`LessonEvent::driver_estimate`]), so an observer that
/// does not ask pays nothing.
#[derive(Debug, Clone, Copy)]
pub struct DriverEvidence<'a> {
    /// The experience's onsets, oldest first.
    pub onsets: &'a [Onset],
    /// The lane change's duration (s) a start must keep the safety layer's
    /// distance for (the standard ALC's).
    pub lane_change_duration_s: f64,
}

impl DriverEvidence<'_> {
    /// What palc believes about the driver's start after these observations;
    /// `None` before any onset recorded its scene.
    pub fn estimate(&self) -> Option<DriverEstimate> {
        DriverEstimate::from_onsets(self.onsets, self.lane_change_duration_s)
    }

    /// The gap-acceptance drivers these observations allow, from which a start
    /// on the cues it reads is carried ([`GapAcceptanceSet`]); `None` before any
    /// onset.
    pub fn gap_acceptance(&self) -> Option<GapAcceptanceSet> {
        GapAcceptanceSet::from_onsets(self.onsets)
    }
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

    /// What palc believes about the driver after this lesson (the posterior over
    /// start models, [`DriverEstimate`]); `None` before any onset recorded its
    /// scene. Computed on each call.
    pub fn driver_estimate(&self) -> Option<DriverEstimate> {
        match self {
            LessonEvent::Learned { driver, .. } | LessonEvent::Failed { driver, .. } => {
                driver.estimate()
            }
        }
    }

    /// The gap-acceptance drivers the onsets allow after this lesson
    /// ([`GapAcceptanceSet`]); `None` before any onset. Computed on each call.
    pub fn gap_acceptance(&self) -> Option<GapAcceptanceSet> {
        match self {
            LessonEvent::Learned { driver, .. } | LessonEvent::Failed { driver, .. } => {
                driver.gap_acceptance()
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
