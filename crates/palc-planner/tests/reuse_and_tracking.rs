//! The cached QP structure gives the same plans as a fresh build, and the tracking
//! term reproduces a dynamically consistent reference.

mod common;

use common::lane_change;
use palc_planner::{LateralBound, LateralBoundsMode, Planner, PlannerConfig, Tracking, feature};
use proptest::prelude::*;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(16))]

    #[test]
    fn reused_structure_matches_a_fresh_solver(
        speeds in prop::collection::vec(12.0..30.0f64, 3),
        w1 in 0.0..1.0f64,
    ) {
        let config = PlannerConfig { horizon: 50, dt: 0.1, ..PlannerConfig::default() };
        let mut cached = Planner::new(config.clone()).unwrap();
        for (n, &speed) in speeds.iter().enumerate() {
            let mut problem = lane_change(&config, speed);
            for column in problem.weights.columns_mut() {
                column[0] = w1;
            }
            let a = cached.plan(&problem).unwrap();
            prop_assert_eq!(a.stats.structure_reused, n > 0);
            let b = Planner::new(config.clone()).unwrap().plan(&problem).unwrap();
            prop_assert!(!b.stats.structure_reused);
            for (x, y) in a.states.iter().zip(&b.states) {
                prop_assert!((x.l - y.l).abs() < 1e-5 && (x.s - y.s).abs() < 1e-5);
            }
            prop_assert!((a.objective - b.objective).abs() < 1e-6 * (1.0 + b.objective.abs()));
        }
    }
}

#[test]
fn a_new_bound_pattern_rebuilds_the_structure() {
    let config = PlannerConfig {
        horizon: 30,
        ..PlannerConfig::default()
    };
    let mut planner = Planner::new(config.clone()).unwrap();
    let mut problem = lane_change(&config, 20.0);
    assert!(!planner.plan(&problem).unwrap().stats.structure_reused);
    assert!(planner.plan(&problem).unwrap().stats.structure_reused);
    problem.lateral_bounds[5] = None;
    assert!(!planner.plan(&problem).unwrap().stats.structure_reused);
    problem.terminal.s = Some(600.0 * 0.1);
    let plan = planner.plan(&problem).unwrap();
    assert!(!plan.stats.structure_reused);
    assert!((plan.states[30].s - 60.0).abs() < 1e-6);
}

#[test]
fn strong_tracking_reproduces_a_feasible_reference() {
    let config = PlannerConfig {
        horizon: 40,
        lateral_bounds_mode: LateralBoundsMode::Hard,
        ..PlannerConfig::default()
    };
    let mut planner = Planner::new(config.clone()).unwrap();
    let mut problem = lane_change(&config, 20.0);
    // A reference that is itself a plan (dynamically consistent), from other weights.
    let mut other = problem.clone();
    for column in other.weights.columns_mut() {
        column[0] = 2.0;
    }
    let reference = planner.plan(&other).unwrap();
    problem.tracking = Some(Tracking {
        weights: [1e3, 1e3, 1e5, 1e5],
        reference: reference.states.iter().copied().map(Some).collect(),
    });
    problem.lateral_bounds[20] = Some(LateralBound::new(-1.75, 5.25));
    let plan = planner.plan(&problem).unwrap();
    for (x, r) in plan.states.iter().zip(&reference.states) {
        assert!((x.l - r.l).abs() < 1e-2, "l {} vs reference {}", x.l, r.l);
    }
    assert!(plan.extras.tracking > 0.0);
    // The QP's expansion of the tracking term carries a constant Σ q r² of order 1e8
    // here, so the identity holds to rounding relative to that constant.
    let constant: f64 = reference
        .states
        .iter()
        .map(|r| 1e3 * (r.s * r.s + r.v * r.v) + 1e5 * (r.l * r.l + r.phi * r.phi))
        .sum();
    let total = plan.learned_cost + plan.extras.total();
    assert!((plan.objective - total).abs() <= 1e-12 * (1.0 + constant));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(16))]

    /// The acceleration penalty acts around the reference profile's own acceleration:
    /// without a learned longitudinal term (`w7`, `w9`, `w10` zero), a plan whose
    /// terminal speed and station are the reference's follows the reference speed
    /// profile, whatever its shape (an ACC slowing down behind a vehicle, say).
    #[test]
    fn without_longitudinal_terms_the_plan_follows_the_reference_speed(
        start in 12.0..30.0f64,
        change in -6.0..6.0f64,
        bend in 0.0..1.0f64,
    ) {
        let config = PlannerConfig { horizon: 60, dt: 0.1, ..PlannerConfig::default() };
        let (k, dt) = (config.horizon, config.dt);
        let mut problem = lane_change(&config, start);
        for column in problem.weights.columns_mut() {
            column[feature::S_DELTA] = 0.0;
            column[feature::DIST_PRECEDING] = 0.0;
            column[feature::DIST_ADJACENT] = 0.0;
        }
        // A speed profile from `start` to `start + change`, eased by `bend`.
        let speed = |i: usize| {
            let x = i as f64 / k as f64;
            start + change * ((1.0 - bend) * x + bend * x * x)
        };
        problem.reference_speed = (0..k).map(speed).collect();
        // The forward-Euler station the profile reaches, as the plan's dynamics has it.
        let station: f64 = (0..k).map(|i| speed(i) * dt).sum();
        problem.terminal.v = speed(k);
        problem.terminal.s = Some(station);
        let plan = Planner::new(config.clone()).unwrap().plan(&problem).unwrap();
        for i in 0..k {
            let a_ref = problem.reference_acceleration(i, dt);
            prop_assert!((plan.controls[i].a - a_ref).abs() < 1e-4, "step {i}");
            prop_assert!((plan.states[i].v - speed(i)).abs() < 1e-4, "step {i}");
        }
        prop_assert!(plan.extras.acceleration < 1e-6, "{}", plan.extras.acceleration);
    }
}
