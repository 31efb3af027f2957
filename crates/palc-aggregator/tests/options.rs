//! The options map one to one onto a TOML table, with defaults and no unknown fields.

use palc_aggregator::{
    AggregatorOptions, CorrectionRule, ExpertKind, IncrementalRule, LearnableRows,
};

#[test]
fn empty_table_gives_the_defaults() {
    let options: AggregatorOptions = toml::from_str("").unwrap();
    assert_eq!(options, AggregatorOptions::default());
    assert_eq!(options.learnable_rows, LearnableRows::from_indices([0, 1]));
    assert!(!options.use_zone);
    options.validate().unwrap();
}

#[test]
fn a_full_table_parses_and_round_trips() {
    let text = r#"
        learnable_rows = ["w1", "w2", "w4"]
        use_zone = true
        feature_scale = [12.25, 3.5, 2.5e-3, 0.05, 0.035, 5e-4, 1.0, 1e-4, 2500.0, 2500.0]

        [expert]
        kind = "zone_centre"
        lateral_weight = 5.0

        [correction]
        rule = "incremental"
        step_size = 0.5
        max_inner_solves = 6

        [convex_set]
        min_curvature = 1e-5

        [bounds]
        projection = "paper"
    "#;
    let options: AggregatorOptions = toml::from_str(text).unwrap();
    options.validate().unwrap();
    assert_eq!(options.learnable_rows.to_string(), "[w1, w2, w4]");
    assert!(matches!(options.expert, ExpertKind::ZoneCentre(e) if e.lateral_weight == 5.0));
    assert_eq!(
        options.correction,
        CorrectionRule::Incremental(IncrementalRule {
            step_size: 0.5,
            max_inner_solves: 6,
            ..IncrementalRule::default()
        })
    );
    let back: AggregatorOptions = toml::from_str(&toml::to_string(&options).unwrap()).unwrap();
    assert_eq!(back, options);
}

#[test]
fn paper_preset_round_trips_and_validates() {
    let paper = AggregatorOptions::paper();
    paper.validate().unwrap();
    let back: AggregatorOptions = toml::from_str(&toml::to_string(&paper).unwrap()).unwrap();
    assert_eq!(back, paper);
}

#[test]
fn unknown_fields_and_bad_values_are_refused() {
    for (text, needle) in [
        ("use_zones = true", "use_zones"),
        ("learnable_rows = [\"w11\"]", "w11"),
        (
            "[expert]\nkind = \"lesson\"\nlateral_weight = 1.0",
            "lateral_weight",
        ),
        ("[expert]\nkind = \"oracle\"", "oracle"),
        (
            "[correction]\nrule = \"apprenticeship\"\nstep_size = 1.0",
            "step_size",
        ),
    ] {
        let err = toml::from_str::<AggregatorOptions>(text).unwrap_err();
        assert!(err.to_string().contains(needle), "{text}: {err}");
    }
    let bad: AggregatorOptions =
        toml::from_str("[correction]\nrule = \"incremental\"\nstep_size = -1.0").unwrap();
    let err = bad.validate().unwrap_err();
    assert_eq!(
        err.to_string(),
        "option `correction.step_size` = -1.0 is out of range: must be finite and > 0"
    );
    let bad: AggregatorOptions =
        toml::from_str("feature_scale = [1, 1, 1, 1, 0, 1, 1, 1, 1, 1]").unwrap();
    assert!(
        bad.validate()
            .unwrap_err()
            .to_string()
            .contains("feature_scale[4] (w5)")
    );
}
