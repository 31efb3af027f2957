//! Where a user starts to change lanes, in the relative space the user sees: the
//! anchor that carries a learned lane change from one scene into another.
//!
//! The weights of an [`crate::Experience`] are indexed by time since the start of
//! the plan. What a user does once the lane change has started (its lateral
//! profile) does not depend on the scene; *when* it starts does, through what the
//! user sees: the time headway, time to collision and gap to the vehicle ahead,
//! and the gaps on the target lane. An [`Onset`] records that relative state at
//! the user's observed start, so that a new scene can find the moment it recurs
//! and shift the weights there ([`crate::resample_weights_shifted`]).

use serde::{Deserialize, Serialize};

use crate::AggregatorError;

/// The relative state at a user's start of a lane change, observed in one scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Onset {
    /// The scene it was observed in (free text, e.g. `collector-high / 40 m`).
    pub scenario: String,
    /// Time of the start after the start of that scene's plan (s).
    pub time_s: f64,
    /// Time headway to the preceding vehicle: net gap over ego speed (s).
    pub time_headway_s: f64,
    /// Time to collision with the preceding vehicle (s); `None` when not closing.
    pub ttc_s: Option<f64>,
    /// Net gap to the preceding vehicle (m).
    pub gap_m: f64,
    /// Net gap to the target lane's leader over the ego speed (s), when that gap
    /// held the user back: the leader was alongside or absent at an earlier step
    /// of the plan, so the user waited for this gap. `None` otherwise.
    pub lead_time_gap_s: Option<f64>,
    /// Net gap to the target lane's follower over the follower's speed (s), when
    /// that gap held the user back (as `lead_time_gap_s`). `None` otherwise.
    pub lag_time_gap_s: Option<f64>,
    /// The largest net gap to the target lane's leader over the ego speed (s) that
    /// the user refused in this scene after it had decided to change lanes: a step
    /// before the start at which the decision feature had fallen to its threshold
    /// (as learned from the onsets before and this one) and the follower's gap was
    /// at least the one accepted at the start, so that only the leader's gap can
    /// have held the user back. A lower bound on the lead gap the user needs (the
    /// largest rejected gap of gap-acceptance models). `None` when no such step.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rejected_lead_time_gap_s: Option<f64>,
    /// The time headway (s) at the last step before the target lane's follower
    /// came alongside at which the target-lane gaps were open (as far as the
    /// observer can tell), when that follower held the user back
    /// (`lag_time_gap_s` set): the user had not started there, so, if nothing
    /// else held it back, its decision threshold is below this value. When the
    /// gaps were never open before the follower came, the headway at the step
    /// just before it came (the earliest start the wait allows). `None`
    /// otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_headway_ceiling_s: Option<f64>,
    /// The net gap to the target lane's leader over the ego speed (s) at the start
    /// itself, whether or not it held the user back: the user accepted it, so the
    /// lead gap it needs is at most this (the accepted gap of gap-acceptance
    /// models). `None` without a leader at the start.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub accepted_lead_time_gap_s: Option<f64>,
    /// The time headway (s) at the start itself when the start was read as a
    /// wait for the target lane's follower (a start below the standard ALC's
    /// decision headway with the follower's gap opening into it): `time_headway_s`
    /// is then raised to the standard ALC's decision headway and `lag_time_gap_s`
    /// holds the follower's gap. Kept so that the start can be read again as the
    /// user's decision when another scene shows the user accepting a smaller
    /// follower gap. `None` otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub follower_wait_time_headway_s: Option<f64>,
    /// Lessons this onset is the mean of.
    pub observations: u64,
    /// What the driver saw at every step of the scene (the ego keeping its
    /// lane), so that a model of the decision is checked at every step, the
    /// steps at which the driver did not start as much as its start. `None` in
    /// files written before it was recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scene: Option<SceneSteps>,
}

/// What a driver saw at each step of one scene, as plain numbers: the vehicle
/// ahead on its own lane and the nearest vehicles ahead and behind on the target
/// lane (palc-user's `Situation`, step by step).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSteps {
    /// Step (s).
    pub dt: f64,
    /// The ego's set speed (m/s).
    pub set_speed_mps: f64,
    /// One entry per step, from the start of the plan.
    pub steps: Vec<SeenStep>,
}

/// What a driver saw at one step. Gaps are net (bumper to bumper) in metres; a
/// missing vehicle is `None`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeenStep {
    /// Ego speed (m/s).
    pub ego_speed: f64,
    /// The vehicle ahead on the ego's lane: `(gap, speed)`.
    pub preceding: Option<(f64, f64)>,
    /// The target lane's leader: `(gap, speed)`.
    pub target_lead: Option<(f64, f64)>,
    /// The target lane's follower: `(gap, speed)`; a negative gap while alongside.
    pub target_lag: Option<(f64, f64)>,
    /// Under the safety layer: whether both target-lane gaps were at the safe
    /// distance. `None` without the layer.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub safe: Option<bool>,
}

impl SceneSteps {
    fn validate(&self, index: usize) -> Result<(), AggregatorError> {
        let field = |name: String| format!("onsets[{index}].scene.{name}");
        for (name, value) in [("dt", self.dt), ("set_speed_mps", self.set_speed_mps)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(AggregatorError::NonFinite {
                    field: field(name.to_owned()),
                    value,
                });
            }
        }
        for (i, step) in self.steps.iter().enumerate() {
            let pairs = [
                ("preceding", step.preceding),
                ("target_lead", step.target_lead),
                ("target_lag", step.target_lag),
            ];
            let values = pairs
                .iter()
                .flat_map(|&(name, pair)| pair.map(|(gap, speed)| [(name, gap), (name, speed)]))
                .flatten()
                .chain(std::iter::once(("ego_speed", step.ego_speed)));
            for (name, value) in values {
                if !value.is_finite() {
                    return Err(AggregatorError::NonFinite {
                        field: field(format!("steps[{i}].{name}")),
                        value,
                    });
                }
            }
        }
        Ok(())
    }
}

impl Onset {
    /// Checks that every value is finite (the time also non-negative), naming the
    /// field of the first that is not.
    pub fn validate(&self, index: usize) -> Result<(), AggregatorError> {
        let values = [
            ("time_s", Some(self.time_s)),
            ("time_headway_s", Some(self.time_headway_s)),
            ("ttc_s", self.ttc_s),
            ("gap_m", Some(self.gap_m)),
            ("lead_time_gap_s", self.lead_time_gap_s),
            ("lag_time_gap_s", self.lag_time_gap_s),
            ("rejected_lead_time_gap_s", self.rejected_lead_time_gap_s),
            ("time_headway_ceiling_s", self.time_headway_ceiling_s),
            ("accepted_lead_time_gap_s", self.accepted_lead_time_gap_s),
            (
                "follower_wait_time_headway_s",
                self.follower_wait_time_headway_s,
            ),
        ];
        for (name, value) in values {
            if let Some(x) = value {
                if !x.is_finite() || (name == "time_s" && x < 0.0) {
                    return Err(AggregatorError::NonFinite {
                        field: format!("onsets[{index}].{name}"),
                        value: x,
                    });
                }
            }
        }
        self.scene
            .as_ref()
            .map_or(Ok(()), |scene| scene.validate(index))
    }

    /// The running mean of this onset and `other`, observed in the same scene:
    /// each value weighted by its number of observations (an option present in
    /// only one of the two is kept), except the refused lead gap, the larger of
    /// the two (both are lower bounds), and the accepted lead gap, the smaller (both
    /// are upper bounds).
    pub fn merged(&self, other: &Onset) -> Onset {
        let (a, b) = (self.observations as f64, other.observations as f64);
        let n = (a + b).max(1.0);
        let mean = |x: f64, y: f64| (a * x + b * y) / n;
        let option = |x: Option<f64>, y: Option<f64>| match (x, y) {
            (Some(x), Some(y)) => Some(mean(x, y)),
            (x, y) => x.or(y),
        };
        Onset {
            scenario: other.scenario.clone(),
            time_s: mean(self.time_s, other.time_s),
            time_headway_s: mean(self.time_headway_s, other.time_headway_s),
            ttc_s: option(self.ttc_s, other.ttc_s),
            gap_m: mean(self.gap_m, other.gap_m),
            lead_time_gap_s: option(self.lead_time_gap_s, other.lead_time_gap_s),
            lag_time_gap_s: option(self.lag_time_gap_s, other.lag_time_gap_s),
            rejected_lead_time_gap_s: match (
                self.rejected_lead_time_gap_s,
                other.rejected_lead_time_gap_s,
            ) {
                (Some(x), Some(y)) => Some(x.max(y)),
                (x, y) => x.or(y),
            },
            time_headway_ceiling_s: option(
                self.time_headway_ceiling_s,
                other.time_headway_ceiling_s,
            ),
            accepted_lead_time_gap_s: match (
                self.accepted_lead_time_gap_s,
                other.accepted_lead_time_gap_s,
            ) {
                (Some(x), Some(y)) => Some(x.min(y)),
                (x, y) => x.or(y),
            },
            follower_wait_time_headway_s: option(
                self.follower_wait_time_headway_s,
                other.follower_wait_time_headway_s,
            ),
            observations: self.observations + other.observations,
            scene: other.scene.clone().or_else(|| self.scene.clone()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn onset(time_s: f64, headway: f64, lag: Option<f64>, n: u64) -> Onset {
        Onset {
            scenario: "a".into(),
            time_s,
            time_headway_s: headway,
            ttc_s: None,
            gap_m: 20.0 * headway,
            lead_time_gap_s: None,
            lag_time_gap_s: lag,
            rejected_lead_time_gap_s: None,
            time_headway_ceiling_s: None,
            accepted_lead_time_gap_s: None,
            follower_wait_time_headway_s: None,
            observations: n,
            scene: None,
        }
    }

    #[test]
    fn merging_keeps_the_smallest_accepted_lead_gap() {
        let with = |gap: Option<f64>| Onset {
            accepted_lead_time_gap_s: gap,
            ..onset(1.0, 1.0, None, 1)
        };
        assert_eq!(
            with(Some(0.9))
                .merged(&with(Some(1.4)))
                .accepted_lead_time_gap_s,
            Some(0.9)
        );
        assert_eq!(
            with(None).merged(&with(Some(1.4))).accepted_lead_time_gap_s,
            Some(1.4)
        );
        assert_eq!(
            with(None).merged(&with(None)).accepted_lead_time_gap_s,
            None
        );
    }

    #[test]
    fn merging_is_a_mean_weighted_by_observations() {
        let m = onset(1.0, 1.0, Some(4.0), 3).merged(&onset(2.0, 2.0, None, 1));
        assert!((m.time_s - 1.25).abs() < 1e-12);
        assert!((m.time_headway_s - 1.25).abs() < 1e-12);
        assert_eq!(m.lag_time_gap_s, Some(4.0));
        assert_eq!(m.observations, 4);
    }

    #[test]
    fn non_finite_values_are_named() {
        let mut bad = onset(1.0, 1.0, None, 1);
        bad.lag_time_gap_s = Some(f64::NAN);
        let message = bad.validate(2).unwrap_err().to_string();
        assert!(message.contains("onsets[2].lag_time_gap_s"), "{message}");
        assert!(onset(-1.0, 1.0, None, 1).validate(0).is_err());
        assert!(onset(1.0, 1.0, None, 1).validate(0).is_ok());
    }
}
