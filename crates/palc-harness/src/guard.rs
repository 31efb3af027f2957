//! The longitudinal guard: whatever drives the ego (a lane-change plan, a re-plan,
//! the user after a takeover), it never accelerates beyond what the ACC would
//! command behind the vehicle ahead.
//!
//! The paper holds every speed constant per speed case, and so does a plan made at
//! those speeds: an ego that moves over behind a slower target-lane vehicle keeps
//! closing on it until the horizon ends
//! (docs/experiments/0034-the-longitudinal-guard.md). A production lane-change
//! assistant runs on top of the ACC, which keeps braking for the vehicle ahead
//! while the lateral controller changes lanes. The guard is that ACC underneath: at
//! each step the ego's acceleration is
//!
//! ```text
//! a = min( a_drive,  a_limit )
//! a_limit = max( k_s (g − s_0 − T v) + k_v (v_l − v),  −b )    behind a vehicle in a lane the ego moved into
//! a_limit = ∞                                                 behind one in the lane it started in
//! ```
//!
//! each with the ACC's emergency branch (the kinematic deceleration
//! `(v − v_l)² / (2 (g − s_0))`, up to the emergency limit, when `b` cannot match
//! speeds before the standstill gap), over the nearest vehicle ahead in each lane
//! the ego's body occupies. In its start lane only the emergency brake acts: the
//! approach there is the one the users' start rules were judged on (the paper's
//! constant speed, or the ACC's when it is on), and braking earlier moved the ego
//! away from where the plan moves over. The law has no cruise term and no
//! acceleration limit: on a free road, or far enough behind, it changes nothing.
//! The lateral path is the driver's (plan or user) at each step; only the speed
//! and the station along the road change. A plan the guard never limits is driven
//! bit for bit.

use palc_planner::State;
use palc_traffic::{Driver, Scene, Vehicle, ballistic_step};

use crate::HarnessError;
use crate::acc::AccConfig;
use crate::setup::Setup;

impl AccConfig {
    /// The guard's limit on the ego's acceleration at speed `v` behind `leader` =
    /// (net gap, leader speed) in a lane the ego has moved into: the ACC's
    /// time-gap law without its cruise term and acceleration limit, and its
    /// emergency branch. `None` when the guard is off.
    ///
    /// Not RSS's response of [`AccConfig::acceleration_keeping`]: under the safety
    /// layer every plan is checked safe before it is driven, and braking at RSS's
    /// `b_min` a second of closing speed before the safe distance (as the ACC does
    /// when it drives) made plans the layer had let through close the gap to the
    /// target lane's lag, and the layer then refused them
    /// (docs/experiments/0034-the-longitudinal-guard.md).
    pub(crate) fn guard_following(&self, v: f64, (gap, leader_v): (f64, f64)) -> Option<f64> {
        if !self.guard {
            return None;
        }
        let comfortable = self
            .following(v, gap, leader_v)
            .max(-self.comfort_deceleration_mps2);
        Some(self.emergency(v, gap, leader_v).unwrap_or(comfortable))
    }

    /// The guard's limit behind `leader` in the ego's own lane: the emergency
    /// branch alone, an automatic emergency brake. `None` when the guard is off or
    /// comfortable braking would still match the leader's speed in time.
    pub(crate) fn guard_emergency(&self, v: f64, (gap, leader_v): (f64, f64)) -> Option<f64> {
        self.guard
            .then(|| self.emergency(v, gap, leader_v))
            .flatten()
    }
}

/// The guard's limit on the ego's acceleration at speed `v` in `scene`: over the
/// nearest vehicle ahead in each lane the ego's body occupies, the emergency brake
/// behind one in the lane the ego started in, the ACC's following law behind one
/// in another lane. Infinite when nothing limits.
fn guard_limit(setup: &Setup, scene: &Scene, v: f64) -> f64 {
    let Some(ego) = scene.ego() else {
        return f64::INFINITY;
    };
    let start_lane = setup.scene.ego().map(|e| e.lane);
    let road = scene.road();
    let mut nearest: Vec<&Vehicle> = Vec::new();
    for other in scene.vehicles() {
        if matches!(other.driver, Driver::External { .. })
            || other.state.s <= ego.state.s
            || !road.occupies(ego.state.l, ego.width, other.lane)
        {
            continue;
        }
        match nearest.iter_mut().find(|n| n.lane == other.lane) {
            Some(n) if other.state.s < n.state.s => *n = other,
            Some(_) => {}
            None => nearest.push(other),
        }
    }
    let acc = &setup.acc;
    nearest
        .iter()
        .filter_map(|leader| {
            let leader_gap = (leader.rear() - ego.state.s, leader.state.v);
            if Some(leader.lane) == start_lane {
                acc.guard_emergency(v, leader_gap)
            } else {
                acc.guard_following(v, leader_gap)
            }
        })
        .fold(f64::INFINITY, f64::min)
}

/// Speeds and stations that differ by less than this are the plan's: a trajectory
/// the guard has already limited, driven again in the same scene, is not limited
/// twice by rounding.
const ON_PLAN_TOLERANCE: f64 = 1e-9;

/// The state the ego reaches at the next step when the system drives from
/// `previous` (the state driven) towards `planned` (the plan's next state, whose
/// previous state is `planned_previous`) in `scene` (the scene at `previous`).
///
/// On the plan and within the guard's limit, `planned` itself. Otherwise the ego
/// tracks the plan's speed (the plan's acceleration plus the ACC's speed gain
/// times the speed it lags by) under the guard's limit, on the plan's lateral path.
pub(crate) fn guarded_step(
    setup: &Setup,
    scene: &Scene,
    previous: &State,
    planned_previous: &State,
    planned: &State,
) -> State {
    let dt = setup.dt;
    let planned_acceleration = (planned.v - planned_previous.v) / dt;
    let limit = guard_limit(setup, scene, previous.v);
    let on_plan = (previous.s - planned_previous.s).abs() <= ON_PLAN_TOLERANCE
        && (previous.v - planned_previous.v).abs() <= ON_PLAN_TOLERANCE;
    if on_plan && planned_acceleration <= limit + ON_PLAN_TOLERANCE {
        return *planned;
    }
    let tracking = planned_acceleration + setup.acc.speed_gain * (planned_previous.v - previous.v);
    let moved = ballistic_step(previous.v, tracking.min(limit), dt);
    State {
        s: previous.s + moved.distance,
        v: moved.speed,
        l: planned.l,
        phi: planned.phi,
    }
}

/// Drives `states` (plan frame) under the guard in `scene`, which is at
/// `states[0]`: calls `visit(i, driven, scene)` with the state driven at each step
/// `i` and the scene there, from step 0, until it returns `true` or the states end.
///
/// # Errors
/// A scene error while driving.
pub(crate) fn drive_states(
    setup: &Setup,
    scene: &mut Scene,
    states: &[State],
    mut visit: impl FnMut(usize, &State, &Scene) -> bool,
) -> Result<(), HarnessError> {
    let Some(&first) = states.first() else {
        return Ok(());
    };
    let mut driven = first;
    for i in 0..states.len() {
        if i > 0 {
            driven = guarded_step(setup, scene, &driven, &states[i - 1], &states[i]);
            scene.step(setup.dt, setup.ego_state(&driven))?;
        }
        if visit(i, &driven, scene) {
            break;
        }
    }
    Ok(())
}

/// The guard's limit on the acceleration a user chose after a takeover.
pub(crate) fn guarded_user_acceleration(setup: &Setup, scene: &Scene, v: f64, chosen: f64) -> f64 {
    chosen.min(guard_limit(setup, scene, v))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn far_behind_the_guard_does_not_limit_and_off_it_never_does() {
        let acc = AccConfig::default();
        let far = acc.guard_following(20.0, (200.0, 18.0));
        assert!(
            far.is_some_and(|a| a > acc.max_acceleration_mps2),
            "{far:?}"
        );
        assert_eq!(acc.guard_emergency(20.0, (10.0, 17.8)), None);
        let off = AccConfig {
            guard: false,
            ..acc
        };
        assert_eq!(off.guard_following(20.0, (5.0, 10.0)), None);
        assert_eq!(off.guard_emergency(20.0, (3.0, 10.0)), None);
    }

    #[test]
    fn closing_on_a_slower_vehicle_the_guard_brakes_as_the_acc_would() {
        // The guard is on whether or not the ACC drives the approach.
        let off = AccConfig::default();
        let on = AccConfig {
            enabled: true,
            ..off
        };
        for acc in [off, on] {
            // 10 m behind a vehicle 2.2 m/s slower at 20 m/s: inside the time gap.
            let limit = acc.guard_following(20.0, (10.0, 17.8));
            let law = on.acceleration(20.0, 20.0, Some((10.0, 17.8)));
            assert!(limit.is_some_and(|a| a < 0.0), "{limit:?}");
            assert_eq!(limit, Some(law));
        }
        // Closing at 10 m/s with 12 m of room: the emergency branch, 5 m/s^2, in
        // the ego's own lane too.
        for limit in [
            off.guard_following(20.0, (12.0, 10.0)),
            off.guard_emergency(20.0, (12.0, 10.0)),
        ] {
            assert!(limit.is_some_and(|a| (a + 5.0).abs() < 1e-12), "{limit:?}");
        }
    }
}
