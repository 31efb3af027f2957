//! One lane change with a live driver, step by step ([`LiveLaneChange`]): the
//! system drives until the driver takes over, the driver's commands after.

use palc_planner::{Plan, State};
use palc_traffic::{Scene, ballistic_step};
use palc_user::{Situation, TakeoverCause};

use super::input::{LiveInput, LiveLimits, LiveView};
use super::system::SystemDriver;
use crate::HarnessError;
use crate::acc::acc_leader;
use crate::drive::{Drive, perceived_safety_ratio};
use crate::guard::guarded_user_acceleration;
use crate::record::{ClosedLoopStats, Takeover};
use crate::safety::{SafetyMetrics, SafetyMonitor, Violation};
use crate::setup::{Setup, situation};

/// Whether a live lane change goes on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LiveStatus {
    /// More steps remain.
    Driving,
    /// The last step (`K`) was driven: finish it.
    Done,
}

/// One lane change driven step by step with a live driver
/// ([`crate::LearningLoop::begin_live`], [`LiveLaneChange::advance`],
/// [`crate::LearningLoop::finish_live`]).
#[derive(Debug, Clone)]
pub struct LiveLaneChange {
    system: SystemDriver,
    limits: LiveLimits,
    horizon: usize,
    dt: f64,
    scene: Scene,
    situation: Situation,
    /// What the system drives to at the next step (or, after a takeover, the ego
    /// holding its lateral position).
    proposed: State,
    /// The ACC's command at the next step.
    acc: f64,
    driven: Vec<State>,
    preceding: Vec<[f64; 2]>,
    adjacent: Vec<[f64; 2]>,
    system_monitor: SafetyMonitor,
    user_monitor: SafetyMonitor,
    /// The step of the takeover and the system's state there.
    takeover: Option<(usize, State)>,
    user_speed_differs: bool,
    /// The predicted safety of the plan driven and the safety layer's refusal of
    /// the learned one, if it refused it.
    pub(crate) checked: (SafetyMetrics, Option<Violation>),
}

impl LiveLaneChange {
    /// A lane change in `setup` whose system side is `system`.
    pub(crate) fn new(
        setup: &Setup,
        system: SystemDriver,
        first: &Plan,
        limits: LiveLimits,
        checked: (SafetyMetrics, Option<Violation>),
    ) -> Self {
        let scene = setup.scene.clone();
        let system_monitor = SafetyMonitor::new(setup.safety, &scene, setup.target_l);
        let k = setup.horizon;
        Self {
            system,
            limits,
            horizon: k,
            dt: setup.dt,
            situation: situation(&scene),
            proposed: first.states[0],
            acc: 0.0,
            scene,
            driven: Vec::with_capacity(k + 1),
            preceding: Vec::with_capacity(k + 1),
            adjacent: Vec::with_capacity(k + 1),
            user_monitor: system_monitor.clone(),
            system_monitor,
            takeover: None,
            user_speed_differs: false,
            checked,
        }
    }

    /// What the driver sees before the next step.
    pub fn view(&self) -> LiveView<'_> {
        LiveView {
            step: self.driven.len(),
            dt: self.dt,
            previous: self.driven.last().copied(),
            proposed: self.proposed,
            taken_over: self.takeover.is_some(),
            acc_mps2: self.acc,
            scene: &self.scene,
            situation: &self.situation,
        }
    }

    /// The scene at the last step driven.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The states driven so far (plan frame).
    pub fn driven(&self) -> &[State] {
        &self.driven
    }

    /// The step of the takeover, if the driver has taken over.
    pub fn takeover_step(&self) -> Option<usize> {
        self.takeover.map(|(step, _)| step)
    }

    /// The step to be driven next (`K + 1` once done).
    pub fn step(&self) -> usize {
        self.driven.len()
    }

    /// The lane change's last step, `K`.
    pub fn horizon(&self) -> usize {
        self.horizon
    }

    /// Drives the next step with the driver's `input`: the system's proposed
    /// state, or after a takeover the driver's commands held to the limits (the
    /// acceleration also to the longitudinal guard, as a simulated user's, and
    /// the lateral position to the road, the ego's body between its edges).
    ///
    /// # Errors
    /// [`HarnessError::LiveOutOfStep`] after the last step; scene and re-plan errors.
    pub fn advance(&mut self, setup: &Setup, input: LiveInput) -> Result<LiveStatus, HarnessError> {
        let i = self.driven.len();
        let k = self.horizon;
        if i > k {
            return Err(HarnessError::LiveOutOfStep {
                steps: i,
                expected: k + 1,
                action: "stepped",
            });
        }
        if self.takeover.is_none() && input.take_over {
            self.takeover = Some((i, self.proposed));
        }
        let by_user = self.takeover.is_some();
        let state = match (by_user, self.driven.last().copied()) {
            (true, Some(previous)) => self.commanded(setup, &previous, &input),
            _ => self.proposed,
        };
        if i > 0 {
            self.scene.step(setup.dt, setup.ego_state(&state))?;
        }
        if by_user {
            self.user_monitor.observe(i, &self.scene);
        } else {
            self.system_monitor.observe(i, &self.scene);
            if i > 0 {
                self.system.drove(setup, &self.scene, state, i)?;
            }
        }
        let frame = |p: Option<&palc_traffic::Vehicle>| {
            p.map_or([1e4, 0.0], |v| [v.state.s - setup.origin_s, v.state.l])
        };
        self.preceding.push(frame(self.scene.preceding()));
        self.adjacent.push(frame(self.scene.adjacent()));
        self.driven.push(state);
        if i == k {
            return Ok(LiveStatus::Done);
        }
        self.situation = situation(&self.scene);
        self.acc = (setup.acc).ego_acceleration(
            state.v,
            setup.set_speed,
            acc_leader(&self.scene),
            &setup.safety,
        );
        self.proposed = if by_user {
            let moved = ballistic_step(state.v, self.acc, setup.dt);
            State {
                s: state.s + moved.distance,
                v: moved.speed,
                ..state
            }
        } else {
            self.system.propose(setup, &self.scene, &state, i + 1)
        };
        Ok(LiveStatus::Driving)
    }

    /// The driver's state one step after `previous` under `input`.
    fn commanded(&mut self, setup: &Setup, previous: &State, input: &LiveInput) -> State {
        let chosen = self.limits.acceleration(input, self.acc);
        // Exact: a driver who leaves its speed to the ACC gets its command.
        self.user_speed_differs |= chosen != self.acc;
        let acceleration = guarded_user_acceleration(setup, &self.scene, previous.v, chosen);
        let moved = ballistic_step(previous.v, acceleration, setup.dt);
        // The ego's body stays on the road: a driver steering on meets its edge.
        let road = self.scene.road();
        let half = self.scene.ego().map_or(0.0, |ego| ego.width / 2.0);
        let (low, high) = (road.right_edge() + half, road.left_edge() - half);
        let l = previous.l + self.limits.lateral_speed(input) * setup.dt;
        State {
            s: previous.s + moved.distance,
            v: moved.speed,
            l: if low <= high { l.clamp(low, high) } else { l },
            phi: 0.0,
        }
    }

    /// The finished lane change as a [`Drive`], as [`crate::advanced::execute`]
    /// returns a simulated user's, and the closed loop's counts. A live driver
    /// states no expectation: `expected_l` is empty, `expected` is the standard
    /// ALC's lane change, and the deviations are measured between the plan and
    /// what was driven.
    ///
    /// # Errors
    /// [`HarnessError::LiveOutOfStep`] before the last step.
    pub(crate) fn finish(
        self,
        setup: &Setup,
    ) -> Result<(Drive, Option<ClosedLoopStats>), HarnessError> {
        let k = self.horizon;
        if self.driven.len() != k + 1 {
            return Err(HarnessError::LiveOutOfStep {
                steps: self.driven.len(),
                expected: k + 1,
                action: "finished",
            });
        }
        let (plan, stats) = self.system.finish(setup)?;
        let mut driven = self.driven;
        let dt = setup.dt;
        if let Some((step, _)) = self.takeover {
            for i in step..k {
                let run = (driven[i].v * dt).max(1e-9);
                driven[i].phi = (driven[i + 1].l - driven[i].l) / run;
            }
        }
        let deviation = |i: usize| (plan.states[i].l - driven[i].l).abs();
        let takeover = self.takeover.map(|(step, at)| Takeover {
            step,
            time_s: step as f64 * dt,
            distance_m: at.s,
            deviation_m: deviation(step),
            cause: TakeoverCause::Deviation,
        });
        let perceived_safety_ratio =
            perceived_safety_ratio(&driven, setup.target_l, k, takeover.as_ref());
        let max_deviation_m = (0..=k).map(deviation).fold(0.0, f64::max);
        let drive = Drive {
            plan,
            expected: setup.standard_lane_change(&setup.standard_alc),
            expected_l: Vec::new(),
            takeover,
            driven,
            preceding: self.preceding,
            adjacent: self.adjacent,
            max_deviation_m,
            perceived_safety_ratio,
            safety: self.system_monitor.metrics(),
            user_safety: self.user_monitor.metrics(),
            user_speed_differs: self.user_speed_differs,
        };
        Ok((drive, stats))
    }
}
