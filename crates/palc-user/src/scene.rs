//! What a driver is shown of one scenario, in plain numbers: the step, what it
//! sees at each step of the search window with the ego keeping its lane, the
//! ego's motion while it does, the target lane's centre, and the safe distance
//! a user who waits for safe gaps keeps.
//!
//! The loop builds a [`UserScene`] from its own set-up; a driver model needs
//! nothing else, so it compiles and is tested without the loop.

use crate::situation::Situation;

/// One scenario as a driver sees it, from the trigger (step 0) to the end of
/// the search window.
#[derive(Debug, Clone, Copy)]
pub struct UserScene<'a> {
    /// Step (s).
    pub dt: f64,
    /// What the driver sees at each step, the ego keeping its lane.
    pub situations: &'a [Situation],
    /// The ego keeping its lane under its ACC: `(s − s₀, v)` at each step, with
    /// `s₀` the ego's position at step 0 (m, m/s); as long as `situations`.
    pub lane_keeping: &'a [[f64; 2]],
    /// The ego's set speed (m/s): a speed-matching user's target when the
    /// target lane is empty.
    pub set_speed: f64,
    /// Lateral position of the target lane's centre (m); the current lane's is 0.
    pub target_l: f64,
    /// With users who wait for safe gaps: the safe distance both target-lane
    /// gaps must keep over the whole lane change. `None`: the user's own gap
    /// acceptance alone.
    pub safe_gaps: Option<SafeDistance>,
}

impl UserScene<'_> {
    /// The last step of the search window.
    pub fn window(&self) -> usize {
        self.situations.len().saturating_sub(1)
    }

    /// The search window (s).
    pub fn window_s(&self) -> f64 {
        self.window() as f64 * self.dt
    }
}

/// The longitudinal safe distance of the Responsibility-Sensitive Safety model
/// (Shalev-Shwartz, Shammah and Shashua, 2017, Definition 1): a rear vehicle at
/// `v_r` behind a front vehicle at `v_f` keeps at least
///
/// ```text
/// d_min = [ v_r ρ + ½ a_acc ρ² + (v_r + ρ a_acc)² / (2 b_min) − v_f² / (2 b_max) ]⁺
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SafeDistance {
    /// Response time `ρ` of the rear vehicle (s).
    pub response_time_s: f64,
    /// Largest acceleration `a_acc` of the rear vehicle during its response (m/s²).
    pub max_acceleration_mps2: f64,
    /// Smallest braking `b_min` the rear vehicle applies after its response (m/s²).
    pub min_braking_mps2: f64,
    /// Largest braking `b_max` of the front vehicle (m/s²).
    pub max_braking_mps2: f64,
}

impl SafeDistance {
    /// The safe distance (m) of a rear vehicle at `rear_v` behind a front one at `front_v`.
    pub fn distance(&self, rear_v: f64, front_v: f64) -> f64 {
        let rho = self.response_time_s;
        let a = self.max_acceleration_mps2;
        let after_response = rear_v + rho * a;
        let d = rear_v * rho
            + 0.5 * a * rho * rho
            + after_response * after_response / (2.0 * self.min_braking_mps2)
            - front_v * front_v / (2.0 * self.max_braking_mps2);
        d.max(0.0)
    }

    /// Whether both target-lane gaps in `situation` are at least the safe
    /// distance: the ego behind the lead, the lag behind the ego.
    pub fn target_gaps_safe(&self, situation: &Situation) -> bool {
        let v = situation.ego_speed;
        let lead_ok = match (situation.target_lead_gap_m, situation.target_lead_speed) {
            (Some(gap), Some(lead_v)) => gap >= self.distance(v, lead_v),
            _ => true,
        };
        let lag_ok = match (situation.target_lag_gap_m, situation.target_lag_speed) {
            (Some(gap), Some(lag_v)) => gap >= self.distance(lag_v, v),
            _ => true,
        };
        lead_ok && lag_ok
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const RSS: SafeDistance = SafeDistance {
        response_time_s: 0.5,
        max_acceleration_mps2: 1.5,
        min_braking_mps2: 6.0,
        max_braking_mps2: 6.0,
    };

    #[test]
    fn the_safe_distance_grows_with_the_rear_speed_and_is_never_negative() {
        let slow = RSS.distance(20.0, 25.0);
        let fast = RSS.distance(30.0, 25.0);
        assert!(fast > slow, "{fast} <= {slow}");
        assert_eq!(RSS.distance(0.0, 30.0), 0.0);
        // Equal speeds and brakes: the response distance and the extra speed gained in it.
        let v: f64 = 25.0;
        let expected = v * 0.5 + 0.5 * 1.5 * 0.25 + ((v + 0.75).powi(2) - v * v) / 12.0;
        assert!((RSS.distance(v, v) - expected).abs() < 1e-12);
    }
}
