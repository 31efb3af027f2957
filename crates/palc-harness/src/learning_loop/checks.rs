//! The refusals of a scenario in which the user's own lane change is not sane
//! to teach from: the user would take it over itself, it collides under the
//! longitudinal guard, or it enters the target lane beside a vehicle.

use palc_user::{Expectation, User};

use crate::HarnessError;
use crate::drive::{judge, own_lane_change_enters_beside, states_safety};
use crate::refusal::Refusal;
use crate::safety::SafetyMetrics;
use crate::setup::Setup;

/// Refuses `setup` for `user` when its own lane change `nominal` is not sane to
/// teach from, naming the step or the vehicles.
pub(super) fn check_own_lane_change(
    setup: &Setup,
    user: &dyn User,
    nominal: &Expectation,
) -> Result<(), HarnessError> {
    let refused = |refusal: Refusal| HarnessError::Refused {
        scenario: setup.label.clone(),
        refusal: Box::new(refusal),
    };
    // The user's own lane change, driven, must not make it take over (its
    // perceived-safety bound against its own gap acceptance).
    if let Some((step, cause)) = judge(setup, user, nominal, &nominal.states[..=setup.horizon])? {
        return Err(refused(Refusal::OwnLaneChangeTakenOver {
            user: user.name().to_owned(),
            step,
            cause,
        }));
    }
    // Under the longitudinal guard, the user's own lane change driven in the
    // scene must not collide: a scene in which it does has no sane lane change
    // for this user (without the guard, the paper's constant speeds run most of
    // them into the slower target-lane vehicle, and the scene is driven as is).
    if setup.acc.guard {
        let own = states_safety(setup, &nominal.states[..=setup.horizon])?;
        if own.collision {
            return Err(refused(Refusal::OwnLaneChangeCollides {
                user: user.name().to_owned(),
                vehicles: collided_with(&own),
            }));
        }
    }
    // The user's own lane change, driven by the user, must not enter the
    // target lane beside a vehicle of it: the user would hold there, so it
    // would take over any other plan and then teach a hold it does not expect.
    if let Some(step) = own_lane_change_enters_beside(setup, user, nominal)? {
        return Err(refused(Refusal::OwnLaneChangeEntersBeside {
            user: user.name().to_owned(),
            step,
        }));
    }
    Ok(())
}

/// The vehicles a collision of `metrics` overlapped, with their smallest net gap.
fn collided_with(metrics: &SafetyMetrics) -> String {
    let roles = [
        ("the preceding vehicle", metrics.min_gap_preceding_m),
        ("the target lane's lead", metrics.min_gap_target_lead_m),
        ("the target lane's lag", metrics.min_gap_target_lag_m),
    ];
    let overlapped: Vec<String> = (roles.iter())
        .filter_map(|(role, gap)| {
            gap.filter(|g| *g <= 0.0)
                .map(|g| format!("{role} at {g:.1} m"))
        })
        .collect();
    if overlapped.is_empty() {
        "another vehicle".to_owned()
    } else {
        overlapped.join(", ")
    }
}
