//! Fuzz-style property tests of every input format `palc` reads: random bytes,
//! random truncations and random field mutations of the shipped examples in
//! `configs/` (the learn, test-bed, platoon and evaluation configs, the plan problem,
//! the zone config, the zone model that `palc zone fit` writes for the zone example,
//! the samples and points CSVs, the user file `configs/examples/user.toml`) and of
//! the experience file that `palc learn --save-experience` writes for the default
//! config (weights, zone, onsets with their scenes, anchor and demonstration). An
//! accepted experience is also planned from, as `palc learn --experience` does. Each parser must return a typed error or a
//! value that is valid and carries no NaN; none may panic. A zone model or points
//! file that parses is also classified: every posterior must be a probability.
//!
//! The default budget is small (proptest's `PROPTEST_CASES`, 64 cases here); run
//! `PROPTEST_CASES=100000 cargo test -p palc-cli --release fuzz` for a long run.
//!
//! Long run recorded (release, one property at a time, 100,000 cases each, on a
//! two-core machine shared with other builds): every property passed, no failure
//! found. Wall times: learn config 4.6 s, test-bed config 4.1 s, platoon config
//! 3.4 s, evaluation config 10.6 s, plan problem 11.9 s, zone config 16.6 s, zone
//! model 3.4 s, zone samples CSV 17.9 s, zone points CSV 8.2 s; later, experience
//! file 173.9 s (each accepted one planned from) and user file 35.5 s. Most mutated inputs
//! are refused by the parser or the validation, so these times are mostly parsing.

use palc_aggregator::Experience;
use palc_eval::EvalConfig;
use palc_harness::LearnConfig;
use palc_planner::Planner;
use palc_traffic::{ScenarioConfig, Scene};
use std::sync::LazyLock;

use palc_zone_filter::{FeatureSet, ZoneConfig, ZoneModel};
use proptest::prelude::*;
use proptest::test_runner::Config;

use crate::commands::{
    plan::PlanInput,
    zone::{csv_rows, samples_from_csv},
};
use crate::parse;

const LEARN: &str = include_str!("../../../configs/learn.toml");
const TESTBED: &str = include_str!("../../../configs/testbed.toml");
const PLATOON: &str = include_str!("../../../configs/platoon.toml");
const REPRODUCE: &str = include_str!("../../../configs/reproduce.toml");
const PLAN: &str = include_str!("../../../configs/examples/plan-problem.json");
const SAMPLES: &str = include_str!("../../../configs/examples/zone-samples.csv");
const ZONE: &str = include_str!("../../../configs/examples/zone.toml");
const POINTS: &str = include_str!("../../../configs/examples/zone-points.csv");
const USER: &str = include_str!("../../../configs/examples/user.toml");

/// The experience `palc learn --save-experience` writes for the default config,
/// as its JSON text: the example of the experience format.
static EXPERIENCE: LazyLock<&'static str> = LazyLock::new(|| {
    let config = LearnConfig::from_toml_str(LEARN).unwrap();
    let result = palc_harness::run(&config, None, &mut palc_harness::NoObserver).unwrap();
    let path =
        std::env::temp_dir().join(format!("palc-fuzz-experience-{}.json", std::process::id()));
    result.experience.save(&path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let _ = std::fs::remove_file(&path);
    Box::leak(text.into_boxed_str())
});

/// The model that `palc zone fit` writes for the shipped zone example (config and
/// samples), as pretty JSON: the example of the zone-model format.
static MODEL: LazyLock<&'static str> = LazyLock::new(|| {
    let model = ZoneModel::fit(example_zone_config(), &example_samples()).unwrap();
    let mut json = serde_json::to_string_pretty(&model).unwrap();
    json.push('\n');
    Box::leak(json.into_boxed_str())
});

fn example_zone_config() -> ZoneConfig {
    parse::toml(ZONE).unwrap()
}

fn example_samples() -> Vec<palc_zone_filter::Sample> {
    samples_from_csv(SAMPLES.as_bytes(), FeatureSet::Paper).unwrap()
}

/// Classifies `rows` (row-major points of the model's features) as `palc zone
/// classify` does; every posterior it returns must be a probability.
fn classified(model: &ZoneModel, rows: &[f64]) -> Result<(), TestCaseError> {
    let d = model.config().feature_set.dimension();
    let mut p_safe = vec![0.0; rows.len() / d];
    if rows.len() % d == 0 && model.posteriors_safe_into(rows, &mut p_safe).is_ok() {
        prop_assert!(
            p_safe.iter().all(|p| (0.0..=1.0).contains(p)),
            "a posterior is no probability: {p_safe:?}"
        );
    }
    Ok(())
}

/// Values that have broken parsers before: extremes, non-numbers, wrong types.
const NASTY: &[&str] = &[
    "0",
    "-0",
    "-1",
    "1e308",
    "-1e308",
    "1e-308",
    "4294967295",
    "18446744073709551615",
    "1000000",
    "nan",
    "inf",
    "-inf",
    "NaN",
    "\"x\"",
    "[]",
    "{}",
    "true",
    "",
    "0.5",
    "3",
];

/// The budget: `PROPTEST_CASES` if set, else a small one for CI.
fn config() -> Config {
    let cases = std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|c| c.parse().ok())
        .unwrap_or(64);
    Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    }
}

/// The byte ranges of the number-like tokens of `text` (digits, signs, dots, `e`).
fn number_spans(text: &str) -> Vec<(usize, usize)> {
    let bytes = text.as_bytes();
    let mut spans = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i].is_ascii_digit() {
            let start = if i > 0 && bytes[i - 1] == b'-' {
                i - 1
            } else {
                i
            };
            while i < bytes.len()
                && (bytes[i].is_ascii_digit() || matches!(bytes[i], b'.' | b'e' | b'E' | b'-'))
            {
                i += 1;
            }
            spans.push((start, i));
        } else {
            i += 1;
        }
    }
    spans
}

/// One input derived from `example`: a field mutation (most cases), a truncation, or
/// random bytes.
fn mutated(example: &'static str) -> impl Strategy<Value = String> {
    let spans = number_spans(example);
    let count = spans.len().max(1);
    let field = (
        proptest::collection::vec((0..count, 0..NASTY.len()), 1..4),
        any::<bool>(),
    )
        .prop_map(move |(edits, drop_line)| {
            let mut edits: Vec<(usize, &str)> = edits
                .into_iter()
                .filter_map(|(s, v)| spans.get(s).map(|_| (s, NASTY[v])))
                .collect();
            edits.sort_by_key(|e| std::cmp::Reverse(e.0));
            edits.dedup_by_key(|e| e.0);
            let mut text = example.to_owned();
            for (s, value) in edits {
                let (a, b) = spans[s];
                text.replace_range(a..b, value);
            }
            if drop_line {
                // Also remove one line, which may be a whole table header or a field.
                let lines: Vec<&str> = text.lines().collect();
                let k = text.len() % lines.len().max(1);
                let kept: Vec<&str> = (lines.iter().enumerate())
                    .filter(|(i, _)| *i != k)
                    .map(|(_, l)| *l)
                    .collect();
                text = kept.join("\n");
            }
            text
        });
    let truncated = (0..=example.len()).prop_map(move |cut| {
        let mut cut = cut;
        while !example.is_char_boundary(cut) {
            cut -= 1;
        }
        example[..cut].to_owned()
    });
    let bytes = proptest::collection::vec(any::<u8>(), 0..512)
        .prop_map(|b| String::from_utf8_lossy(&b).into_owned());
    prop_oneof![6 => field, 2 => truncated, 1 => bytes]
}

/// A parsed value must not carry a NaN on: no `NaN` in its `Debug` text outside
/// its strings (a name may well contain the letters).
fn no_nan(value: &impl std::fmt::Debug) -> Result<(), TestCaseError> {
    let text = format!("{value:?}");
    let (mut numbers, mut in_string, mut escaped) = (String::new(), false, false);
    for c in text.chars() {
        match (in_string, escaped, c) {
            (true, true, _) => escaped = false,
            (true, false, '\\') => escaped = true,
            (_, false, '"') => in_string = !in_string,
            (false, _, c) => numbers.push(c),
            _ => {}
        }
    }
    prop_assert!(!numbers.contains("NaN"), "a NaN travelled on: {text}");
    Ok(())
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn fuzz_learn_config(text in mutated(LEARN)) {
        // The [traffic] tables are checked when the cell's scene is built, before any
        // run: what must be NaN-free is what the loop is given.
        if let Ok(config) = LearnConfig::from_toml_str(&text) {
            no_nan(&config.stopping)?;
            no_nan(&config.user)?;
            if let Ok(cell) = config.cell() {
                if let Ok(scene) = Scene::for_cell(&config.traffic, &cell) {
                    no_nan(&(cell, scene))?;
                }
            }
        }
    }

    #[test]
    fn fuzz_testbed_config(text in mutated(TESTBED)) {
        // `from_toml_str` checks the road, vehicle and IDM tables; the scenario's own
        // table is checked when a scene is built, which is what a simulation gets.
        if let Ok(config) = ScenarioConfig::from_toml_str(&text) {
            no_nan(&(&config.road, &config.vehicle, &config.idm))?;
            if let Ok(scene) = Scene::from_config(&config, 0) {
                no_nan(&scene)?;
            }
        }
    }

    #[test]
    fn fuzz_platoon_config(text in mutated(PLATOON)) {
        // `from_toml_str` checks the road, vehicle and IDM tables; the scenario's own
        // table is checked when a scene is built, which is what a simulation gets.
        if let Ok(config) = ScenarioConfig::from_toml_str(&text) {
            no_nan(&(&config.road, &config.vehicle, &config.idm))?;
            if let Ok(scene) = Scene::from_config(&config, 0) {
                no_nan(&scene)?;
            }
        }
    }

    #[test]
    fn fuzz_eval_config(text in mutated(REPRODUCE)) {
        if let Ok(config) = EvalConfig::from_toml_str(&text) {
            no_nan(&config)?;
            let base = LearnConfig::from_toml_str(LEARN).unwrap();
            let testbed = base.traffic.testbed.as_ref().unwrap();
            for quick in [true, false] {
                if let Ok(selection) = config.select(quick, testbed) {
                    no_nan(&selection)?;
                    let _ = palc_eval::plan::expand(&selection, testbed);
                }
            }
        }
    }

    #[test]
    fn fuzz_plan_problem(text in mutated(PLAN)) {
        if let Ok(input) = crate::parse::json::<PlanInput>(text.as_bytes()) {
            if let Ok(mut planner) = Planner::new(input.config) {
                if let Ok(plan) = planner.plan(&input.problem) {
                    no_nan(&plan)?;
                }
            }
        }
    }

    #[test]
    fn fuzz_zone_samples(text in mutated(SAMPLES)) {
        if let Ok(samples) = samples_from_csv(text.as_bytes(), FeatureSet::Paper) {
            no_nan(&samples)?;
            if let Ok(model) = ZoneModel::fit(Default::default(), &samples) {
                no_nan(&model)?;
            }
        }
    }

    #[test]
    fn fuzz_zone_config(text in mutated(ZONE)) {
        // As `palc zone fit --config`: parsed, validated, then fitted.
        if let Ok(config) = parse::toml::<ZoneConfig>(&text) {
            if config.validate().is_ok() {
                no_nan(&config)?;
                if let Ok(model) = ZoneModel::fit(config, &example_samples()) {
                    no_nan(&model)?;
                }
            }
        }
    }

    #[test]
    fn fuzz_zone_model(text in mutated(*MODEL)) {
        // As `palc zone classify --model`: parsed (which checks and refits the
        // statistics), then used on the example points.
        if let Ok(model) = parse::json::<ZoneModel>(text.as_bytes()) {
            no_nan(&model)?;
            let rows: Vec<f64> = csv_rows(POINTS.as_bytes(), model.config().feature_set, false)
                .unwrap()
                .into_iter()
                .flat_map(|(x, _)| x)
                .collect();
            classified(&model, &rows)?;
        }
    }

    #[test]
    fn fuzz_experience(text in mutated(*EXPERIENCE)) {
        // As `palc learn --experience`: parsed and checked, then planned from.
        static CONFIG: LazyLock<LearnConfig> =
            LazyLock::new(|| LearnConfig::from_toml_str(LEARN).unwrap());
        let path = std::path::Path::new("experience.json");
        if let Ok(experience) = Experience::from_json(text.as_bytes(), path) {
            no_nan(&experience)?;
            if let Ok(run) = palc_harness::LearningLoop::new(&CONFIG, Some(&experience)) {
                no_nan(&run.next_plan().states)?;
            }
        }
    }

    #[test]
    fn fuzz_user_file(text in mutated(USER)) {
        // As `palc learn --user`: parsed and checked, then asked for its lane change.
        static CONFIG: LazyLock<LearnConfig> =
            LazyLock::new(|| LearnConfig::from_toml_str(LEARN).unwrap());
        let threshold = CONFIG.planning.takeover_threshold_m;
        if let Ok(user) = palc_harness::UserConfig::from_toml_str(&text, threshold) {
            no_nan(&user)?;
            let config = CONFIG.clone().with_user(user);
            if let Ok(run) = palc_harness::LearningLoop::new(&config, None) {
                no_nan(&run.next_plan().states)?;
            }
        }
    }

    #[test]
    fn fuzz_zone_points(text in mutated(POINTS)) {
        static FITTED: LazyLock<ZoneModel> =
            LazyLock::new(|| ZoneModel::fit(example_zone_config(), &example_samples()).unwrap());
        if let Ok(rows) = csv_rows(text.as_bytes(), FeatureSet::Paper, false) {
            no_nan(&rows)?;
            let rows: Vec<f64> = rows.into_iter().flat_map(|(x, _)| x).collect();
            classified(&FITTED, &rows)?;
        }
    }
}

#[test]
fn the_shipped_examples_parse() {
    LearnConfig::from_toml_str(LEARN).unwrap();
    for text in [TESTBED, PLATOON] {
        let config = ScenarioConfig::from_toml_str(text).unwrap();
        Scene::from_config(&config, 0).unwrap();
    }
    EvalConfig::from_toml_str(REPRODUCE).unwrap();
    palc_harness::UserConfig::from_toml_str(USER, 0.3).unwrap();
    let experience =
        Experience::from_json(EXPERIENCE.as_bytes(), std::path::Path::new("e.json")).unwrap();
    assert!(experience.metadata.lessons > 0, "{:?}", experience.metadata);
    assert!(!experience.onsets.is_empty() && experience.demonstration.is_some());
    let input: PlanInput = crate::parse::json(PLAN.as_bytes()).unwrap();
    Planner::new(input.config)
        .unwrap()
        .plan(&input.problem)
        .unwrap();
    let model = ZoneModel::fit(example_zone_config(), &example_samples()).unwrap();
    assert!(model.is_informative());
    assert_eq!(parse::json::<ZoneModel>(MODEL.as_bytes()).unwrap(), model);
    let points = csv_rows(POINTS.as_bytes(), FeatureSet::Paper, false).unwrap();
    assert_eq!(points.len(), 18);
}
