//! The accelerating-lag stress scene (`configs/stress/accelerating-lag.toml`): a
//! target-lane vehicle that accelerates into the gap once the ego starts its lane
//! change; with `planning.safety.enforce` the safety layer must refuse the lane
//! change into that closing gap and record why.

use palc_harness::safety::Role;
use palc_harness::{
    LaneChangeRecord, LearnConfig, LearningLoop, Observer, StylePreset, UserConfig,
    safety::Violation,
};

const STRESS: &str = include_str!("../../../configs/stress/accelerating-lag.toml");

/// The stress scene's cell collector-high / 50 m / seed 1 with an aggressive user, the
/// ACC, the safety layer and users who start only into safe gaps on, as
/// `configs/learn-safe.toml` has them.
fn config() -> LearnConfig {
    let mut config = LearnConfig::from_toml_str(STRESS).unwrap();
    config.cell.speed_case = "collector-high".to_owned();
    config.cell.headway_m = 50.0;
    config.cell.seed = 1;
    config.planning.safety.enforce = true;
    config.planning.safety.users_wait_for_safe_gaps = true;
    config.planning.acc.enabled = true;
    config.planning.standard_alc.min_lag_gap_s = 0.8;
    config.with_user(UserConfig::preset(StylePreset::Aggressive))
}

/// Keeps the refusal events the loop reports.
#[derive(Default)]
struct Refusals(Vec<(usize, Violation)>);

impl Observer for Refusals {
    fn safety_refusal(&mut self, lane_change: usize, violation: &Violation) {
        self.0.push((lane_change, *violation));
    }
}

/// The first `n` lane changes of `config`, with the refusals observed.
fn drive(config: &LearnConfig, n: usize) -> (Vec<LaneChangeRecord>, Vec<(usize, Violation)>) {
    let mut run = LearningLoop::new(config, None).unwrap();
    let mut refusals = Refusals::default();
    for _ in 0..n {
        run.step(&mut refusals).unwrap();
    }
    (run.records().to_vec(), refusals.0)
}

#[test]
fn the_safety_layer_refuses_a_lane_change_into_a_gap_the_lag_vehicle_closes() {
    let (records, events) = drive(&config(), 2);
    let violation = records[1]
        .safety_refusal
        .expect("the second lane change's learned plan is refused");
    assert_eq!(violation.role, Role::TargetLag, "{violation}");
    assert!(violation.gap_m < violation.safe_distance_m, "{violation}");
    assert!(
        violation
            .to_string()
            .starts_with("unsafe gap: target-lane lag vehicle"),
        "{violation}"
    );
    assert_eq!(events, vec![(1, violation)]);
    // What was driven instead is safe.
    assert!(records[1].safety.is_safe(), "{:?}", records[1].safety);

    // The same run without the acceleration refuses nothing: the user starts into
    // a gap at the RSS distance, and the learned plan that follows it stays there.
    let mut calm = config();
    calm.traffic.testbed.as_mut().unwrap().lag_accelerating = None;
    let (records, events) = drive(&calm, 2);
    assert!(events.is_empty(), "{events:?}");
    assert!(records.iter().all(|r| r.safety.is_safe()));
}

#[test]
fn a_bad_lag_acceleration_is_refused_naming_the_field() {
    for (field, from, to) in [
        (
            "trigger_lateral_m",
            "trigger_lateral_m = 0.3",
            "trigger_lateral_m = 0.0",
        ),
        (
            "trigger_lateral_m",
            "trigger_lateral_m = 0.3",
            "trigger_lateral_m = 4.0",
        ),
        (
            "acceleration_mps2",
            "acceleration_mps2 = 4.0",
            "acceleration_mps2 = 60.0",
        ),
        ("speed_ratio", "speed_ratio = 1.5", "speed_ratio = 1.0"),
    ] {
        let text = STRESS.replace(from, to);
        assert_ne!(text, STRESS);
        let err = match LearnConfig::from_toml_str(&text) {
            Err(err) => err.to_string(),
            Ok(config) => palc_harness::prepare(&config).unwrap_err().to_string(),
        };
        assert!(
            err.contains(&format!("testbed.lag_accelerating.{field}")),
            "{to}: {err}"
        );
    }
}

#[test]
fn in_closed_loop_the_safety_layer_checks_every_replan_in_the_same_scene() {
    let mut config = config();
    config.planning.closed_loop.enabled = true;
    let (records, events) = drive(&config, 3);
    for record in &records {
        let stats = record.closed_loop.expect("closed-loop records");
        assert!(stats.replans > 0, "{stats:?}");
        assert!(record.safety.is_safe(), "{:?}", record.safety);
        if let Some(violation) = stats.first_refusal {
            assert!(violation.gap_m < violation.safe_distance_m, "{violation}");
        }
    }
    let refused = records
        .iter()
        .filter(|r| r.safety_refusal.is_some())
        .count();
    assert_eq!(events.len(), refused);
    // The second lane change's learned plan is refused at its start, as in open
    // loop, and the standard ALC's weights drive it from there.
    assert_eq!(
        records[1].closed_loop.and_then(|c| c.fallback_step),
        Some(0)
    );
    assert_eq!(
        records[1].safety_refusal.map(|v| v.role),
        Some(Role::TargetLag)
    );
}

#[test]
fn a_user_who_waits_for_safe_gaps_does_not_move_in_ahead_of_a_lag_vehicle_that_closed_the_gap() {
    // The user takes over the first lane change (the standard ALC's plan starts
    // after it) and drives its own; the lag vehicle accelerates once the ego is
    // 0.3 m over. The user looks again before its footprint enters the target
    // lane and holds its lateral position while the gap is below the RSS
    // distance, as it waited for a safe gap before its start.
    let (records, _) = drive(&config(), 2);
    let first = &records[0];
    assert!(
        first.takeover.is_some(),
        "the user drives the first lane change"
    );
    assert_eq!(
        first.user_safety.rss_violations, 0,
        "{:?}",
        first.user_safety
    );
    assert!(!first.user_safety.collision);
    // It held: the driven path lags the expected one somewhere.
    let held = first
        .driven_l
        .iter()
        .zip(&first.expected_l)
        .any(|(driven, expected)| expected - driven > 0.3);
    assert!(held, "the user's path was never held back");
}
