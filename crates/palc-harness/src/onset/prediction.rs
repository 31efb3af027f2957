//! The relative state a start revealed ([`onset_at`]) and the start it predicts
//! in a new scene ([`predicted_start_s`]).

use std::collections::BTreeMap;

use palc_aggregator::{Onset, SceneSteps};

use crate::setup::{Setup, target_gaps_safe};
use palc_user::Situation;

/// Relative spread below which a decision feature counts as consistent across
/// scenes.
const CONSISTENT_SPREAD: f64 = 0.1;

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

/// The target-lane gaps as time gaps (s): `(lead, lag)`.
fn lead_time_gap(s: &Situation) -> Option<f64> {
    s.target_lead_times_s().map(|(gap, _)| gap)
}
fn lag_time_gap(s: &Situation) -> Option<f64> {
    s.target_lag_times_s().map(|(gap, _)| gap)
}
fn ttc(s: &Situation) -> Option<f64> {
    Some(s.preceding_ttc_s()).filter(|t| t.is_finite())
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
/// the prediction weighs ([`predicted_start_s`]). Without a ceiling the decision
/// kept only its lower bound, the latest start the wait allows; with the fallback the transfer
/// matrix's pairs need 190 takeovers instead of 197 (deterministic users), and
/// fewer or as many for every start rule
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

/// The lead gap (s) a user is assumed to need besides what it has shown, given
/// the smallest lead gap it has accepted (`f64::INFINITY` for none): the standard
/// ALC's, until the user has accepted a smaller one (an accepted gap bounds the
/// user's requirement from above). Under the safety layer none is assumed: the
/// safe distance is required there anyway.
fn assumed_lead_gap_s(setup: &Setup, smallest_accepted: f64) -> f64 {
    if setup.safety.enforce {
        0.0
    } else {
        setup.standard_alc.min_lead_gap_s.min(smallest_accepted)
    }
}

/// The largest target-lane lead time gap the user refused before its start at
/// `step` although it had decided (the decision feature at or below its
/// threshold) and the follower's gap was at least the one it accepted at the
/// start ([`Onset::rejected_lead_time_gap_s`]). Steps where the leader's gap was
/// also at least the accepted one (or there was no leader) say nothing: there
/// the decision learned so far does not explain the wait.
fn rejected_lead(setup: &Setup, step: usize, (feature, threshold): (Decision, f64)) -> Option<f64> {
    let start = &setup.situations[step];
    let (lead_accepted, lag_accepted) = (lead_time_gap(start)?, lag_time_gap(start));
    setup.situations[..step]
        .iter()
        .filter(|s| {
            s.time_headway_s > 0.0 && feature.of_situation(s).is_some_and(|x| x <= threshold)
        })
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

/// The feature of the vehicle ahead whose fall to a threshold decides the lane
/// change.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Decision {
    TimeHeadway,
    TimeToCollision,
    Gap,
}

impl Decision {
    /// The feature at `s` as a threshold decision reads it: behind a vehicle
    /// ahead (a positive time headway), and finite.
    fn read_at(self, s: &Situation) -> Option<f64> {
        (s.time_headway_s > 0.0)
            .then(|| self.of_situation(s))
            .flatten()
            .filter(|x| x.is_finite())
    }

    fn of_situation(self, s: &Situation) -> Option<f64> {
        match self {
            Decision::TimeHeadway => Some(s.time_headway_s),
            Decision::TimeToCollision => ttc(s),
            Decision::Gap => Some(s.preceding_gap_m),
        }
    }

    fn of_onset(self, onset: &Onset) -> Option<f64> {
        match self {
            Decision::TimeHeadway => Some(onset.time_headway_s),
            Decision::TimeToCollision => onset.ttc_s,
            Decision::Gap => Some(onset.gap_m),
        }
    }
}

/// The decision feature and its threshold learned from `onsets`.
///
/// Onsets a target-lane gap held back only bound the decision from below; the
/// others give it. The threshold is the largest value seen (the earliest start the
/// user has shown). When every onset was held back, the time headway's threshold
/// is raised to the lowest [`Onset::time_headway_ceiling_s`] above it: the
/// earliest start the waits allow, assuming nothing but the follower held the
/// user back ([`decision_range`] keeps the interval). The feature is the time
/// headway (the paper's user model and the usual measure of following) unless,
/// over onsets from two or more scenes,
/// it varies by more than [`CONSISTENT_SPREAD`] while the time to collision or the
/// gap does not, or a held-back onset started at a headway above the threshold
/// (more than [`CONSISTENT_SPREAD`] above: a held-back start comes after the
/// decision); then the most consistent of those that no held-back onset
/// contradicts.
fn decision(onsets: &[Onset]) -> (Decision, f64) {
    let range = decision_range(onsets);
    (range.feature, range.highest)
}

/// What [`decision_range`] learned: the feature and the thresholds it allows.
#[derive(Debug, Clone, Copy, PartialEq)]
struct DecisionRange {
    feature: Decision,
    /// The lowest threshold the onsets allow.
    lowest: f64,
    /// The threshold (the highest the onsets allow).
    highest: f64,
    /// How many free onsets' scenes revealed the threshold as the middle of the
    /// interval they all allow ([`revealed_threshold`]); 0 when it is read from
    /// the onsets' midpoints or ceilings.
    revealed_by: usize,
    /// The readings' own model explains the onsets: the feature decided on
    /// is consistent across them (within [`CONSISTENT_SPREAD`], over the free
    /// onsets, or over all when none is free) and no held-back start
    /// contradicts it. Always so for a single onset.
    explained: bool,
}

impl DecisionRange {
    fn one(feature: Decision, threshold: f64, revealed_by: usize) -> Self {
        DecisionRange {
            feature,
            lowest: threshold,
            highest: threshold,
            revealed_by,
            explained: true,
        }
    }
}

/// [`decision`] with the lowest threshold the onsets allow. The two differ only
/// when every onset was held back and a ceiling raised the time headway's
/// threshold above the largest headway at which the user started (the onsets
/// bound the decision to that interval and say nothing more).
fn decision_range(onsets: &[Onset]) -> DecisionRange {
    let onsets = &reread_follower_waits(onsets);
    let free = free_onsets(onsets);
    let informative: Vec<&Onset> = if free.is_empty() {
        onsets.iter().collect()
    } else {
        free.clone()
    };
    let spread = |feature: Decision| -> Option<(f64, f64)> {
        let values: Vec<f64> = (informative.iter())
            .map(|o| feature.of_onset(o))
            .collect::<Option<_>>()?;
        let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let min = values.iter().copied().fold(f64::INFINITY, f64::min);
        (max > 0.0).then(|| ((max - min) / max, max))
    };
    let mut headway = spread(Decision::TimeHeadway).unwrap_or((0.0, 0.0));
    let lowest_headway = headway.1;
    if free.is_empty() {
        // Only lower bounds: take the earliest start they allow, the lowest
        // headway at which a follower's arrival interrupted a wait.
        let ceiling = (onsets.iter())
            .filter_map(|o| o.time_headway_ceiling_s)
            .reduce(f64::min);
        if let Some(ceiling) = ceiling.filter(|&c| c > headway.1) {
            headway.1 = ceiling;
        }
    }
    // A held-back start comes after the decision: its value of the decision
    // feature is at most the threshold. One above it contradicts the feature.
    let contradicted = |feature: Decision, threshold: f64| {
        !free.is_empty()
            && (onsets.iter())
                .filter(|o| o.lead_time_gap_s.is_some() || o.lag_time_gap_s.is_some())
                .any(|o| {
                    feature
                        .of_onset(o)
                        .is_some_and(|v| v > threshold * (1.0 + CONSISTENT_SPREAD))
                })
    };
    let headway_fails = (informative.len() >= 2 && headway.0 > CONSISTENT_SPREAD)
        || contradicted(Decision::TimeHeadway, headway.1);
    if headway_fails {
        let best = [Decision::TimeToCollision, Decision::Gap]
            .into_iter()
            .filter_map(|d| spread(d).map(|(spread, max)| (d, spread, max)))
            .filter(|&(d, spread, max)| spread <= CONSISTENT_SPREAD && !contradicted(d, max))
            .min_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((feature, _, threshold)) = best {
            return match revealed_threshold(&free, feature) {
                Some(revealed) => DecisionRange::one(feature, revealed, free.len()),
                None => DecisionRange::one(feature, threshold, 0),
            };
        }
    }
    let explained = !headway_fails;
    match revealed_threshold(&free, Decision::TimeHeadway) {
        Some(revealed) => DecisionRange {
            explained,
            ..DecisionRange::one(Decision::TimeHeadway, revealed, free.len())
        },
        None => DecisionRange {
            feature: Decision::TimeHeadway,
            lowest: lowest_headway,
            highest: headway.1,
            revealed_by: 0,
            explained,
        },
    }
}

/// The threshold of `feature` the free onsets' scenes reveal: the middle of the
/// interval they all allow ([`revealed_interval`]). Under a uniform belief over
/// the interval, the start that most of it leads to in a new scene is the one
/// its middle leads to. With one onset it is that onset's [`revealed`]
/// midpoint; with more, the largest midpoint (the readings' threshold before)
/// could lie outside the interval and start the next scene a step early or late
/// (docs/experiments/0089-the-thresholds-every-scene-allows.md).
fn revealed_threshold(free: &[&Onset], feature: Decision) -> Option<f64> {
    revealed_interval(free, feature).map(|(lowest, highest)| 0.5 * (lowest + highest))
}

/// The onsets no target-lane gap held back: their start is the decision's.
fn free_onsets(onsets: &[Onset]) -> Vec<&Onset> {
    (onsets.iter())
        .filter(|o| o.lead_time_gap_s.is_none() && o.lag_time_gap_s.is_none())
        .collect()
}

/// Whether the threshold the readings predict with is one that the scenes of at
/// least two free onsets reveal exactly ([`revealed_interval`]): every start is a
/// threshold of one cue crossed at a step, as a driver who decides on that cue
/// starts. The driver estimate, whose observation error is
/// [`OBSERVATION_SD_S`](crate::driver::prior::OBSERVATION_SD_S) (0.2 s, two
/// steps, for starts read from noisy paths), does not place such a start to
/// the step; the interval does.
pub(crate) fn threshold_revealed_by_scenes(onsets: &[Onset]) -> bool {
    decision_range(onsets).revealed_by >= 2
}

/// Whether the readings' own model explains `onsets` ([`DecisionRange`]'s
/// `explained`): where no feature is consistent across the scenes, the
/// readings fall back to the time headway, which their scenes contradict
/// (docs/experiments/0095-a-wait-weighed-by-the-prior-and-readings-that-contradict-themselves.md).
pub(crate) fn readings_explain(onsets: &[Onset]) -> bool {
    decision_range(onsets).explained
}

/// The thresholds of `feature` that every free onset allows, from the scenes
/// they recorded: a start at step `k` says that the feature had fallen to the
/// threshold there and not at the step before, `θ ∈ [x(k), x(k − 1))`, and the
/// scenes together allow the intersection `[max x(k), min x(k − 1))`. `None`
/// when an onset recorded no scene or is the mean of several starts in its
/// scene ([`Onset::merged`]: a mean of starts is not a step at which the driver
/// started), or the intervals do not intersect (a driver whose threshold is not
/// one value): the midpoints stand.
fn revealed_interval(free: &[&Onset], feature: Decision) -> Option<(f64, f64)> {
    if free.is_empty() {
        return None;
    }
    let value = |s: &Situation| feature.read_at(s);
    let (mut lowest, mut highest) = (f64::NEG_INFINITY, f64::INFINITY);
    for onset in free {
        let (scene, step) = start_in_scene(onset)?;
        lowest = lowest.max(value(&crate::driver::situation(&scene.steps[step]))?);
        if let Some(before) = value(&crate::driver::situation(&scene.steps[step - 1])) {
            highest = highest.min(before);
        }
    }
    (lowest < highest && highest.is_finite()).then_some((lowest, highest))
}

/// The scene `onset` recorded and the step of it at which the driver started;
/// `None` without a scene, for a mean of several starts ([`Onset::merged`]: a
/// mean of starts is not a step at which the driver started), and for a start
/// at the scene's first step or past its end.
fn start_in_scene(onset: &Onset) -> Option<(&SceneSteps, usize)> {
    let scene = onset.scene.as_ref().filter(|_| onset.observations == 1)?;
    let step = (onset.time_s / scene.dt).round();
    (step >= 1.0 && step < scene.steps.len() as f64).then_some((scene, step as usize))
}

/// `onsets` with each start that was read as a wait for the follower
/// ([`waited_for_the_follower`]) read again as the user's own decision when
/// another onset started with a smaller follower gap than the one the wait
/// learned (by more than [`CONSISTENT_SPREAD`]): a user who accepts that
/// smaller gap did not wait for the larger one
/// (the accepted gap bounds the needed one from above), so the start is where it
/// decided, at the headway it had there. One scene cannot tell the two readings
/// apart; a time-to-collision user who decides below the standard ALC's headway
/// as the follower's gap opens looks like a user who waited for that gap
/// (docs/experiments/0060-a-wait-the-standard-alc-would-not-make.md; the reading
/// again is measured in docs/experiments/0061-a-wait-read-again.md).
fn reread_follower_waits(onsets: &[Onset]) -> Vec<Onset> {
    let smaller_lag_elsewhere = |i: usize, gap: f64| {
        (onsets.iter().enumerate()).any(|(j, o)| {
            j != i && (o.lag_time_gap_s).is_some_and(|g| g < gap * (1.0 - CONSISTENT_SPREAD))
        })
    };
    (onsets.iter().enumerate())
        .map(
            |(i, o)| match (o.follower_wait_time_headway_s, o.lag_time_gap_s) {
                (Some(headway), Some(gap)) if smaller_lag_elsewhere(i, gap) => Onset {
                    time_headway_s: headway,
                    lag_time_gap_s: None,
                    follower_wait_time_headway_s: None,
                    ..o.clone()
                },
                _ => o.clone(),
            },
        )
        .collect()
}

/// The smallest target-lane time gap that held the user back in `onsets`, or 0
/// (a vehicle alongside is never accepted) when none did.
fn acceptance(onsets: &[Onset], gap: fn(&Onset) -> Option<f64>) -> f64 {
    onsets
        .iter()
        .filter_map(gap)
        .reduce(f64::min)
        .map_or(0.0, |g| g.max(0.0))
}

/// [`acceptance`] of the follower's gap, where two or more starts read as waits
/// for it ([`waited_for_the_follower`]) reveal the gap the user needs as the
/// interval every one of their scenes allows: a wait that ended at step `k`
/// refused the gap at `k − 1` and took the one at `k`, `a ∈ (g(k − 1), g(k)]`, and
/// the scenes together allow `(max g(k − 1), min g(k)]`. Each wait then stands for
/// that interval's middle (under a uniform belief over it, the start most of it
/// leads to in a new scene), not for its own midpoint, which can lie below what
/// another scene refused and start the next scene a step early, as the
/// thresholds' midpoints did (docs/experiments/0089-the-thresholds-every-scene-allows.md,
/// docs/experiments/0100-the-follower-gap-every-wait-allows.md). With one wait,
/// or intervals that do not meet, each wait's own midpoint stands.
fn lag_acceptance(onsets: &[Onset]) -> f64 {
    let waited = |o: &Onset| o.follower_wait_time_headway_s.is_some();
    let waits: Vec<&Onset> = (onsets.iter())
        .filter(|o| waited(o) && o.lag_time_gap_s.is_some())
        .collect();
    let revealed = (waits.len() >= 2)
        .then(|| waited_gap_interval(&waits))
        .flatten()
        .map(|(lowest, highest)| 0.5 * (lowest + highest));
    (onsets.iter())
        .filter_map(|o| {
            o.lag_time_gap_s
                .map(|g| revealed.filter(|_| waited(o)).unwrap_or(g))
        })
        .reduce(f64::min)
        .map_or(0.0, |g| g.max(0.0))
}

/// The follower's gaps every wait of `waits` allows, `(max g(k − 1), min g(k)]`,
/// from the scenes they recorded; `None` when one recorded no scene, is the mean
/// of several starts ([`Onset::merged`]), has no follower at its start or the
/// step before, or the intervals do not meet.
fn waited_gap_interval(waits: &[&Onset]) -> Option<(f64, f64)> {
    let (mut lowest, mut highest) = (f64::NEG_INFINITY, f64::INFINITY);
    for onset in waits {
        let (scene, step) = start_in_scene(onset)?;
        let gap = |i: usize| lag_time_gap(&crate::driver::situation(&scene.steps[i]));
        lowest = lowest.max(gap(step - 1)?);
        highest = highest.min(gap(step)?);
    }
    (lowest < highest).then_some((lowest, highest))
}

/// The user's start (s after the start of the plan) predicted in `setup` from the
/// observed `onsets`: the first step at which the decision feature has fallen to
/// its threshold, then the first step from there at which the target-lane gaps
/// are at least the learned ones (for the leader, also above every lead gap the
/// user refused after deciding, and at least the standard ALC's lead gap or the
/// smallest one the user accepted, whichever is smaller). When the onsets bound
/// the time headway's threshold to an interval ([`decision_range`]; from below
/// also by the standard ALC's decision headway, which every user's is above: the
/// paper's premise), each threshold of it gives a start, and the start given by
/// the largest part of the interval is predicted, the earliest of those within
/// one step's fall of the headway of each other: a uniform belief over what the
/// scenes allow, not a choice of one end. Taking
/// the upper end (the earliest start, as for a free onset) started users held
/// back in dense scenes up to 20 s early in sparser ones. Under the safety layer
/// the gaps are also at the safe distance at every step of the carried lane
/// change (`duration_s` from the start, on the lane-keeping prediction): a start
/// whose lane change the layer would refuse is not predicted. `None` without
/// onsets, or when the prediction does not start within the search window.
pub(crate) fn predicted_start_s(setup: &Setup, onsets: &[Onset], duration_s: f64) -> Option<f64> {
    if onsets.is_empty() {
        return None;
    }
    let DecisionRange {
        feature,
        lowest,
        highest: threshold,
        ..
    } = decision_range(onsets);
    // A lead gap the user refused after deciding is below the one it needs.
    let refused = (onsets.iter())
        .filter_map(|o| o.rejected_lead_time_gap_s)
        .fold(0.0, f64::max);
    // What the user needs from the leader: at least what held it back or what it
    // refused; of the rest, what the system itself requires until the user has
    // accepted a smaller gap (what it accepted bounds its requirement from above).
    // The system's requirement is the standard ALC's lead gap, or, under the safety
    // layer, the safe distance, which `accepts` below requires anyway.
    let safety = &setup.safety;
    let accepted = (onsets.iter())
        .filter_map(|o| o.accepted_lead_time_gap_s)
        .reduce(f64::min)
        .unwrap_or(f64::INFINITY);
    let assumed = assumed_lead_gap_s(setup, accepted);
    // A refused gap is read through the learned threshold (the user had decided,
    // so only the leader can have held it back), an accepted one is seen: a
    // driver who accepted a gap does not need a larger one, so a refused gap
    // above an accepted one was a misreading (the decision came later than the
    // threshold said) and bounds the need by the accepted gap at most
    // (docs/experiments/0073-a-drive-of-varied-scenes.md).
    let refused = refused.min(accepted);
    let lead = (acceptance(onsets, |o| o.lead_time_gap_s).max(refused)).max(assumed);
    let lag = lag_acceptance(onsets);
    let situations = &setup.situations;
    // Under the safety layer a lane change below the safe distance would be
    // refused.
    let steps = (duration_s / setup.dt).ceil().max(0.0) as usize;
    let safe_through = |i: usize| {
        let end = i.saturating_add(steps).min(situations.len() - 1);
        situations[i..=end]
            .iter()
            .all(|s| target_gaps_safe(s, safety))
    };
    let accepts = |i: usize| {
        let s = &situations[i];
        lead_time_gap(s).is_none_or(|g| g > 0.0 && g >= lead)
            && lag_time_gap(s).is_none_or(|g| g > 0.0 && g >= lag)
            && (!safety.enforce || safe_through(i))
    };
    // Every user decides before the standard ALC would (the paper's premise,
    // `Setup::check_conservative`): no time-headway threshold lies below the
    // standard ALC's.
    let lowest = match feature {
        Decision::TimeHeadway => lowest.max(setup.standard_alc.time_headway_s),
        _ => lowest,
    };
    let mut weight = BTreeMap::<usize, f64>::new();
    let mut start = None;
    let decisions = decision_steps(setup, feature, (lowest.min(threshold), threshold));
    // The interval is resolved in steps: parts within one step's fall of the
    // feature are equal, and a start wins only by more than that.
    let resolution = decisions.iter().map(|&(_, w)| w).fold(0.0, f64::max);
    for (decided, width) in decisions {
        // The first accepted step from an earlier decision is the first from
        // this one too, unless this decision comes after it; with none from an
        // earlier decision there is none from a later one.
        if start.is_none_or(|s| s < decided) {
            start = (decided..situations.len()).find(|&i| accepts(i));
        }
        let Some(start) = start else { break };
        *weight.entry(start).or_default() += width;
    }
    // The start most thresholds lead to; the earliest of equals (with a free
    // fall of the feature every step's thresholds start at their own step, and
    // the earliest is the one the interval's upper end, the ceiling, gives).
    let (start, _) =
        (weight.into_iter()).fold(None, |best: Option<(usize, f64)>, (start, w)| match best {
            Some((_, b)) if b + resolution >= w => best,
            _ => Some((start, w)),
        })?;
    Some(start as f64 * setup.dt)
}

/// The steps at which thresholds of `feature` in `range` decide, each with the
/// length of the part of `range` that decides there: a threshold decides at the
/// first step at which the feature has fallen to it (behind a positive time
/// headway). A range of one value decides at one step, with weight 1.
fn decision_steps(
    setup: &Setup,
    feature: Decision,
    (lowest, highest): (f64, f64),
) -> Vec<(usize, f64)> {
    let value = |s: &Situation| feature.read_at(s);
    let situations = &setup.situations;
    if lowest >= highest {
        return (situations.iter())
            .position(|s| value(s).is_some_and(|x| x <= highest))
            .map(|i| vec![(i, 1.0)])
            .unwrap_or_default();
    }
    let mut steps = Vec::new();
    // Thresholds at or above `above` have decided at an earlier step.
    let mut above = f64::INFINITY;
    for (i, s) in situations.iter().enumerate() {
        let Some(x) = value(s).filter(|&x| x < above) else {
            continue;
        };
        // Thresholds in [x, above) decide here.
        let width = above.min(highest) - x.max(lowest);
        if width > 0.0 {
            steps.push((i, width));
        }
        above = x;
        if x <= lowest {
            break;
        }
    }
    steps
}

#[cfg(test)]
mod tests {
    use super::*;
    use palc_aggregator::SeenStep;

    /// The scene of `configs/learn.toml`, whose target-lane vehicles a test sets.
    fn learn_scene() -> Setup {
        let text = include_str!("../../../../configs/learn.toml");
        let config = crate::config::LearnConfig::from_toml_str(text).unwrap();
        crate::scenario::prepare(&config).unwrap()
    }

    fn onset(headway: f64, ttc: f64, lag: Option<f64>) -> Onset {
        Onset {
            scenario: "s".into(),
            time_s: 1.0,
            time_headway_s: headway,
            ttc_s: Some(ttc),
            gap_m: 20.0 * headway,
            lead_time_gap_s: None,
            lag_time_gap_s: lag,
            rejected_lead_time_gap_s: None,
            time_headway_ceiling_s: None,
            accepted_lead_time_gap_s: None,
            follower_wait_time_headway_s: None,
            observations: 1,
            scene: None,
        }
    }

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

    #[test]
    fn waits_for_the_follower_need_the_middle_of_the_gaps_every_scene_allows() {
        let base = learn_scene();
        assert!(base.situations.len() > 30);
        // A follower whose time gap opens by `rate` s a step from `offset` s; a
        // user who needs 0.5 s starts at the first step at which it has it.
        let waited = |rate: f64, offset: f64| {
            let mut setup = base.clone();
            for (i, situation) in setup.situations.iter_mut().enumerate() {
                situation.target_lead_gap_m = None;
                situation.target_lag_speed = Some(20.0);
                situation.target_lag_gap_m = Some(20.0 * (offset + rate * i as f64));
            }
            let gap = |i: usize| offset + rate * i as f64;
            let step = (0..setup.situations.len())
                .find(|&i| gap(i) >= 0.5)
                .unwrap();
            let mut wait = onset(1.0, 10.0, Some(0.5 * (gap(step - 1) + gap(step))));
            wait.time_s = step as f64 * setup.dt;
            wait.follower_wait_time_headway_s = Some(0.8);
            wait.scene = Some(crate::driver::scene_steps(&setup));
            wait
        };
        let close = |a: f64, b: f64| (a - b).abs() < 1e-9;
        // Refused 0.48 s and took 0.51 s; refused 0.49 s and took 0.53 s.
        let (a, b) = (waited(0.03, 0.0), waited(0.04, 0.01));
        assert!(close(a.lag_time_gap_s.unwrap(), 0.495));
        assert!(close(b.lag_time_gap_s.unwrap(), 0.51));
        // Alone, each wait needs its own midpoint.
        assert!(close(lag_acceptance(std::slice::from_ref(&a)), 0.495));
        // Together they allow (0.49, 0.51]: the need is its middle, not the
        // smaller midpoint 0.495, which the second scene refused.
        assert!(close(lag_acceptance(&[a.clone(), b.clone()]), 0.5));
        // A mean of starts is no step: the midpoints stand.
        let merged = Onset {
            observations: 2,
            ..b.clone()
        };
        assert!(close(lag_acceptance(&[a.clone(), merged]), 0.495));
        // A follower that held the user back elsewhere with a smaller gap bounds it.
        let held = onset(1.2, 10.0, Some(0.2));
        assert!(close(lag_acceptance(&[a, b, held]), 0.2));
    }

    #[test]
    fn a_refused_lead_gap_above_an_accepted_one_asks_no_more_than_the_accepted_one() {
        let setup = learn_scene();
        // The lead gaps this scene offers over its steps: a refused gap between
        // two of them moves the start when it is the need, and must not here.
        let gaps: Vec<f64> = setup.situations.iter().filter_map(lead_time_gap).collect();
        let low = gaps
            .iter()
            .copied()
            .filter(|g| *g > 0.0)
            .fold(f64::INFINITY, f64::min);
        let high = gaps.iter().copied().fold(0.0, f64::max);
        assert!(low < high, "the scene's lead gaps vary: {low} to {high}");
        let accepted = low;
        let mut seen = onset(1.2, 10.0, None);
        seen.accepted_lead_time_gap_s = Some(accepted);
        let with_refused = |refused: f64| {
            let mut refusing = onset(1.2, 10.0, None);
            refusing.rejected_lead_time_gap_s = Some(refused);
            predicted_start_s(&setup, &[seen.clone(), refusing], 2.0)
        };
        let at_accepted = with_refused(accepted);
        assert!(at_accepted.is_some());
        for refused in [0.5 * (accepted + high), high, 10.0 * high] {
            assert_eq!(with_refused(refused), at_accepted, "refused {refused} s");
        }
    }

    #[test]
    fn the_decision_is_the_headway_unless_another_feature_is_consistent() {
        assert_eq!(decision(&[onset(1.2, 10.0, None)]).0, Decision::TimeHeadway);
        let headway_user = [onset(1.2, 10.0, None), onset(1.21, 5.0, None)];
        let (feature, threshold) = decision(&headway_user);
        assert_eq!(feature, Decision::TimeHeadway);
        assert!((threshold - 1.21).abs() < 1e-12);
        let ttc_user = [onset(1.6, 8.0, None), onset(0.8, 8.1, None)];
        assert_eq!(decision(&ttc_user).0, Decision::TimeToCollision);
        // An onset held back by a gap does not set the decision.
        let held = [onset(1.2, 10.0, None), onset(0.3, 2.0, Some(0.1))];
        assert_eq!(decision(&held), (Decision::TimeHeadway, 1.2));
    }

    #[test]
    fn the_readings_explain_their_onsets_while_one_feature_is_consistent() {
        // One scene, or scenes that agree on the headway or on another feature.
        assert!(readings_explain(&[onset(1.2, 10.0, None)]));
        assert!(readings_explain(&[
            onset(1.2, 10.0, None),
            onset(1.21, 5.0, None)
        ]));
        assert!(readings_explain(&[
            onset(1.6, 8.0, None),
            onset(0.8, 8.1, None)
        ]));
        // No feature agrees across the two scenes: the headway (and the gap,
        // twenty metres a second of it here) a third apart, the time to
        // collision half.
        assert!(!readings_explain(&[
            onset(1.2, 10.0, None),
            onset(0.8, 5.0, None)
        ]));
        // A held-back start says nothing about consistency of free ones.
        assert!(readings_explain(&[
            onset(1.2, 10.0, None),
            onset(0.8, 5.0, Some(0.2))
        ]));
    }

    #[test]
    fn a_held_back_start_above_the_threshold_rules_the_feature_out() {
        // A time-to-collision user: free at a headway of 0.89 s, and held back by
        // a follower in another scene until a headway of 1.41 s, earlier than a
        // headway user at 0.89 s would have decided. Its time to collision there
        // (6.3 s) is below the free onset's 8 s, as a decision before it requires.
        let free = onset(0.89, 8.0, None);
        let held = Onset {
            gap_m: 10.0,
            ..onset(1.41, 6.3, Some(0.0))
        };
        assert_eq!(
            decision(std::slice::from_ref(&free)).0,
            Decision::TimeHeadway
        );
        assert_eq!(decision(&[free, held]), (Decision::TimeToCollision, 8.0));
        // A held-back start below the headway threshold contradicts nothing.
        let below = onset(0.6, 6.3, Some(0.0));
        assert_eq!(
            decision(&[onset(0.89, 8.0, None), below]).0,
            Decision::TimeHeadway
        );
    }

    #[test]
    fn a_wait_for_the_follower_is_the_decision_once_a_smaller_follower_gap_was_accepted() {
        // The time-to-collision user above, whose start at a headway of 0.89 s came
        // as the follower's gap opened (0.59 s): read as a wait for that gap, with
        // the decision raised to the standard ALC's 1.0 s.
        let waited = Onset {
            follower_wait_time_headway_s: Some(0.89),
            ..onset(1.0, 8.0, Some(0.59))
        };
        let alone = std::slice::from_ref(&waited);
        assert_eq!(reread_follower_waits(alone), alone.to_vec());
        assert_eq!(decision(alone), (Decision::TimeHeadway, 1.0));
        // Another scene in which it started as soon as a follower had cleared (a
        // gap of 0): it needs no 0.59 s behind, so the start was its decision.
        let held = Onset {
            gap_m: 10.0,
            ..onset(1.41, 6.3, Some(0.0))
        };
        let reread = reread_follower_waits(&[waited.clone(), held.clone()]);
        assert_eq!(reread[0].time_headway_s, 0.89);
        assert_eq!(reread[0].lag_time_gap_s, None);
        assert_eq!(reread[1], held);
        assert_eq!(
            decision(&[waited.clone(), held]),
            (Decision::TimeToCollision, 8.0)
        );
        // A user that waited for about as large a gap in every scene keeps the
        // reading.
        let again = Onset {
            follower_wait_time_headway_s: Some(0.7),
            ..onset(1.0, 6.0, Some(0.62))
        };
        let both = [waited, again];
        assert_eq!(reread_follower_waits(&both), both.to_vec());
    }

    #[test]
    fn without_a_free_onset_the_headway_rises_to_the_lowest_ceiling() {
        let held = |headway: f64, ceiling: Option<f64>| Onset {
            time_headway_ceiling_s: ceiling,
            ..onset(headway, 10.0 * headway, Some(0.0))
        };
        // Two waits: the user had not started at 1.5 s nor at 1.3 s (neither the
        // time to collision nor the gap is consistent across them).
        let waits = [held(0.6, Some(1.5)), held(0.8, Some(1.3))];
        assert_eq!(decision(&waits), (Decision::TimeHeadway, 1.3));
        // A ceiling below a start the user has shown says nothing.
        assert_eq!(decision(&[held(0.9, Some(0.7))]).1, 0.9);
        // A free onset gives the threshold itself.
        let with_free = [held(0.6, Some(1.5)), onset(1.2, 10.0, None)];
        assert_eq!(decision(&with_free).1, 1.2);
    }

    /// The default scene's set-up at arterial-high / 45 m, seed 1 (prepared once).
    fn arterial_setup() -> &'static Setup {
        static SETUP: std::sync::OnceLock<Setup> = std::sync::OnceLock::new();
        SETUP.get_or_init(|| {
            let text = include_str!("../../../../configs/learn.toml");
            let config = crate::config::LearnConfig::from_toml_str(text)
                .unwrap()
                .with_cell(crate::config::CellChoice {
                    speed_case: "arterial-high".into(),
                    headway_m: 45.0,
                    seed: 1,
                });
            crate::scenario::prepare(&config).unwrap()
        })
    }

    /// The first step at which a threshold of the time headway decides, by its
    /// definition: the slower reference of [`decision_steps`].
    fn deciding_step(setup: &Setup, threshold: f64) -> Option<usize> {
        (setup.situations.iter())
            .position(|s| s.time_headway_s > 0.0 && s.time_headway_s <= threshold)
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(64))]

        /// Over any range the headway falls through in the scene (from 3 s at
        /// its start to below 0.5 s), the widths share the range out at
        /// increasing steps, and each step is where the thresholds of its part
        /// decide by definition.
        #[test]
        fn the_thresholds_of_a_range_decide_at_steps_that_share_it_out(
            lowest in 0.5f64..2.5,
            width in 0.001f64..0.5,
        ) {
            let setup = arterial_setup();
            let range = (lowest, lowest + width);
            let steps = decision_steps(setup, Decision::TimeHeadway, range);
            let total: f64 = steps.iter().map(|&(_, w)| w).sum();
            proptest::prop_assert!((total - width).abs() < 1e-9, "{} against {}", total, width);
            for pair in steps.windows(2) {
                proptest::prop_assert!(pair[0].0 < pair[1].0);
            }
            for &(i, part) in &steps {
                let threshold = setup.situations[i].time_headway_s.max(range.0);
                proptest::prop_assert!(part > 0.0);
                proptest::prop_assert_eq!(deciding_step(setup, threshold), Some(i));
            }
            // Every threshold of the range decides at one of the steps.
            for k in 0..=4 {
                let threshold = range.0 + width * f64::from(k) / 4.0;
                let step = deciding_step(setup, threshold).unwrap();
                proptest::prop_assert!(steps.iter().any(|&(i, _)| i == step), "{}", threshold);
            }
        }
    }

    /// A scene of an ego at `speed` (m/s) closing on the vehicle ahead at
    /// `closing` (m/s) from a time headway of 3 s, the target lane empty, and the
    /// onset of a user who decides at the time headway `threshold` in it (the
    /// first step at which [`Situation::decides_at`] holds), read as the
    /// readings read it.
    fn onset_of_a_closing_scene(speed: f64, closing: f64, threshold: f64) -> Onset {
        let dt = 0.1;
        let steps: Vec<SeenStep> = (0..3000)
            .map(|i| SeenStep {
                ego_speed: speed,
                preceding: Some((3.0 * speed - closing * dt * f64::from(i), speed - closing)),
                target_lead: None,
                target_lag: None,
                safe: None,
            })
            .collect();
        let scene = SceneSteps {
            dt,
            set_speed_mps: speed,
            steps,
        };
        let seen = crate::driver::situation;
        let start = (scene.steps.iter())
            .position(|s| seen(s).decides_at(threshold))
            .unwrap();
        let headway = |i: usize| seen(&scene.steps[i]).time_headway_s;
        Onset {
            time_s: start as f64 * dt,
            time_headway_s: 0.5 * (headway(start) + headway(start - 1)),
            scene: Some(scene),
            ..onset(0.0, 10.0, None)
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(128))]

        /// Whatever the scenes a user who decides at one time headway started
        /// in, the interval the readings keep contains that headway: a start
        /// never rules out the user's own threshold.
        #[test]
        fn a_users_threshold_lies_in_the_interval_its_starts_allow(
            threshold in 0.8f64..2.5,
            scenes in proptest::collection::vec((10.0f64..35.0, 0.5f64..8.0), 1..6),
        ) {
            let onsets: Vec<Onset> = (scenes.iter())
                .map(|&(speed, closing)| onset_of_a_closing_scene(speed, closing, threshold))
                .collect();
            let free: Vec<&Onset> = onsets.iter().collect();
            let (lowest, highest) = revealed_interval(&free, Decision::TimeHeadway).unwrap();
            proptest::prop_assert!(
                lowest <= threshold && threshold < highest,
                "{} not in [{}, {})", threshold, lowest, highest
            );
            let range = decision_range(&onsets);
            proptest::prop_assert_eq!(range.feature, Decision::TimeHeadway);
            proptest::prop_assert!((range.highest - 0.5 * (lowest + highest)).abs() < 1e-12);
            proptest::prop_assert_eq!(range.revealed_by, onsets.len());
        }
    }

    /// Two scenes whose largest midpoint lies above what the other allows: the
    /// interval still decides where the user does, the midpoint a step early.
    #[test]
    fn the_interval_decides_where_a_midpoint_above_it_does_not() {
        let threshold = 1.151;
        let coarse = onset_of_a_closing_scene(20.0, 6.0, threshold);
        let fine = onset_of_a_closing_scene(20.0, 0.5, threshold);
        let (lowest, highest) =
            revealed_interval(&[&coarse, &fine], Decision::TimeHeadway).unwrap();
        assert!(
            lowest <= threshold && threshold < highest,
            "[{lowest}, {highest})"
        );
        let largest_midpoint = coarse.time_headway_s.max(fine.time_headway_s);
        assert!(
            largest_midpoint > highest,
            "{largest_midpoint} against {highest}"
        );
        let predicted = decision_range(&[coarse, fine]).highest;
        assert!(lowest <= predicted && predicted < highest, "{predicted}");
    }

    /// Two starts of a driver in one scene merged into their mean: the mean is
    /// not a step the driver started at, and reveals no interval.
    #[test]
    fn a_mean_of_starts_reveals_no_interval() {
        let first = onset_of_a_closing_scene(20.0, 2.0, 1.2);
        let second = onset_of_a_closing_scene(20.0, 2.0, 1.3);
        let mean = first.merged(&second);
        assert!(revealed_interval(&[&first, &second], Decision::TimeHeadway).is_none());
        assert!(revealed_interval(&[&mean, &first], Decision::TimeHeadway).is_none());
        assert!(revealed_interval(&[&first], Decision::TimeHeadway).is_some());
    }

    #[test]
    fn one_threshold_decides_at_one_step() {
        let setup = arterial_setup();
        let one = decision_steps(setup, Decision::TimeHeadway, (1.5, 1.5));
        assert_eq!(one, vec![(deciding_step(setup, 1.5).unwrap(), 1.0)]);
    }

    #[test]
    fn acceptance_is_the_smallest_gap_that_held_the_user_back() {
        let onsets = [onset(1.2, 10.0, Some(0.4)), onset(1.2, 10.0, Some(0.2))];
        assert!((acceptance(&onsets, |o| o.lag_time_gap_s) - 0.2).abs() < 1e-12);
        assert_eq!(acceptance(&onsets, |o| o.lead_time_gap_s), 0.0);
    }
}
