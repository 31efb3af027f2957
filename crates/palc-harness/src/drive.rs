//! One lane change: plan, execute in the scene, let the user judge each step.

use palc_planner::{LateralBound, Plan, Position, Problem, State, Terminal, Weights};
use palc_traffic::EgoState;

use crate::HarnessError;
use crate::record::Takeover;
use crate::setup::Setup;
use crate::user::{ExpectedLaneChange, first_takeover, max_deviation};

/// The planning problem of this scenario with the given weights and lateral bounds.
pub fn problem(setup: &Setup, weights: Weights, bounds: Vec<Option<LateralBound>>) -> Problem {
    let k = setup.horizon;
    let position = |p: &[f64; 2]| Position { s: p[0], l: p[1] };
    Problem {
        initial: State {
            s: 0.0,
            v: setup.ego_speed,
            l: 0.0,
            phi: 0.0,
        },
        reference_speed: vec![setup.ego_speed; k],
        curvature: 0.0,
        weights,
        preceding: setup.preceding[..k].iter().map(position).collect(),
        adjacent: setup.adjacent[..k].iter().map(position).collect(),
        terminal: Terminal {
            s: None,
            v: setup.ego_speed,
            l: setup.target_l,
        },
        lateral_bounds: if bounds.is_empty() {
            vec![None; k + 1]
        } else {
            bounds
        },
        tracking: None,
    }
}

/// What happened in one lane change.
#[derive(Debug, Clone)]
pub struct Drive {
    /// The plan the system drove.
    pub plan: Plan,
    /// The lane change the user expected.
    pub expected: ExpectedLaneChange,
    /// Expected lateral positions at steps `0..=K`.
    pub expected_l: Vec<f64>,
    /// The takeover, if any.
    pub takeover: Option<Takeover>,
    /// Driven states at steps `0..=K`: the plan up to the takeover, the user after.
    pub driven: Vec<State>,
    /// Preceding vehicle `(s, l)` at steps `0..=K` as it moved in the scene (plan frame).
    pub preceding: Vec<[f64; 2]>,
    /// Adjacent vehicle `(s, l)` at steps `0..=K` as it moved in the scene (plan frame).
    pub adjacent: Vec<[f64; 2]>,
    /// Largest `|planned − expected|` (m).
    pub max_deviation_m: f64,
    /// Perceived safety distance ratio (1 without takeover).
    pub perceived_safety_ratio: f64,
}

/// Drives `plan` in a clone of the scene; the user of `expected` takes over at the
/// first step deviating more than `threshold` and then drives the expected path.
pub fn execute(
    setup: &Setup,
    plan: Plan,
    expected: ExpectedLaneChange,
    threshold: f64,
) -> Result<Drive, HarnessError> {
    let k = setup.horizon;
    let dt = setup.dt;
    let planned_l: Vec<f64> = plan.states.iter().map(|x| x.l).collect();
    let expected_l = expected.sample(k, dt);
    let takeover_step = first_takeover(&planned_l, &expected_l, threshold);

    let driven: Vec<State> = match takeover_step {
        None => plan.states.clone(),
        Some(step) => {
            let mut driven = plan.states[..step].to_vec();
            let mut s = driven.last().map_or(0.0, |x| x.s);
            for i in step..=k {
                if i > 0 {
                    s += setup.ego_speed * dt;
                }
                let next_l = expected_l[(i + 1).min(k)];
                let phi = (next_l - expected_l[i]) / (setup.ego_speed * dt);
                driven.push(State {
                    s,
                    v: setup.ego_speed,
                    l: expected_l[i],
                    phi: if i == k { 0.0 } else { phi },
                });
            }
            driven
        }
    };

    let mut scene = setup.scene.clone();
    let mut preceding = Vec::with_capacity(k + 1);
    let mut adjacent = Vec::with_capacity(k + 1);
    let frame = |p: Option<&palc_traffic::Vehicle>| {
        p.map_or([1e4, 0.0], |v| [v.state.s - setup.origin_s, v.state.l])
    };
    for i in 0..=k {
        preceding.push(frame(scene.preceding()));
        adjacent.push(frame(scene.adjacent()));
        if i < k {
            let x = driven[i + 1];
            scene.step(
                dt,
                EgoState {
                    s: x.s + setup.origin_s,
                    l: x.l,
                    v: x.v.max(0.0),
                    heading: x.phi,
                },
            )?;
        }
    }

    let takeover = takeover_step.map(|step| Takeover {
        step,
        time_s: step as f64 * dt,
        distance_m: plan.states[step].s,
        deviation_m: (planned_l[step] - expected_l[step]).abs(),
    });
    let perceived_safety_ratio = match &takeover {
        None => 1.0,
        Some(t) => {
            // The lane change ends where the driven path settles on the target lane,
            // and never before the step after the takeover, so that a takeover
            // always gives a ratio below 1.
            let end = lane_change_end(&driven, setup.target_l)
                .max(t.step + 1)
                .min(k);
            let whole = driven[end].s;
            if whole > 0.0 {
                (t.distance_m / whole).clamp(0.0, 1.0)
            } else {
                0.0
            }
        }
    };
    Ok(Drive {
        max_deviation_m: max_deviation(&planned_l, &expected_l),
        plan,
        expected,
        expected_l,
        takeover,
        driven,
        preceding,
        adjacent,
        perceived_safety_ratio,
    })
}

/// The first step from which the driven lateral position stays within 5 cm of the
/// target lane's centre: the end of the lane change.
fn lane_change_end(driven: &[State], target_l: f64) -> usize {
    let mut end = driven.len() - 1;
    for i in (0..driven.len()).rev() {
        if (driven[i].l - target_l).abs() > 0.05 {
            break;
        }
        end = i;
    }
    end
}
