//! A small lane-change scene and lessons built from it, shared by the tests.
#![allow(dead_code)]

use palc_aggregator::Lesson;
use palc_planner::{
    FEATURE_COUNT, LateralBound, Plan, Planner, PlannerConfig, Position, Problem, State, Terminal,
    Weights,
};
use palc_zone_filter::{FeatureInput, FeatureSet, Label, Sample, StepScene, features};

/// Ego and target speed (m/s).
pub const SPEED: f64 = 20.0;

/// Standard weights: weak pull to the lane centre, smooth heading and steering.
pub const STANDARD: [f64; FEATURE_COUNT] = [0.1, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 10.0, 0.0, 0.0];

pub fn config(horizon: usize, dt: f64) -> PlannerConfig {
    PlannerConfig {
        horizon,
        dt,
        ..PlannerConfig::default()
    }
}

fn preceding_at(t: f64) -> Position {
    Position {
        s: 40.0 + 18.0 * t,
        l: 0.0,
    }
}

fn adjacent_at(t: f64) -> Position {
    Position {
        s: -30.0 + 20.0 * t,
        l: 3.5,
    }
}

/// A lane change from `initial` to the target lane's centre over `horizon` steps
/// starting at time `t0`, with predictions of a slower preceding vehicle and an
/// adjacent vehicle behind on the target lane.
pub fn problem_from(initial: State, t0: f64, horizon: usize, dt: f64, weights: Weights) -> Problem {
    let time = |i: usize| t0 + dt * i as f64;
    Problem {
        initial,
        reference_speed: vec![SPEED; horizon],
        curvature: 0.0,
        weights,
        preceding: (0..horizon).map(|i| preceding_at(time(i))).collect(),
        adjacent: (0..horizon).map(|i| adjacent_at(time(i))).collect(),
        terminal: Terminal {
            s: None,
            v: SPEED,
            l: 3.5,
        },
        lateral_bounds: vec![Some(LateralBound::new(-1.75, 5.25)); horizon + 1],
        tracking: None,
    }
}

/// The template of the lesson's scene.
pub fn template(horizon: usize, dt: f64) -> Problem {
    let initial = State {
        s: 0.0,
        v: SPEED,
        l: 0.0,
        phi: 0.0,
    };
    problem_from(
        initial,
        0.0,
        horizon,
        dt,
        Weights::constant(horizon, STANDARD),
    )
}

/// A user who moves over earlier than the standard weights: a pull `w2 = -pull`
/// towards the left, on top of the standard weights.
pub fn user_weights(horizon: usize, pull: f64) -> Weights {
    let mut column = STANDARD;
    column[1] = -pull;
    Weights::constant(horizon, column)
}

/// A lesson: the system drives `planned` up to `takeover_step`, then the user
/// re-plans from that state with a pull `pull` and drives to the target lane's centre.
/// The executed trajectory follows the planner's model and ends at the terminal state.
pub fn lesson(
    planner: &mut Planner,
    planned_problem: &Problem,
    takeover_step: usize,
    pull: f64,
) -> Lesson {
    let config = planner.config().clone();
    let (k, dt) = (config.horizon, config.dt);
    let planned = planner
        .plan(planned_problem)
        .expect("the lesson's plan is feasible");
    let rest = k - takeover_step;
    let mut executed: Vec<State> = planned.states[..=takeover_step].to_vec();
    if rest > 0 {
        let mut user_planner = Planner::new(PlannerConfig {
            horizon: rest,
            ..config
        })
        .expect("valid config");
        let start = planned.states[takeover_step];
        let user = user_planner
            .plan(&problem_from(
                start,
                dt * takeover_step as f64,
                rest,
                dt,
                user_weights(rest, pull),
            ))
            .expect("the user's plan is feasible");
        executed.extend_from_slice(&user.states[1..]);
    }
    let samples = samples(&planned, &executed, takeover_step, dt);
    let step_scenes = step_scenes(&planned, dt);
    Lesson {
        planned,
        executed,
        demonstration: None,
        takeover_step,
        samples,
        step_scenes,
    }
}

fn feature_input(state: &State, t: f64) -> FeatureInput {
    let (p, a) = (preceding_at(t), adjacent_at(t));
    FeatureInput {
        ego_s: state.s,
        ego_l: state.l,
        ego_speed: state.v,
        preceding: [p.s, p.l],
        adjacent: [a.s, a.l],
    }
}

/// The paper's labelling: system-driven positions safe, user-driven ones unsafe.
pub fn samples(_planned: &Plan, executed: &[State], takeover_step: usize, dt: f64) -> Vec<Sample> {
    executed
        .iter()
        .enumerate()
        .map(|(i, x)| {
            let y = if i < takeover_step {
                Label::Safe
            } else {
                Label::Unsafe
            };
            let x = features(FeatureSet::Paper, &feature_input(x, dt * i as f64))
                .expect("finite features");
            Sample::new(x, y)
        })
        .collect()
}

/// Per step `0..=K`, the scene the zone is projected on, around the plan.
pub fn step_scenes(planned: &Plan, dt: f64) -> Vec<StepScene> {
    planned
        .states
        .iter()
        .enumerate()
        .map(|(i, x)| {
            let input = feature_input(x, dt * i as f64);
            StepScene {
                ego_s: x.s,
                reference_l: x.l,
                ego_speed: x.v,
                preceding: input.preceding,
                adjacent: input.adjacent,
            }
        })
        .collect()
}

/// The largest residual of the planner's forward-Euler model (crate docs of
/// `palc-planner`) along a plan, on a straight road.
pub fn dynamics_residual(plan: &Plan, problem: &Problem, dt: f64, wheelbase: f64) -> f64 {
    let mut worst: f64 = 0.0;
    for (i, u) in plan.controls.iter().enumerate() {
        let (x, next) = (plan.states[i], plan.states[i + 1]);
        let v_ref = problem.reference_speed[i];
        let predicted = [
            x.s + dt * x.v,
            x.v + dt * u.a,
            x.l + dt * v_ref * x.phi,
            x.phi + dt * v_ref / wheelbase * u.delta - dt * v_ref * problem.curvature,
        ];
        for (p, n) in predicted.iter().zip(next.to_array()) {
            worst = worst.max((p - n).abs() / (1.0 + n.abs()));
        }
    }
    worst
}
