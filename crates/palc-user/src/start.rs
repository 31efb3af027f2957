//! When a driver starts its lane change: the one definition of the start
//! decision, which the simulated users run forward and palc's learner estimates
//! (palc-harness `driver/`).
//!
//! A [`StartModel`] decides at the first step at which its [`StartRule`] is met
//! (the decision), waits its reaction time, then starts at the first step from
//! there at which the target lane's gaps are acceptable: the leader's net gap at
//! least `min_lead_gap_s` at the ego's speed, the follower's positive and at least
//! `min_lag_gap_s` at its own speed ([`Style::accepts`]). This is the structure of
//! gap-acceptance models (Ahmed, 1999; Toledo et al., 2003): a decision on the
//! vehicle ahead, then a critical gap on the target lane.

use crate::family::{Family, StartRule};
use crate::situation::Situation;
use crate::style::Style;

/// The parameters of a driver's start decision.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StartModel {
    /// The decision's cue and threshold.
    pub rule: StartRule,
    /// The time-headway threshold (s) of the rules that read the headway
    /// ([`StartRule::TimeHeadway`], [`StartRule::HeadwayOrTtc`]).
    pub time_headway_s: f64,
    /// Delay between the decision and the earliest start (s).
    pub reaction_s: f64,
    /// Smallest accepted net gap to the target lane's leader, as a time gap at
    /// the ego's speed (s).
    pub min_lead_gap_s: f64,
    /// Smallest accepted net gap to the target lane's follower, as a time gap at
    /// the follower's speed (s).
    pub min_lag_gap_s: f64,
}

/// Why a start model does not start in a scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NoStart {
    /// The rule is never met within the situations given.
    NeverDecides,
    /// The rule is met at the first step: the driver would have gone before the
    /// scene began.
    DecidedAtFirstStep,
    /// After the decision (at this step) the gaps are never acceptable.
    GapsNeverAcceptable {
        /// The decision's step.
        decision_step: usize,
    },
}

impl StartModel {
    /// The start model of a user of `style` refined by `family`: the family's gap
    /// acceptances where it sets them, the style's otherwise.
    pub fn of(style: &Style, family: &Family) -> StartModel {
        StartModel {
            rule: family.start,
            time_headway_s: style.time_headway_s,
            reaction_s: family.reaction_s,
            min_lead_gap_s: family.min_lead_gap_s.unwrap_or(style.min_lead_gap_s),
            min_lag_gap_s: family.min_lag_gap_s.unwrap_or(style.min_lag_gap_s),
        }
    }

    /// Whether the decision is taken in `situation`, for an ego whose set speed
    /// is `set_speed_mps`.
    pub fn decides(&self, situation: &Situation, set_speed_mps: f64) -> bool {
        self.rule
            .decides(situation, self.time_headway_s, set_speed_mps)
    }

    /// Whether, once decided, the driver accepts the target lane's gaps in
    /// `situation` ([`Style::accepts`]).
    pub fn accepts(&self, situation: &Situation) -> bool {
        self.gaps().accepts(situation)
    }

    /// The reaction in whole steps of `dt`, rounding up (1e-9 absorbs a delay
    /// that is a multiple of the step up to rounding).
    pub fn reaction_steps(&self, dt: f64) -> usize {
        StartModel::steps_of_reaction(self.reaction_s, dt)
    }

    /// A reaction of `reaction_s` in whole steps of `dt`, as
    /// [`StartModel::reaction_steps`] counts it.
    pub fn steps_of_reaction(reaction_s: f64, dt: f64) -> usize {
        (reaction_s / dt - 1e-9).ceil().max(0.0) as usize
    }

    /// The decision's step and the start's step in `situations` (step `dt`),
    /// where `also` says at which steps a start is allowed beyond the gaps (the
    /// safety layer's check; `|_| true` without it).
    ///
    /// # Errors
    /// [`NoStart`] says which part of the decision never happened.
    pub fn start_step(
        &self,
        situations: &[Situation],
        dt: f64,
        set_speed_mps: f64,
        also: impl Fn(usize) -> bool,
    ) -> Result<(usize, usize), NoStart> {
        let decision_step = (situations.iter())
            .position(|s| self.decides(s, set_speed_mps))
            .ok_or(NoStart::NeverDecides)?;
        if decision_step == 0 {
            return Err(NoStart::DecidedAtFirstStep);
        }
        let earliest = decision_step + self.reaction_steps(dt);
        let start = (earliest..situations.len())
            .find(|&i| self.accepts(&situations[i]) && also(i))
            .ok_or(NoStart::GapsNeverAcceptable { decision_step })?;
        Ok((decision_step, start))
    }

    fn gaps(&self) -> Style {
        Style {
            time_headway_s: self.time_headway_s,
            lane_change_duration_s: 1.0,
            min_lead_gap_s: self.min_lead_gap_s,
            min_lag_gap_s: self.min_lag_gap_s,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seen(headway: f64, lead: Option<f64>, lag: Option<f64>) -> Situation {
        Situation {
            time_headway_s: headway,
            preceding_gap_m: headway * 20.0,
            preceding_speed: Some(15.0),
            target_lead_gap_m: lead,
            target_lag_gap_m: lag,
            ego_speed: 20.0,
            target_lead_speed: lead.map(|_| 20.0),
            target_lag_speed: lag.map(|_| 20.0),
        }
    }

    #[test]
    fn decides_reacts_then_waits_for_the_gaps() {
        let model = StartModel {
            rule: StartRule::TimeHeadway,
            time_headway_s: 1.5,
            reaction_s: 0.2,
            min_lead_gap_s: 0.5,
            min_lag_gap_s: 0.5,
        };
        // Headway falls 0.1 s per step; the follower is alongside until step 6.
        let situations: Vec<Situation> = (0..12)
            .map(|i| {
                let lag = if i < 6 { -1.0 } else { 12.0 };
                seen(2.0 - 0.1 * f64::from(i), Some(30.0), Some(lag))
            })
            .collect();
        assert_eq!(
            model.start_step(&situations, 0.1, 25.0, |_| true),
            Ok((5, 7))
        );
        // The follower at 12 m = 0.6 s is accepted from step 6 for a driver
        // without reaction, and refused for one who needs 0.7 s behind.
        let quick = StartModel {
            reaction_s: 0.0,
            ..model
        };
        assert_eq!(
            quick.start_step(&situations, 0.1, 25.0, |_| true),
            Ok((5, 6))
        );
        let wary = StartModel {
            min_lag_gap_s: 0.7,
            ..model
        };
        assert_eq!(
            wary.start_step(&situations, 0.1, 25.0, |_| true),
            Err(NoStart::GapsNeverAcceptable { decision_step: 5 })
        );
        let early = StartModel {
            time_headway_s: 3.0,
            ..model
        };
        assert_eq!(
            early.start_step(&situations, 0.1, 25.0, |_| true),
            Err(NoStart::DecidedAtFirstStep)
        );
    }
}
