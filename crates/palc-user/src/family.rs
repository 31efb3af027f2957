//! The built-in families of simulated users: how a user decides to start, how
//! long it reacts, the shape of its lateral move, its speed during the lane
//! change, and when it takes over for safety rather than for the path.
//!
//! A [`Family`] refines a [`Style`](crate::Style) (the paper's headway,
//! duration and gap acceptance): its defaults are the paper's user, so an empty
//! `[user.family]` table changes nothing. docs/experiments/0036-user-families.md
//! says why each rule is plausible for a human driver.

use palc_traffic::IdmParams;
use serde::{Deserialize, Serialize};

use crate::UserError;
use crate::error::within;
use crate::profile::LateralProfile;
use crate::situation::Situation;
use crate::style::MAX_GAP_ACCEPTANCE_S;

/// Bounds of the time-to-collision start threshold (s).
pub const TTC_START_BOUNDS_S: (f64, f64) = (1.0, 30.0);
/// Bounds of the distance-gap start threshold (m).
pub const DISTANCE_START_BOUNDS_M: (f64, f64) = (2.0, 200.0);
/// Largest reaction time (s): drivers' brake reaction times rarely exceed 2.5 s
/// (Green, 2000); 3 s leaves room for a distracted driver.
pub const MAX_REACTION_S: f64 = 3.0;
/// Bounds of the acceleration towards the target lane's speed (m/s²): a driver
/// who accelerates at all, and at most what a passenger car does at full throttle.
pub const ACCELERATION_BOUNDS_MPS2: (f64, f64) = (0.1, 4.0);
/// Bounds of the perceived-safety time gap (s).
pub const COMFORT_TIME_GAP_BOUNDS_S: (f64, f64) = (0.1, 5.0);
/// Bounds of the perceived-safety time to collision (s).
pub const COMFORT_TTC_BOUNDS_S: (f64, f64) = (0.5, 20.0);
/// Distance from the target lane's centre within which the lane change is over (m):
/// the 5 cm by which the harness finds the end of a driven lane change.
pub const SETTLED_M: f64 = 0.05;
/// Bounds of the lateral offset from which a user judges the target lane's gaps (m).
pub const ONSET_BOUNDS_M: (f64, f64) = (0.05, 3.0);

/// Bounds of the incentive start threshold (m/s²): MOBIL's switching threshold
/// `Δa_th` is 0.1 m/s² for cars (Kesting, Treiber and Helbing, 2007, Table 1); a
/// driver who needs 2 m/s² of advantage hardly ever changes lanes.
pub const INCENTIVE_START_BOUNDS_MPS2: (f64, f64) = (0.0, 2.0);
/// The target lane's follower may be made to brake at most this hard (m/s²) by an
/// incentive-based start: MOBIL's safety criterion `b_safe` (Kesting et al., 2007,
/// Table 1: 4 m/s²), below the physical limit of about 9 m/s².
pub const INCENTIVE_SAFE_DECELERATION_MPS2: f64 = 4.0;

/// When a user decides to change lanes; gap acceptance on the target lane and
/// the reaction time come after the decision.
///
/// The first three rules are thresholds on one cue of the vehicle ahead; the last
/// two are the driver-modelling literature's decisions that are not: a speed
/// gain weighed against the target lane (MOBIL), and several cues at once.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(tag = "rule", rename_all = "kebab-case", deny_unknown_fields)]
pub enum StartRule {
    /// The time headway to the preceding vehicle has fallen to the style's
    /// `time_headway_s` (the paper's user).
    #[default]
    TimeHeadway,
    /// The time to collision with the preceding vehicle has fallen to `seconds`.
    TimeToCollision {
        /// Threshold (s), in [`TTC_START_BOUNDS_S`].
        seconds: f64,
    },
    /// The net distance gap to the preceding vehicle has fallen to `metres`.
    DistanceGap {
        /// Threshold (m), in [`DISTANCE_START_BOUNDS_M`].
        metres: f64,
    },
    /// The speed-gain incentive of MOBIL (Kesting, Treiber and Helbing, 2007,
    /// Eqs. 4-5) with politeness 0, the speed-gain motive of SUMO's LC2013: the
    /// ego's IDM acceleration behind the target lane's leader (or on a free road)
    /// exceeds its acceleration behind the preceding vehicle by `threshold_mps2`,
    /// and the target lane's follower behind the ego would brake less than
    /// [`INCENTIVE_SAFE_DECELERATION_MPS2`]. The driver reasons with the IDM of
    /// Treiber et al. (2000) at the ego's set speed, the model of the background
    /// traffic ([`IdmParams::treiber_2000`]).
    Incentive {
        /// Switching threshold `Δa_th` (m/s²), in [`INCENTIVE_START_BOUNDS_MPS2`].
        threshold_mps2: f64,
    },
    /// Two cues at once: the time headway has fallen to the style's
    /// `time_headway_s` or the time to collision to `ttc_seconds`, whichever
    /// comes first (a driver who reacts to closeness in slow traffic and to a
    /// closing speed in fast traffic).
    HeadwayOrTtc {
        /// Time-to-collision threshold (s), in [`TTC_START_BOUNDS_S`].
        ttc_seconds: f64,
    },
}

impl StartRule {
    /// The rule's name in reports: `time-headway`, `time-to-collision`, `distance-gap`.
    pub fn name(&self) -> &'static str {
        match self {
            StartRule::TimeHeadway => "time-headway",
            StartRule::TimeToCollision { .. } => "time-to-collision",
            StartRule::DistanceGap { .. } => "distance-gap",
            StartRule::Incentive { .. } => "incentive",
            StartRule::HeadwayOrTtc { .. } => "headway-or-ttc",
        }
    }

    /// Whether the rule is met in `situation` for a style headway of
    /// `time_headway_s` and the ego's set speed `set_speed_mps` (the incentive's
    /// desired speed); never once the ego has reached the preceding vehicle.
    pub fn decides(&self, situation: &Situation, time_headway_s: f64, set_speed_mps: f64) -> bool {
        situation.time_headway_s > 0.0
            && match self {
                StartRule::TimeHeadway => situation.time_headway_s <= time_headway_s,
                StartRule::TimeToCollision { seconds } => situation.preceding_ttc_s() <= *seconds,
                StartRule::DistanceGap { metres } => situation.preceding_gap_m <= *metres,
                StartRule::Incentive { threshold_mps2 } => {
                    let (gain, follower) = incentive_mps2(situation, set_speed_mps);
                    gain > *threshold_mps2 && follower >= -INCENTIVE_SAFE_DECELERATION_MPS2
                }
                StartRule::HeadwayOrTtc { ttc_seconds } => {
                    situation.time_headway_s <= time_headway_s
                        || situation.preceding_ttc_s() <= *ttc_seconds
                }
            }
    }

    fn validate(&self, table: &str) -> Result<(), UserError> {
        match *self {
            StartRule::TimeHeadway => Ok(()),
            StartRule::TimeToCollision { seconds } => {
                within(&format!("{table}.seconds"), seconds, TTC_START_BOUNDS_S)
            }
            StartRule::DistanceGap { metres } => {
                within(&format!("{table}.metres"), metres, DISTANCE_START_BOUNDS_M)
            }
            StartRule::Incentive { threshold_mps2 } => within(
                &format!("{table}.threshold_mps2"),
                threshold_mps2,
                INCENTIVE_START_BOUNDS_MPS2,
            ),
            StartRule::HeadwayOrTtc { ttc_seconds } => within(
                &format!("{table}.ttc_seconds"),
                ttc_seconds,
                TTC_START_BOUNDS_S,
            ),
        }
    }
}

/// MOBIL's two accelerations in `situation` for an ego whose desired speed is
/// `set_speed_mps` (Kesting et al., 2007, Eqs. 4-5): the ego's advantage
/// `ã_c − a_c` (its IDM acceleration behind the target lane's leader, or on a
/// free road, minus that behind the preceding vehicle), and `ã_n`, the IDM
/// acceleration of the target lane's follower behind the ego after the change
/// (0 without a follower; the IDM's hardest braking with the follower alongside).
/// The follower's desired speed is its own speed or the ego's set speed,
/// whichever is higher: a vehicle the driver cannot read is assumed content.
pub fn incentive_mps2(situation: &Situation, set_speed_mps: f64) -> (f64, f64) {
    let v = situation.ego_speed;
    let ego = IdmParams::treiber_2000(set_speed_mps.max(v).max(1.0));
    let here = (situation.preceding_speed)
        .filter(|_| situation.preceding_gap_m.is_finite())
        .map(|speed| (situation.preceding_gap_m, v - speed));
    let there = situation.target_lead_gap_m.zip(situation.target_lead_speed);
    let there = there.map(|(gap, speed)| (gap, v - speed));
    let gain = ego.acceleration_behind(v, there) - ego.acceleration_behind(v, here);
    let follower = match situation.target_lag_gap_m.zip(situation.target_lag_speed) {
        Some((gap, speed)) => {
            let params = IdmParams::treiber_2000(speed.max(set_speed_mps).max(1.0));
            params.acceleration(speed, gap, speed - v)
        }
        None => 0.0,
    };
    (gain, follower)
}

/// The user's speed during its lane change.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(tag = "rule", rename_all = "kebab-case", deny_unknown_fields)]
pub enum SpeedRule {
    /// The ego ACC's speed, as while keeping the lane (the paper's constant
    /// speed when the ACC is off).
    #[default]
    Constant,
    /// From the start, accelerate towards the target lane's speed (its leader's,
    /// else its follower's) at most at `max_acceleration_mps2`, never faster than
    /// the ACC allows behind the vehicle ahead.
    Accelerating {
        /// Largest acceleration (m/s²), in [`ACCELERATION_BOUNDS_MPS2`].
        max_acceleration_mps2: f64,
    },
}

impl SpeedRule {
    /// The rule's name in reports: `constant` or `accelerating`.
    pub fn name(&self) -> &'static str {
        match self {
            SpeedRule::Constant => "constant",
            SpeedRule::Accelerating { .. } => "accelerating",
        }
    }
}

/// The perceived-safety takeover rule: during the lane change (from `onset_m`
/// towards the target lane until the ego has settled within [`SETTLED_M`] of the
/// target lane's centre), the user takes over when a target-lane vehicle is nearer
/// than its comfort bound (as a time gap, or a time to collision), whatever the
/// lateral deviation. This is what the paper's perceived safe zone exists to learn.
/// Once settled, the ego follows in its new lane: the ACC's concern, measured by
/// the safety metrics, not the lane change the user judges.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PerceivedSafety {
    /// Smallest comfortable net gap to the target lane's leader (at the ego's
    /// speed) or follower (at its speed), as a time gap (s).
    pub min_time_gap_s: f64,
    /// Smallest comfortable time to collision with either (s); `None` ignores it.
    pub min_ttc_s: Option<f64>,
    /// Lateral offset from the current lane's centre from which the user judges
    /// the target lane's gaps (m); by default 0.5 m, where the move is visibly
    /// under way but the ego's side has not yet reached the lane marking (at
    /// 0.85 m for a 1.8 m wide car on a 3.5 m lane).
    pub onset_m: f64,
}

impl Default for PerceivedSafety {
    fn default() -> Self {
        Self {
            min_time_gap_s: 0.8,
            min_ttc_s: None,
            onset_m: 0.5,
        }
    }
}

impl PerceivedSafety {
    /// Whether a user with this comfort bound is uncomfortable at `situation`
    /// with the ego at `offset_m` towards the target lane, `width_m` away; returns
    /// the gap and time to collision that broke the bound, and which vehicle
    /// (`true` the leader).
    pub fn breached(
        &self,
        offset_m: f64,
        width_m: f64,
        situation: &Situation,
    ) -> Option<(bool, f64, f64)> {
        if offset_m < self.onset_m || width_m - offset_m < SETTLED_M {
            return None;
        }
        let ttc_bound = self.min_ttc_s.unwrap_or(0.0);
        let lead = situation.target_lead_times_s().map(|t| (true, t));
        let lag = situation.target_lag_times_s().map(|t| (false, t));
        [lead, lag]
            .into_iter()
            .flatten()
            .find(|(_, (gap, ttc))| *gap < self.min_time_gap_s || *ttc < ttc_bound)
            .map(|(lead, (gap, ttc))| (lead, gap, ttc))
    }

    fn validate(&self, table: &str) -> Result<(), UserError> {
        within(
            &format!("{table}.min_time_gap_s"),
            self.min_time_gap_s,
            COMFORT_TIME_GAP_BOUNDS_S,
        )?;
        if let Some(ttc) = self.min_ttc_s {
            within(&format!("{table}.min_ttc_s"), ttc, COMFORT_TTC_BOUNDS_S)?;
        }
        within(&format!("{table}.onset_m"), self.onset_m, ONSET_BOUNDS_M)
    }
}

/// A family of simulated users: the rules that refine a style. The default is
/// the paper's user (time-headway start, no reaction delay, quintic profile,
/// constant speed, takeover on lateral deviation only).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct Family {
    /// When the user decides to change lanes.
    pub start: StartRule,
    /// Delay between the decision and the earliest start (s), in `[0, MAX_REACTION_S]`.
    pub reaction_s: f64,
    /// Replaces the style's `min_lead_gap_s` (s).
    pub min_lead_gap_s: Option<f64>,
    /// Replaces the style's `min_lag_gap_s` (s).
    pub min_lag_gap_s: Option<f64>,
    /// The shape of the lateral move.
    pub profile: LateralProfile,
    /// The speed during the lane change.
    pub speed: SpeedRule,
    /// The perceived-safety takeover rule, besides the lateral deviation; none by default.
    pub perceived_safety: Option<PerceivedSafety>,
}

impl Family {
    /// A short description for reports, e.g. `time-to-collision start, cosine profile`.
    pub fn describe(&self) -> String {
        let mut parts = vec![format!("{} start", self.start.name())];
        if self.reaction_s > 0.0 {
            parts.push(format!("{} s reaction", self.reaction_s));
        }
        parts.push(format!("{} profile", self.profile.name()));
        parts.push(format!("{} speed", self.speed.name()));
        if self.perceived_safety.is_some() {
            parts.push("perceived-safety takeover".to_owned());
        }
        parts.join(", ")
    }

    /// Checks every parameter against its bound, naming the field under `table`.
    pub fn validate(&self, table: &str) -> Result<(), UserError> {
        self.start.validate(&format!("{table}.start"))?;
        within(
            &format!("{table}.reaction_s"),
            self.reaction_s,
            (0.0, MAX_REACTION_S),
        )?;
        for (name, value) in [
            ("min_lead_gap_s", self.min_lead_gap_s),
            ("min_lag_gap_s", self.min_lag_gap_s),
        ] {
            if let Some(value) = value {
                within(
                    &format!("{table}.{name}"),
                    value,
                    (0.0, MAX_GAP_ACCEPTANCE_S),
                )?;
            }
        }
        self.profile.validate(&format!("{table}.profile"))?;
        if let SpeedRule::Accelerating {
            max_acceleration_mps2,
        } = self.speed
        {
            within(
                &format!("{table}.speed.max_acceleration_mps2"),
                max_acceleration_mps2,
                ACCELERATION_BOUNDS_MPS2,
            )?;
        }
        if let Some(comfort) = &self.perceived_safety {
            comfort.validate(&format!("{table}.perceived_safety"))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seen(headway: f64, lead_gap: f64, lag_gap: f64) -> Situation {
        Situation {
            time_headway_s: headway,
            preceding_gap_m: headway * 20.0,
            preceding_speed: Some(15.0),
            target_lead_gap_m: Some(lead_gap),
            target_lag_gap_m: Some(lag_gap),
            ego_speed: 20.0,
            target_lead_speed: Some(20.0),
            target_lag_speed: Some(20.0),
        }
    }

    #[test]
    fn each_start_rule_reads_its_own_measure() {
        // 1.2 s headway at 20 m/s: a 24 m gap closing at 5 m/s, TTC 4.8 s.
        let s = seen(1.2, 50.0, 20.0);
        assert!(StartRule::TimeHeadway.decides(&s, 1.23, 25.0));
        assert!(!StartRule::TimeHeadway.decides(&s, 1.1, 25.0));
        assert!(StartRule::TimeToCollision { seconds: 5.0 }.decides(&s, 0.0, 25.0));
        assert!(!StartRule::TimeToCollision { seconds: 4.5 }.decides(&s, 0.0, 25.0));
        assert!(StartRule::DistanceGap { metres: 25.0 }.decides(&s, 0.0, 25.0));
        assert!(!StartRule::DistanceGap { metres: 20.0 }.decides(&s, 0.0, 25.0));
        // Either cue of two.
        let either = StartRule::HeadwayOrTtc { ttc_seconds: 5.0 };
        assert!(either.decides(&s, 1.1, 25.0));
        assert!(either.decides(&s, 1.23, 25.0));
        assert!(!StartRule::HeadwayOrTtc { ttc_seconds: 4.5 }.decides(&s, 1.1, 25.0));
        // Never behind a vehicle already reached.
        let reached = seen(-0.1, 50.0, 20.0);
        assert!(!StartRule::DistanceGap { metres: 25.0 }.decides(&reached, 0.0, 25.0));
    }

    #[test]
    fn the_incentive_weighs_the_target_lane_against_the_own_one() {
        // 24 m behind a leader 5 m/s slower; the target lane's leader 50 m ahead
        // at the ego's speed: changing gains acceleration.
        let s = seen(1.2, 50.0, 20.0);
        let (gain, follower) = incentive_mps2(&s, 25.0);
        let ego = IdmParams::treiber_2000(25.0);
        let expected = ego.acceleration(20.0, 50.0, 0.0) - ego.acceleration(20.0, 24.0, 5.0);
        assert!((gain - expected).abs() < 1e-12 && gain > 0.5, "{gain}");
        assert!(follower > -INCENTIVE_SAFE_DECELERATION_MPS2, "{follower}");
        let rule = StartRule::Incentive {
            threshold_mps2: 0.1,
        };
        assert!(rule.decides(&s, 0.0, 25.0));
        // The same gain is refused with a follower that would brake beyond b_safe.
        let tailgated = seen(1.2, 50.0, 1.0);
        assert!(incentive_mps2(&tailgated, 25.0).1 < -INCENTIVE_SAFE_DECELERATION_MPS2);
        assert!(!rule.decides(&tailgated, 0.0, 25.0));
        // Far from a leader as fast as the ego, a slower target lane gains nothing.
        let free = Situation {
            time_headway_s: 5.0,
            preceding_gap_m: 100.0,
            preceding_speed: Some(20.0),
            target_lead_speed: Some(15.0),
            target_lead_gap_m: Some(20.0),
            ..s
        };
        assert!(incentive_mps2(&free, 25.0).0 < 0.0);
        assert!(!rule.decides(&free, 0.0, 25.0));
        // Symmetry: the same vehicle ahead on both lanes gains exactly nothing.
        let same = Situation {
            target_lead_gap_m: Some(s.preceding_gap_m),
            target_lead_speed: s.preceding_speed,
            ..s
        };
        assert!(incentive_mps2(&same, 25.0).0.abs() < 1e-12);
    }

    #[test]
    fn perceived_safety_judges_gaps_only_once_the_move_is_under_way() {
        let comfort = PerceivedSafety {
            min_time_gap_s: 0.8,
            min_ttc_s: None,
            onset_m: 0.5,
        };
        let close_lag = seen(1.0, 50.0, 10.0); // 0.5 s behind at 20 m/s
        assert_eq!(comfort.breached(0.2, 3.5, &close_lag), None);
        let (lead, gap, _) = comfort.breached(0.6, 3.5, &close_lag).unwrap();
        assert!(!lead && (gap - 0.5).abs() < 1e-12);
        assert_eq!(comfort.breached(1.0, 3.5, &seen(1.0, 50.0, 20.0)), None);
        // Settled on the target lane: the lane change is over.
        assert_eq!(comfort.breached(3.47, 3.5, &close_lag), None);
    }

    #[test]
    fn out_of_range_parameters_name_their_field() {
        let cases = [
            (
                Family {
                    start: StartRule::TimeToCollision { seconds: 0.2 },
                    ..Family::default()
                },
                "user.family.start.seconds",
            ),
            (
                Family {
                    reaction_s: 4.0,
                    ..Family::default()
                },
                "user.family.reaction_s",
            ),
            (
                Family {
                    speed: SpeedRule::Accelerating {
                        max_acceleration_mps2: f64::NAN,
                    },
                    ..Family::default()
                },
                "user.family.speed.max_acceleration_mps2",
            ),
            (
                Family {
                    perceived_safety: Some(PerceivedSafety {
                        min_ttc_s: Some(100.0),
                        ..PerceivedSafety::default()
                    }),
                    ..Family::default()
                },
                "user.family.perceived_safety.min_ttc_s",
            ),
            (
                Family {
                    min_lag_gap_s: Some(-1.0),
                    ..Family::default()
                },
                "user.family.min_lag_gap_s",
            ),
        ];
        for (family, field) in cases {
            let err = family.validate("user.family").unwrap_err().to_string();
            assert!(err.contains(field), "{err}");
        }
        Family::default().validate("user.family").unwrap();
    }
}
