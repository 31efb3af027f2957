//! The cue a driver decides on and the interval of its threshold that the
//! onsets allow ([`decision_range`]).

use palc_aggregator::Onset;
use palc_user::Situation;

use super::gaps::lag_acceptance;
use super::{is_follower_wait, start_in_scene};
use palc_user::{MAX_REACTION_S, StartModel};

use crate::driver::READ_BY_THE_READINGS;
use crate::driver::prior::Cue;
use crate::onset::cues::{cue_value, onset_value};

/// Relative spread below which a decision feature counts as consistent across
/// scenes.
const CONSISTENT_SPREAD: f64 = 0.1;

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
pub(crate) fn decision(onsets: &[Onset]) -> (Cue, f64) {
    let range = decision_range(onsets);
    (range.feature, range.highest)
}

/// What [`decision_range`] learned: the feature and the thresholds it allows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct DecisionRange {
    pub(super) feature: Cue,
    /// The lowest threshold the onsets allow.
    pub(super) lowest: f64,
    /// The threshold (the highest the onsets allow).
    pub(super) highest: f64,
    /// How many free onsets' scenes revealed the threshold as the middle of the
    /// interval they all allow ([`revealed_threshold`]); 0 when it is read from
    /// the onsets' midpoints or ceilings.
    pub(super) revealed_by: usize,
    /// The readings' own model explains the onsets: the feature decided on
    /// is consistent across them (within [`CONSISTENT_SPREAD`], over the free
    /// onsets, or over all when none is free) and no held-back start
    /// contradicts it. Always so for a single onset.
    pub(super) explained: bool,
    /// The reaction (s) between the decision and the earliest start: 0 but
    /// where no cue has one threshold every free start allows and a reaction
    /// gives one ([`reaction_range`]).
    pub(super) reaction_s: f64,
}

impl DecisionRange {
    pub(super) fn one(feature: Cue, threshold: f64, revealed_by: usize) -> Self {
        DecisionRange {
            feature,
            lowest: threshold,
            highest: threshold,
            revealed_by,
            explained: true,
            reaction_s: 0.0,
        }
    }
}

/// [`decision`] with the lowest threshold the onsets allow. The two differ only
/// when every onset was held back and a ceiling raised the time headway's
/// threshold above the largest headway at which the user started (the onsets
/// bound the decision to that interval and say nothing more).
pub(super) fn decision_range(onsets: &[Onset]) -> DecisionRange {
    reread_follower_waits(onsets).1
}

/// [`decision_range`], [`reaction_range`] and the follower's gap needed
/// (`gaps::lag_acceptance`) of `onsets`, their waits read again once for all
/// three ([`reread_follower_waits`] copies every onset with its scene).
pub(super) fn decision_and_reaction(
    onsets: &[Onset],
) -> (DecisionRange, Option<DecisionRange>, f64) {
    let (reread, range) = reread_follower_waits(onsets);
    (range, reaction_range(&reread), lag_acceptance(&reread))
}

/// [`decision_range`] of onsets whose waits were read again.
fn range_of_reread(onsets: &[Onset]) -> DecisionRange {
    let free = free_onsets(onsets);
    let informative: Vec<&Onset> = if free.is_empty() {
        onsets.iter().collect()
    } else {
        free.clone()
    };
    let spread = |feature: Cue| -> Option<(f64, f64)> {
        let values: Vec<f64> = (informative.iter())
            .map(|o| onset_value(feature, o))
            .collect::<Option<_>>()?;
        let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let min = values.iter().copied().fold(f64::INFINITY, f64::min);
        (max > 0.0).then(|| ((max - min) / max, max))
    };
    let mut headway = spread(Cue::TimeHeadway).unwrap_or((0.0, 0.0));
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
    let contradicted = |feature: Cue, threshold: f64| {
        !free.is_empty()
            && (onsets.iter())
                .filter(|o| o.lead_time_gap_s.is_some() || o.lag_time_gap_s.is_some())
                .any(|o| {
                    onset_value(feature, o)
                        .is_some_and(|v| v > threshold * (1.0 + CONSISTENT_SPREAD))
                })
    };
    let headway_fails = (informative.len() >= 2 && headway.0 > CONSISTENT_SPREAD)
        || contradicted(Cue::TimeHeadway, headway.1);
    if headway_fails {
        let best = [Cue::TimeToCollision, Cue::DistanceGap]
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
    match revealed_threshold(&free, Cue::TimeHeadway) {
        Some(revealed) => DecisionRange {
            explained,
            ..DecisionRange::one(Cue::TimeHeadway, revealed, free.len())
        },
        None => DecisionRange {
            feature: Cue::TimeHeadway,
            lowest: lowest_headway,
            highest: headway.1,
            revealed_by: 0,
            explained,
            reaction_s: 0.0,
        },
    }
}

/// The threshold of `feature` the free onsets' scenes reveal: the middle of the
/// interval they all allow ([`revealed_interval`]). Under a uniform belief over
/// the interval, the start that most of it leads to in a new scene is the one
/// its middle leads to. With one onset it is that onset's `observed::revealed`
/// midpoint; with more, the largest midpoint (the readings' threshold before)
/// could lie outside the interval and start the next scene a step early or late
/// (docs/experiments/0089-the-thresholds-every-scene-allows.md).
fn revealed_threshold(free: &[&Onset], feature: Cue) -> Option<f64> {
    revealed_interval(free, feature).map(|(lowest, highest)| 0.5 * (lowest + highest))
}

/// The onsets no target-lane gap held back: their start is the decision's.
fn free_onsets(onsets: &[Onset]) -> Vec<&Onset> {
    (onsets.iter())
        .filter(|o| o.lead_time_gap_s.is_none() && o.lag_time_gap_s.is_none())
        .collect()
}

/// The thresholds of `feature` that every free onset allows, from the scenes
/// they recorded: a start at step `k` says that the feature had fallen to the
/// threshold there and not at the step before, `θ ∈ [x(k), x(k − 1))`, and the
/// scenes together allow the intersection `[max x(k), min x(k − 1))`. `None`
/// when an onset recorded no scene or is the mean of several starts in its
/// scene ([`Onset::merged`]: a mean of starts is not a step at which the driver
/// started), or the intervals do not intersect (a driver whose threshold is not
/// one value): the midpoints stand.
fn revealed_interval(free: &[&Onset], feature: Cue) -> Option<(f64, f64)> {
    revealed_interval_after(free, feature, 0.0)
}

/// [`revealed_interval`] for a driver who starts `reaction_s` after deciding
/// (in whole steps of each scene, as palc-user's
/// [`StartModel::reaction_steps`](palc_user::StartModel::reaction_steps) counts
/// them): a start at step `k` says the feature had fallen to the threshold
/// `r` steps before, `θ ∈ [x(k − r), x(k − r − 1))`. `None` also where a
/// scene's start comes too early for the reaction (a decision at the scene's
/// first step or before it).
fn revealed_interval_after(free: &[&Onset], feature: Cue, reaction_s: f64) -> Option<(f64, f64)> {
    if free.is_empty() {
        return None;
    }
    let value = |s: &Situation| cue_value(feature, s);
    let (mut lowest, mut highest) = (f64::NEG_INFINITY, f64::INFINITY);
    for onset in free {
        let (scene, step) = start_in_scene(onset)?;
        let reaction = StartModel::steps_of_reaction(reaction_s, scene.dt);
        let decided = step.checked_sub(reaction).filter(|&d| d >= 1)?;
        lowest = lowest.max(value(&crate::driver::situation(&scene.steps[decided]))?);
        if let Some(before) = value(&crate::driver::situation(&scene.steps[decided - 1])) {
            highest = highest.min(before);
        }
    }
    (lowest < highest && highest.is_finite()).then_some((lowest, highest))
}

/// Where two or more free starts are no threshold of any cue the set reads
/// (their intervals meet for none, [`revealed_interval`]), the decision of a
/// driver who starts a reaction after deciding, as palc-user's users of a
/// reaction do: the shortest reaction, in steps of the first free start's
/// scene up to palc-user's largest ([`MAX_REACTION_S`]), after which one cue's
/// intervals meet, the time headway's first among equals (the paper's cue),
/// and the middle of what they allow. The driver's own reaction always lets its
/// threshold's intervals meet, so the one found is never longer than the
/// driver's. `None` where a cue needs none, below two free starts, or where no
/// reaction makes the starts one threshold.
///
/// `onsets` are the ones whose waits were read again
/// ([`reread_follower_waits`], [`decision_and_reaction`]).
fn reaction_range(onsets: &[Onset]) -> Option<DecisionRange> {
    let free = free_onsets(onsets);
    if free.len() < 2
        || (READ_BY_THE_READINGS.iter()).any(|&c| revealed_interval(&free, c).is_some())
    {
        return None;
    }
    let (scene, first_start) = start_in_scene(free[0])?;
    // A reaction that reaches back past the first start's scene decides
    // nowhere in it: the search ends there whatever the step.
    let longest = ((MAX_REACTION_S / scene.dt).round() as usize).min(first_start - 1);
    let dt = scene.dt;
    (1..=longest).find_map(|steps| {
        let reaction_s = steps as f64 * dt;
        (READ_BY_THE_READINGS.iter()).find_map(|&cue| {
            let (lowest, highest) = revealed_interval_after(&free, cue, reaction_s)?;
            Some(DecisionRange {
                reaction_s,
                ..DecisionRange::one(cue, 0.5 * (lowest + highest), free.len())
            })
        })
    })
}

/// `onsets` with the starts read as waits for the follower
/// (`observed::waited_for_the_follower`) read again as the user's own decisions,
/// at the headway each started at, where the scenes say so.
///
/// One scene cannot tell the two readings apart: both place the start where it
/// was, and the paper's premise (every user decides before the standard ALC)
/// chooses the wait (docs/experiments/0093-a-wait-for-the-follower-or-a-closer-decision.md).
/// Two or more scenes can:
/// - every start is read as a decision where, so read, the free starts reveal
///   one threshold of a cue (the intervals their scenes allow meet,
///   `DecisionRange::revealed_by`) that no held-back start contradicts
///   (`DecisionRange::explained`). The wait needs one more parameter (the
///   follower's gap) to explain what the decision explains without it; a
///   recorded driver who decides closer than the standard ALC does so in
///   every scene (docs/experiments/0103-waits-the-other-scenes-do-not-need.md);
/// - otherwise a wait is read again as a decision where another onset started
///   with a smaller follower gap than the one the wait learned (by more than
///   [`CONSISTENT_SPREAD`]): a user who accepts that smaller gap did not wait for
///   the larger one (the accepted gap bounds the needed one from above). A
///   time-to-collision user who decides below the standard ALC's headway as the
///   follower's gap opens looks like a user who waited for that gap
///   (docs/experiments/0060-a-wait-the-standard-alc-would-not-make.md,
///   docs/experiments/0061-a-wait-read-again.md).
///
/// Returned with the [`DecisionRange`] of the onsets so read, which the choice
/// computes anyway.
fn reread_follower_waits(onsets: &[Onset]) -> (Vec<Onset>, DecisionRange) {
    if onsets.len() >= 2 && onsets.iter().any(is_follower_wait) {
        let decisions: Vec<Onset> = onsets.iter().map(read_as_decision).collect();
        let range = range_of_reread(&decisions);
        if range.explained && range.revealed_by >= 2 {
            return (decisions, range);
        }
    }
    let smaller_lag_elsewhere = |i: usize, gap: f64| {
        (onsets.iter().enumerate()).any(|(j, o)| {
            j != i && (o.lag_time_gap_s).is_some_and(|g| g < gap * (1.0 - CONSISTENT_SPREAD))
        })
    };
    let reread: Vec<Onset> = (onsets.iter().enumerate())
        .map(|(i, o)| match o.lag_time_gap_s {
            Some(gap) if smaller_lag_elsewhere(i, gap) => read_as_decision(o),
            _ => o.clone(),
        })
        .collect();
    let range = range_of_reread(&reread);
    (reread, range)
}

/// `onset` with a start read as a wait for the follower read as the user's own
/// decision instead, at the headway it started at; any other onset unchanged.
fn read_as_decision(onset: &Onset) -> Onset {
    match onset.follower_wait_time_headway_s {
        Some(headway) if is_follower_wait(onset) => Onset {
            time_headway_s: headway,
            lag_time_gap_s: None,
            follower_wait_time_headway_s: None,
            ..onset.clone()
        },
        _ => onset.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::onset::test_scenes::{onset, onset_of_a_closing_scene, onset_of_a_reacting_driver};

    #[test]
    fn the_decision_is_the_headway_unless_another_feature_is_consistent() {
        assert_eq!(decision(&[onset(1.2, 10.0, None)]).0, Cue::TimeHeadway);
        let headway_user = [onset(1.2, 10.0, None), onset(1.21, 5.0, None)];
        let (feature, threshold) = decision(&headway_user);
        assert_eq!(feature, Cue::TimeHeadway);
        assert!((threshold - 1.21).abs() < 1e-12);
        let ttc_user = [onset(1.6, 8.0, None), onset(0.8, 8.1, None)];
        assert_eq!(decision(&ttc_user).0, Cue::TimeToCollision);
        // An onset held back by a gap does not set the decision.
        let held = [onset(1.2, 10.0, None), onset(0.3, 2.0, Some(0.1))];
        assert_eq!(decision(&held), (Cue::TimeHeadway, 1.2));
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
        assert_eq!(decision(std::slice::from_ref(&free)).0, Cue::TimeHeadway);
        assert_eq!(decision(&[free, held]), (Cue::TimeToCollision, 8.0));
        // A held-back start below the headway threshold contradicts nothing.
        let below = onset(0.6, 6.3, Some(0.0));
        assert_eq!(
            decision(&[onset(0.89, 8.0, None), below]).0,
            Cue::TimeHeadway
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
        assert_eq!(reread_follower_waits(alone).0, alone.to_vec());
        assert_eq!(decision(alone), (Cue::TimeHeadway, 1.0));
        // Another scene in which it started as soon as a follower had cleared (a
        // gap of 0): it needs no 0.59 s behind, so the start was its decision.
        let held = Onset {
            gap_m: 10.0,
            ..onset(1.41, 6.3, Some(0.0))
        };
        let (reread, _) = reread_follower_waits(&[waited.clone(), held.clone()]);
        assert_eq!(reread[0].time_headway_s, 0.89);
        assert_eq!(reread[0].lag_time_gap_s, None);
        assert_eq!(reread[1], held);
        assert_eq!(
            decision(&[waited.clone(), held]),
            (Cue::TimeToCollision, 8.0)
        );
        // A user that waited for about as large a gap in every scene keeps the
        // reading.
        let again = Onset {
            follower_wait_time_headway_s: Some(0.7),
            ..onset(1.0, 6.0, Some(0.62))
        };
        let both = [waited, again];
        assert_eq!(reread_follower_waits(&both).0, both.to_vec());
    }

    /// The onset of a user who decides at the time headway `threshold` in a
    /// scene closing at `closing` m/s from `speed` m/s, with every cue read at its
    /// start as the readings read them (the middle of its values at the start's
    /// step and the step before).
    fn decided(speed: f64, closing: f64, threshold: f64) -> Onset {
        let onset = onset_of_a_closing_scene(speed, closing, threshold);
        let (scene, step) = start_in_scene(&onset).unwrap();
        let at = |cue: Cue| {
            let value = |i: usize| cue_value(cue, &crate::driver::situation(&scene.steps[i]));
            Some(0.5 * (value(step)? + value(step - 1)?))
        };
        Onset {
            ttc_s: at(Cue::TimeToCollision),
            gap_m: at(Cue::DistanceGap).unwrap(),
            ..onset
        }
    }

    #[test]
    fn waits_are_decisions_where_the_decisions_reveal_one_threshold() {
        // A start at a headway of 0.9 s as the follower's gap opened, read as a
        // wait for that gap with the decision at the standard ALC's 1.0 s.
        let start = decided(20.0, 2.0, 0.9);
        let waited = Onset {
            time_headway_s: 1.0,
            follower_wait_time_headway_s: Some(start.time_headway_s),
            lag_time_gap_s: Some(0.59),
            ..start.clone()
        };
        // Alone it stays a wait: one scene cannot tell.
        let alone = std::slice::from_ref(&waited);
        assert_eq!(reread_follower_waits(alone).0, alone.to_vec());
        // Another scene's free start reveals the same threshold (their
        // intervals of the headway meet): the start was the user's decision.
        let free = decided(25.0, 3.0, 0.9);
        let (reread, _) = reread_follower_waits(&[waited.clone(), free.clone()]);
        assert_eq!(reread, vec![start, free]);
        // A free start at 1.23 s: no threshold of any cue allows both starts
        // as decisions, and the wait stands.
        let earlier = decided(25.0, 3.0, 1.23);
        let kept = [waited, earlier];
        assert_eq!(reread_follower_waits(&kept).0, kept.to_vec());
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
        assert_eq!(decision(&waits), (Cue::TimeHeadway, 1.3));
        // A ceiling below a start the user has shown says nothing.
        assert_eq!(decision(&[held(0.9, Some(0.7))]).1, 0.9);
        // A free onset gives the threshold itself.
        let with_free = [held(0.6, Some(1.5)), onset(1.2, 10.0, None)];
        assert_eq!(decision(&with_free).1, 1.2);
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
            let (lowest, highest) = revealed_interval(&free, Cue::TimeHeadway).unwrap();
            proptest::prop_assert!(
                lowest <= threshold && threshold < highest,
                "{} not in [{}, {})", threshold, lowest, highest
            );
            let range = decision_range(&onsets);
            proptest::prop_assert_eq!(range.feature, Cue::TimeHeadway);
            proptest::prop_assert!((range.highest - 0.5 * (lowest + highest)).abs() < 1e-12);
            proptest::prop_assert_eq!(range.revealed_by, onsets.len());
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(128))]

        /// Whatever the scenes a user who decides at one time headway and
        /// starts a reaction later started in, the interval its starts allow
        /// after its own reaction contains its threshold, and the reaction the
        /// set finds, if any, is never longer than its own.
        #[test]
        fn a_reacting_users_threshold_and_reaction_lie_in_the_set(
            threshold in 0.8f64..2.5,
            reaction in 0usize..12,
            scenes in proptest::collection::vec((10.0f64..35.0, 0.5f64..8.0), 2..6),
        ) {
            let onsets: Vec<Onset> = (scenes.iter())
                .map(|&(speed, closing)| onset_of_a_reacting_driver(speed, closing, threshold, reaction))
                .collect();
            let free: Vec<&Onset> = onsets.iter().collect();
            let reaction_s = reaction as f64 * 0.1;
            let (lowest, highest) =
                revealed_interval_after(&free, Cue::TimeHeadway, reaction_s).unwrap();
            proptest::prop_assert!(
                lowest <= threshold && threshold < highest,
                "{} not in [{}, {})", threshold, lowest, highest
            );
            if let Some(found) = reaction_range(&onsets) {
                proptest::prop_assert!(found.reaction_s <= reaction_s + 1e-9, "{:?}", found);
            }
        }
    }

    /// A driver of a 0.8 s reaction seen in three scenes closing at rates from
    /// 0.5 to 8 m/s: its starts are no threshold of any cue without a reaction,
    /// and the shortest reaction that makes them one is its own (scenes closing
    /// at closer rates can leave a shorter one, never a longer one: the
    /// property above).
    #[test]
    fn the_shortest_reaction_that_makes_the_starts_one_threshold_is_found() {
        let onsets: Vec<Onset> = [(20.0, 0.5), (30.0, 8.0), (12.0, 6.0)]
            .iter()
            .map(|&(speed, closing)| onset_of_a_reacting_driver(speed, closing, 1.3, 8))
            .collect();
        assert_eq!(decision_range(&onsets).revealed_by, 0);
        let found = reaction_range(&onsets).expect("a reaction makes them one threshold");
        assert_eq!(found.feature, Cue::TimeHeadway);
        assert!((found.reaction_s - 0.8).abs() < 1e-9, "{found:?}");
        assert!((found.highest - 1.3).abs() < 0.02, "{found:?}");
        assert_eq!(found.revealed_by, 3);
        // A driver without a reaction needs none.
        let instant: Vec<Onset> = [(20.0, 1.0), (25.0, 6.0)]
            .iter()
            .map(|&(speed, closing)| onset_of_a_closing_scene(speed, closing, 1.3))
            .collect();
        assert_eq!(reaction_range(&instant), None);
    }

    /// A scene of a vanishing step (an experience file's, say) bounds the
    /// reactions searched by its start's step, not by the largest reaction in
    /// such steps (which would not end).
    #[test]
    fn the_reactions_searched_end_at_the_first_starts_step() {
        let tiny = |onset: Onset| {
            let mut scene = onset.scene.clone().unwrap();
            scene.dt = 1e-300;
            Onset {
                time_s: onset.time_s / 0.1 * 1e-300,
                scene: Some(scene),
                ..onset
            }
        };
        let onsets: Vec<Onset> = [(20.0, 0.5), (30.0, 8.0), (12.0, 6.0)]
            .iter()
            .map(|&(speed, closing)| tiny(onset_of_a_reacting_driver(speed, closing, 1.3, 8)))
            .collect();
        assert!(start_in_scene(&onsets[0]).is_some());
        let found = reaction_range(&onsets).expect("the steps are the scene's own");
        assert!((found.reaction_s - 8e-300).abs() < 1e-309, "{found:?}");
    }

    /// Two scenes whose largest midpoint lies above what the other allows: the
    /// interval still decides where the user does, the midpoint a step early.
    #[test]
    fn the_interval_decides_where_a_midpoint_above_it_does_not() {
        let threshold = 1.151;
        let coarse = onset_of_a_closing_scene(20.0, 6.0, threshold);
        let fine = onset_of_a_closing_scene(20.0, 0.5, threshold);
        let (lowest, highest) = revealed_interval(&[&coarse, &fine], Cue::TimeHeadway).unwrap();
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
        assert!(revealed_interval(&[&first, &second], Cue::TimeHeadway).is_none());
        assert!(revealed_interval(&[&mean, &first], Cue::TimeHeadway).is_none());
        assert!(revealed_interval(&[&first], Cue::TimeHeadway).is_some());
    }
}
