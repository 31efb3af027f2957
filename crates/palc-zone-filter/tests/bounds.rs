//! The zone in the road plane: boundary, both projections, explicit outcomes,
//! and the resolution tolerance.

mod common;

use common::{config, features_at, fit, linspace, samples_at, scene};
use palc_zone_filter::{
    BoundsConfig, Discriminant, FeatureSet, Label, Projection, StepBounds, ZoneConfig, ZoneModel,
    lateral_bounds, step_boundary,
};
use proptest::prelude::*;

fn bounds_config(projection: Projection) -> BoundsConfig {
    BoundsConfig {
        projection,
        ..BoundsConfig::default()
    }
}

/// Safe samples left of the lane centre, unsafe ones towards the marking.
fn one_sided_model(set: FeatureSet) -> ZoneModel {
    let mut samples = samples_at(set, 0.0, &linspace(-0.6, 0.4, 15), Label::Safe);
    samples.extend(samples_at(set, 0.0, &linspace(1.2, 2.2, 15), Label::Unsafe));
    // Vary s a little so that the longitudinal features are not constant.
    samples.extend(samples_at(set, 2.0, &linspace(-0.6, 0.4, 15), Label::Safe));
    samples.extend(samples_at(set, 2.0, &linspace(1.2, 2.2, 15), Label::Unsafe));
    fit(config(set), &samples)
}

/// Safe everywhere except in a narrow band around l = 1.5 (quadratic discriminant).
fn unsafe_band_model() -> ZoneModel {
    let set = FeatureSet::NoDistance;
    let mut samples = samples_at(set, 0.0, &linspace(-1.5, 5.0, 60), Label::Safe);
    samples.extend(samples_at(set, 0.0, &linspace(1.3, 1.7, 20), Label::Unsafe));
    fit(
        ZoneConfig {
            feature_set: set,
            discriminant: Discriminant::Quadratic,
            ..ZoneConfig::default()
        },
        &samples,
    )
}

#[test]
fn the_linear_boundary_matches_its_analytic_root_within_the_tolerance() {
    // Without distance columns, the linear log-odds is affine in l on a station line.
    let model = one_sided_model(FeatureSet::NoDistance);
    let at = |l: f64| {
        model
            .log_odds_safe(&features_at(FeatureSet::NoDistance, 0.0, l))
            .unwrap()
    };
    let root = at(0.0) / (at(0.0) - at(1.0));
    let config = BoundsConfig::default();
    let boundary = step_boundary(&model, &scene(0.0), &config).unwrap();
    assert_eq!(boundary.crossings.len(), 1);
    assert!(boundary.crossings[0].safe_below);
    assert!(
        (boundary.crossings[0].l - root).abs() <= 0.5 * config.tolerance + 1e-12,
        "{} vs {root}",
        boundary.crossings[0].l
    );
    for projection in [Projection::Paper, Projection::SafeInterval] {
        let bounds = lateral_bounds(&model, &[scene(0.0)], &bounds_config(projection)).unwrap();
        let StepBounds::Bounded { min, max } = bounds[0] else {
            panic!("{projection:?}: {:?}", bounds[0]);
        };
        assert_eq!(min, -1.75, "{projection:?}: safe down to the range edge");
        assert!((max - root).abs() <= 0.5 * config.tolerance + 1e-12);
    }
}

#[test]
fn the_paper_projection_can_return_an_unsafe_interval_and_the_corrected_one_cannot() {
    let model = unsafe_band_model();
    let reference = 1.5;
    let paper = lateral_bounds(
        &model,
        &[scene(reference)],
        &bounds_config(Projection::Paper),
    )
    .unwrap()[0];
    let StepBounds::Bounded { min, max } = paper else {
        panic!("{paper:?}");
    };
    assert!(min > 0.5 && max < 2.5 && min < reference && reference < max);
    let inside = features_at(FeatureSet::NoDistance, 0.0, 0.5 * (min + max));
    assert_eq!(model.classify(&inside).unwrap(), Label::Unsafe);

    let corrected = lateral_bounds(
        &model,
        &[scene(reference)],
        &bounds_config(Projection::SafeInterval),
    )
    .unwrap()[0];
    let StepBounds::Bounded { min, max } = corrected else {
        panic!("{corrected:?}");
    };
    for l in linspace(min + 1e-3, max - 1e-3, 50) {
        let x = features_at(FeatureSet::NoDistance, 0.0, l);
        assert_eq!(model.classify(&x).unwrap(), Label::Safe, "l = {l}");
    }
}

#[test]
fn the_corrected_projection_keeps_the_interval_that_contains_the_reference() {
    let model = unsafe_band_model();
    let boundary = step_boundary(&model, &scene(0.0), &BoundsConfig::default()).unwrap();
    let intervals = boundary.safe_intervals();
    assert_eq!(intervals.len(), 2, "{intervals:?}");
    for (reference, expected) in [(0.0, intervals[0]), (4.0, intervals[1])] {
        let bounds = lateral_bounds(&model, &[scene(reference)], &BoundsConfig::default()).unwrap();
        assert_eq!(
            bounds[0],
            StepBounds::Bounded {
                min: expected[0],
                max: expected[1]
            }
        );
    }
}

#[test]
fn a_step_with_no_safe_point_is_reported_as_such() {
    // Safe samples only far to the right of the searched range.
    let set = FeatureSet::NoDistance;
    let mut samples = samples_at(set, 0.0, &linspace(9.0, 10.0, 10), Label::Safe);
    samples.extend(samples_at(
        set,
        0.0,
        &linspace(-1.0, 4.0, 10),
        Label::Unsafe,
    ));
    let model = fit(config(set), &samples);
    for projection in [Projection::Paper, Projection::SafeInterval] {
        let bounds = lateral_bounds(&model, &[scene(0.0)], &bounds_config(projection)).unwrap();
        assert_eq!(bounds, vec![StepBounds::NoSafeInterval], "{projection:?}");
    }
    // Widening the search range finds the safe stretch.
    let wide = BoundsConfig {
        lateral_range: [-1.75, 12.0],
        ..BoundsConfig::default()
    };
    let bounds = lateral_bounds(&model, &[scene(0.0)], &wide).unwrap();
    assert!(matches!(bounds[0], StepBounds::Bounded { max, .. } if max == 12.0));
}

#[test]
fn a_step_that_is_safe_everywhere_is_unconstrained_not_the_road_edges() {
    let set = FeatureSet::NoDistance;
    let mut samples = samples_at(set, 0.0, &linspace(-1.0, 4.0, 10), Label::Safe);
    samples.extend(samples_at(
        set,
        0.0,
        &linspace(9.0, 10.0, 10),
        Label::Unsafe,
    ));
    let model = fit(config(set), &samples);
    let bounds = lateral_bounds(&model, &[scene(0.0)], &BoundsConfig::default()).unwrap();
    assert_eq!(bounds, vec![StepBounds::Unconstrained]);
}

#[test]
fn the_quadratic_discriminant_can_describe_a_band_around_the_users_path() {
    let set = FeatureSet::NoDistance;
    let mut samples = samples_at(set, 0.0, &linspace(-0.3, 0.3, 20), Label::Safe);
    samples.extend(samples_at(
        set,
        0.0,
        &linspace(-1.7, -1.0, 10),
        Label::Unsafe,
    ));
    samples.extend(samples_at(set, 0.0, &linspace(1.0, 2.5, 10), Label::Unsafe));
    let quadratic = fit(
        ZoneConfig {
            feature_set: set,
            discriminant: Discriminant::Quadratic,
            ..ZoneConfig::default()
        },
        &samples,
    );
    let bounds = lateral_bounds(&quadratic, &[scene(0.0)], &BoundsConfig::default()).unwrap();
    let StepBounds::Bounded { min, max } = bounds[0] else {
        panic!("{:?}", bounds[0]);
    };
    assert!(
        -1.0 < min && min < -0.3 && 0.3 < max && max < 1.0,
        "[{min}, {max}]"
    );
    // The shared covariance gives at most one crossing on a station line here.
    let linear = fit(config(set), &samples);
    let boundary = step_boundary(&linear, &scene(0.0), &BoundsConfig::default()).unwrap();
    assert!(boundary.crossings.len() <= 1);
}

#[test]
fn a_non_finite_scene_names_its_step() {
    let model = one_sided_model(FeatureSet::Paper);
    let mut scenes = vec![scene(0.0); 3];
    scenes[2].adjacent[1] = f64::NAN;
    let err = lateral_bounds(&model, &scenes, &BoundsConfig::default()).unwrap_err();
    assert!(err.to_string().starts_with("step 2 adjacent.l"), "{err}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    #[test]
    fn a_finer_grid_moves_no_bound_by_more_than_the_tolerance(
        reference in -1.5..5.0f64,
        s in -5.0..5.0f64,
        quadratic in any::<bool>(),
    ) {
        let model = if quadratic { unsafe_band_model() } else { one_sided_model(FeatureSet::Paper) };
        let mut step = scene(reference);
        step.ego_s = s;
        let coarse = BoundsConfig::default();
        let fine = BoundsConfig { grid_step: 0.005, tolerance: 1e-5, ..coarse };
        let a = lateral_bounds(&model, &[step], &coarse).unwrap()[0];
        let b = lateral_bounds(&model, &[step], &fine).unwrap()[0];
        match (a, b) {
            (StepBounds::Bounded { min: a0, max: a1 }, StepBounds::Bounded { min: b0, max: b1 }) => {
                prop_assert!((a0 - b0).abs() <= 0.5 * coarse.tolerance + 1e-5, "{a0} vs {b0}");
                prop_assert!((a1 - b1).abs() <= 0.5 * coarse.tolerance + 1e-5, "{a1} vs {b1}");
            }
            _ => prop_assert_eq!(a, b),
        }
    }

    #[test]
    fn safe_interval_bounds_are_ordered_inside_the_range_and_safe(
        reference in -1.75..5.25f64, s in -5.0..5.0f64, quadratic in any::<bool>()
    ) {
        let model = if quadratic { unsafe_band_model() } else { one_sided_model(FeatureSet::Paper) };
        let set = model.config().feature_set;
        let mut step = scene(reference);
        step.ego_s = s;
        let config = BoundsConfig::default();
        if let StepBounds::Bounded { min, max } = lateral_bounds(&model, &[step], &config).unwrap()[0] {
            prop_assert!(config.lateral_range[0] <= min && min < max && max <= config.lateral_range[1]);
            let centre = features_at(set, s, 0.5 * (min + max));
            prop_assert_eq!(model.classify(&centre).unwrap(), Label::Safe);
        }
    }
}
