//! The Intelligent Driver Model (Treiber, Hennecke and Helbing, 2000) and the
//! ballistic update that integrates it.
//!
//! The paper's background vehicles follow the IDM (Section III.A). The model is
//! written with the literature's parameter names; the gap is the net,
//! bumper-to-bumper distance: the leader's rear minus the follower's front.

use serde::{Deserialize, Serialize};

/// How the desired dynamical gap `s*` treats a leader that pulls away.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DesiredGap {
    /// `s* = s0 + v T + v dv / (2 sqrt(a b))`, as printed by Treiber, Hennecke and
    /// Helbing (2000). When the leader is much faster (`dv << 0`) the dynamic part is
    /// negative, `s*` falls below `s0` and can even change sign (its square then brakes).
    #[serde(rename = "treiber2000")]
    Treiber2000,
    /// `s* = s0 + max(0, v T + v dv / (2 sqrt(a b)))`, the convention of SUMO and of
    /// Treiber and Kesting's book: `s*` never falls below `s0`. The two differ by up to
    /// 1.7 m of position over 60 s when a follower is much slower than its leader. The
    /// default, and what the test bed uses: a follower never accelerates beyond its
    /// free-road value because its leader pulls away, `s*` never changes sign, and the
    /// reproduction's published numbers were measured with it.
    #[default]
    Clamped,
}

/// Parameters of the Intelligent Driver Model, named as in Treiber et al. (2000).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct IdmParams {
    /// v0, desired speed on a free road (m/s).
    pub v0: f64,
    /// T, desired time gap to the leader (s).
    pub t: f64,
    /// s0, minimum net gap at standstill (m).
    pub s0: f64,
    /// a, maximum acceleration (m/s^2).
    pub a: f64,
    /// b, comfortable deceleration, positive (m/s^2).
    pub b: f64,
    /// delta, acceleration exponent (dimensionless, 4 in the literature).
    pub delta: f64,
    /// The form of `s*`; [`DesiredGap::Clamped`] by default.
    #[serde(default)]
    pub desired_gap: DesiredGap,
}

impl IdmParams {
    /// The parameters of Treiber et al. (2000), Table 1, with the given desired speed:
    /// T = 1.6 s, s0 = 2 m, a = 0.73 m/s^2, b = 1.67 m/s^2, delta = 4.
    pub fn treiber_2000(v0: f64) -> IdmParams {
        IdmParams {
            v0,
            t: 1.6,
            s0: 2.0,
            a: 0.73,
            b: 1.67,
            delta: 4.0,
            desired_gap: DesiredGap::default(),
        }
    }

    /// Desired dynamical gap s*(v, dv) = s0 + v T + v dv / (2 sqrt(a b)), with the dynamic
    /// part clamped at 0 for [`DesiredGap::Clamped`]; `dv = v - v_leader` is the approach
    /// rate.
    pub fn desired_gap(&self, v: f64, dv: f64) -> f64 {
        let dynamic = v * self.t + v * dv / (2.0 * (self.a * self.b).sqrt());
        match self.desired_gap {
            DesiredGap::Treiber2000 => self.s0 + dynamic,
            DesiredGap::Clamped => self.s0 + dynamic.max(0.0),
        }
    }

    /// Free-road acceleration a (1 - (v/v0)^delta).
    pub fn free_acceleration(&self, v: f64) -> f64 {
        self.a * (1.0 - (v.max(0.0) / self.v0).powf(self.delta))
    }

    /// IDM acceleration behind a leader at net gap `gap` approached at rate `dv = v - v_leader`:
    /// a [1 - (v/v0)^delta - (s*(v, dv)/gap)^2].
    ///
    /// A gap at or below [`MIN_INTERACTION_GAP`] is treated as that gap, so that a vehicle
    /// that finds another beside or inside its own length (a cut-in) brakes as hard as the
    /// scene allows instead of producing an infinite or NaN acceleration. Callers clip the
    /// result to the physical braking limit.
    pub fn acceleration(&self, v: f64, gap: f64, dv: f64) -> f64 {
        let gap = gap.max(MIN_INTERACTION_GAP);
        let ratio = self.desired_gap(v, dv) / gap;
        self.free_acceleration(v) - self.a * ratio * ratio
    }

    /// Acceleration with an optional leader given as `(gap, dv)`.
    pub fn acceleration_behind(&self, v: f64, leader: Option<(f64, f64)>) -> f64 {
        match leader {
            Some((gap, dv)) => self.acceleration(v, gap, dv),
            None => self.free_acceleration(v),
        }
    }

    /// Closed-form equilibrium (stationary) net gap at speed `v`:
    /// s_e(v) = (s0 + v T) / sqrt(1 - (v/v0)^delta).
    ///
    /// Returns `None` when `v >= v0`, where no finite gap holds the speed.
    pub fn equilibrium_gap(&self, v: f64) -> Option<f64> {
        let free = 1.0 - (v.max(0.0) / self.v0).powf(self.delta);
        (free > 0.0).then(|| (self.s0 + v.max(0.0) * self.t) / free.sqrt())
    }
}

/// Smallest net gap the interaction term divides by (m); see [`IdmParams::acceleration`].
pub const MIN_INTERACTION_GAP: f64 = 0.1;

/// Longitudinal state after one ballistic step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BallisticStep {
    /// Distance travelled during the step (m), never negative.
    pub distance: f64,
    /// Speed at the end of the step (m/s), never negative.
    pub speed: f64,
}

/// Ballistic update with constant acceleration `acc` over `dt` (Treiber and Kanagaraj, 2015):
/// v' = v + acc dt and ds = v dt + acc dt^2 / 2, except when the vehicle would reach zero
/// speed inside the step: then it stops at t* = v / |acc| after ds = v^2 / (2 |acc|) and stays.
///
/// The result never has negative speed, and a standing vehicle with a negative acceleration
/// does not move (it would move backwards under the plain formula).
pub fn ballistic_step(v: f64, acc: f64, dt: f64) -> BallisticStep {
    let v = v.max(0.0);
    let speed = v + acc * dt;
    if speed >= 0.0 {
        BallisticStep {
            distance: v * dt + 0.5 * acc * dt * dt,
            speed,
        }
    } else {
        // acc < 0 here, because v >= 0 and v + acc dt < 0.
        BallisticStep {
            distance: v * v / (-2.0 * acc),
            speed: 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equilibrium_gap_holds_speed() {
        let idm = IdmParams::treiber_2000(30.0);
        let v = 20.0;
        let gap = idm.equilibrium_gap(v).unwrap();
        assert!(idm.acceleration(v, gap, 0.0).abs() < 1e-12);
        assert!(idm.equilibrium_gap(30.0).is_none());
    }

    #[test]
    fn stopping_inside_a_step_stops_at_the_stopping_distance() {
        let step = ballistic_step(2.0, -4.0, 1.0);
        assert_eq!(step.speed, 0.0);
        assert!((step.distance - 0.5).abs() < 1e-12);
        let standing = ballistic_step(0.0, -3.0, 0.5);
        assert_eq!(
            standing,
            BallisticStep {
                distance: 0.0,
                speed: 0.0
            }
        );
    }
}
