//! What the harness hands over after one takeover.

use palc_planner::{Plan, State};
use palc_zone_filter::{Sample, StepScene};

use crate::AggregatorError;

/// One lesson: the lane change that was taken over.
#[derive(Debug, Clone, PartialEq)]
pub struct Lesson {
    /// The plan that was being driven (planned with the experience's weights); its
    /// features are `Φ(ψ^(t-1))` of Eq. (35).
    pub planned: Plan,
    /// The executed trajectory, steps `0..=K` (length `K + 1`): the system's part up to
    /// `takeover_step`, then the user's part.
    pub executed: Vec<State>,
    /// What the lesson demonstrates, derived from `executed` by the method (e.g. the
    /// user's whole lane change fitted before the takeover), steps `0..=K`; `None`
    /// when it demonstrates what was driven. The lesson expert tracks it.
    pub demonstration: Option<Vec<State>>,
    /// The first step driven by the user (`0..=K`).
    pub takeover_step: usize,
    /// The lesson's labelled samples for the zone model. The caller labels them: the
    /// labelling rule belongs to the method, not to the aggregator.
    pub samples: Vec<Sample>,
    /// Per planning step `0..=K` (length `K + 1`), the scene the zone filter projects
    /// its boundary on (ego station, reference `l`, predicted vehicles). Used only when
    /// the options use the zone.
    pub step_scenes: Vec<StepScene>,
}

impl Lesson {
    /// The trajectory the lesson demonstrates: [`Lesson::demonstration`], else
    /// what was driven.
    pub fn demonstrated(&self) -> &[State] {
        self.demonstration.as_deref().unwrap_or(&self.executed)
    }

    /// Checks the lengths against the horizon `K` and that the executed states are finite.
    pub(crate) fn validate(&self, horizon: usize, use_zone: bool) -> Result<(), AggregatorError> {
        let mismatch = |field, expected, found| {
            if expected == found {
                Ok(())
            } else {
                Err(AggregatorError::LessonMismatch {
                    field,
                    expected,
                    found,
                })
            }
        };
        mismatch("executed", horizon + 1, self.executed.len())?;
        if let Some(demonstration) = &self.demonstration {
            mismatch("demonstration", horizon + 1, demonstration.len())?;
        }
        mismatch("planned.controls", horizon, self.planned.controls.len())?;
        mismatch("planned.features", horizon, self.planned.features.horizon())?;
        if use_zone {
            mismatch("step_scenes", horizon + 1, self.step_scenes.len())?;
        }
        if self.takeover_step > horizon {
            return Err(AggregatorError::InvalidOption {
                field: "lesson.takeover_step",
                value: self.takeover_step as f64,
                bound: "at most the horizon K",
            });
        }
        let demonstrated = self.demonstration.iter().map(|d| ("demonstration", d));
        for (field, states) in [("executed", &self.executed)]
            .into_iter()
            .chain(demonstrated)
        {
            for (i, x) in states.iter().enumerate() {
                for (name, value) in [("s", x.s), ("v", x.v), ("l", x.l), ("phi", x.phi)] {
                    if !value.is_finite() {
                        return Err(AggregatorError::NonFinite {
                            field: format!("{field}[{i}].{name}"),
                            value,
                        });
                    }
                }
            }
        }
        Ok(())
    }
}
