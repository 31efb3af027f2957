//! Carrying an experience into a new scene
//! (docs/experiments/0046-carrying-rehearsal-and-bounds.md): the weights anchored
//! at the user's start predicted in relative space, and a rehearsal of the user's
//! path in the new scene's dynamics.

use palc_aggregator::{
    AggregatorError, AggregatorOptions, Experience, Lesson, StepOutcome, learn_from_lesson,
    plan_problem, resample_weights_shifted,
};
use palc_planner::{Planner, Problem, State, Weights};

use crate::HarnessError;
use crate::driver::{CarriedBelief, start_beyond_readings};
use crate::lesson::scenes;
use crate::onset::{GapAcceptanceSet, UserLaneChange};
use crate::setup::Setup;

/// Who and where an experience is learned: the names it is saved with.
#[derive(Debug, Clone, Copy)]
pub struct Names<'a> {
    /// The user (its style's name).
    pub user: &'a str,
    /// The scenario's label.
    pub scenario: &'a str,
    /// The method's name.
    pub method: &'a str,
}

/// An experience carried into a scene ([`Personalization::carry`](crate::advanced::Personalization::carry)).
#[derive(Debug, Clone)]
pub struct Carried {
    /// The experience the run starts from.
    pub experience: Experience,
    /// The user's path to rehearse in this scene, if any.
    pub rehearsal: Option<Vec<f64>>,
    /// What the driver estimate believed when it was consulted (relative space,
    /// two recorded scenes or more).
    pub belief: Option<CarriedBelief>,
}

/// The experience a run starts from: `previous` carried into this scenario, or a
/// fresh one with the standard ALC's weights; with it, the user's path to rehearse
/// in this scene when there is one.
///
/// The weights are resampled to this scenario's horizon and step. When `relative`
/// (experience in relative space) and a user's start was observed before, they are
/// also shifted so that the learned start falls where this scene predicts the
/// relative state the user started in ([`GapAcceptanceSet::predicted_start_s`]),
/// held no later than [`latest_planned_start_s`]; the last lesson's path is shifted alike and returned
/// for [`rehearse`]. Without an observed start, or when none is predicted here, the
/// weights keep their time base.
///
/// A fresh experience holds `standard_weights` (the standard ALC's at this
/// scenario's horizon) and `names` (user, scenario, method); a carried one takes
/// the scenario's name.
pub(crate) fn starting_experience(
    names: Names<'_>,
    standard_weights: &Weights,
    setup: &Setup,
    previous: Option<&Experience>,
    relative: bool,
) -> Result<Carried, HarnessError> {
    let (k, dt) = (setup.horizon, setup.dt);
    let Some(previous) = previous else {
        let fresh = Experience::new(
            names.user,
            names.scenario,
            names.method,
            standard_weights.clone(),
            dt,
        )?;
        return Ok(Carried {
            experience: fresh,
            rehearsal: None,
            belief: None,
        });
    };
    let mut carried = previous.clone();
    carried.metadata.dt = dt;
    names.scenario.clone_into(&mut carried.metadata.scenario);
    let mut belief = None;
    let anchored = match (relative, previous.anchor_s) {
        (true, Some(anchor)) => {
            let settled = settled_duration_s(setup, previous, anchor);
            let latest = latest_planned_start_s(setup, settled);
            // The lane change whose gaps the prediction checks: the model fitted to
            // the demonstration (a quintic settles within 1 % at 88 % of its
            // duration, and a user who checks its whole lane change waits longer).
            let lane_change = (previous.demonstration.as_deref())
                .and_then(|path| UserLaneChange::fit(path, 0, previous.metadata.dt, setup.target_l))
                .map_or(settled, |fitted| fitted.duration_s.max(settled));
            let estimated = start_beyond_readings(setup, &previous.onsets, lane_change);
            belief = estimated.belief;
            // Where two or more free starts reveal one threshold of a cue the
            // gap-acceptance set reads, its interval places the start to the
            // step; the estimate's predictive, with its 0.2 s observation error,
            // does not, unless it is sure of a cue the set does not read (0089,
            // 0099).
            let set = GapAcceptanceSet::from_onsets(&previous.onsets);
            let exact = set.as_ref().is_some_and(GapAcceptanceSet::revealed_exactly);
            // Where the estimate is sure of a reaction on a cue the set reads,
            // the shortest reaction that makes the starts one threshold places
            // the start to the step, if the set finds one (0102).
            let reacting = (set.as_ref())
                .and_then(GapAcceptanceSet::with_reaction)
                .filter(|_| estimated.on_a_reaction);
            (reacting.and_then(|set| set.predicted_start_s(setup, lane_change)))
                .or_else(|| (estimated.start_s).filter(|_| estimated.on_another_cue || !exact))
                // Where no cue the set reads is consistent across the scenes, its
                // model does not explain them: the estimate's most probable
                // start, however unsure (0095).
                .or_else(|| {
                    let unexplained = set.as_ref().is_some_and(|set| !set.explains());
                    (estimated.most_likely_s).filter(|_| unexplained)
                })
                .or_else(|| set.as_ref()?.predicted_start_s(setup, lane_change))
                .map(|start| (anchor, start.min(latest)))
        }
        _ => None,
    };
    let Some((anchor, start)) = anchored else {
        carried.weights = previous.weights_for(k, dt)?;
        carried.demonstration = None;
        // The weights keep their time base: an anchor past this scene's horizon
        // lies outside it, and an experience holding it would refuse every lesson.
        carried.anchor_s = previous
            .anchor_s
            .filter(|a| (0.0..=k as f64 * dt).contains(a));
        return Ok(Carried {
            experience: carried,
            rehearsal: None,
            belief,
        });
    };
    let shift = start - anchor;
    let from_dt = previous.metadata.dt;
    carried.weights = resample_weights_shifted(&previous.weights, from_dt, k, dt, shift)?;
    carried.anchor_s = Some(start);
    let path = (previous.demonstration.as_deref())
        .filter(|path| !path.is_empty())
        .map(|path| shifted_path(path, from_dt, k, dt, shift));
    carried.demonstration.clone_from(&path);
    Ok(Carried {
        experience: carried,
        rehearsal: path,
        belief,
    })
}

/// The latest start (s) a carried lane change is anchored at: the one whose lane
/// change, `duration_s` long ([`settled_duration_s`]), ends within the planning
/// horizon. Never before the standard ALC's start.
///
/// Users whose family waits for a follower's gap start after the standard ALC (the
/// premise that no user does holds for the paper's three styles only); holding
/// every prediction at the standard ALC's start put theirs up to a second early.
/// The horizon may have been extended to cover the simulated user's own lane
/// change plus the margin; a prediction held at its end is then still later than
/// the user's start by the margin, so the bound never turns a late prediction
/// into a right one.
fn latest_planned_start_s(setup: &Setup, duration_s: f64) -> f64 {
    let standard_start = setup.standard_start_step as f64 * setup.dt;
    (setup.horizon as f64 * setup.dt - duration_s).max(standard_start)
}

/// The duration (s) of the carried lane change: its demonstration from `anchor_s`
/// until it settles within 1 % of its end. A demonstration that settles before
/// its own start (none learned yet) says nothing: the standard ALC's duration, the
/// longest, is assumed instead.
fn settled_duration_s(setup: &Setup, previous: &Experience, anchor_s: f64) -> f64 {
    (previous.demonstration.as_deref())
        .and_then(|path| settled_s(path, previous.metadata.dt))
        .map(|end| end - anchor_s)
        .filter(|&duration| duration > 0.0)
        .unwrap_or(setup.standard_alc.lane_change_duration_s)
}

/// The first time (s) from which `path` (step `dt`) stays within 1 % of its last
/// value's magnitude; `None` for an empty path or a last value of 0.
fn settled_s(path: &[f64], dt: f64) -> Option<f64> {
    let last = *path.last()?;
    let tolerance = 0.01 * last.abs();
    if tolerance == 0.0 {
        return None;
    }
    let unsettled = path.iter().rposition(|l| (l - last).abs() > tolerance);
    Some(unsettled.map_or(0.0, |i| (i + 1) as f64 * dt))
}

/// `path` (step `from_dt`) at steps `0..=horizon` of `to_dt`, moved `shift_s`
/// later: linear between samples, its first value held before its start and its
/// last after its end. `path` is not empty.
fn shifted_path(path: &[f64], from_dt: f64, horizon: usize, to_dt: f64, shift_s: f64) -> Vec<f64> {
    let last = path.len() - 1;
    (0..=horizon)
        .map(|i| {
            let position = ((i as f64 * to_dt - shift_s) / from_dt).clamp(0.0, last as f64);
            let below = position.floor() as usize;
            let above = (below + 1).min(last);
            let fraction = position - below as f64;
            path[below] + fraction * (path[above] - path[below])
        })
        .collect()
}

/// Rehearses the user's `path` (at steps `0..=K` of this scene) before the first
/// lane change: one lesson in which the user drove the whole path, learned as any
/// other ([`learn_from_lesson`]), so that the carried weights produce that path in
/// this scene's dynamics (its speeds, horizon and terminal condition) and not only
/// in the scene they were learned in. The lesson counter is left as it was: a
/// rehearsal is not a takeover. When the rehearsal cannot be learned (an expert
/// that cannot be planned), the carried experience is returned unchanged.
pub(crate) fn rehearse(
    planner: &mut Planner,
    setup: &Setup,
    template: &Problem,
    experience: Experience,
    path: &[f64],
    options: &AggregatorOptions,
) -> Experience {
    let rehearsed = (|| -> Result<StepOutcome, AggregatorError> {
        let (problem, _) = plan_problem(
            planner,
            &experience,
            template,
            &scenes(setup, None),
            options,
        )?;
        let planned = planner.plan(&problem)?;
        let executed = (path.iter().enumerate())
            .map(|(i, &l)| {
                let [s, v] = setup.lane_keeping[i];
                State { s, v, l, phi: 0.0 }
            })
            .collect();
        let lesson = Lesson {
            step_scenes: scenes(setup, Some(&planned.states)),
            planned,
            executed,
            demonstration: None,
            takeover_step: 0,
            samples: Vec::new(),
        };
        learn_from_lesson(planner, &experience, &lesson, template, options)
    })();
    match rehearsed {
        Ok(outcome) => Experience {
            metadata: experience.metadata.clone(),
            ..outcome.experience
        },
        Err(_) => experience,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shifted_path_holds_both_ends() {
        let path = [0.0, 1.0, 2.0, 3.0];
        let later = shifted_path(&path, 0.1, 5, 0.1, 0.15);
        let expected = [0.0, 0.0, 0.5, 1.5, 2.5, 3.0];
        for (got, want) in later.iter().zip(expected) {
            assert!((got - want).abs() < 1e-12, "{later:?}");
        }
        assert_eq!(shifted_path(&path, 0.1, 3, 0.1, 0.0), path.to_vec());
    }

    #[test]
    fn a_path_settles_where_it_stays_within_one_percent_of_its_end() {
        let path = [0.0, 0.0, 1.0, 3.0, 3.47, 3.5, 3.5];
        // 3.47 is within 0.035 of 3.5; 3.0 is not.
        let settled = settled_s(&path, 0.1).expect("a lane change");
        assert!((settled - 0.4).abs() < 1e-12, "{settled}");
        assert_eq!(settled_s(&[0.0, 0.0], 0.1), None);
        assert_eq!(settled_s(&[], 0.1), None);
    }
}
