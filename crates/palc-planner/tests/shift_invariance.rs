//! The optimum does not depend on where the longitudinal origin lies (issue 12,
//! item 4): shifting every `s` of a problem (initial, predicted vehicles, terminal,
//! tracking) by up to 1e9 m gives the same trajectory relative to the shift and the
//! same objective, with both backends. Positions are first rounded to multiples of
//! 2^-20 m, so that each shifted position is exact and the problems are the same.
//!
//! The feature `s δ` (w7) depends on the origin by definition, so it is off here.

mod common;

use common::{convex_problem, lane_change};
use palc_planner::{Backend, Plan, Planner, PlannerConfig, Problem};
use proptest::prelude::*;

/// Rounds `s` to a multiple of 2^-20 m, exact after adding an integer below 2^32.
fn on_grid(s: f64) -> f64 {
    let grid = 2.0_f64.powi(20);
    (s * grid).round() / grid
}

fn prepared(mut problem: Problem) -> Problem {
    for column in problem.weights.columns_mut() {
        column[palc_planner::feature::S_DELTA] = 0.0;
    }
    problem.initial.s = on_grid(problem.initial.s);
    for p in problem
        .preceding
        .iter_mut()
        .chain(problem.adjacent.iter_mut())
    {
        p.s = on_grid(p.s);
    }
    problem.terminal.s = problem.terminal.s.map(on_grid);
    if let Some(t) = &mut problem.tracking {
        for r in t.reference.iter_mut().flatten() {
            r.s = on_grid(r.s);
        }
    }
    problem
}

fn shifted(problem: &Problem, shift: f64) -> Problem {
    let mut out = problem.clone();
    out.initial.s += shift;
    for p in out.preceding.iter_mut().chain(out.adjacent.iter_mut()) {
        p.s += shift;
    }
    out.terminal.s = out.terminal.s.map(|s| s + shift);
    if let Some(t) = &mut out.tracking {
        for r in t.reference.iter_mut().flatten() {
            r.s += shift;
        }
    }
    out
}

/// Checks the plan of the shifted problem against the plan of the original.
fn assert_same(base: &Plan, moved: &Plan, shift: f64) -> Result<(), TestCaseError> {
    let relative = |a: f64, b: f64| (a - b).abs() <= 1e-9 * (1.0 + b.abs());
    prop_assert!(
        relative(moved.objective, base.objective),
        "shift {shift:e}: objective {} vs {}",
        moved.objective,
        base.objective
    );
    // `s` carries the rounding of the shifted position itself (half an ulp of 1e9 m).
    let s_tolerance = 1e-9 + 4.0 * f64::EPSILON * shift.abs();
    for (x, y) in moved.states.iter().zip(&base.states) {
        prop_assert!(
            ((x.s - shift) - y.s).abs() <= s_tolerance,
            "s {} vs {}",
            x.s - shift,
            y.s
        );
        prop_assert!(relative(x.v, y.v) && relative(x.l, y.l) && relative(x.phi, y.phi));
    }
    for (u, w) in moved.controls.iter().zip(&base.controls) {
        prop_assert!(relative(u.a, w.a) && relative(u.delta, w.delta));
    }
    Ok(())
}

fn plan(backend: Backend, config: &PlannerConfig, problem: &Problem) -> Plan {
    Planner::new(PlannerConfig {
        backend,
        ..config.clone()
    })
    .unwrap()
    .plan(problem)
    .unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig {
        rng_seed: proptest::test_runner::RngSeed::Fixed(20261201),
        failure_persistence: None,
        ..ProptestConfig::with_cases(32)
    })]

    #[test]
    fn shifting_the_origin_leaves_the_optimum_unchanged(
        (config, problem) in convex_problem(),
        shift in -999_999_000i64..=999_999_000,
        riccati in prop::bool::ANY,
    ) {
        let backend = if riccati { Backend::Riccati } else { Backend::Clarabel };
        let problem = prepared(problem);
        let base = plan(backend, &config, &problem);
        let shift = shift as f64;
        let moved = plan(backend, &config, &shifted(&problem, shift));
        assert_same(&base, &moved, shift)?;
    }
}

#[test]
fn the_lane_change_is_the_same_a_billion_metres_down_the_road() {
    let config = PlannerConfig {
        horizon: 40,
        ..PlannerConfig::default()
    };
    let problem = prepared(lane_change(&config, 20.1168));
    for backend in [Backend::Riccati, Backend::Clarabel] {
        let base = plan(backend, &config, &problem);
        for shift in [1e3, 1e6, -3e8, 1e9 - 1e3] {
            let moved = plan(backend, &config, &shifted(&problem, shift));
            assert_same(&base, &moved, shift).unwrap();
        }
    }
}
