//! What the onsets of a user's lessons allow of a gap-acceptance driver
//! ([`GapAcceptanceSet`]), and the start they predict in a new scene
//! ([`GapAcceptanceSet::predicted_start_s`]).
//!
//! The model is the one the paper's user follows: the driver decides when one
//! cue of the vehicle ahead (time headway, time to collision or gap,
//! [`Cue`]) has fallen to a threshold, then starts
//! at the first step from there at which the target lane's leader and follower
//! are at least the time gaps it needs. Each onset is an observation of that
//! model in its scene, and the set keeps what every observation allows
//! (set membership, not a best fit):
//!
//! - the cue and the interval of its threshold (`decision.rs`): a free start at
//!   step `k` allows `θ ∈ [x(k), x(k − 1))`, and scenes together their
//!   intersection; a start a target-lane gap held back bounds the threshold from
//!   below, and the last step at which it could have started before that wait
//!   (its ceiling) from above;
//! - the gaps (`gaps.rs`): the leader's gap the driver needs, from below by
//!   every gap that held it back or that it refused after deciding, from above by
//!   the smallest it accepted; the follower's gap, from the waits for it.
//!
//! Where the scenes leave an interval, the start predicted is the one most of it
//! leads to in the new scene (`start.rs`): a uniform belief over what the
//! scenes allow, not a choice of one end. Where no cue is consistent across the
//! scenes the model does not explain them ([`GapAcceptanceSet::explains`]) and
//! the driver estimate (`crate::driver`) predicts instead.

mod decision;
mod gaps;
mod start;

use palc_aggregator::{Onset, SceneSteps};

use crate::driver::prior::Cue;

pub(crate) use decision::decision;
pub(crate) use gaps::assumed_lead_gap_s;

use decision::{DecisionRange, decision_and_reaction};
use gaps::acceptance;

/// The gap-acceptance drivers a user's onsets allow: the cue it decides on with
/// the interval of its threshold, and the target-lane gaps it needs. What the
/// carry predicts a start from for the cues it reads (`crate::carry`), printed
/// by `palc learn` after every lesson ([`crate::DriverEvidence::gap_acceptance`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GapAcceptanceSet {
    /// The cue and the thresholds of it the onsets allow.
    decision: DecisionRange,
    /// The leader's time gap (s) the driver needs at least: the smallest that
    /// held it back, or the largest it refused after deciding, but no more than
    /// the smallest it accepted.
    lead_at_least_s: f64,
    /// The smallest leader's time gap (s) the driver accepted; infinite for none.
    smallest_accepted_lead_s: f64,
    /// The follower's time gap (s) the driver needs.
    lag_s: f64,
    /// Where the free starts are no threshold of any cue without a reaction,
    /// the decision of the shortest reaction that makes them one.
    reacting: Option<DecisionRange>,
}

impl GapAcceptanceSet {
    /// What `onsets` allow; `None` without onsets.
    pub fn from_onsets(onsets: &[Onset]) -> Option<Self> {
        if onsets.is_empty() {
            return None;
        }
        // A lead gap the user refused after deciding is below the one it needs.
        let refused = (onsets.iter())
            .filter_map(|o| o.rejected_lead_time_gap_s)
            .fold(0.0, f64::max);
        let accepted = (onsets.iter())
            .filter_map(|o| o.accepted_lead_time_gap_s)
            .reduce(f64::min)
            .unwrap_or(f64::INFINITY);
        // A refused gap is read through the learned threshold (the user had
        // decided, so only the leader can have held it back), an accepted one is
        // seen: a driver who accepted a gap does not need a larger one, so a
        // refused gap above an accepted one was a misreading (the decision came
        // later than the threshold said) and bounds the need by the accepted gap
        // at most (docs/experiments/0073-a-drive-of-varied-scenes.md).
        let refused = refused.min(accepted);
        let (decision, reacting, lag_s) = decision_and_reaction(onsets);
        Some(GapAcceptanceSet {
            decision,
            lead_at_least_s: acceptance(onsets, |o| o.lead_time_gap_s).max(refused),
            smallest_accepted_lead_s: accepted,
            lag_s,
            reacting,
        })
    }

    /// Whether the threshold predicted with is one that the scenes of at least
    /// two free onsets reveal exactly (`decision::revealed_interval`): every
    /// start is a threshold of one cue crossed at a step, as a driver who
    /// decides on that cue starts. The driver estimate, whose observation error
    /// is [`OBSERVATION_SD_S`](crate::driver::prior::OBSERVATION_SD_S) (0.2 s,
    /// two steps, for starts read from noisy paths), does not place such a start
    /// to the step; the interval does.
    pub fn revealed_exactly(&self) -> bool {
        self.decision.revealed_by >= 2
    }

    /// Whether the model explains the onsets (`DecisionRange::explained`): where
    /// no cue is consistent across the scenes, the set falls back to the time
    /// headway, which the scenes contradict
    /// (docs/experiments/0095-a-wait-weighed-by-the-prior-and-readings-that-contradict-themselves.md).
    pub fn explains(&self) -> bool {
        self.decision.explained
    }

    /// The same set for a driver who starts a reaction after deciding, where
    /// two or more free starts are no threshold of any cue without one and the
    /// shortest reaction that makes them one is found (`decision::reaction_range`):
    /// its cue, the middle of the interval the starts allow after it, and the
    /// reaction. `None` otherwise.
    pub fn with_reaction(&self) -> Option<GapAcceptanceSet> {
        self.reacting.map(|decision| GapAcceptanceSet {
            decision,
            reacting: None,
            ..*self
        })
    }

    /// The reaction (s) between the decision and the earliest start: 0 but for
    /// a set [`GapAcceptanceSet::with_reaction`] gave.
    pub fn reaction_s(&self) -> f64 {
        self.decision.reaction_s
    }

    /// The cue the driver is believed to decide on.
    pub fn cue(&self) -> Cue {
        self.decision.feature
    }

    /// The thresholds of [`GapAcceptanceSet::cue`] the onsets allow, `(lowest,
    /// highest)`, in the cue's unit (s, or m for the distance gap); the two are
    /// equal where one threshold stands for the set (the middle of an interval
    /// the scenes revealed, or the largest start value seen). For the time
    /// headway the prediction also holds the lowest at the standard ALC's
    /// decision headway (the paper's premise).
    pub fn thresholds(&self) -> (f64, f64) {
        (self.decision.lowest, self.decision.highest)
    }

    /// The leader's time gap (s) the driver needs at least, from what held it
    /// back and what it refused; the prediction also assumes the standard ALC's
    /// until the driver accepted a smaller one.
    pub fn lead_gap_at_least_s(&self) -> f64 {
        self.lead_at_least_s
    }

    /// The smallest leader's time gap (s) the driver accepted; `None` for none.
    pub fn smallest_accepted_lead_gap_s(&self) -> Option<f64> {
        Some(self.smallest_accepted_lead_s).filter(|g| g.is_finite())
    }

    /// The follower's time gap (s) the driver needs (0 when no follower held it
    /// back: a follower alongside is never accepted).
    pub fn lag_gap_s(&self) -> f64 {
        self.lag_s
    }

    /// One line for a reader: the cue, its thresholds, how the scenes pinned
    /// them, and the gaps.
    pub fn describe(&self) -> String {
        let unit = if self.cue() == Cue::DistanceGap {
            "m"
        } else {
            "s"
        };
        let (lowest, highest) = self.thresholds();
        let thresholds = if lowest < highest {
            format!("from {lowest:.2} to {highest:.2} {unit} (waits bound it)")
        } else if self.revealed_exactly() {
            format!(
                "at {highest:.2} {unit} (the middle of what {} starts allow)",
                self.decision.revealed_by
            )
        } else {
            format!("at {highest:.2} {unit}")
        };
        // The leader's gap needed lies between what held the driver back or it
        // refused and the smallest it accepted.
        let lead = match self.smallest_accepted_lead_gap_s() {
            Some(accepted) => format!(
                "between {:.2} and {accepted:.2} s",
                self.lead_gap_at_least_s()
            ),
            None => format!("of {:.2} s or more", self.lead_gap_at_least_s()),
        };
        let reaction = match self.reaction_s() {
            0.0 => String::new(),
            r => format!(" {r:.1} s before starting"),
        };
        let unexplained = if self.explains() {
            ""
        } else {
            "; no cue agrees across the scenes, so the estimate predicts"
        };
        format!(
            "decides on the {} {thresholds}{reaction}, needs a leader's gap {lead} and a \
             follower's gap of {:.2} s{unexplained}",
            self.cue().name(),
            self.lag_gap_s(),
        )
    }
}

/// Whether `onset` is a start read as a wait for the follower
/// (`observed::waited_for_the_follower`): the headway it started at and the
/// follower's gap it waited for are both recorded.
fn is_follower_wait(onset: &Onset) -> bool {
    onset.follower_wait_time_headway_s.is_some() && onset.lag_time_gap_s.is_some()
}

/// The scene `onset` recorded and the step of it at which the driver started;
/// `None` without a scene, for a mean of several starts ([`Onset::merged`]: a
/// mean of starts is not a step at which the driver started), and for a start
/// at the scene's first step or past its end.
fn start_in_scene(onset: &Onset) -> Option<(&SceneSteps, usize)> {
    let scene = onset.scene.as_ref().filter(|_| onset.observations == 1)?;
    let step = (onset.time_s / scene.dt).round();
    (step >= 1.0 && step < scene.steps.len() as f64).then_some((scene, step as usize))
}

#[cfg(test)]
mod tests {
    use super::GapAcceptanceSet;
    use crate::driver::prior::Cue;
    use crate::onset::test_scenes::{onset, onset_of_a_closing_scene, onset_of_a_reacting_driver};

    fn explains(onsets: &[palc_aggregator::Onset]) -> bool {
        GapAcceptanceSet::from_onsets(onsets).unwrap().explains()
    }

    #[test]
    fn no_onset_allows_no_set() {
        assert_eq!(GapAcceptanceSet::from_onsets(&[]), None);
    }

    #[test]
    fn the_model_explains_its_onsets_while_one_cue_is_consistent() {
        // One scene, or scenes that agree on the headway or on another feature.
        assert!(explains(&[onset(1.2, 10.0, None)]));
        assert!(explains(&[onset(1.2, 10.0, None), onset(1.21, 5.0, None)]));
        assert!(explains(&[onset(1.6, 8.0, None), onset(0.8, 8.1, None)]));
        // No feature agrees across the two scenes: the headway (and the gap,
        // twenty metres a second of it here) a third apart, the time to
        // collision half.
        assert!(!explains(&[onset(1.2, 10.0, None), onset(0.8, 5.0, None)]));
        // A held-back start says nothing about consistency of free ones.
        assert!(explains(&[
            onset(1.2, 10.0, None),
            onset(0.8, 5.0, Some(0.2))
        ]));
    }

    #[test]
    fn the_set_says_what_it_allows() {
        // Two free starts of a driver at 1.2 s in scenes closing at different
        // rates: their intervals meet around the threshold.
        let (slow, fast) = (
            onset_of_a_closing_scene(20.0, 1.0, 1.2),
            onset_of_a_closing_scene(25.0, 3.0, 1.2),
        );
        let set = GapAcceptanceSet::from_onsets(&[slow, fast]).unwrap();
        assert_eq!(set.cue(), Cue::TimeHeadway);
        assert!(set.revealed_exactly() && set.explains());
        let (lowest, highest) = set.thresholds();
        assert_eq!(lowest, highest);
        assert!((highest - 1.2).abs() < 0.05, "{highest}");
        assert_eq!(set.smallest_accepted_lead_gap_s(), None);
        assert_eq!(set.lag_gap_s(), 0.0);
        let line = set.describe();
        assert!(line.contains("time-headway at 1.2"), "{line}");
        assert!(line.contains("what 2 starts allow"), "{line}");
        // Waits alone bound the headway to an interval, up to their ceiling.
        let wait = palc_aggregator::Onset {
            time_headway_ceiling_s: Some(1.5),
            accepted_lead_time_gap_s: Some(1.1),
            ..onset(0.9, 8.0, Some(0.4))
        };
        let set = GapAcceptanceSet::from_onsets(&[wait]).unwrap();
        assert_eq!(set.thresholds(), (0.9, 1.5));
        assert_eq!(set.lag_gap_s(), 0.4);
        assert_eq!(set.smallest_accepted_lead_gap_s(), Some(1.1));
        let line = set.describe();
        assert!(line.contains("from 0.90 to 1.50 s"), "{line}");
        assert!(
            line.contains("leader's gap between 0.00 and 1.10 s"),
            "{line}"
        );
        assert!(line.contains("follower's gap of 0.40 s"), "{line}");
    }

    #[test]
    fn a_set_with_a_reaction_says_so_and_starts_after_it() {
        let onsets: Vec<palc_aggregator::Onset> = [(20.0, 0.5), (30.0, 8.0), (12.0, 6.0)]
            .iter()
            .map(|&(speed, closing)| onset_of_a_reacting_driver(speed, closing, 1.3, 8))
            .collect();
        let set = GapAcceptanceSet::from_onsets(&onsets).unwrap();
        assert_eq!(set.reaction_s(), 0.0);
        assert!(!set.revealed_exactly());
        let reacting = set
            .with_reaction()
            .expect("a reaction makes them one threshold");
        assert!((reacting.reaction_s() - 0.8).abs() < 1e-9);
        assert!(reacting.revealed_exactly());
        assert!(reacting.with_reaction().is_none());
        let line = reacting.describe();
        assert!(line.contains("0.8 s before starting"), "{line}");
        // Without a reaction found, there is no such set.
        let instant = [onset_of_a_closing_scene(20.0, 1.0, 1.3)];
        assert!(
            GapAcceptanceSet::from_onsets(&instant)
                .unwrap()
                .with_reaction()
                .is_none()
        );
    }
}
