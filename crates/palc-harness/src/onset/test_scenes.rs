//! Scenes, onsets and lane-change shapes the onset module's tests share.

use palc_aggregator::{Onset, SceneSteps, SeenStep};

use super::shape::{Base, Shape};
use crate::setup::Setup;

/// The scene of `configs/learn.toml`, whose target-lane vehicles a test sets.
pub(crate) fn learn_scene() -> Setup {
    let text = include_str!("../../../../configs/learn.toml");
    let config = crate::config::LearnConfig::from_toml_str(text).unwrap();
    crate::scenario::prepare(&config).unwrap()
}

pub(crate) fn onset(headway: f64, ttc: f64, lag: Option<f64>) -> Onset {
    Onset {
        scenario: "s".into(),
        time_s: 1.0,
        time_headway_s: headway,
        ttc_s: Some(ttc),
        gap_m: 20.0 * headway,
        lead_time_gap_s: None,
        lag_time_gap_s: lag,
        rejected_lead_time_gap_s: None,
        time_headway_ceiling_s: None,
        accepted_lead_time_gap_s: None,
        follower_wait_time_headway_s: None,
        observations: 1,
        scene: None,
    }
}

/// The default scene's set-up at arterial-high / 45 m, seed 1 (prepared once).
pub(crate) fn arterial_setup() -> &'static Setup {
    static SETUP: std::sync::OnceLock<Setup> = std::sync::OnceLock::new();
    SETUP.get_or_init(|| {
        let text = include_str!("../../../../configs/learn.toml");
        let config = crate::config::LearnConfig::from_toml_str(text)
            .unwrap()
            .with_cell(crate::config::CellChoice {
                speed_case: "arterial-high".into(),
                headway_m: 45.0,
                seed: 1,
            });
        crate::scenario::prepare(&config).unwrap()
    })
}

/// A scene of an ego at `speed` (m/s) closing on the vehicle ahead at
/// `closing` (m/s) from a time headway of 3 s, the target lane empty, and the
/// onset of a user who decides at the time headway `threshold` in it (the
/// first step at which
/// [`Situation::decides_at`](palc_user::Situation::decides_at) holds), read as the
/// readings read it.
pub(crate) fn onset_of_a_closing_scene(speed: f64, closing: f64, threshold: f64) -> Onset {
    onset_of_a_reacting_driver(speed, closing, threshold, 0)
}

/// [`onset_of_a_closing_scene`] for a user who starts `reaction` steps (of
/// 0.1 s) after deciding.
pub(crate) fn onset_of_a_reacting_driver(
    speed: f64,
    closing: f64,
    threshold: f64,
    reaction: usize,
) -> Onset {
    let dt = 0.1;
    let steps: Vec<SeenStep> = (0..3000)
        .map(|i| SeenStep {
            ego_speed: speed,
            preceding: Some((3.0 * speed - closing * dt * f64::from(i), speed - closing)),
            target_lead: None,
            target_lag: None,
            safe: None,
        })
        .collect();
    let scene = SceneSteps {
        dt,
        set_speed_mps: speed,
        steps,
    };
    let seen = crate::driver::situation;
    let start = (scene.steps.iter())
        .position(|s| seen(s).decides_at(threshold))
        .unwrap()
        + reaction;
    let headway = |i: usize| seen(&scene.steps[i]).time_headway_s;
    Onset {
        time_s: start as f64 * dt,
        time_headway_s: 0.5 * (headway(start) + headway(start - 1)),
        scene: Some(scene),
        ..onset(0.0, 10.0, None)
    }
}

/// Lane-change models of both bases, symmetric and skewed.
pub(crate) fn shapes() -> Vec<Shape> {
    let skewed = |base, peak| Shape { base, peak };
    vec![
        Shape::QUINTIC,
        skewed(Base::HalfSine, 0.5),
        skewed(Base::Quintic, 0.4),
        skewed(Base::Quintic, 0.65),
        skewed(Base::HalfSine, 0.3),
        skewed(Base::HalfSine, 0.72),
    ]
}
