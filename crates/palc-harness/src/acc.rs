//! The ego's longitudinal behaviour while it keeps or changes lanes: an adaptive
//! cruise control (ACC) with a constant time gap, and an emergency brake.
//!
//! The paper holds every speed constant per speed case. palc does not: an ego that
//! keeps its speed while a user waits for a gap on the target lane drives through
//! the slower vehicle ahead (docs/experiments/0030-safety-measures-acc-and-gap-seeking.md).
//! Whenever the system is not executing a lane-change plan (the approach, the
//! lane-keeping prediction that users' start rules see, the user's own driving after
//! a takeover) the ego follows the nearest vehicle ahead in the lanes its body
//! occupies with the constant-time-gap law of Rajamani (*Vehicle Dynamics and
//! Control*, 2nd ed., Sec. 6.5):
//!
//! ```text
//! a = clamp( k_s (g − s_0 − T v) + k_v (v_l − v),  −b,  a_max )   and  a ≤ k_c (v_set − v)
//! ```
//!
//! with `g` the net gap, `v_l` the leader's speed and `v_set` the ego's speed at the
//! start of the scene (its set speed). The gains give a closed loop
//! `λ² + (k_v + k_s T) λ + k_s = 0` with damping 0.93 at the defaults, so the gap
//! settles without overshoot. When closing so fast that the comfortable
//! deceleration `b` cannot match speeds before the standstill gap, the ego brakes
//! with the kinematic deceleration `(v − v_l)² / (2 (g − s_0))`, up to the
//! emergency limit (an automatic emergency brake). Under the safety layer the ACC
//! also keeps the RSS safe distance ([`AccConfig::acceleration_keeping`]): closing
//! within it (plus [`SAFE_DISTANCE_LEAD_S`] of closing speed), it brakes at RSS's
//! `b_min`. While a plan or the user drives the ego, the same law without its
//! cruise term caps their acceleration (the longitudinal guard, `guard.rs`,
//! [`AccConfig::guard`]), with the ACC on or off.

use palc_traffic::{Driver, Scene};
use serde::{Deserialize, Serialize};

use crate::HarnessError;
use crate::safety::SafetyConfig;

/// Parameters of the ego's ACC; defaults in `configs/learn.toml` (`[planning.acc]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AccConfig {
    /// Whether the ACC drives the ego. Off by default: the ego then holds its speed,
    /// as in the paper (the evaluation's scenes and figures). On, an ego behind a
    /// vehicle as slow as the target lane slows to its speed and drops back to seek
    /// a gap, and the users' headway start rules no longer describe that situation
    /// (docs/experiments/0030-safety-measures-acc-and-gap-seeking.md, an open problem).
    pub enabled: bool,
    /// Time gap `T` kept to the vehicle ahead (s). 0.8 s is the shortest that
    /// ISO 15622 lets an ACC offer; it must be shorter than every user's start
    /// headway (the paper's shortest is 1.15 s), or the users waiting behind the
    /// slower vehicle would never reach it.
    pub time_gap_s: f64,
    /// Net gap `s_0` kept at standstill (m).
    pub standstill_gap_m: f64,
    /// Gap gain `k_s` (1/s²).
    pub gap_gain: f64,
    /// Speed-difference gain `k_v` (1/s).
    pub speed_gain: f64,
    /// Gain `k_c` towards the set speed on a free road (1/s).
    pub cruise_gain: f64,
    /// Largest acceleration `a_max` (m/s²).
    pub max_acceleration_mps2: f64,
    /// Comfortable deceleration `b` (m/s²), the limit of the time-gap law.
    pub comfort_deceleration_mps2: f64,
    /// Emergency deceleration (m/s²), used only when `b` cannot avoid the vehicle ahead.
    pub emergency_deceleration_mps2: f64,
    /// How much slower than the target lane's traffic the ego drives while the gap
    /// beside it is not safe (m/s): it drops back until a safe gap comes alongside.
    /// Behind a vehicle as slow as the target lane, an ego that only follows it would
    /// keep its place beside the same target-lane vehicles for ever.
    pub gap_seeking_speed_mps: f64,
    /// Whether the ACC's following law also limits the ego's acceleration while a
    /// plan or the user drives it (the longitudinal guard, `guard.rs`): on by
    /// default, with the ACC on or off, so that no lane change drives into the
    /// vehicle ahead. Off, a plan is driven as planned (the paper's execution).
    pub guard: bool,
}

impl Default for AccConfig {
    fn default() -> Self {
        Self {
            enabled: false,
            time_gap_s: 0.8,
            standstill_gap_m: 2.0,
            gap_gain: 0.15,
            speed_gain: 0.6,
            cruise_gain: 0.5,
            max_acceleration_mps2: 1.5,
            comfort_deceleration_mps2: 3.0,
            emergency_deceleration_mps2: 8.0,
            gap_seeking_speed_mps: 2.0,
            guard: true,
        }
    }
}

/// Largest deceleration any config may ask for (m/s²): about the friction limit
/// of a passenger car on dry asphalt.
pub const MAX_DECELERATION_MPS2: f64 = 10.0;

impl AccConfig {
    /// Checks every field against its bound.
    pub fn validate(&self, table: &str) -> Result<(), HarnessError> {
        let positive = [
            ("time_gap_s", self.time_gap_s, 10.0),
            ("gap_gain", self.gap_gain, 10.0),
            ("speed_gain", self.speed_gain, 10.0),
            ("cruise_gain", self.cruise_gain, 10.0),
            ("max_acceleration_mps2", self.max_acceleration_mps2, 10.0),
            (
                "comfort_deceleration_mps2",
                self.comfort_deceleration_mps2,
                MAX_DECELERATION_MPS2,
            ),
            (
                "emergency_deceleration_mps2",
                self.emergency_deceleration_mps2,
                MAX_DECELERATION_MPS2,
            ),
        ];
        for (name, value, max) in positive {
            if !(value.is_finite() && value > 0.0 && value <= max) {
                return Err(HarnessError::InvalidConfig {
                    field: format!("{table}.{name}"),
                    value,
                    bound: format!("a value in (0, {max:?}]"),
                });
            }
        }
        if !(self.gap_seeking_speed_mps.is_finite()
            && (0.0..=10.0).contains(&self.gap_seeking_speed_mps))
        {
            return Err(HarnessError::InvalidConfig {
                field: format!("{table}.gap_seeking_speed_mps"),
                value: self.gap_seeking_speed_mps,
                bound: "a value in [0, 10.0]".to_owned(),
            });
        }
        if !(self.standstill_gap_m.is_finite() && (0.0..=50.0).contains(&self.standstill_gap_m)) {
            return Err(HarnessError::InvalidConfig {
                field: format!("{table}.standstill_gap_m"),
                value: self.standstill_gap_m,
                bound: "a value in [0, 50.0]".to_owned(),
            });
        }
        if self.emergency_deceleration_mps2 < self.comfort_deceleration_mps2 {
            return Err(HarnessError::InvalidConfig {
                field: format!("{table}.emergency_deceleration_mps2"),
                value: self.emergency_deceleration_mps2,
                bound: format!(
                    "at least comfort_deceleration_mps2 ({:?})",
                    self.comfort_deceleration_mps2
                ),
            });
        }
        Ok(())
    }

    /// The ACC's acceleration at speed `v` with set speed `set_speed`, behind
    /// `leader` = (net gap, leader speed), or on a free road; 0 when it is off.
    pub fn acceleration(&self, v: f64, set_speed: f64, leader: Option<(f64, f64)>) -> f64 {
        if !self.enabled {
            return 0.0;
        }
        let cruise = self.cruise_gain * (set_speed - v);
        let Some((gap, leader_v)) = leader else {
            return cruise.clamp(-self.comfort_deceleration_mps2, self.max_acceleration_mps2);
        };
        let follow = self.following(v, gap, leader_v);
        let comfortable = follow
            .min(cruise)
            .clamp(-self.comfort_deceleration_mps2, self.max_acceleration_mps2);
        self.emergency(v, gap, leader_v).unwrap_or(comfortable)
    }

    /// The time-gap law `k_s (g − s_0 − T v) + k_v (v_l − v)`, unclamped.
    pub(crate) fn following(&self, v: f64, gap: f64, leader_v: f64) -> f64 {
        self.gap_gain * (gap - self.standstill_gap_m - self.time_gap_s * v)
            + self.speed_gain * (leader_v - v)
    }

    /// The emergency branch: when closing so fast that the comfortable deceleration
    /// cannot match the leader's speed before the standstill gap, the kinematic
    /// deceleration that does, up to the emergency limit; `None` otherwise.
    pub(crate) fn emergency(&self, v: f64, gap: f64, leader_v: f64) -> Option<f64> {
        let closing = v - leader_v;
        if closing <= 0.0 {
            return None;
        }
        // The deceleration that matches the leader's speed just at the standstill gap.
        let room = (gap - self.standstill_gap_m).max(1e-3);
        let needed = closing * closing / (2.0 * room);
        (needed > self.comfort_deceleration_mps2)
            .then(|| -needed.min(self.emergency_deceleration_mps2))
    }
}

/// Seconds of closing speed added to the safe distance at which the ACC starts
/// RSS's proper response: a leader that brakes makes the safe distance grow by
/// `v_l b_l / b_max` per second while the gap shrinks at the closing speed, so the
/// response starts before the distance is reached rather than at it.
pub const SAFE_DISTANCE_LEAD_S: f64 = 1.0;

impl AccConfig {
    /// The ego's acceleration under `safety`:
    /// [`acceleration_keeping`](Self::acceleration_keeping) when the safety layer is on
    /// (`safety.enforce`), else [`acceleration`](Self::acceleration) (the paper's
    /// set-up is unchanged).
    pub fn ego_acceleration(
        &self,
        v: f64,
        set_speed: f64,
        leader: Option<(f64, f64)>,
        safety: &SafetyConfig,
    ) -> f64 {
        if safety.enforce {
            self.acceleration_keeping(v, set_speed, leader, safety)
        } else {
            self.acceleration(v, set_speed, leader)
        }
    }

    /// [`acceleration`](Self::acceleration), and RSS's proper response towards the
    /// leader: once the gap falls to the safe distance of `safety` (plus
    /// `SAFE_DISTANCE_LEAD_S` = 1 s of closing speed), at least `safety.min_braking_mps2`
    /// of braking, up to the emergency limit. With the ACC off, 0.
    pub fn acceleration_keeping(
        &self,
        v: f64,
        set_speed: f64,
        leader: Option<(f64, f64)>,
        safety: &SafetyConfig,
    ) -> f64 {
        let a = self.acceleration(v, set_speed, leader);
        let Some((gap, leader_v)) = leader.filter(|_| self.enabled) else {
            return a;
        };
        let closing = (v - leader_v).max(0.0);
        let keep = safety.safe_distance(v, leader_v) + SAFE_DISTANCE_LEAD_S * closing;
        if closing > 0.0 && gap < keep {
            a.min(
                -safety
                    .min_braking_mps2
                    .min(self.emergency_deceleration_mps2),
            )
        } else {
            a
        }
    }
}

/// The vehicle the ego's ACC follows: the nearest vehicle ahead (front bumper
/// ahead of the ego's) in any lane the ego's body occupies, as (net gap, speed).
pub fn acc_leader(scene: &Scene) -> Option<(f64, f64)> {
    let ego = scene.ego()?;
    let road = scene.road();
    scene
        .vehicles()
        .iter()
        .filter(|v| !matches!(v.driver, Driver::External { .. }))
        .filter(|v| v.state.s > ego.state.s && road.occupies(ego.state.l, ego.width, v.lane))
        .min_by(|a, b| a.state.s.total_cmp(&b.state.s))
        .map(|v| (v.rear() - ego.state.s, v.state.v))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn on() -> AccConfig {
        AccConfig {
            enabled: true,
            ..AccConfig::default()
        }
    }

    #[test]
    fn off_the_ego_holds_its_speed() {
        let acc = AccConfig::default();
        assert_eq!(acc.acceleration(20.0, 25.0, Some((5.0, 10.0))), 0.0);
    }

    #[test]
    fn the_defaults_are_valid_and_bad_values_name_their_field() {
        AccConfig::default().validate("planning.acc").unwrap();
        let bad = AccConfig {
            time_gap_s: -1.0,
            ..AccConfig::default()
        };
        let err = bad.validate("planning.acc").unwrap_err().to_string();
        assert!(err.contains("planning.acc.time_gap_s"), "{err}");
        assert!(err.contains("-1.0"), "{err}");
        let bad = AccConfig {
            emergency_deceleration_mps2: 2.0,
            ..AccConfig::default()
        };
        let err = bad.validate("planning.acc").unwrap_err().to_string();
        assert!(err.contains("emergency_deceleration_mps2"), "{err}");
    }

    #[test]
    fn the_equilibrium_gap_has_zero_acceleration() {
        let acc = on();
        for v in [5.0, 15.0, 30.0] {
            let gap = acc.standstill_gap_m + acc.time_gap_s * v;
            // Set speed above v, so that cruising does not cap the law.
            let a = acc.acceleration(v, v + 5.0, Some((gap, v)));
            assert!(a.abs() < 1e-12, "v {v}: {a}");
        }
    }

    #[test]
    fn a_free_road_returns_to_the_set_speed_and_respects_the_limits() {
        let acc = on();
        assert!(acc.acceleration(20.0, 20.0, None).abs() < 1e-12);
        assert!((acc.acceleration(10.0, 30.0, None) - acc.max_acceleration_mps2).abs() < 1e-12);
        assert!(acc.acceleration(30.0, 20.0, Some((1000.0, 30.0))) < 0.0);
    }

    #[test]
    fn keeping_the_safe_distance_brakes_at_the_rss_response_only_when_closing_inside_it() {
        let (acc, safety) = (on(), SafetyConfig::default());
        // Closing at 8 m/s from 40 m: the safe distance of 29 -> 21 m/s is about 45 m.
        let plain = acc.acceleration(29.0, 29.0, Some((40.0, 21.0)));
        let kept = acc.acceleration_keeping(29.0, 29.0, Some((40.0, 21.0)), &safety);
        assert!(plain > -safety.min_braking_mps2, "{plain}");
        assert!((kept + safety.min_braking_mps2).abs() < 1e-12, "{kept}");
        // Far behind, or not closing, the plain law.
        for leader in [Some((200.0, 21.0)), Some((10.0, 29.0)), None] {
            let plain = acc.acceleration(29.0, 29.0, leader);
            assert_eq!(acc.acceleration_keeping(29.0, 29.0, leader, &safety), plain);
        }
        // The ego keeps the distance only under the safety layer.
        let enforced = SafetyConfig {
            enforce: true,
            ..safety
        };
        let leader = Some((40.0, 21.0));
        assert_eq!(acc.ego_acceleration(29.0, 29.0, leader, &enforced), kept);
        assert_eq!(acc.ego_acceleration(29.0, 29.0, leader, &safety), plain);
        // Off, nothing.
        let off = AccConfig::default();
        assert_eq!(
            off.acceleration_keeping(29.0, 29.0, Some((40.0, 21.0)), &safety),
            0.0
        );
    }

    #[test]
    fn a_fast_approach_brakes_beyond_comfort_up_to_the_emergency_limit() {
        let acc = on();
        // Closing at 10 m/s with 12 m of room: (10^2) / (2 * 10) = 5 m/s^2 needed.
        let a = acc.acceleration(20.0, 20.0, Some((12.0, 10.0)));
        assert!((a + 5.0).abs() < 1e-12, "{a}");
        // Closing at 20 m/s with 5 m: beyond the emergency limit, which caps it.
        let a = acc.acceleration(30.0, 30.0, Some((7.0, 10.0)));
        assert!((a + acc.emergency_deceleration_mps2).abs() < 1e-12, "{a}");
    }
}
