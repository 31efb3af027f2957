//! Fixtures shared by the integration tests.
#![allow(dead_code)]

use palc_zone_filter::{
    FeatureInput, FeatureSet, Label, Sample, StepScene, ZoneConfig, ZoneModel, features,
};

/// The scene of most tests: preceding 30 m ahead in the ego lane, adjacent 10 m
/// ahead in the target lane, ego at s = 0.
pub const PRECEDING: [f64; 2] = [30.0, 0.0];
pub const ADJACENT: [f64; 2] = [10.0, 3.5];

/// Features of the ego at `(s, l)` in the fixed scene.
pub fn features_at(set: FeatureSet, s: f64, l: f64) -> Vec<f64> {
    let input = FeatureInput {
        ego_s: s,
        ego_l: l,
        ego_speed: 20.0,
        preceding: PRECEDING,
        adjacent: ADJACENT,
    };
    features(set, &input).expect("finite scene")
}

/// Samples at the given lateral positions, all at s = `s`.
pub fn samples_at(set: FeatureSet, s: f64, ls: &[f64], y: Label) -> Vec<Sample> {
    ls.iter()
        .map(|&l| Sample::new(features_at(set, s, l), y))
        .collect()
}

/// `n` evenly spaced values from `a` to `b`.
pub fn linspace(a: f64, b: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| a + (b - a) * k as f64 / (n - 1) as f64)
        .collect()
}

/// The step scene at s = 0 of the fixed scene.
pub fn scene(reference_l: f64) -> StepScene {
    StepScene {
        ego_s: 0.0,
        reference_l,
        ego_speed: 20.0,
        preceding: PRECEDING,
        adjacent: ADJACENT,
    }
}

/// A lesson along a lane change: the system (safe) drove s in [0, 20] m with
/// l rising slowly; the user (unsafe label) drove the same stretch further left.
pub fn lane_change_lesson(set: FeatureSet) -> Vec<Sample> {
    let mut samples = Vec::new();
    for k in 0..40 {
        let s = 0.5 * k as f64;
        let l = 0.05 * k as f64;
        samples.push(Sample::new(features_at(set, s, l), Label::Safe));
        samples.push(Sample::new(features_at(set, s, l + 1.0), Label::Unsafe));
    }
    samples
}

pub fn config(set: FeatureSet) -> ZoneConfig {
    ZoneConfig {
        feature_set: set,
        ..ZoneConfig::default()
    }
}

pub fn fit(config: ZoneConfig, samples: &[Sample]) -> ZoneModel {
    ZoneModel::fit(config, samples).expect("fit succeeds")
}
