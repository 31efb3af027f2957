//! One lane change: plan, execute in the scene, let the user judge each step.

use palc_planner::{LateralBound, Plan, Position, Problem, State, Terminal, Weights};
use palc_traffic::{Scene, ballistic_step};

use crate::HarnessError;
use crate::acc::acc_leader;
use crate::guard::{drive_states, guarded_step, guarded_user_acceleration};
use crate::record::Takeover;
use crate::safety::{SafetyMetrics, SafetyMonitor};
use crate::setup::{Setup, situation, target_gaps_safe};
use crate::world::{Traffic, World};
use palc_user::{Expectation, ExpectedLaneChange, TakeoverCause, User, max_deviation};

/// The planning problem of this scenario with the given weights and lateral bounds.
///
/// The reference and terminal speeds are the ego ACC's while it keeps its lane
/// ([`Setup::lane_keeping`]): the plan slows down behind a slower vehicle as the
/// ego would.
pub fn problem(setup: &Setup, weights: Weights, bounds: Vec<Option<LateralBound>>) -> Problem {
    let k = setup.horizon;
    let position = |p: &[f64; 2]| Position { s: p[0], l: p[1] };
    let speed = |i: usize| setup.lane_keeping[i][1];
    Problem {
        initial: State {
            s: 0.0,
            v: speed(0),
            l: 0.0,
            phi: 0.0,
        },
        reference_speed: (0..k).map(speed).collect(),
        curvature: 0.0,
        weights,
        preceding: setup.preceding[..k].iter().map(position).collect(),
        adjacent: setup.adjacent[..k].iter().map(position).collect(),
        terminal: Terminal {
            // Under the ACC the plan ends where the ego keeping its lane would, so
            // that it does not run ahead of it between start and end.
            s: setup.acc.enabled.then(|| setup.lane_keeping[k][0]),
            v: speed(k),
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
    /// Safety of the steps the system drove (the plan, up to a takeover).
    pub safety: SafetyMetrics,
    /// Safety of the steps the user drove after a takeover (default without one).
    pub user_safety: SafetyMetrics,
    /// Whether the user, after a takeover, drove at another acceleration than the
    /// ego's ACC would have at some step: a speed of its own, which the plans can
    /// learn ([`palc_aggregator::AggregatorOptions::follow_user_speed`]).
    pub user_speed_differs: bool,
}

/// The first step at which `user`, expecting `expectation`, takes over the ego
/// driving `states` (plan frame, from the trigger) in a clone of the scene, and why.
///
/// # Errors
/// A scene error while driving.
pub fn judge(
    setup: &Setup,
    user: &dyn User,
    expectation: &Expectation,
    states: &[State],
) -> Result<Option<(usize, TakeoverCause)>, HarnessError> {
    let mut scene = setup.scene.clone();
    let mut judged = None;
    drive_states(setup, &mut scene, states, |i, driven, scene| {
        judged = user
            .takes_over(expectation, i, driven, &situation(scene))
            .map(|cause| (i, cause));
        judged.is_some()
    })?;
    Ok(judged)
}

/// Drives `plan` in a clone of the scene; `user`, expecting `expectation`, judges
/// each step as it is driven ([`User::takes_over`]) and after a takeover drives
/// its expected lateral path, at the acceleration of
/// [`User::acceleration_after_takeover`] (by default the ego's ACC behind
/// whatever is ahead in the lanes it occupies).
pub fn execute(
    setup: &Setup,
    plan: Plan,
    user: &dyn User,
    expectation: &Expectation,
) -> Result<Drive, HarnessError> {
    execute_in(setup, plan, user, expectation, None)
}

/// As [`execute`], in `world`'s traffic when given (see [`World`]): the world
/// places the scene at the trigger and moves the other vehicles at every step.
///
/// The user judges step `i` as the system would drive it, with the other vehicles
/// one step on from the mirror by palc's models (in palc's own traffic, exactly
/// where the step moves them: they react to the ego's previous state only), so
/// that a takeover at step `i` drives step `i` already.
pub fn execute_in(
    setup: &Setup,
    plan: Plan,
    user: &dyn User,
    expectation: &Expectation,
    world: Option<&mut dyn World>,
) -> Result<Drive, HarnessError> {
    let k = setup.horizon;
    let dt = setup.dt;
    let planned_l: Vec<f64> = plan.states.iter().map(|x| x.l).collect();
    let expected_l = expectation.lateral(k);
    let mut judged: Option<(usize, TakeoverCause)> = None;

    let mut traffic = Traffic::of(world);
    let mut scene = setup.scene.clone();
    traffic.place(&scene, dt)?;
    let mut system = SafetyMonitor::new(setup.safety, &scene, setup.target_l);
    let mut by_user_monitor = system.clone();
    let mut driven: Vec<State> = Vec::with_capacity(k + 1);
    let mut preceding = Vec::with_capacity(k + 1);
    let mut adjacent = Vec::with_capacity(k + 1);
    let frame = |p: Option<&palc_traffic::Vehicle>| {
        p.map_or([1e4, 0.0], |v| [v.state.s - setup.origin_s, v.state.l])
    };
    let mut user_speed_differs = false;
    let driving = UserDriving::new(setup, user, expectation, &expected_l);
    // Where the system had driven the ego when the user took over: the plan's
    // state there, unless the longitudinal guard held the ego back.
    let mut at_takeover = plan.states[0];
    // Steps the user has held its lateral position after the takeover, with a
    // target-lane vehicle alongside: its lane change resumes this much later.
    let mut held = 0;
    for i in 0..=k {
        // The system's state at this step, while it drives, and the user's look at it.
        if judged.is_none() {
            let by_system = match driven.last() {
                None => plan.states[0],
                Some(previous) => guarded_step(
                    setup,
                    &scene,
                    previous,
                    &plan.states[i - 1],
                    &plan.states[i],
                ),
            };
            let seen = if i == 0 {
                situation(&scene)
            } else {
                let mut ahead = scene.clone();
                ahead.step(dt, setup.ego_state(&by_system))?;
                situation(&ahead)
            };
            judged = (user.takes_over(expectation, i, &by_system, &seen)).map(|cause| (i, cause));
            at_takeover = by_system;
            if judged.is_none() {
                if i > 0 {
                    traffic.advance(&mut scene, dt, setup.ego_state(&by_system))?;
                }
                system.observe(i, &scene);
                preceding.push(frame(scene.preceding()));
                adjacent.push(frame(scene.adjacent()));
                driven.push(by_system);
                continue;
            }
        }
        let state = match driven.last() {
            None => State {
                l: expected_l[0],
                ..plan.states[0]
            },
            Some(previous) => {
                let (mut next, differs) = driving.step(&scene, previous, i, held);
                user_speed_differs |= differs;
                if driving.holds_before_entering(&scene, previous, &next, i, held)? {
                    held += 1;
                    next.l = previous.l;
                }
                next
            }
        };
        if i > 0 {
            traffic.advance(&mut scene, dt, setup.ego_state(&state))?;
        }
        by_user_monitor.observe(i, &scene);
        preceding.push(frame(scene.preceding()));
        adjacent.push(frame(scene.adjacent()));
        driven.push(state);
    }
    let takeover_step = judged.as_ref().map(|(step, _)| *step);
    // The user's heading follows its lateral path.
    if let Some(step) = takeover_step {
        for i in step..k {
            let run = (driven[i].v * dt).max(1e-9);
            driven[i].phi = (driven[i + 1].l - driven[i].l) / run;
        }
    }

    let takeover = judged.map(|(step, cause)| Takeover {
        step,
        time_s: step as f64 * dt,
        distance_m: at_takeover.s,
        deviation_m: (planned_l[step] - expected_l[step]).abs(),
        cause,
    });
    let perceived_safety_ratio =
        perceived_safety_ratio(&driven, setup.target_l, k, takeover.as_ref());
    Ok(Drive {
        max_deviation_m: max_deviation(&planned_l, &expected_l),
        plan,
        expected: expectation.lane_change.clone(),
        expected_l,
        takeover,
        driven,
        preceding,
        adjacent,
        perceived_safety_ratio,
        safety: system.metrics(),
        user_safety: by_user_monitor.metrics(),
        user_speed_differs,
    })
}

/// How the simulated user drives after its takeover: its expected lateral path,
/// held back by the steps it waited before moving over, at its own acceleration.
struct UserDriving<'a> {
    setup: &'a Setup,
    user: &'a dyn User,
    expectation: &'a Expectation,
    /// Expected lateral positions at steps `0..=K`.
    expected_l: &'a [f64],
    /// The step at which the expected lane change ends.
    seeking_until: usize,
}

impl<'a> UserDriving<'a> {
    /// `user` driving `expectation` (its lateral positions `expected_l`).
    fn new(
        setup: &'a Setup,
        user: &'a dyn User,
        expectation: &'a Expectation,
        expected_l: &'a [f64],
    ) -> Self {
        UserDriving {
            setup,
            user,
            expectation,
            expected_l,
            seeking_until: (expectation.lane_change.end_s() / setup.dt - 1e-9)
                .ceil()
                .max(0.0) as usize,
        }
    }

    /// The user's state at step `i` after `previous`, its lateral path `held` steps
    /// late, and whether its acceleration differs from the ego ACC's.
    ///
    /// Until its lane change ends, the user moves as the lane-keeping prediction
    /// does, gap seeking included: the motion on which it chose its start and
    /// checked its gaps. A lane change held back ends that much later, and the user
    /// seeks a gap meanwhile; after it, the ACC drives (a speed-matching user's own
    /// rule capped by either), under the longitudinal guard.
    fn step(&self, scene: &Scene, previous: &State, i: usize, held: usize) -> (State, bool) {
        let setup = self.setup;
        let acc = if i <= self.seeking_until + held {
            setup.lane_keeping_acceleration(scene, i - 1)
        } else {
            (setup.acc).ego_acceleration(
                previous.v,
                setup.set_speed,
                acc_leader(scene),
                &setup.safety,
            )
        };
        let chosen = (self.user).acceleration_after_takeover(self.expectation, i, previous.v, acc);
        // Exact: a user who leaves its speed to the ACC returns its command.
        let differs = chosen != acc;
        let acceleration = guarded_user_acceleration(setup, scene, previous.v, chosen);
        let moved = ballistic_step(previous.v, acceleration, setup.dt);
        let next = State {
            s: previous.s + moved.distance,
            v: moved.speed,
            l: self.expected_l[i - held],
            phi: 0.0,
        };
        (next, differs)
    }

    /// Whether the user, at `previous` in `scene`, holds its lateral position
    /// instead of moving to `next` (step `i`, its path `held` steps late): the move
    /// would bring the ego's footprint into the target lane at a gap it does not
    /// enter. Every user holds beside a target-lane vehicle
    /// (`beside`). A user who waits for safe gaps
    /// (`planning.safety.users_wait_for_safe_gaps`) also holds when its lane change
    /// from here, driven on a clone of the scene to the horizon's end, would bring
    /// the target lane's lead or lag vehicle below the RSS safe distance while the
    /// ego occupies that lane: the check of its start, made again. The user took
    /// over after its own start, which it checked on the lane-keeping prediction;
    /// the system may have left the ego elsewhere (a plan that slowed down
    /// earlier), or a target-lane vehicle may have accelerated into the gap since
    /// (`traffic.testbed.lag_accelerating`).
    fn holds_before_entering(
        &self,
        scene: &Scene,
        previous: &State,
        next: &State,
        i: usize,
        held: usize,
    ) -> Result<bool, HarnessError> {
        let setup = self.setup;
        let Some(mut ahead) = entering(setup, scene, previous, next)? else {
            return Ok(false);
        };
        if beside(&ahead) {
            return Ok(true);
        }
        let safety = &setup.safety;
        if !safety.users_wait_for_safe_gaps {
            return Ok(false);
        }
        let road = scene.road();
        let lane = road.nearest_lane(setup.target_l);
        let width = scene.ego().map_or(0.0, |ego| ego.width);
        let mut state = *next;
        for j in i..=setup.horizon {
            if j > i {
                state = self.step(&ahead, &state, j, held).0;
                ahead.step(setup.dt, setup.ego_state(&state))?;
            }
            if road.occupies(state.l, width, lane) && !target_gaps_safe(&situation(&ahead), safety)
            {
                return Ok(true);
            }
        }
        Ok(false)
    }
}

/// The scene one step after `scene` with the ego moved to `next`, when that move
/// brings the ego's footprint into the target lane (from `previous`, outside it);
/// `None` for any other move.
fn entering(
    setup: &Setup,
    scene: &Scene,
    previous: &State,
    next: &State,
) -> Result<Option<Scene>, HarnessError> {
    let Some(ego) = scene.ego() else {
        return Ok(None);
    };
    let road = scene.road();
    let lane = road.nearest_lane(setup.target_l);
    if next.l <= previous.l
        || road.occupies(previous.l, ego.width, lane)
        || !road.occupies(next.l, ego.width, lane)
    {
        return Ok(None);
    }
    let mut ahead = scene.clone();
    ahead.step(setup.dt, setup.ego_state(next))?;
    Ok(Some(ahead))
}

/// Whether a target-lane vehicle is beside the ego in `scene`: their lengths
/// overlap (a gap of zero or less). A driver does not steer into a vehicle
/// beside it.
fn beside(scene: &Scene) -> bool {
    situation(scene).target_vehicle_beside()
}

/// The first step at which `user`, driving its own expected lane change
/// `expectation` from the trigger (as it drives after a takeover), would enter
/// the target lane beside a vehicle of it, the move it never makes
/// ([`UserDriving::holds_before_entering`]); `None` when its lane change never
/// does. A user whose expectation does is inconsistent in the scene: it takes
/// over any plan that differs from that expectation and then drives something
/// else (it holds), which is what it teaches, and the plan copying the hold is
/// taken over again.
pub(crate) fn own_lane_change_enters_beside(
    setup: &Setup,
    user: &dyn User,
    expectation: &Expectation,
) -> Result<Option<usize>, HarnessError> {
    let k = setup.horizon;
    let expected_l = expectation.lateral(k);
    let driving = UserDriving::new(setup, user, expectation, &expected_l);
    let mut scene = setup.scene.clone();
    let mut previous = State {
        l: expected_l[0],
        ..expectation.states[0]
    };
    for i in 1..=k {
        let (next, _) = driving.step(&scene, &previous, i, 0);
        if entering(setup, &scene, &previous, &next)?.is_some_and(|ahead| beside(&ahead)) {
            return Ok(Some(i));
        }
        scene.step(setup.dt, setup.ego_state(&next))?;
        previous = next;
    }
    Ok(None)
}

/// The safety of `plan` driven to its end in a clone of the scene, with the other
/// vehicles reacting as the simulation moves them: the prediction that the safety
/// layer checks before the ego drives a plan.
pub fn plan_safety(setup: &Setup, plan: &Plan) -> Result<SafetyMetrics, HarnessError> {
    states_safety(setup, &plan.states)
}

/// The safety of `states` (plan frame, from the trigger) driven by the system to
/// their end in a clone of the scene, under the longitudinal guard.
pub(crate) fn states_safety(
    setup: &Setup,
    states: &[State],
) -> Result<SafetyMetrics, HarnessError> {
    let mut scene = setup.scene.clone();
    let mut monitor = SafetyMonitor::new(setup.safety, &scene, setup.target_l);
    drive_states(setup, &mut scene, states, |i, _, scene| {
        monitor.observe(i, scene);
        false
    })?;
    Ok(monitor.metrics())
}

/// The share of the driven lane change's distance covered before the takeover
/// (1 without one). The lane change ends where the driven path settles on the
/// target lane, and never before the step after the takeover, so that a
/// takeover always gives a ratio below 1.
pub(crate) fn perceived_safety_ratio(
    driven: &[State],
    target_l: f64,
    k: usize,
    takeover: Option<&Takeover>,
) -> f64 {
    let Some(t) = takeover else {
        return 1.0;
    };
    let end = lane_change_end(driven, target_l).max(t.step + 1).min(k);
    let whole = driven[end].s;
    if whole > 0.0 {
        (t.distance_m / whole).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// The first step from which the driven lateral position stays within 5 cm of the
/// target lane's centre: the end of the lane change.
pub(crate) fn lane_change_end(driven: &[State], target_l: f64) -> usize {
    let mut end = driven.len() - 1;
    for i in (0..driven.len()).rev() {
        if (driven[i].l - target_l).abs() > 0.05 {
            break;
        }
        end = i;
    }
    end
}
