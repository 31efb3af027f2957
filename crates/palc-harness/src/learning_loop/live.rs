//! The loop with a live driver: [`LearningLoop::begin_live`] starts the next
//! lane change, the caller advances it step by step with the driver's inputs
//! ([`LiveLaneChange::advance`]), and [`LearningLoop::finish_live`] records it
//! and learns from a takeover as [`LearningLoop::step`] does for a simulated user.
//! [`LearningLoop::step_live`] does all three with a [`LiveDriver`].

use crate::HarnessError;
use crate::live::{LiveDriver, LiveLaneChange, LiveLimits, LiveStatus, system::SystemDriver};
use crate::observer::Observer;
use crate::record::{LaneChangeRecord, Outcome, RunResult};
use crate::setup::Setup;

use super::LearningLoop;

impl LearningLoop {
    /// The scenario's set-up.
    pub fn setup(&self) -> &Setup {
        &self.scenario.setup
    }

    /// Starts the next lane change with a live driver held to `limits`: the plan
    /// the safety layer lets through and, in closed loop, its re-planning.
    ///
    /// # Errors
    /// Invalid limits (`live.*`); a scene error of the safety check.
    pub fn begin_live(&self, limits: LiveLimits) -> Result<LiveLaneChange, HarnessError> {
        limits.validate("live")?;
        let (plan, planned_safety, refusal) = self.checked_plan()?;
        let closed_loop = (self.scenario.closed_loop.clone()).map(|driver| {
            let experience = self.learner.experience.clone();
            (driver, experience, self.policy.options.clone())
        });
        let system = SystemDriver::new(plan.clone(), refusal.is_some(), closed_loop);
        let setup = &self.scenario.setup;
        Ok(LiveLaneChange::new(
            setup,
            system,
            &plan,
            limits,
            (planned_safety, refusal),
        ))
    }

    /// Records the finished live `lane_change` and, on a takeover within the cap,
    /// learns from what the driver drove (the lesson, as a simulated user's).
    ///
    /// # Errors
    /// [`HarnessError::LiveOutOfStep`] for a lane change not driven to its end;
    /// feature errors of the lesson.
    pub fn finish_live(
        &mut self,
        lane_change: LiveLaneChange,
        observer: &mut dyn Observer,
    ) -> Result<&LaneChangeRecord, HarnessError> {
        let index = self.run.records.len();
        let (planned_safety, refusal) = lane_change.checked;
        let (drive, closed_loop) = lane_change.finish(&self.scenario.setup)?;
        let refusal = refusal.or(closed_loop.and_then(|c| c.first_refusal));
        if let Some(violation) = &refusal {
            observer.safety_refusal(index, violation);
        }
        let mut record = self.record(&drive, false);
        record.index = index;
        record.with_spread = false;
        record.planned_safety = planned_safety;
        record.safety_refusal = refusal;
        record.closed_loop = closed_loop;
        self.conclude(index, &drive, record, observer)
    }

    /// Drives the next lane change with `driver` deciding every step, then
    /// records and learns: [`LearningLoop::begin_live`], the steps,
    /// [`LearningLoop::finish_live`].
    ///
    /// # Errors
    /// Those of the three.
    pub fn step_live(
        &mut self,
        driver: &mut dyn LiveDriver,
        limits: LiveLimits,
        observer: &mut dyn Observer,
    ) -> Result<&LaneChangeRecord, HarnessError> {
        let mut lane_change = self.begin_live(limits)?;
        loop {
            let input = driver.decide(&lane_change.view());
            if lane_change.advance(&self.scenario.setup, input)? == LiveStatus::Done {
                break;
            }
        }
        self.finish_live(lane_change, observer)
    }

    /// The run so far as a [`RunResult`] ending in `outcome`, without a further
    /// lane change (no frozen evaluation): what a study that stops a scene on its
    /// own rule records, in `palc learn --record`'s format.
    pub fn into_result(self, outcome: Outcome) -> RunResult {
        let summary = self.run.summary(outcome, &self.policy.stopping);
        RunResult {
            label: self.scenario.label,
            method: self.policy.method,
            horizon: self.scenario.setup.horizon,
            dt: self.scenario.setup.dt,
            summary,
            records: self.run.records,
            experience: self.learner.experience,
            carried_belief: self.learner.carried_belief,
        }
    }
}
