//! Closed-loop execution (`[planning.closed_loop]`): with exact predictions it
//! drives the one-shot plan, so the user takes over where they would in open
//! loop; its config is checked naming the field; its record round-trips.

use palc_aggregator::{AggregatorOptions, Experience, plan_problem};
use palc_harness::advanced::{execute, problem};
use palc_harness::closed_loop::ClosedLoop;
use palc_harness::user::{SimulatedUser, User};
use palc_harness::{
    LearnConfig, Setup, StylePreset,
    config::{PlanningConfig, StandardWeights},
    record::ClosedLoopStats,
    safety::Violation,
};
use palc_planner::{Planner, PlannerConfig};
use palc_traffic::{
    Driver, IdmParams, Lane, Road, Scene, SpeedProfile, Vehicle, VehicleId, VehicleState,
};

fn vehicle(id: u32, lane: Lane, s: f64, v: f64, driver: Driver) -> Vehicle {
    Vehicle {
        id: VehicleId(id),
        length: 5.0,
        width: 1.8,
        lane,
        state: VehicleState {
            s,
            l: Road::paper().lane_centre(lane),
            v,
            a: 0.0,
            heading: 0.0,
        },
        driver,
    }
}

/// A scene in which nothing reacts to the ego: a slower preceding vehicle and a
/// target-lane vehicle far ahead, both at scripted constant speeds, so that every
/// prediction is exact.
fn scripted_scene() -> Scene {
    let constant = |v: f64| Driver::Scripted(SpeedProfile::new(vec![(0.0, v)]).unwrap());
    let ego = vehicle(
        0,
        Lane(0),
        20.0,
        20.0,
        Driver::External {
            stand_in: IdmParams::treiber_2000(20.0),
        },
    );
    Scene::new(
        Road::paper(),
        vec![
            ego,
            vehicle(1, Lane(0), 80.0, 15.0, constant(15.0)),
            vehicle(2, Lane(1), 150.0, 20.0, constant(20.0)),
        ],
        9.0,
    )
    .unwrap()
    .with_roles(VehicleId(1), VehicleId(2))
    .unwrap()
}

/// The scripted scene's set-up, the standard ALC's weights as an experience,
/// `palc`'s options, the planner's config, the problem template and its plan.
fn standard_plan() -> (
    Setup,
    Experience,
    AggregatorOptions,
    PlannerConfig,
    palc_planner::Problem,
    palc_planner::Plan,
) {
    let planning = PlanningConfig::default();
    let setup = Setup::new(&scripted_scene(), &planning, "scripted").unwrap();
    let (k, dt) = (setup.horizon, setup.dt);
    let standard = setup.standard_lane_change(&planning.standard_alc);
    let weights = StandardWeights::default().weights(&standard, k, dt);
    let experience = Experience::new("aggressive", "scripted", "palc", weights, dt).unwrap();
    let options = AggregatorOptions::default();
    let config = PlannerConfig {
        horizon: k,
        dt,
        ..PlannerConfig::default()
    };
    let mut planner = Planner::new(config.clone()).unwrap();
    let template = problem(&setup, experience.weights.clone(), Vec::new());
    let (first, _) = plan_problem(&planner, &experience, &template, &[], &options).unwrap();
    let plan = planner.plan(&first).unwrap();
    (setup, experience, options, config, template, plan)
}

#[test]
fn with_exact_predictions_the_closed_loop_sees_the_open_loop_takeover() {
    let (setup, experience, options, planner, _, plan) = standard_plan();
    let k = setup.horizon;
    let user = SimulatedUser::paper(StylePreset::Aggressive.style()).unwrap();
    let expected = user.nominal(&setup.user_scene()).unwrap();

    let open = execute(&setup, plan.clone(), &user, &expected).unwrap();
    let driver = ClosedLoop::new(planner, 1, None).unwrap();
    let (driven, stats) = driver
        .drive(&setup, &experience, &options, &plan, false)
        .unwrap();
    assert_eq!(stats.replans, k - 2, "{stats:?}");
    assert_eq!(stats.replan_failures, 0);
    let closed = execute(&setup, driven, &user, &expected).unwrap();

    let open_takeover = open
        .takeover
        .expect("the aggressive user takes over the standard plan");
    let closed_takeover = closed.takeover.expect("and the closed loop's");
    assert_eq!(open_takeover.step, closed_takeover.step);
    assert!((open_takeover.deviation_m - closed_takeover.deviation_m).abs() < 1e-3);
    // What the system drove is the one-shot plan, to the solver's tolerance.
    for (a, b) in open.plan.states.iter().zip(&closed.plan.states) {
        assert!((a.l - b.l).abs() < 1e-3, "{} vs {}", a.l, b.l);
        assert!((a.s - b.s).abs() < 1e-2, "{} vs {}", a.s, b.s);
    }
}

#[test]
fn the_replan_period_is_checked_naming_the_field() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../configs/learn.toml"
    ))
    .unwrap();
    let base = LearnConfig::from_toml_str(&text).unwrap();
    assert!(!base.planning.closed_loop.enabled);
    // Disabled, the period need not be a multiple of the step (the timing
    // experiment runs at 0.2 s), but it must still be a period.
    let with = text.replace("replan_period_s = 0.1 ", "replan_period_s = 0.15 ");
    LearnConfig::from_toml_str(&with).unwrap();
    let with = text.replace("replan_period_s = 0.1 ", "replan_period_s = -1.0 ");
    let err = LearnConfig::from_toml_str(&with).unwrap_err().to_string();
    assert!(
        err.contains("planning.closed_loop.replan_period_s"),
        "{err}"
    );
    let text = text.replace(
        "enabled = false                    # off: one plan",
        "enabled = true # one plan",
    );
    for (period, bound) in [
        ("0.0", "> 0"),
        ("-0.1", "> 0"),
        ("0.15", "multiple of planning.dt"),
        ("0.05", "multiple of planning.dt"),
    ] {
        let with = text.replace(
            "replan_period_s = 0.1 ",
            &format!("replan_period_s = {period} "),
        );
        let err = LearnConfig::from_toml_str(&with).unwrap_err().to_string();
        assert!(
            err.contains("planning.closed_loop.replan_period_s") && err.contains(bound),
            "{period}: {err}"
        );
    }
    let with = text.replace("replan_period_s = 0.1 ", "replan_period_s = 0.3 ");
    LearnConfig::from_toml_str(&with).unwrap();
    // Longer than the horizon: refused when the scenario is prepared.
    let with = text
        .replace(
            "enabled = false                    # off: one plan",
            "enabled = true # one plan",
        )
        .replace("replan_period_s = 0.1 ", "replan_period_s = 50.0 ");
    let config = LearnConfig::from_toml_str(&with).unwrap();
    assert!(config.planning.closed_loop.enabled);
    let err = palc_harness::LearningLoop::new(&config, None)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("planning.closed_loop.replan_period_s") && err.contains("at most the horizon"),
        "{err}"
    );
}

#[test]
fn closed_loop_stats_round_trip_through_json() {
    let stats = ClosedLoopStats {
        replans: 41,
        replan_failures: 1,
        refusals: 2,
        fallback_step: Some(12),
        first_refusal: Some(Violation {
            step: 12,
            role: palc_harness::safety::Role::TargetLag,
            vehicle: 4,
            gap_m: 6.1,
            safe_distance_m: 14.2,
        }),
    };
    let text = serde_json::to_string(&stats).unwrap();
    let back: ClosedLoopStats = serde_json::from_str(&text).unwrap();
    assert_eq!(back, stats);
}

/// The base learning config with the closed loop on, re-planning every 0.5 s.
fn closed_loop_config() -> LearnConfig {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../configs/learn.toml"
    ))
    .unwrap();
    let mut config = LearnConfig::from_toml_str(&text).unwrap();
    config.planning.closed_loop.enabled = true;
    config.planning.closed_loop.replan_period_s = 0.5;
    config
}

#[test]
fn a_closed_loop_run_records_its_replans_and_round_trips() {
    let mut config = closed_loop_config();
    config.stopping.max_takeovers = 2;
    let mut run = palc_harness::LearningLoop::new(&config, None).unwrap();
    let record = run.step(&mut palc_harness::NoObserver).unwrap().clone();
    let stats = record.closed_loop.expect("a closed-loop record");
    assert!(stats.replans > 0, "{stats:?}");
    let text = serde_json::to_string(&record).unwrap();
    let back: palc_harness::LaneChangeRecord = serde_json::from_str(&text).unwrap();
    assert_eq!(back, record);
    // An open-loop record written before the field existed still reads.
    let mut value: serde_json::Value = serde_json::from_str(&text).unwrap();
    value.as_object_mut().unwrap().remove("closed_loop");
    let old: palc_harness::LaneChangeRecord = serde_json::from_value(value).unwrap();
    assert_eq!(old.closed_loop, None);
}

/// `ClosedLoop::plan_at_speeds`: the re-plans follow the speeds the learning loop's
/// plans follow (a user's, with `follow_user_speed`), not the scenario's.
#[test]
fn the_replans_follow_the_speeds_they_are_given() {
    let (setup, experience, options, planner_config, template, plan) = standard_plan();
    let k = setup.horizon;
    let scenario_speed = template.terminal.v;
    // 2 m/s slower by the middle of the horizon, as a user who slows down.
    let slower: Vec<f64> = (0..k)
        .map(|i| scenario_speed - 2.0 * (2.0 * i as f64 / k as f64).min(1.0))
        .collect();
    let terminal = palc_planner::Terminal {
        v: scenario_speed - 2.0,
        ..template.terminal
    };
    let end_speed = |driver: &ClosedLoop| {
        let (driven, stats) = driver
            .drive(&setup, &experience, &options, &plan, false)
            .unwrap();
        assert_eq!(stats.replan_failures, 0);
        driven.states.last().unwrap().v
    };
    let scenario = ClosedLoop::new(planner_config.clone(), 1, None).unwrap();
    let mut following = ClosedLoop::new(planner_config, 1, None).unwrap();
    following.plan_at_speeds(&slower, terminal).unwrap();
    // A reference of another length, or a speed that is not one, is refused.
    let err = following
        .plan_at_speeds(&slower[1..], terminal)
        .unwrap_err();
    assert!(
        err.to_string().contains("closed_loop.reference_speed"),
        "{err}"
    );
    let mut nan = slower.clone();
    nan[3] = f64::NAN;
    let err = following.plan_at_speeds(&nan, terminal).unwrap_err();
    assert!(
        err.to_string().contains("closed_loop.reference_speed[3]"),
        "{err}"
    );
    let (kept, followed) = (end_speed(&scenario), end_speed(&following));
    assert!(
        (kept - scenario_speed).abs() < 0.1,
        "{kept} vs {scenario_speed}"
    );
    assert!(
        (followed - terminal.v).abs() < 0.1,
        "{followed} vs {}",
        terminal.v
    );
}

/// A lane change after a lesson that could not be learned drives the same plan
/// with the same experience; the learning loop hands back the drive before it
/// instead of re-planning again, and what it hands back is the drive computed
/// afresh.
#[test]
fn a_closed_loop_drive_repeated_after_a_failed_lesson_is_the_one_driven_afresh() {
    let mut config = closed_loop_config();
    config.method = palc_harness::Method::Paper;
    config.stopping.max_takeovers = 4;
    let options = palc_harness::advanced::aggregator_options(&config);
    let mut run = palc_harness::LearningLoop::new(&config, None).unwrap();
    let setup = run.setup().clone();
    let planner = PlannerConfig {
        horizon: setup.horizon,
        dt: setup.dt,
        lateral_bounds_mode: palc_planner::LateralBoundsMode::Hard,
        ..config.planner.clone()
    };
    let period = config.planning.closed_loop.period_steps(setup.dt);
    let driver = ClosedLoop::new(planner, period, None).unwrap();
    let mut repeats = 0;
    let mut failed_before = false;
    for _ in 0..4 {
        let (afresh, stats) = driver
            .drive(&setup, run.experience(), &options, run.next_plan(), false)
            .unwrap();
        let record = run.step(&mut palc_harness::NoObserver).unwrap();
        assert_eq!(record.closed_loop, Some(stats));
        let planned: Vec<f64> = afresh.states.iter().map(|x| x.l).collect();
        assert_eq!(record.planned_l, planned);
        repeats += usize::from(failed_before);
        failed_before = record.learning_error.is_some();
    }
    assert!(repeats > 0, "the paper's lessons are expected to fail here");
}
