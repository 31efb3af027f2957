//! The closed loop's re-plan (`Planner::replan`) finds the optimum a cold plan finds,
//! starts warm only from the planner's own last plan, and otherwise is `plan`.

mod common;

use common::{convex_problem, lane_change, shifted};
use palc_planner::{LateralBound, LateralBoundsMode, Plan, Planner, PlannerConfig, Problem};
use proptest::prelude::*;

/// Whether two plans are the same optimum to the solver's tolerances: objectives to
/// 1e-6 relative and trajectories to 1e-3 (m, m/s, rad), as in `backends_agree.rs`:
/// both stop at a relative gap of 1e-8, and in the flattest random problems that
/// leaves the lateral position free to about 1e-4.
fn same_optimum(a: &Plan, b: &Plan) -> Result<(), TestCaseError> {
    let scale = 1.0 + b.objective.abs();
    prop_assert!(
        (a.objective - b.objective).abs() <= 1e-6 * scale,
        "objectives {} and {}",
        a.objective,
        b.objective
    );
    for (x, y) in a.states.iter().zip(&b.states) {
        let close = x
            .to_array()
            .iter()
            .zip(y.to_array())
            .all(|(p, q)| (p - q).abs() <= 1e-3);
        prop_assert!(close, "states {x:?} and {y:?}");
    }
    Ok(())
}

/// Plans `first` cold, then `steps` closed-loop re-plans, each checked against a cold
/// plan of the same problem; returns the iterations of the re-plans and of the cold
/// plans.
fn closed_loop(
    config: &PlannerConfig,
    first: Problem,
    steps: usize,
) -> Result<(u32, u32), TestCaseError> {
    let mut planner = Planner::new(config.clone()).unwrap();
    let mut cold = Planner::new(config.clone()).unwrap();
    let mut problem = first;
    let Ok(mut previous) = planner.plan(&problem) else {
        return Ok((0, 0));
    };
    let (mut warm_iterations, mut cold_iterations) = (0, 0);
    for _ in 0..steps {
        problem = shifted(&problem, &previous);
        let reference = cold.plan(&problem);
        let plan = planner.replan(&problem, &previous);
        match (plan, reference) {
            (Ok(plan), Ok(reference)) => {
                same_optimum(&plan, &reference)?;
                warm_iterations += plan.stats.iterations;
                cold_iterations += reference.stats.iterations;
                previous = plan;
            }
            (Err(_), Err(_)) => break,
            (plan, reference) => {
                prop_assert!(false, "re-plan {plan:?}, cold plan {reference:?}");
            }
        }
    }
    Ok((warm_iterations, cold_iterations))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Along a closed loop of random problems (every step bounded, so that the bound
    /// pattern survives the shift and the warm start is taken), each re-plan is the
    /// optimum of a cold plan.
    #[test]
    fn replans_find_the_cold_optimum((config, mut problem) in convex_problem()) {
        for bound in &mut problem.lateral_bounds {
            bound.get_or_insert(LateralBound::new(-1.75, 5.25));
        }
        closed_loop(&config, problem, 4)?;
    }
}

/// On the benchmark's lane change, the re-plans take fewer iterations than cold plans
/// (the warm start is used; iterations, not time, are compared).
#[test]
fn replans_start_warm() {
    for mode in [
        LateralBoundsMode::Hard,
        LateralBoundsMode::Soft { weight: 100.0 },
    ] {
        let config = PlannerConfig {
            horizon: 120,
            dt: 0.05,
            lateral_bounds_mode: mode,
            ..PlannerConfig::default()
        };
        let (warm, cold) = closed_loop(&config, lane_change(&config, 20.0), 10).unwrap();
        assert!(
            warm < cold,
            "{mode:?}: {warm} warm and {cold} cold iterations"
        );
    }
}

/// A `previous` plan that is not the planner's last one, or a changed bound pattern,
/// gives exactly the cold plan.
#[test]
fn replan_from_another_plan_is_a_cold_plan() {
    let config = PlannerConfig {
        horizon: 60,
        dt: 0.1,
        ..PlannerConfig::default()
    };
    let first = lane_change(&config, 20.0);
    let mut planner = Planner::new(config.clone()).unwrap();
    let previous = planner.plan(&first).unwrap();
    let next = shifted(&first, &previous);
    let cold = Planner::new(config.clone()).unwrap().plan(&next).unwrap();
    // Another plan in between: `previous` is no longer the planner's last plan.
    planner.plan(&lane_change(&config, 25.0)).unwrap();
    let replanned = planner.replan(&next, &previous).unwrap();
    assert_eq!(replanned.states, cold.states);
    assert_eq!(replanned.stats.iterations, cold.stats.iterations);
    // A new bound pattern: the warm start does not apply.
    let mut planner = Planner::new(config.clone()).unwrap();
    let previous = planner.plan(&first).unwrap();
    let mut next = shifted(&first, &previous);
    next.lateral_bounds[10] = None;
    let cold = Planner::new(config).unwrap().plan(&next).unwrap();
    let replanned = planner.replan(&next, &previous).unwrap();
    assert_eq!(replanned.states, cold.states);
}

/// A planner carries nothing from one plan to the next but the last plan a re-plan
/// starts from: its buffers are kept between plans and not zeroed, so every entry
/// must be written before it is read. After cold plans and re-plans of another
/// problem, with hard and soft bounds, each plan and re-plan is bit for bit a new
/// planner's.
#[test]
fn a_used_planner_plans_as_a_new_one() {
    for mode in [
        LateralBoundsMode::Hard,
        LateralBoundsMode::Soft { weight: 100.0 },
    ] {
        let config = PlannerConfig {
            horizon: 60,
            dt: 0.1,
            lateral_bounds_mode: mode,
            ..PlannerConfig::default()
        };
        let mut used = Planner::new(config.clone()).unwrap();
        let other = lane_change(&config, 26.0);
        let plan = used.plan(&other).unwrap();
        used.replan(&shifted(&other, &plan), &plan).unwrap();

        let mut new = Planner::new(config.clone()).unwrap();
        let first = lane_change(&config, 18.0);
        let (a, b) = (used.plan(&first).unwrap(), new.plan(&first).unwrap());
        assert_eq!(a.states, b.states, "{mode:?}");
        assert_eq!(a.lateral_violation, b.lateral_violation, "{mode:?}");
        let next = shifted(&first, &a);
        let (a, b) = (
            used.replan(&next, &a).unwrap(),
            new.replan(&next, &b).unwrap(),
        );
        assert_eq!(a.states, b.states, "{mode:?}");
        assert_eq!(a.lateral_violation, b.lateral_violation, "{mode:?}");
        assert_eq!(a.stats.iterations, b.stats.iterations, "{mode:?}");
    }
}
