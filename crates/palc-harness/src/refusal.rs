//! Why a scenario is refused before (or, for a drawn lane change, while) it
//! runs: one variant per check, with the numbers that failed it.
//!
//! A refusal is not a failure of the method: the scenario does not fit the
//! planning set-up (the paper's premise, a user without a sane lane change, a
//! scene with no safe lane change). The evaluation counts refusals by
//! [`Refusal::kind`] and keeps each one's fields in `runs.json`; the message of
//! each variant is the sentence the report prints.

use palc_user::{TakeoverCause, UserRefusal};
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::violation::Violation;

/// Why a scenario does not fit the planning set-up.
#[derive(Debug, Clone, PartialEq, Error, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
#[non_exhaustive]
pub enum Refusal {
    /// The scene has no ego vehicle.
    #[error("the scene has no ego vehicle")]
    NoEgo,
    /// The ego does not move at the start.
    #[error("the ego speed is {speed_mps:?} m/s, expected > 0")]
    EgoNotMoving {
        /// The ego's speed (m/s).
        speed_mps: f64,
    },
    /// The scene has no preceding vehicle to change lanes around.
    #[error("the scene has no preceding vehicle")]
    NoPreceding,
    /// The time headway never falls to the planning trigger.
    #[error(
        "the time headway never falls to the trigger {trigger_time_headway_s:?} s within \
         {max_approach_s:?} s"
    )]
    NeverTriggers {
        /// The trigger's time headway (s).
        trigger_time_headway_s: f64,
        /// The longest approach (s).
        max_approach_s: f64,
    },
    /// The ego stops behind the preceding vehicle before the trigger.
    #[error(
        "the ego has stopped behind the preceding vehicle before the trigger (speed \
         {speed_mps:?} m/s)"
    )]
    StoppedBeforeTrigger {
        /// The ego's speed at the trigger (m/s).
        speed_mps: f64,
    },
    /// The standard ALC's start rule is never met.
    #[error("the standard ALC never starts within the {window_s:?} s search window")]
    StandardNeverStarts {
        /// The search window (s).
        window_s: f64,
    },
    /// One of the paper's styles never starts, so the standard ALC cannot wait for it.
    #[error(
        "a user ({time_headway_s:?} s headway) never starts within the {window_s:?} s search window"
    )]
    StyleNeverStarts {
        /// The style's time headway (s).
        time_headway_s: f64,
        /// The search window (s).
        window_s: f64,
    },
    /// Under the safety layer, the target lane's gaps never stay at the safe
    /// distance over the standard ALC's lane change.
    #[error(
        "no safe lane change for the standard ALC's {duration_s:?} s lane change within the \
         {window_s:?} s search window: the target-lane gaps stay below the safe distance"
    )]
    StandardGapsUnsafe {
        /// The standard ALC's lane-change duration (s).
        duration_s: f64,
        /// The search window (s).
        window_s: f64,
    },
    /// The ego has reached the preceding vehicle when the standard ALC would start.
    #[error(
        "no safe lane change for the standard ALC's {duration_s:?} s lane change within the \
         {window_s:?} s search window: the ego has reached the preceding vehicle (time headway \
         {time_headway_s:.2} s) when the standard ALC would start, {delay_steps} steps after \
         the latest user"
    )]
    StandardBehindPreceding {
        /// The standard ALC's lane-change duration (s).
        duration_s: f64,
        /// The search window (s).
        window_s: f64,
        /// The time headway at the earliest start (s).
        time_headway_s: f64,
        /// The standard ALC's delay after the latest style (steps).
        delay_steps: usize,
    },
    /// The standard ALC's horizon is longer than the search window.
    #[error("the horizon ({horizon} steps) exceeds the search window ({window} steps)")]
    HorizonBeyondWindow {
        /// The horizon (steps).
        horizon: usize,
        /// The search window (steps).
        window: usize,
    },
    /// A user's lane change ends too late for any horizon within the search window.
    #[error(
        "a lane change ending at {end_s:.2} s needs a horizon of {needed} steps, beyond the \
         search window ({window} steps)"
    )]
    LaneChangeBeyondWindow {
        /// End of the lane change (s).
        end_s: f64,
        /// The horizon it needs (steps).
        needed: usize,
        /// The search window (steps).
        window: usize,
    },
    /// The paper's premise: one of its styles does not change lanes within the horizon.
    #[error("the {style} user does not change lanes within the horizon")]
    StyleNotWithinHorizon {
        /// The style's name.
        style: String,
    },
    /// The paper's premise: the standard ALC starts no later than a style.
    #[error(
        "the standard ALC starts at {standard_start_s:.2} s, not later than the {style} user \
         ({user_start_s:.2} s)"
    )]
    StandardNotLater {
        /// The standard ALC's start (s).
        standard_start_s: f64,
        /// The style's name.
        style: String,
        /// The style's start (s).
        user_start_s: f64,
    },
    /// The paper's premise: the standard ALC's lane change is no slower than a style's.
    #[error(
        "the standard ALC's lane change ({standard_duration_s:?} s) is not slower than the {style} \
         user's ({user_duration_s:?} s)"
    )]
    StandardNotSlower {
        /// The standard ALC's duration (s).
        standard_duration_s: f64,
        /// The style's name.
        style: String,
        /// The style's duration (s).
        user_duration_s: f64,
    },
    /// The user has no sane lane change in the scenario.
    #[error("user `{user}`: {refusal}")]
    User {
        /// The user's name.
        user: String,
        /// What the user refused.
        refusal: UserRefusal,
    },
    /// The user would take over its own lane change.
    #[error("user `{user}` would take over its own lane change at step {step}: {cause}")]
    OwnLaneChangeTakenOver {
        /// The user's name.
        user: String,
        /// The step of the takeover.
        step: usize,
        /// Why.
        cause: TakeoverCause,
    },
    /// Under the longitudinal guard, the user's own lane change collides.
    #[error("the lane change user `{user}` expects collides in this scene ({vehicles})")]
    OwnLaneChangeCollides {
        /// The user's name.
        user: String,
        /// The vehicles it overlapped, with their smallest net gaps.
        vehicles: String,
    },
    /// The user's own lane change would enter the target lane beside a vehicle.
    #[error(
        "user `{user}` would hold its own lane change beside a target-lane vehicle at step {step}"
    )]
    OwnLaneChangeEntersBeside {
        /// The user's name.
        user: String,
        /// The step.
        step: usize,
    },
    /// Under the safety layer, the standard ALC's own plan is unsafe.
    #[error("no safe lane change: the standard ALC's plan is refused ({violation})")]
    StandardPlanUnsafe {
        /// The first violation of its plan.
        violation: Violation,
    },
    /// A user with spread drew a lane change that ends after the horizon.
    #[error(
        "a drawn lane change of user `{user}` (start {start_s:.3} s, duration {duration_s:.3} s) \
         ends after the {horizon_s:.2} s horizon"
    )]
    DrawBeyondHorizon {
        /// The user's name.
        user: String,
        /// The drawn start (s).
        start_s: f64,
        /// The drawn duration (s).
        duration_s: f64,
        /// The horizon (s).
        horizon_s: f64,
    },
}

impl Refusal {
    /// The kind's name, as in `runs.json` and the report's table of refusals; a
    /// user's refusal is `user/` and the user's kind.
    pub fn kind(&self) -> String {
        let kind = match self {
            Refusal::NoEgo => "no-ego",
            Refusal::EgoNotMoving { .. } => "ego-not-moving",
            Refusal::NoPreceding => "no-preceding",
            Refusal::NeverTriggers { .. } => "never-triggers",
            Refusal::StoppedBeforeTrigger { .. } => "stopped-before-trigger",
            Refusal::StandardNeverStarts { .. } => "standard-never-starts",
            Refusal::StyleNeverStarts { .. } => "style-never-starts",
            Refusal::StandardGapsUnsafe { .. } => "standard-gaps-unsafe",
            Refusal::StandardBehindPreceding { .. } => "standard-behind-preceding",
            Refusal::HorizonBeyondWindow { .. } => "horizon-beyond-window",
            Refusal::LaneChangeBeyondWindow { .. } => "lane-change-beyond-window",
            Refusal::StyleNotWithinHorizon { .. } => "style-not-within-horizon",
            Refusal::StandardNotLater { .. } => "standard-not-later",
            Refusal::StandardNotSlower { .. } => "standard-not-slower",
            Refusal::User { refusal, .. } => return format!("user/{}", refusal.kind()),
            Refusal::OwnLaneChangeTakenOver { .. } => "own-lane-change-taken-over",
            Refusal::OwnLaneChangeCollides { .. } => "own-lane-change-collides",
            Refusal::OwnLaneChangeEntersBeside { .. } => "own-lane-change-enters-beside",
            Refusal::StandardPlanUnsafe { .. } => "standard-plan-unsafe",
            Refusal::DrawBeyondHorizon { .. } => "draw-beyond-horizon",
        };
        kind.to_owned()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::violation::Role;

    /// One refusal of every kind, the user's refusals included.
    fn every_refusal() -> Vec<Refusal> {
        let user = |refusal| Refusal::User {
            user: "probe".into(),
            refusal,
        };
        vec![
            Refusal::NoEgo,
            Refusal::EgoNotMoving { speed_mps: 0.0 },
            Refusal::NoPreceding,
            Refusal::NeverTriggers {
                trigger_time_headway_s: 2.2,
                max_approach_s: 60.0,
            },
            Refusal::StoppedBeforeTrigger { speed_mps: 0.0 },
            Refusal::StandardNeverStarts { window_s: 60.0 },
            Refusal::StyleNeverStarts {
                time_headway_s: 1.2,
                window_s: 60.0,
            },
            Refusal::StandardGapsUnsafe {
                duration_s: 3.5,
                window_s: 60.0,
            },
            Refusal::StandardBehindPreceding {
                duration_s: 3.5,
                window_s: 60.0,
                time_headway_s: -0.1,
                delay_steps: 5,
            },
            Refusal::HorizonBeyondWindow {
                horizon: 700,
                window: 600,
            },
            Refusal::LaneChangeBeyondWindow {
                end_s: 61.0,
                needed: 620,
                window: 600,
            },
            Refusal::StyleNotWithinHorizon {
                style: "neutral".into(),
            },
            Refusal::StandardNotLater {
                standard_start_s: 5.0,
                style: "neutral".into(),
                user_start_s: 5.0,
            },
            Refusal::StandardNotSlower {
                standard_duration_s: 3.5,
                style: "neutral".into(),
                user_duration_s: 3.5,
            },
            Refusal::OwnLaneChangeTakenOver {
                user: "probe".into(),
                step: 12,
                cause: TakeoverCause::Deviation,
            },
            Refusal::OwnLaneChangeCollides {
                user: "probe".into(),
                vehicles: "the preceding vehicle at -0.2 m".into(),
            },
            Refusal::OwnLaneChangeEntersBeside {
                user: "probe".into(),
                step: 40,
            },
            Refusal::StandardPlanUnsafe {
                violation: Violation {
                    step: 30,
                    role: Role::TargetLag,
                    vehicle: 3,
                    gap_m: 4.0,
                    safe_distance_m: 9.0,
                },
            },
            Refusal::DrawBeyondHorizon {
                user: "probe".into(),
                start_s: 9.0,
                duration_s: 3.0,
                horizon_s: 11.0,
            },
            user(UserRefusal::StartRuleNeverMet {
                rule: "time-headway".into(),
                window_s: 60.0,
            }),
            user(UserRefusal::StartRuleMetAtTrigger {
                rule: "time-headway".into(),
                time_headway_s: 1.0,
            }),
            user(UserRefusal::GapsNeverAcceptable {
                min_lead_gap_s: 0.6,
                min_lag_gap_s: 0.0,
                safe_distance: true,
                decision_step: 20,
            }),
            user(UserRefusal::EndsAfterWindow {
                end_s: 61.0,
                window_s: 60.0,
            }),
            user(UserRefusal::NotCentreToCentre {
                start_l: 0.1,
                end_l: 3.2,
                from_l: 0.0,
                to_l: 3.5,
            }),
            user(UserRefusal::LeavesLanes {
                l: 6.0,
                low: -1.75,
                high: 5.25,
            }),
            user(UserRefusal::NotSmooth {
                profile: "table".into(),
                duration_s: 1.0,
                acceleration_mps2: 12.0,
                max_acceleration_mps2: 10.0,
                jerk_mps3: 200.0,
                max_jerk_mps3: 150.0,
            }),
            user(UserRefusal::NoSpreadGenerator),
        ]
    }

    #[test]
    fn each_kind_is_the_name_runs_json_gives_it_and_reads_back() {
        let refusals = every_refusal();
        let mut kinds: Vec<String> = Vec::new();
        for refusal in &refusals {
            let json = serde_json::to_value(refusal).unwrap();
            let tag = json["kind"].as_str().unwrap();
            let expected = match refusal {
                Refusal::User { .. } => {
                    format!("user/{}", json["refusal"]["kind"].as_str().unwrap())
                }
                _ => tag.to_owned(),
            };
            assert_eq!(refusal.kind(), expected);
            assert!(!refusal.to_string().is_empty());
            let back: Refusal = serde_json::from_value(json).unwrap();
            assert_eq!(&back, refusal);
            kinds.push(refusal.kind());
        }
        kinds.sort();
        kinds.dedup();
        assert_eq!(kinds.len(), refusals.len(), "two refusals share a kind");
    }
}
