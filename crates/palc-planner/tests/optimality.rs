//! Property tests over random convex problems: feasibility, the objective identity
//! `objective = w · Φ + extras`, first-order optimality and plausible accelerations.

mod common;

use common::{convex_problem, cost, simulate};
use palc_planner::{Control, LateralBoundsMode, Plan, Planner, PlannerConfig, Problem};
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

fn tol(x: f64) -> f64 {
    1e-6 * (1.0 + x.abs())
}

fn check_feasible(
    config: &PlannerConfig,
    problem: &Problem,
    plan: &Plan,
) -> Result<(), TestCaseError> {
    let k = config.horizon;
    prop_assert_eq!(plan.states.len(), k + 1);
    prop_assert_eq!(plan.controls.len(), k);
    // Dynamics residual (Eqs. 11-14).
    for i in 0..k {
        let (x, u, next) = (plan.states[i], plan.controls[i], plan.states[i + 1]);
        let v_ref = problem.reference_speed[i];
        let predicted = [
            x.s + config.dt * x.v,
            x.v + config.dt * u.a,
            x.l + config.dt * v_ref * x.phi,
            x.phi + config.dt * (v_ref / config.wheelbase * u.delta - v_ref * problem.curvature),
        ];
        for (p, n) in predicted.iter().zip(next.to_array()) {
            prop_assert!(
                (p - n).abs() < tol(n),
                "dynamics residual {} at step {}",
                p - n,
                i
            );
        }
    }
    // Boundary conditions (Eqs. 20-21).
    for (a, b) in plan.states[0]
        .to_array()
        .iter()
        .zip(problem.initial.to_array())
    {
        prop_assert!((a - b).abs() < tol(b));
    }
    let end = plan.states[k];
    prop_assert!((end.v - problem.terminal.v).abs() < tol(end.v));
    prop_assert!((end.l - problem.terminal.l).abs() < tol(end.l));
    prop_assert!(end.phi.abs() < 1e-6);
    if let Some(s) = problem.terminal.s {
        prop_assert!((end.s - s).abs() < tol(s));
    }
    // Bounds (Eqs. 22-23), widened by the reported slack in soft mode.
    for u in &plan.controls {
        prop_assert!(
            u.delta <= config.steering_max + 1e-6 && u.delta >= config.steering_min - 1e-6
        );
    }
    for (i, (x, b)) in plan.states.iter().zip(&problem.lateral_bounds).enumerate() {
        let slack = plan.lateral_violation[i];
        prop_assert!(slack >= -1e-7);
        if let Some(b) = b {
            let below = b.min.map_or(0.0, |m| m - x.l);
            let above = b.max.map_or(0.0, |m| x.l - m);
            let distance = below.max(above).max(0.0);
            match config.lateral_bounds_mode {
                LateralBoundsMode::Hard => prop_assert!(distance < 1e-6, "bound violated at {}", i),
                _ => prop_assert!(
                    (distance - slack).abs() < 1e-5,
                    "slack {} vs distance {}",
                    slack,
                    distance
                ),
            }
        } else {
            prop_assert!(slack == 0.0);
        }
    }
    Ok(())
}

/// Solves `G y = r` for the small Gram system of the terminal constraints.
fn solve_small(mut g: Vec<Vec<f64>>, mut r: Vec<f64>) -> Vec<f64> {
    let n = r.len();
    for c in 0..n {
        let p = (c..n)
            .max_by(|&a, &b| g[a][c].abs().total_cmp(&g[b][c].abs()))
            .unwrap();
        g.swap(c, p);
        r.swap(c, p);
        for row in c + 1..n {
            let f = g[row][c] / g[c][c];
            for j in c..n {
                g[row][j] -= f * g[c][j];
            }
            r[row] -= f * r[c];
        }
    }
    let mut y = vec![0.0; n];
    for c in (0..n).rev() {
        y[c] = (r[c] - (c + 1..n).map(|j| g[c][j] * y[j]).sum::<f64>()) / g[c][c];
    }
    y
}

/// Terminal components that the problem fixes.
fn terminal_of(problem: &Problem, x: &palc_planner::State) -> Vec<f64> {
    let mut t = vec![x.v, x.l, x.phi];
    if problem.terminal.s.is_some() {
        t.push(x.s);
    }
    t
}

/// What a perturbation keeps fixed: the terminal components, then the lateral
/// position at each step in `active` (hard bounds the plan touches).
fn kept_of(problem: &Problem, states: &[palc_planner::State], active: &[usize]) -> Vec<f64> {
    let mut kept = terminal_of(problem, &states[states.len() - 1]);
    kept.extend(active.iter().map(|&i| states[i].l));
    kept
}

fn perturbed(controls: &[Control], d: &[f64], eps: f64) -> Vec<Control> {
    controls
        .iter()
        .enumerate()
        .map(|(i, u)| Control {
            a: u.a + eps * d[2 * i],
            delta: u.delta + eps * d[2 * i + 1],
        })
        .collect()
}

fn is_feasible(
    config: &PlannerConfig,
    problem: &Problem,
    states: &[palc_planner::State],
    controls: &[Control],
) -> bool {
    let steering = controls
        .iter()
        .all(|u| u.delta <= config.steering_max + 1e-7 && u.delta >= config.steering_min - 1e-7);
    let lateral = config.lateral_bounds_mode != LateralBoundsMode::Hard
        || states.iter().zip(&problem.lateral_bounds).all(|(x, b)| {
            b.is_none_or(|b| {
                b.min.is_none_or(|m| x.l >= m - 1e-7) && b.max.is_none_or(|m| x.l <= m + 1e-7)
            })
        });
    steering && lateral
}

proptest! {
    // A fixed seed keeps CI reproducible. This checks the default (Riccati) backend.
    // With clarabel, another seed once drew a hard-bounded case where a feasible
    // perturbation lowered the cost by ~2e-5 relative, consistent with clarabel
    // stopping short at its speed settings (tests/backends_agree.rs uses it with
    // refinement and 1e-10 for that reason). The perturbations keep the hard lateral
    // bounds the plan touches: without that, at `PROPTEST_CASES=2000` this seed drew a
    // case (K = 31, hard bounds) where no tried perturbation was feasible.
    #![proptest_config(ProptestConfig {
        rng_seed: proptest::test_runner::RngSeed::Fixed(20261122),
        failure_persistence: None,
        ..ProptestConfig::with_cases(48)
    })]

    #[test]
    fn random_convex_problems_are_solved_feasibly_and_optimally(
        (config, problem) in convex_problem(),
        directions in prop::collection::vec(prop::collection::vec(-1.0..1.0f64, 180), 3),
    ) {
        let mut planner = Planner::new(config.clone()).unwrap();
        let plan = planner.plan(&problem).unwrap();
        check_feasible(&config, &problem, &plan)?;

        // The objective identity: objective = w · Φ(ψ) + extras, to rounding.
        let w_phi = problem.weights.dot(&plan.features).unwrap();
        prop_assert!((plan.learned_cost - w_phi).abs() <= 1e-12 * (1.0 + w_phi.abs()));
        let total = w_phi + plan.extras.total();
        prop_assert!(
            (plan.objective - total).abs() <= 1e-9 * (1.0 + total.abs()),
            "objective {} vs w.phi + extras {}", plan.objective, total
        );
        // And the same value from an independent evaluation of the cost.
        let independent = cost(&config, &problem, &plan.states, &plan.controls);
        prop_assert!((plan.objective - independent).abs() <= 1e-6 * (1.0 + total.abs()));

        // Plausible weights keep the acceleration near the reference profile's (the
        // penalty acts on `a - a_ref`; the random profiles' own accelerations are large).
        let max_a = (plan.controls.iter().enumerate())
            .map(|(i, u)| (u.a - problem.reference_acceleration(i, config.dt)).abs())
            .fold(0.0, f64::max);
        prop_assert!(max_a < 3.0, "max |a - a_ref| = {max_a}");

        // First-order optimality: no small feasible perturbation in the null space of
        // the equality constraints (controls moved, states re-simulated, terminal kept)
        // lowers the cost.
        let k = config.horizon;
        let base_states = simulate(&config, &problem, &plan.controls);
        let base_cost = cost(&config, &problem, &base_states, &plan.controls);
        let base_terminal = terminal_of(&problem, &base_states[k]);
        // Hard lateral bounds the plan touches stay touched (a perturbation that moves
        // such a step's `l` is infeasible one way, and with two of them often both ways).
        let active: Vec<usize> = if config.lateral_bounds_mode == LateralBoundsMode::Hard {
            (0..=k)
                .filter(|&i| {
                    problem.lateral_bounds[i].is_some_and(|b| {
                        let l = base_states[i].l;
                        b.min.is_some_and(|m| (l - m).abs() < 1e-6)
                            || b.max.is_some_and(|m| (l - m).abs() < 1e-6)
                    })
                })
                .collect()
        } else {
            Vec::new()
        };
        let base_kept = kept_of(&problem, &base_states, &active);
        // Steering at its bound stays there (those directions are not feasible both ways).
        let free: Vec<bool> = (0..2 * k)
            .map(|j| {
                j % 2 == 0 || {
                    let delta = plan.controls[j / 2].delta;
                    delta < config.steering_max - 1e-6 && delta > config.steering_min + 1e-6
                }
            })
            .collect();
        let columns: Vec<Vec<f64>> = (0..2 * k)
            .map(|j| {
                if !free[j] {
                    return vec![0.0; base_kept.len()];
                }
                let mut e = vec![0.0; 2 * k];
                e[j] = 1.0;
                let moved = simulate(&config, &problem, &perturbed(&plan.controls, &e, 1.0));
                kept_of(&problem, &moved, &active)
                    .iter()
                    .zip(&base_kept)
                    .map(|(a, b)| a - b)
                    .collect()
            })
            .collect();
        let m = base_kept.len();
        let gram: Vec<Vec<f64>> = (0..m)
            .map(|r| (0..m).map(|c| columns.iter().map(|col| col[r] * col[c]).sum()).collect())
            .collect();
        let mut compared = 0;
        for raw in &directions {
            let mut d: Vec<f64> = raw
                .iter()
                .cycle()
                .zip(&free)
                .map(|(&x, &f)| if f { x } else { 0.0 })
                .collect();
            let gd: Vec<f64> = (0..m).map(|r| columns.iter().zip(&d).map(|(c, x)| c[r] * x).sum()).collect();
            let y = solve_small(gram.clone(), gd);
            if !y.iter().all(|y| y.is_finite()) {
                continue; // dependent kept rows: no projection from this system
            }
            for (j, col) in columns.iter().enumerate() {
                d[j] -= col.iter().zip(&y).map(|(c, y)| c * y).sum::<f64>();
            }
            // The largest step that keeps every free steering angle within its bounds.
            let cap = (0..k)
                .filter(|&i| free[2 * i + 1] && d[2 * i + 1] != 0.0)
                .map(|i| {
                    let delta = plan.controls[i].delta;
                    let room = (config.steering_max - delta).min(delta - config.steering_min);
                    room / d[2 * i + 1].abs()
                })
                .fold(1e-2, f64::min);
            for eps in [cap, -cap, cap / 10.0, -cap / 10.0] {
                let controls = perturbed(&plan.controls, &d, eps);
                let states = simulate(&config, &problem, &controls);
                for (a, b) in terminal_of(&problem, &states[k]).iter().zip(&base_terminal) {
                    prop_assert!((a - b).abs() < 1e-8, "perturbation left the terminal set");
                }
                if !is_feasible(&config, &problem, &states, &controls) {
                    continue;
                }
                compared += 1;
                let c = cost(&config, &problem, &states, &controls);
                prop_assert!(
                    c >= base_cost - 1e-6 * (1.0 + base_cost.abs()),
                    "perturbation by {eps} lowered the cost from {base_cost} to {c}"
                );
            }
        }
        prop_assert!(compared > 0, "no feasible perturbation was compared");
    }
}
