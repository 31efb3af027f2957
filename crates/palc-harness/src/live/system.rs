//! The system's side of a live lane change: the plan driven step by step under
//! the longitudinal guard and, in closed loop, re-planned every period exactly
//! as [`ClosedLoop::drive`] does, so that a live driver meets the trajectory a
//! simulated user would.

use palc_aggregator::{AggregatorOptions, Experience};
use palc_planner::{Control, Plan, State};
use palc_traffic::Scene;

use crate::HarnessError;
use crate::closed_loop::{ClosedLoop, Policy, Replan, driven_plan};
use crate::guard::guarded_step;
use crate::record::ClosedLoopStats;
use crate::setup::Setup;

/// The system driving a lane change until a takeover.
#[derive(Debug, Clone)]
pub(crate) struct SystemDriver {
    /// The re-planning driver and what it re-plans with, in closed loop.
    closed_loop: Option<(ClosedLoop, Experience, AggregatorOptions)>,
    policy: Policy,
    /// The plan being driven and the step of the lane change at which it starts.
    current: Plan,
    start: usize,
    /// The first plan, returned as the drive's plan when nothing was re-planned.
    first: Plan,
    /// States the system drove (steps `0..`), their controls and lateral slacks.
    states: Vec<State>,
    controls: Vec<Control>,
    lateral_violation: Vec<f64>,
    stats: ClosedLoopStats,
}

impl SystemDriver {
    /// The system driving `first` (the safety layer's choice; `fell_back` when it
    /// is the standard ALC's fallback), re-planning with `closed_loop` when given.
    pub(crate) fn new(
        first: Plan,
        fell_back: bool,
        closed_loop: Option<(ClosedLoop, Experience, AggregatorOptions)>,
    ) -> Self {
        let policy = match &closed_loop {
            Some((driver, _, _)) if fell_back && driver.has_fallback() => Policy::Standard,
            _ => Policy::Learned,
        };
        Self {
            closed_loop,
            policy,
            current: first.clone(),
            start: 0,
            lateral_violation: vec![first.lateral_violation.first().copied().unwrap_or(0.0)],
            states: vec![first.states[0]],
            controls: Vec::new(),
            first,
            stats: ClosedLoopStats {
                fallback_step: fell_back.then_some(0),
                ..ClosedLoopStats::default()
            },
        }
    }

    /// The state the system drives the ego to at step `i >= 1` from `previous`
    /// (the state driven at `i − 1`) in `scene` (the scene there).
    pub(crate) fn propose(
        &self,
        setup: &Setup,
        scene: &Scene,
        previous: &State,
        i: usize,
    ) -> State {
        let j = i - self.start;
        guarded_step(
            setup,
            scene,
            previous,
            &self.current.states[j - 1],
            &self.current.states[j],
        )
    }

    /// Records that the system drove `state` at step `i >= 1`, reaching `scene`,
    /// and re-plans there when a period ends and at least two steps remain.
    ///
    /// # Errors
    /// Scene and aggregator errors of the re-plan, as in [`ClosedLoop::drive`].
    pub(crate) fn drove(
        &mut self,
        setup: &Setup,
        scene: &Scene,
        state: State,
        i: usize,
    ) -> Result<(), HarnessError> {
        let j = i - self.start;
        self.controls.push(self.current.controls[j - 1]);
        self.states.push(state);
        (self.lateral_violation).push(
            self.current
                .lateral_violation
                .get(j)
                .copied()
                .unwrap_or(0.0),
        );
        let k = setup.horizon;
        let Some((driver, experience, options)) = &self.closed_loop else {
            return Ok(());
        };
        if i % driver.period() != 0 || k - i < 2 {
            return Ok(());
        }
        let mut tail = self.current.states[j..].to_vec();
        tail[0] = state;
        let mut outcome =
            driver.replan(setup, experience, options, scene, &tail, i, self.policy)?;
        self.stats.replans += 1;
        if let Replan::Refused(violation) = outcome {
            self.stats.refusals += 1;
            self.stats.first_refusal.get_or_insert(violation);
            if self.policy == Policy::Learned && driver.has_fallback() {
                self.policy = Policy::Standard;
                self.stats.fallback_step = Some(i);
                outcome =
                    driver.replan(setup, experience, options, scene, &tail, i, self.policy)?;
                self.stats.replans += 1;
                if let Replan::Refused(_) = outcome {
                    self.stats.refusals += 1;
                }
            }
        }
        match outcome {
            Replan::Drive(plan) => {
                self.current = plan;
                self.start = i;
            }
            Replan::Failed => self.stats.replan_failures += 1,
            Replan::Refused(_) => {}
        }
        Ok(())
    }

    /// The plan of the lane change: the first plan when nothing was re-planned,
    /// else the states the system drove followed by the rest of the plan it was
    /// driving, with the learned cost of the whole (as [`ClosedLoop::drive`]
    /// returns it). Also the closed loop's counts, in closed loop.
    ///
    /// # Errors
    /// A feature error of the assembled trajectory.
    pub(crate) fn finish(
        self,
        setup: &Setup,
    ) -> Result<(Plan, Option<ClosedLoopStats>), HarnessError> {
        let Some((_, experience, _)) = &self.closed_loop else {
            return Ok((self.first, None));
        };
        if self.stats.replans == 0 && self.stats.fallback_step.is_none() {
            return Ok((self.first, Some(self.stats)));
        }
        let last = self.states.len() - 1;
        let j = last - self.start;
        let mut states = self.states.clone();
        states.extend_from_slice(&self.current.states[j + 1..]);
        let mut controls = self.controls.clone();
        controls.extend_from_slice(&self.current.controls[j..]);
        let mut lateral_violation = self.lateral_violation.clone();
        lateral_violation.resize(states.len(), 0.0);
        let pieces = (states, controls, lateral_violation);
        let plan = driven_plan(setup, experience, pieces, &self.first)?;
        Ok((plan, Some(self.stats)))
    }
}
