//! What a user's start reveals in its scene ([`onset_at`]): the relative state
//! at the start, the target-lane gap that held it back, the ceiling a wait for
//! the follower puts on the decision, and the lead gaps refused after deciding;
//! and where a start fitted beside a vehicle moves to
//! ([`start_clear_of_vehicles_beside`]).

use palc_aggregator::Onset;
use palc_user::Situation;

use super::cues::{cue_value, lag_time_gap, lead_time_gap, ttc};
use super::gap_acceptance::{assumed_lead_gap_s, decision};
use crate::driver::prior::Cue;
use crate::setup::{Setup, target_gaps_safe};

/// The step at which a start at `start_s` happened: decisions are taken at
/// control steps. At least 1, so that a step before it exists.
fn start_step(setup: &Setup, start_s: f64) -> Option<usize> {
    let last = setup.situations.len().checked_sub(1)?;
    Some(
        ((start_s / setup.dt).round() as usize)
            .clamp(1, last.max(1))
            .min(last),
    )
}

/// The threshold of a feature revealed by a start at step `step`: the midpoint
/// between its value at that step (where the start condition held) and at the
/// step before (where it did not yet). `None` when the feature is missing or
/// not finite at the start.
fn revealed(setup: &Setup, step: usize, field: impl Fn(&Situation) -> Option<f64>) -> Option<f64> {
    let at = field(setup.situations.get(step)?).filter(|x| x.is_finite())?;
    let before = step
        .checked_sub(1)
        .and_then(|i| field(&setup.situations[i]))
        .filter(|x| x.is_finite());
    Some(before.map_or(at, |b| 0.5 * (at + b)))
}

/// Whether a target-lane gap held the user back before the start at `step`: at
/// the step before it its vehicle was alongside (gap ≤ 0) or absent, while it is
/// present at the start, so the user started as soon as the gap opened.
///
/// Only the step before: a vehicle that left the ego's side earlier may have
/// held the user back a little longer (a follower gap it needs, a reaction) or
/// not at all (a decision that came later), and one scene cannot tell. Read as
/// a wait, such a start only bounded the decision from below and required the
/// follower gap it had; read as a free start, its relative state is the
/// decision. Over every pair of the transfer matrix
/// (docs/experiments/0054-which-starts-were-waits.md) the second reading needs
/// fewer takeovers with experience for every start rule than the first did with a
/// window of 1 s (deterministic users 190 -> 165).
fn held_back(setup: &Setup, step: usize, gap: fn(&Situation) -> Option<f64>) -> bool {
    let present_at_start = gap(&setup.situations[step]).is_some();
    let opened_now = step
        .checked_sub(1)
        .is_some_and(|i| gap(&setup.situations[i]).is_none_or(|g| g <= 0.0));
    present_at_start && opened_now
}

/// The start of a lesson fitted at `start_s` (s), moved to the first step at
/// which no target-lane vehicle is alongside when the fit placed it at a step
/// where one is: nobody moves into a vehicle beside them, so the user started
/// after it had passed, and the fit, which extrapolates the onset from what
/// was seen after the takeover, placed the start too early. Never past
/// `takeover_s`: a vehicle alongside until the takeover leaves the fit's start
/// as it is, and a start after the takeover was seen (the fit holds it within
/// the user's last step at rest and first moved one).
pub(crate) fn start_clear_of_vehicles_beside(setup: &Setup, start_s: f64, takeover_s: f64) -> f64 {
    let Some(step) = start_step(setup, start_s) else {
        return start_s;
    };
    if !setup.situations[step].target_vehicle_beside() {
        return start_s;
    }
    (step..setup.situations.len())
        .find(|&i| !setup.situations[i].target_vehicle_beside())
        .map(|i| i as f64 * setup.dt)
        .filter(|&clear| clear <= takeover_s)
        .unwrap_or(start_s)
}

/// The relative state of `setup` revealed by the user's start at `start_s`, as an
/// [`Onset`] of one observation: each feature's threshold between its values at
/// the start's step and the step before ([`revealed`]), and what the user refused
/// before it. `before` are the onsets of earlier scenes: with this one, they give
/// the decision that tells which waits were for the leader's gap. `None` when the
/// vehicle ahead is gone by then.
pub(crate) fn onset_at(setup: &Setup, start_s: f64, before: &[Onset]) -> Option<Onset> {
    let step = start_step(setup, start_s)?;
    let binding = |gap: fn(&Situation) -> Option<f64>| {
        if !held_back(setup, step, gap) {
            return None;
        }
        // A vehicle that leaves the side of the ego at the start's step reveals
        // nothing beyond "not alongside": the threshold is 0, not the midpoint of a
        // negative and a positive gap (which can lie above the next scene's first
        // positive gap and predict the start a step late).
        let previous = step.checked_sub(1).and_then(|i| gap(&setup.situations[i]));
        match (previous, gap(&setup.situations[step])) {
            (Some(before), Some(at)) if before <= 0.0 && at > 0.0 => Some(0.0),
            _ => revealed(setup, step, gap),
        }
    };
    let mut onset = Onset {
        scenario: setup.label.clone(),
        time_s: start_s,
        time_headway_s: revealed(setup, step, |s| Some(s.time_headway_s))?,
        ttc_s: revealed(setup, step, ttc),
        gap_m: revealed(setup, step, |s| Some(s.preceding_gap_m))?,
        lead_time_gap_s: binding(lead_time_gap),
        lag_time_gap_s: binding(lag_time_gap),
        rejected_lead_time_gap_s: None,
        time_headway_ceiling_s: None,
        accepted_lead_time_gap_s: lead_time_gap(&setup.situations[step]).filter(|g| g.is_finite()),
        follower_wait_time_headway_s: None,
        observations: 1,
        scene: Some(crate::driver::scene_steps(setup)),
    };
    if onset.lag_time_gap_s.is_some() {
        onset.time_headway_ceiling_s = last_open_step_before_alongside(setup, step)
            .map(|i| setup.situations[i].time_headway_s);
    } else if onset.lead_time_gap_s.is_none() && waited_for_the_follower(setup, step) {
        // Every user decides before the standard ALC would (the paper's premise,
        // `Setup::check_conservative`): the decision was taken at a headway of at
        // least the standard ALC's, and the follower's gap held the user back.
        onset.lag_time_gap_s = revealed(setup, step, lag_time_gap);
        onset.follower_wait_time_headway_s = Some(onset.time_headway_s);
        onset.time_headway_s = onset.time_headway_s.max(setup.standard_alc.time_headway_s);
    }
    let mut onsets = before.to_vec();
    onsets.push(onset.clone());
    onset.rejected_lead_time_gap_s = rejected_lead(setup, step, decision(&onsets));
    Some(onset)
}

/// Whether a start at `step` that no vehicle alongside held back waited for the
/// follower's gap: the time headway there is below the standard ALC's decision
/// headway, which a user's own decision never is (the paper's premise: the
/// standard ALC is later than every user), so something held the user back; the
/// follower's gap was opening into the start, and the leader's was already at
/// least the one the user is assumed to need at the step before (so it was not
/// what the user waited for).
fn waited_for_the_follower(setup: &Setup, step: usize) -> bool {
    let Some(before) = step.checked_sub(1).map(|i| &setup.situations[i]) else {
        return false;
    };
    let start = &setup.situations[step];
    let opening = match (lag_time_gap(before), lag_time_gap(start)) {
        (Some(before), Some(at)) => before > 0.0 && at > before,
        _ => false,
    };
    let accepted = lead_time_gap(start).unwrap_or(f64::INFINITY);
    let lead = assumed_lead_gap_s(setup, accepted);
    let leader_open = lead_time_gap(before).is_none_or(|g| g >= lead);
    start.time_headway_s > 0.0
        && start.time_headway_s < setup.standard_alc.time_headway_s
        && opening
        && leader_open
}

/// The last step before the target lane's follower came alongside the ego and
/// held back the user who started at `step` at which the user could have started
/// as far as its gaps tell (its time headway is
/// [`Onset::time_headway_ceiling_s`]): the leader's gap at least the one
/// [`assumed_lead_gap_s`] assumes the user needs (from the gap it accepted at
/// `step`), the follower not alongside, and, under the safety layer, both gaps
/// safe. The user did not start there, so it had not decided yet. Taking the
/// step just before the follower arrived instead, whatever the leader's gap
/// there, mistook a wait for the leader for an undecided user: over every pair of
/// the transfer matrix (deterministic users) the carried start was right to the
/// step in 158 of 246 pairs across speed cases instead of 145, and the
/// time-to-collision users' 93 of 220 instead of 66
/// (docs/experiments/0045-what-the-user-refused.md).
///
/// When the gaps were never open before the follower came, that step is the
/// fallback: the earliest start the wait allows, the upper end of the interval
/// the prediction weighs
/// ([`GapAcceptanceSet::predicted_start_s`](super::GapAcceptanceSet::predicted_start_s)).
/// Without a ceiling the decision kept only its lower bound, the latest start
/// the wait allows; with the fallback the transfer matrix's pairs need 190
/// takeovers instead of 197 (deterministic users), and fewer or as many for
/// every start rule
/// (docs/experiments/0045-what-the-user-refused.md). `None` when the follower was
/// not alongside at the step before the start, or was alongside from the scene's
/// first step.
///
/// The wait began when a target-lane vehicle first came alongside, as the leader
/// or as the follower: a vehicle slower than the ego passes it backwards, beside
/// it as the leader before it is beside it as the follower. Counting only the
/// follower's part put the ceiling at a step with the leader alongside, where
/// nobody starts (docs/experiments/0098-a-wait-that-began-beside-the-leader.md).
fn last_open_step_before_alongside(setup: &Setup, step: usize) -> Option<usize> {
    let lag_alongside = |i: usize| lag_time_gap(&setup.situations[i]).is_some_and(|g| g <= 0.0);
    if !step.checked_sub(1).is_some_and(lag_alongside) {
        return None;
    }
    let alongside = |i: usize| setup.situations[i].target_vehicle_beside();
    let first_alongside = (0..step).rev().take_while(|&i| alongside(i)).last()?;
    let accepted = lead_time_gap(&setup.situations[step]).unwrap_or(f64::INFINITY);
    let lead = assumed_lead_gap_s(setup, accepted);
    let could_start = |s: &Situation| {
        s.time_headway_s > 0.0
            && lead_time_gap(s).is_none_or(|g| g > 0.0 && g >= lead)
            && lag_time_gap(s).is_none_or(|g| g > 0.0)
            && (!setup.safety.enforce || target_gaps_safe(s, &setup.safety))
    };
    // No such step: the scene cannot tell whether the leader's gap or a decision
    // not yet taken kept the user from starting before the follower came; take
    // the earliest start the wait allows, just before the follower arrived.
    (0..first_alongside)
        .rev()
        .find(|&i| could_start(&setup.situations[i]))
        .or_else(|| first_alongside.checked_sub(1))
}

/// The largest target-lane lead time gap the user refused before its start at
/// `step` although it had decided (the decision feature at or below its
/// threshold) and the follower's gap was at least the one it accepted at the
/// start ([`Onset::rejected_lead_time_gap_s`]). Steps where the leader's gap was
/// also at least the accepted one (or there was no leader) say nothing: there
/// the decision learned so far does not explain the wait.
fn rejected_lead(setup: &Setup, step: usize, (feature, threshold): (Cue, f64)) -> Option<f64> {
    let start = &setup.situations[step];
    let (lead_accepted, lag_accepted) = (lead_time_gap(start)?, lag_time_gap(start));
    setup.situations[..step]
        .iter()
        .filter(|s| s.time_headway_s > 0.0 && cue_value(feature, s).is_some_and(|x| x <= threshold))
        .filter(|s| match (lag_time_gap(s), lag_accepted) {
            (None, _) => true,
            (Some(g), Some(accepted)) => g >= accepted.max(0.0) && g > 0.0,
            (Some(g), None) => g > 0.0,
        })
        .filter_map(lead_time_gap)
        .filter(|&g| g < lead_accepted)
        .reduce(f64::max)
        .map(|g| g.max(0.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::onset::test_scenes::learn_scene;

    #[test]
    fn a_start_fitted_beside_a_vehicle_moves_to_where_it_has_passed_until_the_takeover() {
        let mut setup = learn_scene();
        assert!(setup.situations.len() > 60);
        // A follower alongside up to step 40, 5 m behind from step 41; no leader.
        for (i, situation) in setup.situations.iter_mut().enumerate() {
            situation.target_lead_gap_m = None;
            situation.target_lag_gap_m = Some(if i <= 40 { -2.0 } else { 5.0 });
            situation.target_lag_speed = Some(20.0);
        }
        let close = |a: f64, b: f64| (a - b).abs() < 1e-9;
        // Fitted at step 30, beside the follower, taken over at 5 s: it started
        // at step 41, once the follower had passed.
        assert!(close(start_clear_of_vehicles_beside(&setup, 3.0, 5.0), 4.1));
        // Taken over at 4 s, while the follower was still beside: the fit stands.
        assert!(close(start_clear_of_vehicles_beside(&setup, 3.0, 4.0), 3.0));
        // A start fitted where nobody is beside stands.
        assert!(close(
            start_clear_of_vehicles_beside(&setup, 4.53, 5.0),
            4.53
        ));
    }

    #[test]
    fn a_wait_for_the_follower_began_when_it_came_alongside_as_the_leader() {
        let mut setup = learn_scene();
        assert!(setup.situations.len() > 60);
        // A slower target-lane vehicle passes the ego backwards: 40 m ahead up to
        // step 10, 1 m ahead (too close to accept) up to 19, alongside as the
        // leader from 20 to 39 and as the follower from 40 to 50, behind from 51.
        for (i, situation) in setup.situations.iter_mut().enumerate() {
            let (lead, lag) = match i {
                0..=10 => (Some(40.0), None),
                11..=19 => (Some(1.0), None),
                20..=39 => (Some(-2.0), None),
                40..=50 => (None, Some(-2.0)),
                _ => (None, Some(3.0)),
            };
            (situation.target_lead_gap_m, situation.target_lag_gap_m) = (lead, lag);
            situation.target_lead_speed = Some(20.0);
            situation.target_lag_speed = Some(20.0);
        }
        // Started at step 51, when the follower had passed: the user could have
        // started at step 10 at the latest, before the vehicle came alongside as
        // the leader; not at 39, beside it.
        assert_eq!(last_open_step_before_alongside(&setup, 51), Some(10));
        // Never open before: the earliest start the wait allows is the step
        // before the vehicle came alongside, whichever of the two it was then.
        for situation in &mut setup.situations[..=10] {
            situation.target_lead_gap_m = Some(1.0);
        }
        assert_eq!(last_open_step_before_alongside(&setup, 51), Some(19));
        // A start the follower did not hold back has no such step.
        assert_eq!(last_open_step_before_alongside(&setup, 30), None);
    }
}
