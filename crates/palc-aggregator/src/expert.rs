//! Expert trajectory generators (Eqs. 24-26 and a lesson-based one).
//!
//! Both only *build* a planning problem: the expert is planned by the same
//! [`palc_planner::Planner`] as every plan, with its tracking term
//! ([`palc_planner::Tracking`], the form of Eq. 25). There is no second solver.

use palc_planner::{Problem, State, Tracking};
use palc_zone_filter::{BoundsConfig, StepBounds};
use serde::{Deserialize, Serialize};

use crate::{AggregatorError, Lesson};

/// What a generator may read to build the expert problem.
#[derive(Debug, Clone, Copy)]
pub struct ExpertInput<'a> {
    /// The problem template as the caller gave it (its own lateral bounds, e.g. the road).
    pub template: &'a Problem,
    /// The problem the next plan solves: the template with the current weights and the
    /// lateral bounds of the plan (the zone's where it gives one).
    pub plan_problem: &'a Problem,
    /// The lesson.
    pub lesson: &'a Lesson,
    /// The zone's bounds per step `0..=K`, when the zone is used.
    pub zone_bounds: Option<&'a [StepBounds]>,
    /// How the zone bounds were computed (its lateral range tells a one-sided
    /// bound of the paper's projection from a two-sided one).
    pub bounds_config: &'a BoundsConfig,
}

/// Builds the planning problem whose solution is the expert trajectory `ψ^E`.
pub trait ExpertGenerator {
    /// A short name for reports and errors (`zone_centre`, `lesson`).
    fn name(&self) -> &'static str;

    /// The expert problem (the caller plans it with its planner).
    fn problem(&self, input: &ExpertInput<'_>) -> Result<Problem, AggregatorError>;
}

/// The paper's expert (Eqs. 24-26): the current cost `C^init` plus the tracking of the
/// zone's centre line `(l_min,i + l_max,i) / 2` with `Q^p = diag(0, 0, q_l, 0)`.
///
/// Only steps where the zone gives a *two-sided* bound are tracked: where the zone
/// says nothing, or a side of the paper's projection fell back to the edge of the
/// lateral range, the centre would be (near) the lane marking, which must not be
/// tracked (NOTES.md, prototype finding 4). `s`, `v` and `φ` of `X^p_i` are the
/// decision variables themselves in Eq. (26), so their weights are 0 (their reference
/// values, taken from the lesson's plan, do not matter). The expert is constrained by
/// the same lateral bounds as the plan.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ZoneCentreExpert {
    /// `q_l` (per m², per step); finite and `> 0`. Default `10`: half a metre from the
    /// centre costs 2.5 per step, an order above the lateral terms of typical
    /// standard weights, so the centre line dominates where the zone is two-sided.
    pub lateral_weight: f64,
}

impl Default for ZoneCentreExpert {
    fn default() -> Self {
        ZoneCentreExpert {
            lateral_weight: 10.0,
        }
    }
}

impl ExpertGenerator for ZoneCentreExpert {
    fn name(&self) -> &'static str {
        "zone_centre"
    }

    fn problem(&self, input: &ExpertInput<'_>) -> Result<Problem, AggregatorError> {
        check_weight("expert.lateral_weight", self.lateral_weight)?;
        let Some(bounds) = input.zone_bounds else {
            return Err(AggregatorError::ConflictingOptions {
                reason: "the zone_centre expert needs the zone: set use_zone = true or use the lesson expert",
            });
        };
        let [lo, hi] = input.bounds_config.lateral_range;
        let planned = &input.lesson.planned.states;
        let reference = bounds
            .iter()
            .enumerate()
            .map(|(i, b)| match *b {
                StepBounds::Bounded { min, max } if i > 0 && min > lo && max < hi => {
                    let base = planned.get(i).copied().unwrap_or_default();
                    Some(State {
                        l: 0.5 * (min + max),
                        ..base
                    })
                }
                _ => None,
            })
            .collect();
        Ok(Problem {
            tracking: Some(Tracking {
                weights: [0.0, 0.0, self.lateral_weight, 0.0],
                reference,
            }),
            ..input.plan_problem.clone()
        })
    }
}

/// The lesson expert: the executed trajectory (the system's part, then the user's
/// part after the takeover), re-planned with the current cost plus a strong tracking
/// term so that it satisfies the planner's dynamics, steering bounds and terminal
/// condition.
///
/// It is observable and carries exactly the lesson; an independent prototype
/// personalized with it where the zone-centre expert did not (NOTES.md, "A repaired
/// loop did personalize"). The lateral bounds are the template's (e.g. the road), not
/// the zone's: the demonstration is what was driven. Steps `1..=K` are tracked.
///
/// Tolerance: when the executed trajectory follows the planner's model and ends at the
/// terminal condition, the expert's `l` stays within 0.05 m of it at every step with
/// the default weights (tested).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LessonExpert {
    /// Diagonal of `Q^p` for `[s, v, l, φ]`; each entry finite and `>= 0`, `l`'s
    /// `> 0`. Default `[0, 0, 1000, 0]`: `l` only, strong enough that 1 cm costs 0.1
    /// per step (more than a whole stage of typical weights), while the longitudinal
    /// motion stays the planner's own.
    pub tracking: [f64; 4],
}

impl Default for LessonExpert {
    fn default() -> Self {
        LessonExpert {
            tracking: [0.0, 0.0, 1000.0, 0.0],
        }
    }
}

impl ExpertGenerator for LessonExpert {
    fn name(&self) -> &'static str {
        "lesson"
    }

    fn problem(&self, input: &ExpertInput<'_>) -> Result<Problem, AggregatorError> {
        const FIELDS: [&str; 4] = [
            "expert.tracking[0] (s)",
            "expert.tracking[1] (v)",
            "expert.tracking[2] (l)",
            "expert.tracking[3] (phi)",
        ];
        for (field, &q) in FIELDS.iter().zip(&self.tracking) {
            if !(q.is_finite() && q >= 0.0) {
                return Err(AggregatorError::InvalidOption {
                    field,
                    value: q,
                    bound: "finite and >= 0",
                });
            }
        }
        check_weight(FIELDS[2], self.tracking[2])?;
        let reference = (input.lesson.demonstrated().iter())
            .enumerate()
            .map(|(i, x)| (i > 0).then_some(*x))
            .collect();
        Ok(Problem {
            lateral_bounds: input.template.lateral_bounds.clone(),
            tracking: Some(Tracking {
                weights: self.tracking,
                reference,
            }),
            ..input.plan_problem.clone()
        })
    }
}

/// Which expert generator the step uses.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ExpertKind {
    /// [`ZoneCentreExpert`] (the paper, Eqs. 24-26).
    ZoneCentre(ZoneCentreExpert),
    /// [`LessonExpert`] (the default).
    Lesson(LessonExpert),
}

impl Default for ExpertKind {
    fn default() -> Self {
        ExpertKind::Lesson(LessonExpert::default())
    }
}

impl ExpertKind {
    /// The generator behind the option.
    pub fn generator(&self) -> &dyn ExpertGenerator {
        match self {
            ExpertKind::ZoneCentre(g) => g,
            ExpertKind::Lesson(g) => g,
        }
    }
}

fn check_weight(field: &'static str, value: f64) -> Result<(), AggregatorError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(AggregatorError::InvalidOption {
            field,
            value,
            bound: "finite and > 0",
        })
    }
}
