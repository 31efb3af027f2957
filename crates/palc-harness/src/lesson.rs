//! A taken-over lane change as the aggregator's [`Lesson`]: the positions driven
//! and rejected, labelled by the method's rule (Eq. 2), described by the zone
//! model's own features (Eq. 1 or a variant), and the zone filter's view of each
//! planning step.

use palc_aggregator::{AggregatorOptions, Experience, Lesson};
use palc_planner::State;
use palc_zone_filter::{FeatureInput, FeatureSet, Label, Sample, StepScene, features};

use crate::HarnessError;
use crate::drive::Drive;
use crate::method::{Driver, Method, label};
use crate::setup::Setup;

/// The feature set of the zone the lesson's samples will update: the experience's
/// zone when it has one (the aggregator updates that one), else the zone the
/// options would create.
pub(crate) fn zone_feature_set(experience: &Experience, options: &AggregatorOptions) -> FeatureSet {
    experience
        .zone
        .as_ref()
        .map_or(options.zone.feature_set, |zone| zone.config().feature_set)
}

/// Turns a taken-over lane change into a lesson, labelled by the method's rule,
/// with samples in the zone's `feature_set`.
pub(crate) fn lesson(
    method: Method,
    setup: &Setup,
    drive: &Drive,
    takeover_step: usize,
    feature_set: FeatureSet,
) -> Result<Lesson, HarnessError> {
    let mut samples = Vec::new();
    let mut push = |state: &State, i: usize, driver: Driver| -> Result<(), HarnessError> {
        let Some(safe) = label(method, driver) else {
            return Ok(());
        };
        let x = features(
            feature_set,
            &FeatureInput {
                ego_s: state.s,
                ego_l: state.l,
                // The speed the state was driven at (the ego's ACC changes it).
                ego_speed: state.v.max(setup.ego_speed * 1e-3),
                preceding: drive.preceding[i],
                adjacent: drive.adjacent[i],
            },
        )?;
        samples.push(Sample::new(
            x,
            if safe { Label::Safe } else { Label::Unsafe },
        ));
        Ok(())
    };
    for (i, state) in drive.driven.iter().enumerate() {
        let driver = if i < takeover_step {
            Driver::System
        } else {
            Driver::User
        };
        push(state, i, driver)?;
    }
    for (i, state) in drive.plan.states.iter().enumerate().skip(takeover_step) {
        push(state, i, Driver::Rejected)?;
    }
    Ok(Lesson {
        planned: drive.plan.clone(),
        executed: drive.driven.clone(),
        demonstration: None,
        takeover_step,
        samples,
        step_scenes: scenes(setup, Some(&drive.plan.states)),
    })
}

/// The zone filter's view of each planning step: the previous plan's position and
/// speed (or the ego keeping its lane under its ACC before any plan) and the
/// predicted vehicles.
pub(crate) fn scenes(setup: &Setup, previous: Option<&[State]>) -> Vec<StepScene> {
    (0..=setup.horizon)
        .map(|i| {
            let [keeping_s, keeping_v] = setup.lane_keeping[i];
            let (ego_s, reference_l, ego_speed) = previous
                .map_or((keeping_s, 0.0, keeping_v), |states| {
                    (states[i].s, states[i].l, states[i].v.max(keeping_v * 1e-3))
                });
            StepScene {
                ego_s,
                reference_l,
                ego_speed,
                preceding: setup.preceding[i],
                adjacent: setup.adjacent[i],
            }
        })
        .collect()
}
