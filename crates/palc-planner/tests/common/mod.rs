//! Fixtures shared by the planner's integration tests.
#![allow(dead_code)]

use palc_planner::{
    Control, LateralBound, LateralBoundsMode, PlannerConfig, Problem, State, Weights, features,
};
use proptest::prelude::*;

#[path = "../../fixtures/lane_change.rs"]
mod lane_change_fixture;
// Not every test binary re-plans.
#[allow(unused_imports)]
pub use lane_change_fixture::{lane_change, shifted};

/// Random weights in the convex set: every stage block is PSD by construction
/// (couplings at most 90 % of what each diagonal can carry against a third of w8).
pub fn convex_column() -> impl Strategy<Value = [f64; 10]> {
    (
        (0.0..1.0f64, -1.0..1.0f64, 0.1..10.0f64, -0.5..0.5f64),
        (-0.9..0.9f64, -0.9..0.9f64, -0.9..0.9f64),
        (1.0..100.0f64, 0.0..0.01f64, 0.0..0.01f64),
    )
        .prop_map(|((w1, w2, w3, w4), (f5, f6, f7), (w8, w9, w10))| {
            let coupling = |f: f64, d: f64| 2.0 * f * (d * w8 / 3.0).sqrt();
            let w5 = coupling(f5, w1 + w9 + w10);
            let w6 = coupling(f6, w3);
            let w7 = coupling(f7, w9 + w10);
            [w1, w2, w3, w4, w5, w6, w7, w8, w9, w10]
        })
}

/// A random feasible problem with its configuration.
pub fn convex_problem() -> impl Strategy<Value = (PlannerConfig, Problem)> {
    (
        prop_oneof![(20usize..=50, Just(0.1)), (40usize..=90, Just(0.05))],
        prop::bool::ANY,
        10.0..30.0f64,
        any::<u64>(),
    )
        .prop_flat_map(|((k, dt), soft, speed, _)| {
            (
                Just((k, dt, soft, speed)),
                prop::collection::vec(convex_column(), k),
                prop::collection::vec(-0.5..0.5f64, k),
                prop::collection::vec(
                    prop::option::weighted(0.7, (-1.75..-0.5f64, 4.0..5.25f64)),
                    k + 1,
                ),
                prop::option::of(-0.3..0.3f64),
                (-10.0..60.0f64, -40.0..10.0f64),
                prop::option::of((0.0..1.0f64, 0.0..1.0f64)),
            )
        })
        .prop_map(
            |((k, dt, soft, speed), columns, speed_noise, bounds, s_offset, (pre, adj), track)| {
                let config = PlannerConfig {
                    horizon: k,
                    dt,
                    lateral_bounds_mode: if soft {
                        LateralBoundsMode::Soft { weight: 50.0 }
                    } else {
                        LateralBoundsMode::Hard
                    },
                    ..PlannerConfig::default()
                };
                let mut problem = lane_change(&config, speed);
                problem.weights = Weights::from_columns(columns);
                problem.reference_speed = speed_noise.iter().map(|n| speed + n).collect();
                problem.lateral_bounds = bounds
                    .into_iter()
                    .map(|b| b.map(|(min, max)| LateralBound::new(min, max)))
                    .collect();
                for (i, p) in problem.preceding.iter_mut().enumerate() {
                    p.s = pre + (speed - 2.0) * dt * i as f64;
                }
                for (i, p) in problem.adjacent.iter_mut().enumerate() {
                    p.s = adj + (speed + 2.0) * dt * i as f64;
                }
                let duration = k as f64 * dt;
                // An offset of o·T² metres needs accelerations of order o m/s².
                problem.terminal.s = s_offset.map(|o| speed * duration + o * duration * duration);
                if let Some((q_l, q_v)) = track {
                    problem.tracking = Some(palc_planner::Tracking {
                        weights: [0.0, q_v, q_l, 0.0],
                        reference: (0..=k)
                            .map(|i| {
                                let x = i as f64 / k as f64;
                                Some(State {
                                    s: speed * dt * i as f64,
                                    v: speed,
                                    l: 3.5 * x * x * (3.0 - 2.0 * x),
                                    phi: 0.0,
                                })
                            })
                            .collect(),
                    });
                }
                (config, problem)
            },
        )
}

/// `w · Φ + extras` evaluated independently of the QP, for a trajectory that need not
/// be optimal; the soft-bound slack is the L1 distance of `l_i` to the zone.
pub fn cost(
    config: &PlannerConfig,
    problem: &Problem,
    states: &[State],
    controls: &[Control],
) -> f64 {
    let phi = features(states, controls, &problem.preceding, &problem.adjacent).unwrap();
    let mut total = problem.weights.dot(&phi).unwrap();
    // The penalty acts around the reference profile's own acceleration (forward
    // differences, towards the terminal speed at the last step).
    let v_ref = &problem.reference_speed;
    for (i, u) in controls.iter().enumerate() {
        let next = v_ref.get(i + 1).copied().unwrap_or(problem.terminal.v);
        let a_ref = (next - v_ref[i]) / config.dt;
        total += config.acceleration_penalty * (u.a - a_ref).powi(2);
    }
    if let Some(t) = &problem.tracking {
        for (x, r) in states.iter().zip(&t.reference) {
            if let Some(r) = r {
                let (x, r) = (x.to_array(), r.to_array());
                total += (0..4)
                    .map(|c| t.weights[c] * (x[c] - r[c]).powi(2))
                    .sum::<f64>();
            }
        }
    }
    if let LateralBoundsMode::Soft { weight } = config.lateral_bounds_mode {
        for (x, b) in states.iter().zip(&problem.lateral_bounds) {
            if let Some(b) = b {
                let below = b.min.map_or(0.0, |m| m - x.l);
                let above = b.max.map_or(0.0, |m| x.l - m);
                total += weight * below.max(above).max(0.0);
            }
        }
    }
    total
}

/// The states reached from `initial` under `controls` through the model of Eqs. (11)-(14).
pub fn simulate(config: &PlannerConfig, problem: &Problem, controls: &[Control]) -> Vec<State> {
    let dt = config.dt;
    let mut x = problem.initial;
    let mut states = vec![x];
    for (i, u) in controls.iter().enumerate() {
        let v_ref = problem.reference_speed[i];
        x = State {
            s: x.s + dt * x.v,
            v: x.v + dt * u.a,
            l: x.l + dt * v_ref * x.phi,
            phi: x.phi + dt * (v_ref / config.wheelbase * u.delta - v_ref * problem.curvature),
        };
        states.push(x);
    }
    states
}
