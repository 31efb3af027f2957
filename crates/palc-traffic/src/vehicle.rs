//! Vehicles, their states and what drives them.

use crate::idm::IdmParams;
use crate::road::Lane;
use serde::{Deserialize, Serialize};

/// Identifier of a vehicle within one scene; the ego, when present, is always 0.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct VehicleId(pub u32);

/// Kinematic state of a vehicle in Frenet coordinates; `s` is the position of its front bumper.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct VehicleState {
    /// Longitudinal position of the front bumper (m).
    pub s: f64,
    /// Lateral position of the centre line of the vehicle (m), positive to the left.
    pub l: f64,
    /// Longitudinal speed (m/s), never negative.
    pub v: f64,
    /// Acceleration applied during the last step (m/s^2).
    pub a: f64,
    /// Heading relative to the road (rad), positive to the left.
    pub heading: f64,
}

/// State of the ego supplied from outside at every step (the planner or the harness drives it).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct EgoState {
    /// Longitudinal position of the front bumper (m).
    pub s: f64,
    /// Lateral position (m), positive to the left.
    pub l: f64,
    /// Longitudinal speed (m/s).
    pub v: f64,
    /// Heading relative to the road (rad).
    pub heading: f64,
}

/// What decides a vehicle's motion.
#[derive(Debug, Clone, PartialEq)]
pub enum Driver {
    /// The ego: its state is supplied from outside by [`crate::Scene::step`].
    External {
        /// IDM used only by [`crate::Scene::step_autonomous`], which keeps the ego in its lane.
        stand_in: IdmParams,
    },
    /// A background vehicle following the IDM in its lane.
    Idm(IdmParams),
    /// A vehicle whose speed follows a scripted profile over time (a platoon leader).
    Scripted(SpeedProfile),
}

/// One vehicle of a scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Vehicle {
    /// Identifier, unique within the scene.
    pub id: VehicleId,
    /// Length (m); the rear bumper is at `s - length`.
    pub length: f64,
    /// Width (m), used by the lateral occupancy rule.
    pub width: f64,
    /// Lane the vehicle is in; background vehicles never change lanes, the ego's is the
    /// lane nearest to its lateral position.
    pub lane: Lane,
    /// Current state.
    pub state: VehicleState,
    /// What drives it.
    pub driver: Driver,
}

impl Vehicle {
    /// Position of the rear bumper (m).
    pub fn rear(&self) -> f64 {
        self.state.s - self.length
    }
}

/// A piecewise-linear speed profile over time, held constant before the first and after
/// the last point. Breakpoint times are strictly increasing and speeds non-negative.
#[derive(Debug, Clone, PartialEq)]
pub struct SpeedProfile {
    points: Vec<(f64, f64)>,
}

impl SpeedProfile {
    /// Builds a profile from `(time s, speed m/s)` points; returns `None` when there are no
    /// points, a value is not finite, a speed is negative or times are not strictly increasing.
    pub fn new(points: Vec<(f64, f64)>) -> Option<SpeedProfile> {
        let valid = !points.is_empty()
            && points
                .iter()
                .all(|&(t, v)| t.is_finite() && v.is_finite() && v >= 0.0)
            && points.windows(2).all(|w| w[1].0 > w[0].0);
        valid.then_some(SpeedProfile { points })
    }

    /// The `(time, speed)` breakpoints.
    pub fn points(&self) -> &[(f64, f64)] {
        &self.points
    }

    /// Speed at time `t` (m/s).
    pub fn speed_at(&self, t: f64) -> f64 {
        let first = self.points[0];
        let last = self.points[self.points.len() - 1];
        if t <= first.0 {
            return first.1;
        }
        if t >= last.0 {
            return last.1;
        }
        let i = self.points.partition_point(|&(ti, _)| ti <= t);
        let (t0, v0) = self.points[i - 1];
        let (t1, v1) = self.points[i];
        v0 + (v1 - v0) * (t - t0) / (t1 - t0)
    }

    /// Exact distance travelled between `t0` and `t1 >= t0` (m): the integral of the
    /// piecewise-linear speed, split at the breakpoints inside the interval.
    pub fn distance(&self, t0: f64, t1: f64) -> f64 {
        let mut knots = vec![t0];
        knots.extend(
            self.points
                .iter()
                .map(|&(t, _)| t)
                .filter(|&t| t > t0 && t < t1),
        );
        knots.push(t1);
        knots
            .windows(2)
            .map(|w| 0.5 * (self.speed_at(w[0]) + self.speed_at(w[1])) * (w[1] - w[0]))
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn profile_interpolates_and_integrates_exactly() {
        let profile = SpeedProfile::new(vec![(0.0, 10.0), (2.0, 20.0), (4.0, 20.0)]).unwrap();
        assert!((profile.speed_at(1.0) - 15.0).abs() < 1e-12);
        assert!((profile.speed_at(-1.0) - 10.0).abs() < 1e-12);
        assert!((profile.speed_at(9.0) - 20.0).abs() < 1e-12);
        // 0..2 s: trapezoid 30 m; 2..3 s: 20 m.
        assert!((profile.distance(0.0, 3.0) - 50.0).abs() < 1e-12);
        assert!((profile.distance(1.5, 2.5) - (0.5 * (17.5 + 20.0) * 0.5 + 10.0)).abs() < 1e-12);
    }

    #[test]
    fn invalid_profiles_are_refused() {
        assert!(SpeedProfile::new(vec![]).is_none());
        assert!(SpeedProfile::new(vec![(0.0, 1.0), (0.0, 2.0)]).is_none());
        assert!(SpeedProfile::new(vec![(0.0, -1.0)]).is_none());
        assert!(SpeedProfile::new(vec![(f64::NAN, 1.0)]).is_none());
    }
}
