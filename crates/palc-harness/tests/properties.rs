//! Property tests of the harness: perceived safety ratio and labelling.

use palc_harness::advanced::{Driver, execute, label, problem};
use palc_harness::user::{ExpectedLaneChange, SimulatedUser, Style, User, first_takeover};
use palc_harness::{LearnConfig, Method, prepare};
use palc_planner::{Planner, PlannerConfig, Weights};
use proptest::prelude::*;

fn setup() -> (palc_harness::Setup, LearnConfig) {
    let text = include_str!("../../../configs/learn.toml");
    let config = LearnConfig::from_toml_str(text).unwrap();
    (prepare(&config).unwrap(), config)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// The ratio is in [0, 1] and equals 1 exactly when there is no takeover, for
    /// any expected lane change against the standard ALC's plan.
    #[test]
    fn perceived_safety_ratio_is_a_ratio(start in 0.0f64..12.0, duration in 1.5f64..3.5) {
        let (setup, config) = setup();
        let standard = setup.standard_lane_change(&config.planning.standard_alc);
        let weights: Weights = config.standard_weights.weights(&standard, setup.horizon, setup.dt);
        let mut planner = Planner::new(PlannerConfig {
            horizon: setup.horizon,
            dt: setup.dt,
            ..config.planner.clone()
        }).unwrap();
        let plan = planner.plan(&problem(&setup, weights, Vec::new())).unwrap();
        let user = SimulatedUser::paper(Style::NEUTRAL).unwrap();
        let mut expectation = user.nominal(&setup.user_scene()).unwrap();
        expectation.lane_change = ExpectedLaneChange::quintic(start, duration, 0.0, 3.5);
        for (i, state) in expectation.states.iter_mut().enumerate() {
            state.l = expectation.lane_change.lateral(i as f64 * setup.dt);
        }
        let drive = execute(&setup, plan, &user, &expectation).unwrap();
        prop_assert!((0.0..=1.0).contains(&drive.perceived_safety_ratio));
        prop_assert_eq!(drive.perceived_safety_ratio == 1.0, drive.takeover.is_none());
        // Who drove: the plan before the takeover, the user's expectation after it,
        // delayed by the steps the user held its lateral position beside a vehicle.
        let planned: Vec<f64> = drive.plan.states.iter().map(|x| x.l).collect();
        prop_assert_eq!(first_takeover(&planned, &drive.expected_l, 0.3), drive.takeover.map(|t| t.step));
        if let Some(t) = drive.takeover {
            for i in 0..t.step {
                prop_assert_eq!(drive.driven[i].l, planned[i]);
            }
            let mut held = 0;
            for i in t.step..drive.driven.len() {
                let l = drive.driven[i].l;
                if (l - drive.expected_l[i - held]).abs() >= 1e-12 {
                    prop_assert!(i > 0 && l == drive.driven[i - 1].l, "step {}: {} is neither the expected path nor a hold", i, l);
                    held += 1;
                }
            }
        } else {
            prop_assert_eq!(drive.driven.len(), planned.len());
        }
    }
}

#[test]
fn labels_follow_who_drove() {
    // The paper: system-driven positions are safe (y = 1), user-driven unsafe (y = 0).
    assert_eq!(label(Method::Paper, Driver::System), Some(true));
    assert_eq!(label(Method::Paper, Driver::User), Some(false));
    assert_eq!(label(Method::Paper, Driver::Rejected), None);
    // palc: what the user accepted or drove is safe, what the user rejected is not.
    assert_eq!(label(Method::Palc, Driver::System), Some(true));
    assert_eq!(label(Method::Palc, Driver::User), Some(true));
    assert_eq!(label(Method::Palc, Driver::Rejected), Some(false));
}

/// Whether, in the test bed's cell (`speed_case`, `headway`, `seed`), neither the
/// standard ALC nor any user starts behind a vehicle the ego has reached; a cell the
/// set-up refuses has nothing to check.
fn no_start_behind_a_negative_gap(
    speed_case: &str,
    headway: f64,
    seed: u64,
    acc: bool,
) -> Result<(), String> {
    let text = include_str!("../../../configs/learn.toml");
    let mut config = LearnConfig::from_toml_str(text).unwrap();
    config = config.with_cell(palc_harness::CellChoice {
        speed_case: speed_case.to_owned(),
        headway_m: headway,
        seed,
    });
    config.planning.acc.enabled = acc;
    let Ok(setup) = prepare(&config) else {
        return Ok(());
    };
    let standard = setup.standard_start_step;
    if setup.situations[standard].time_headway_s <= 0.0 {
        return Err(format!("the standard ALC starts at step {standard}"));
    }
    for preset in palc_harness::StylePreset::ALL {
        if let Some(expected) = setup.expected(&preset.style()) {
            let start = (expected.start_s / setup.dt).round() as usize;
            if setup.situations[start].time_headway_s <= 0.0 {
                return Err(format!("{preset} starts at step {start}"));
            }
        }
    }
    Ok(())
}

#[test]
fn the_standard_alc_does_not_start_after_the_ego_reached_the_preceding_vehicle() {
    // Found by the property below: the standard ALC's start, 0.5 s after the
    // latest user's, came after the ego (at constant speed) had reached the
    // preceding vehicle.
    no_start_behind_a_negative_gap("collector-slow", 33.23906293902501, 935, false).unwrap();
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// In any scene of the test bed, with the ego holding its speed (the paper's
    /// set-up) or under its ACC, no user's expected lane change and not the standard
    /// ALC's starts behind a vehicle the ego has already reached.
    #[test]
    fn no_lane_change_starts_behind_a_negative_gap(
        case in 0usize..4,
        headway in 20.0f64..60.0,
        seed in 1u64..1000,
        acc in any::<bool>(),
    ) {
        let speed_case = ["collector-high", "collector-slow", "arterial-high", "arterial-slow"][case];
        let checked = no_start_behind_a_negative_gap(speed_case, headway, seed, acc);
        prop_assert!(checked.is_ok(), "{:?}", checked);
    }
}
