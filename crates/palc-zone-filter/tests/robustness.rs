//! One test per error case and per degenerate input the issue lists.

mod common;

use common::{config, features_at, fit, lane_change_lesson, linspace, samples_at, scene};
use palc_zone_filter::{
    BoundsConfig, Discriminant, FeatureInput, FeatureSet, Label, Sample, StepBounds, ZoneConfig,
    ZoneError, ZoneModel, features, lateral_bounds,
};

fn assert_probability(p: f64) {
    assert!((0.0..=1.0).contains(&p), "{p} is not a probability");
}

#[test]
fn a_model_without_samples_is_not_informative_and_bounds_nothing() {
    let mut model = ZoneModel::new(ZoneConfig::default()).unwrap();
    model.update(&[]).unwrap();
    assert!(!model.is_informative());
    assert_eq!(model.theta(), None);
    let x = features_at(FeatureSet::Paper, 0.0, 0.0);
    assert_eq!(
        model.posterior_safe(&x),
        Err(ZoneError::NotInformative {
            safe: 0,
            unsafe_count: 0
        })
    );
    let bounds = lateral_bounds(&model, &[scene(0.0); 3], &BoundsConfig::default()).unwrap();
    assert_eq!(bounds, vec![StepBounds::Unconstrained; 3]);
}

#[test]
fn before_the_first_takeover_only_safe_samples_give_no_bound() {
    let safe = samples_at(
        FeatureSet::Paper,
        0.0,
        &linspace(-0.5, 0.5, 10),
        Label::Safe,
    );
    let model = fit(ZoneConfig::default(), &safe);
    assert!(!model.is_informative());
    assert_eq!(model.theta(), Some(1.0));
    assert!(matches!(
        model.classify(&safe[0].x),
        Err(ZoneError::NotInformative {
            safe: 10,
            unsafe_count: 0
        })
    ));
    let bounds = lateral_bounds(&model, &[scene(0.0)], &BoundsConfig::default()).unwrap();
    assert_eq!(bounds, vec![StepBounds::Unconstrained]);
}

#[test]
fn fewer_samples_than_features_separate_the_two_points_with_a_ridge() {
    // One sample per class has no within-class spread: the ML model has no
    // boundary (every feature is constant within the classes, weight 0), and
    // a positive ridge gives the bisector in standardized units.
    let safe = Sample::new(features_at(FeatureSet::Paper, 0.0, 0.0), Label::Safe);
    let unsafe_ = Sample::new(features_at(FeatureSet::Paper, 0.0, 1.5), Label::Unsafe);
    let ml = fit(ZoneConfig::default(), &[safe.clone(), unsafe_.clone()]);
    assert_eq!(ml.log_odds_safe(&safe.x).unwrap(), 0.0);
    for discriminant in [Discriminant::Linear, Discriminant::Quadratic] {
        let config = ZoneConfig {
            discriminant,
            ridge: 1e-6,
            ..ZoneConfig::default()
        };
        let model = fit(config, &[safe.clone(), unsafe_.clone()]);
        assert!(model.is_informative());
        assert_eq!(model.classify(&safe.x).unwrap(), Label::Safe);
        assert_eq!(model.classify(&unsafe_.x).unwrap(), Label::Unsafe);
        for l in linspace(-1.75, 5.25, 50) {
            assert_probability(
                model
                    .posterior_safe(&features_at(FeatureSet::Paper, 0.0, l))
                    .unwrap(),
            );
        }
    }
}

#[test]
fn a_constant_feature_is_regularized_not_nan() {
    // All samples at the same s: ds_p and ds_a are constant, and dl_p, dl_a,
    // dist_p, dist_a all depend on l alone (rank 1 covariance).
    let mut samples = samples_at(
        FeatureSet::Paper,
        0.0,
        &linspace(-0.5, 0.5, 20),
        Label::Safe,
    );
    samples.extend(samples_at(
        FeatureSet::Paper,
        0.0,
        &linspace(1.0, 2.0, 20),
        Label::Unsafe,
    ));
    for discriminant in [Discriminant::Linear, Discriminant::Quadratic] {
        let model = fit(
            ZoneConfig {
                discriminant,
                ..ZoneConfig::default()
            },
            &samples,
        );
        assert_eq!(
            model
                .classify(&features_at(FeatureSet::Paper, 0.0, -0.2))
                .unwrap(),
            Label::Safe
        );
        assert_eq!(
            model
                .classify(&features_at(FeatureSet::Paper, 0.0, 1.8))
                .unwrap(),
            Label::Unsafe
        );
        // Off the training line (other s) the posterior is still a probability.
        assert_probability(
            model
                .posterior_safe(&features_at(FeatureSet::Paper, 7.0, 0.3))
                .unwrap(),
        );
    }
}

#[test]
fn collinear_and_ill_conditioned_paper_features_are_handled() {
    // dl_p and dl_a are both const - l (exactly collinear) and dist ~ |ds|
    // (condition numbers near 1e14 without regularization).
    let samples = lane_change_lesson(FeatureSet::Paper);
    for discriminant in [Discriminant::Linear, Discriminant::Quadratic] {
        let model = fit(
            ZoneConfig {
                discriminant,
                ..ZoneConfig::default()
            },
            &samples,
        );
        let correct = samples
            .iter()
            .filter(|s| model.classify(&s.x).unwrap() == s.y)
            .count();
        assert!(
            correct as f64 >= 0.95 * samples.len() as f64,
            "{discriminant:?}: {correct} of {} correct",
            samples.len()
        );
        for s in &samples {
            assert_probability(model.posterior_safe(&s.x).unwrap());
        }
    }
}

#[test]
fn an_exactly_singular_covariance_fits_with_weight_zero_on_its_null_directions() {
    // Two identical columns and a constant one: the standardized covariance
    // of the kept features is [[1, 1, 1], [1, 1, 1], [1, 1, 1]].
    let mut samples = Vec::new();
    for k in 0..10 {
        let v = k as f64;
        samples.push(Sample::new(vec![v, v, 1.0, v], Label::Safe));
        samples.push(Sample::new(vec![v + 3.0, v + 3.0, 1.0, v], Label::Unsafe));
    }
    for ridge in [0.0, 1e-6] {
        let model = fit(
            ZoneConfig {
                feature_set: FeatureSet::NoDistance,
                ridge,
                ..ZoneConfig::default()
            },
            &samples,
        );
        assert_eq!(model.classify(&[2.0, 2.0, 1.0, 2.0]).unwrap(), Label::Safe);
        assert_eq!(
            model.classify(&[9.0, 9.0, 1.0, 6.0]).unwrap(),
            Label::Unsafe
        );
        // The constant feature has weight 0.
        assert_eq!(
            model.log_odds_safe(&[2.0, 2.0, 1.0, 2.0]).unwrap(),
            model.log_odds_safe(&[2.0, 2.0, -40.0, 2.0]).unwrap()
        );
    }
}

#[test]
fn non_finite_samples_are_refused_and_leave_the_model_unchanged() {
    let mut model = fit(
        ZoneConfig::default(),
        &lane_change_lesson(FeatureSet::Paper),
    );
    let before = model.clone();
    let mut bad = lane_change_lesson(FeatureSet::Paper);
    bad[5].x[2] = f64::NAN;
    let err = model.update(&bad).unwrap_err();
    assert!(
        matches!(&err, ZoneError::NonFinite { field, .. } if field == "sample 5 feature 2"),
        "{err}"
    );
    assert_eq!(model, before);
    let mut point = features_at(FeatureSet::Paper, 0.0, 0.0);
    point[0] = f64::INFINITY;
    assert!(matches!(
        model.posterior_safe(&point),
        Err(ZoneError::NonFinite { .. })
    ));
}

#[test]
fn wrong_dimensions_are_refused() {
    let mut model = ZoneModel::new(ZoneConfig::default()).unwrap();
    let err = model
        .update(&[Sample::new(vec![1.0; 4], Label::Safe)])
        .unwrap_err();
    assert_eq!(
        err,
        ZoneError::DimensionMismatch {
            what: "sample 0".to_owned(),
            expected: 6,
            found: 4
        }
    );
    let model = fit(
        ZoneConfig::default(),
        &lane_change_lesson(FeatureSet::Paper),
    );
    assert!(matches!(
        model.posteriors_safe_into(&[0.0; 7], &mut [0.0; 1]),
        Err(ZoneError::LengthMismatch {
            expected: 6,
            found: 7,
            ..
        })
    ));
}

#[test]
fn huge_finite_features_overflow_to_a_typed_error_not_nan() {
    let model = fit(
        ZoneConfig {
            discriminant: Discriminant::Quadratic,
            ..ZoneConfig::default()
        },
        &lane_change_lesson(FeatureSet::Paper),
    );
    let err = model.posterior_safe(&[1e200; 6]).unwrap_err();
    assert!(matches!(err, ZoneError::Overflow { .. }), "{err}");
}

#[test]
fn features_on_very_different_scales_give_the_same_zone() {
    // Metres in one column, thousandths of a kilometre in another: the
    // standardization makes the ridge scale-free.
    let lesson = lane_change_lesson(FeatureSet::NoDistance);
    let rescale = |x: &[f64]| vec![x[0] * 1e-3, x[1] * 10.0, x[2] * 1e3, x[3]];
    let rescaled: Vec<Sample> = lesson
        .iter()
        .map(|s| Sample::new(rescale(&s.x), s.y))
        .collect();
    let a = fit(config(FeatureSet::NoDistance), &lesson);
    let b = fit(config(FeatureSet::NoDistance), &rescaled);
    for s in &lesson {
        let (pa, pb) = (
            a.log_odds_safe(&s.x).unwrap(),
            b.log_odds_safe(&rescale(&s.x)).unwrap(),
        );
        assert!((pa - pb).abs() <= 1e-6 * (1.0 + pa.abs()), "{pa} vs {pb}");
    }
}

#[test]
fn invalid_configs_name_the_field() {
    for (config, field) in [
        (
            ZoneConfig {
                ridge: -1.0,
                ..ZoneConfig::default()
            },
            "ridge",
        ),
        (
            ZoneConfig {
                ridge: f64::NAN,
                ..ZoneConfig::default()
            },
            "ridge",
        ),
        (
            ZoneConfig {
                quadratic_pooling: 1.5,
                ..ZoneConfig::default()
            },
            "quadratic_pooling",
        ),
    ] {
        let err = ZoneModel::new(config).unwrap_err();
        assert!(
            matches!(err, ZoneError::InvalidConfig { field: f, .. } if f == field),
            "{err}"
        );
    }
    let model = fit(
        ZoneConfig::default(),
        &lane_change_lesson(FeatureSet::Paper),
    );
    for (bounds, field) in [
        (
            BoundsConfig {
                lateral_range: [2.0, 1.0],
                ..BoundsConfig::default()
            },
            "lateral_range",
        ),
        (
            BoundsConfig {
                grid_step: 0.0,
                ..BoundsConfig::default()
            },
            "grid_step",
        ),
        (
            BoundsConfig {
                tolerance: 0.1,
                grid_step: 0.05,
                ..BoundsConfig::default()
            },
            "tolerance",
        ),
        // A million cells at most, and a bisection that can reach its tolerance.
        (
            BoundsConfig {
                grid_step: 1e-300,
                tolerance: 1e-301,
                ..BoundsConfig::default()
            },
            "grid_step",
        ),
        (
            BoundsConfig {
                tolerance: 1e-17,
                ..BoundsConfig::default()
            },
            "tolerance",
        ),
    ] {
        let err = lateral_bounds(&model, &[scene(0.0)], &bounds).unwrap_err();
        assert!(
            matches!(err, ZoneError::InvalidConfig { field: f, .. } if f == field),
            "{err}"
        );
    }
}

#[test]
fn time_gap_features_need_a_positive_speed() {
    let input = FeatureInput {
        ego_s: 0.0,
        ego_l: 0.0,
        ego_speed: 0.0,
        preceding: [30.0, 0.0],
        adjacent: [10.0, 3.5],
    };
    assert!(matches!(
        features(FeatureSet::TimeGap, &input),
        Err(ZoneError::NonPositiveSpeed { value, .. }) if value == 0.0
    ));
    let moving = FeatureInput {
        ego_speed: 20.0,
        ..input
    };
    assert_eq!(
        features(FeatureSet::TimeGap, &moving).unwrap(),
        vec![1.5, 0.0, 0.5, 3.5]
    );
    assert_eq!(
        features(FeatureSet::Paper, &moving).unwrap(),
        vec![30.0, 0.0, 30.0, 10.0, 3.5, 10.0_f64.hypot(3.5)]
    );
    let nan = FeatureInput {
        preceding: [f64::NAN, 0.0],
        ..moving
    };
    assert!(matches!(
        features(FeatureSet::Paper, &nan),
        Err(ZoneError::NonFinite { field, .. }) if field == "preceding.s"
    ));
}

#[test]
fn stored_models_are_checked_on_load() {
    let model = fit(
        ZoneConfig::default(),
        &lane_change_lesson(FeatureSet::Paper),
    );
    let json = serde_json::to_value(&model).unwrap();
    assert_eq!(json["format_version"], 1);

    let mut future = json.clone();
    future["format_version"] = 2.into();
    let err = serde_json::from_value::<ZoneModel>(future).unwrap_err();
    assert!(err.to_string().contains("format version 2"), "{err}");

    let mut unknown = json.clone();
    unknown["extra"] = 1.into();
    assert!(serde_json::from_value::<ZoneModel>(unknown).is_err());

    let mut short = json.clone();
    short["safe"]["mean"] = serde_json::json!([0.0, 1.0]);
    let err = serde_json::from_value::<ZoneModel>(short).unwrap_err();
    assert!(err.to_string().contains("statistics are invalid"), "{err}");

    let back: ZoneModel = serde_json::from_value(json).unwrap();
    assert!(back.is_informative());
}

#[test]
fn labels_are_zero_or_one() {
    assert_eq!(serde_json::to_string(&Label::Safe).unwrap(), "1");
    assert_eq!(serde_json::from_str::<Label>("0").unwrap(), Label::Unsafe);
    assert!(serde_json::from_str::<Label>("2").is_err());
}

#[test]
fn finite_samples_whose_statistics_overflow_are_refused_and_change_nothing() {
    // 1e308 is finite, but the mean of two such values and their squares are not.
    let mut samples = samples_at(FeatureSet::Paper, 0.0, &[0.0, 1.0, 2.0], Label::Safe);
    for value in [1e308, 1.5e308] {
        let mut x = features_at(FeatureSet::Paper, 0.0, 3.0);
        x[0] = value;
        samples.push(Sample::new(x, Label::Unsafe));
    }
    let mut model = ZoneModel::new(ZoneConfig::default()).unwrap();
    assert_eq!(
        model.update(&samples),
        Err(ZoneError::StatisticsOverflow { class: "unsafe" })
    );
    assert!(!model.is_informative());
    assert_eq!(model.unsafe_statistics().count, 0);
}
