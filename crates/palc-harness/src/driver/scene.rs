//! A scene as the driver saw it, recorded with an onset and replayed for the
//! estimate.

use palc_aggregator::{SceneSteps, SeenStep};
use palc_user::Situation;

use crate::setup::{Setup, target_gaps_safe};

/// What the driver saw at every step of `setup`, with the safety layer's verdict
/// on the target lane's gaps when the layer is on.
pub(crate) fn scene_steps(setup: &Setup) -> SceneSteps {
    let steps = (setup.situations.iter())
        .map(|s| SeenStep {
            ego_speed: s.ego_speed,
            preceding: s.preceding_speed.map(|speed| (s.preceding_gap_m, speed)),
            target_lead: s.target_lead_gap_m.zip(s.target_lead_speed),
            target_lag: s.target_lag_gap_m.zip(s.target_lag_speed),
            safe: (setup.safety.enforce).then(|| target_gaps_safe(s, &setup.safety)),
        })
        .collect();
    SceneSteps {
        dt: setup.dt,
        set_speed_mps: setup.set_speed,
        steps,
    }
}

/// The situations of recorded steps, as the driver saw them.
pub(crate) fn situations(scene: &SceneSteps) -> Vec<Situation> {
    scene.steps.iter().map(situation).collect()
}

/// The situation of one recorded step, as the driver saw it.
pub(crate) fn situation(step: &SeenStep) -> Situation {
    let gap = step.preceding.map_or(f64::INFINITY, |(gap, _)| gap);
    Situation {
        time_headway_s: gap / step.ego_speed,
        preceding_gap_m: gap,
        preceding_speed: step.preceding.map(|(_, speed)| speed),
        target_lead_gap_m: step.target_lead.map(|(gap, _)| gap),
        target_lag_gap_m: step.target_lag.map(|(gap, _)| gap),
        ego_speed: step.ego_speed,
        target_lead_speed: step.target_lead.map(|(_, speed)| speed),
        target_lag_speed: step.target_lag.map(|(_, speed)| speed),
    }
}
