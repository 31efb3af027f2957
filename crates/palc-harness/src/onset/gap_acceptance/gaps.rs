//! The target-lane gaps a driver needs: the leader's from the gaps that held it
//! back, it refused or it accepted ([`acceptance`], [`assumed_lead_gap_s`]), and
//! the follower's from the waits for it ([`lag_acceptance`]).

use palc_aggregator::Onset;

use super::{is_follower_wait, start_in_scene};
use crate::onset::cues::lag_time_gap;
use crate::setup::Setup;

/// The lead gap (s) a user is assumed to need besides what it has shown, given
/// the smallest lead gap it has accepted (`f64::INFINITY` for none): the standard
/// ALC's, until the user has accepted a smaller one (an accepted gap bounds the
/// user's requirement from above). Under the safety layer none is assumed: the
/// safe distance is required there anyway.
pub(crate) fn assumed_lead_gap_s(setup: &Setup, smallest_accepted: f64) -> f64 {
    if setup.safety.enforce {
        0.0
    } else {
        setup.standard_alc.min_lead_gap_s.min(smallest_accepted)
    }
}

/// The smallest target-lane time gap that held the user back in `onsets`, or 0
/// (a vehicle alongside is never accepted) when none did.
pub(super) fn acceptance(onsets: &[Onset], gap: fn(&Onset) -> Option<f64>) -> f64 {
    onsets
        .iter()
        .filter_map(gap)
        .reduce(f64::min)
        .map_or(0.0, |g| g.max(0.0))
}

/// [`acceptance`] of the follower's gap, where two or more starts read as waits
/// for it (`observed::waited_for_the_follower`) reveal the gap the user needs as the
/// interval every one of their scenes allows: a wait that ended at step `k`
/// refused the gap at `k − 1` and took the one at `k`, `a ∈ (g(k − 1), g(k)]`, and
/// the scenes together allow `(max g(k − 1), min g(k)]`. Each wait then stands for
/// that interval's middle (under a uniform belief over it, the start most of it
/// leads to in a new scene), not for its own midpoint, which can lie below what
/// another scene refused and start the next scene a step early, as the
/// thresholds' midpoints did (docs/experiments/0089-the-thresholds-every-scene-allows.md,
/// docs/experiments/0100-the-follower-gap-every-wait-allows.md). With one wait,
/// or intervals that do not meet, each wait's own midpoint stands.
pub(super) fn lag_acceptance(onsets: &[Onset]) -> f64 {
    let waits: Vec<&Onset> = onsets.iter().filter(|o| is_follower_wait(o)).collect();
    let revealed = (waits.len() >= 2)
        .then(|| waited_gap_interval(&waits))
        .flatten()
        .map(|(lowest, highest)| 0.5 * (lowest + highest));
    (onsets.iter())
        .filter_map(|o| {
            o.lag_time_gap_s
                .map(|g| revealed.filter(|_| is_follower_wait(o)).unwrap_or(g))
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::onset::test_scenes::{learn_scene, onset};

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
    fn acceptance_is_the_smallest_gap_that_held_the_user_back() {
        let onsets = [onset(1.2, 10.0, Some(0.4)), onset(1.2, 10.0, Some(0.2))];
        assert!((acceptance(&onsets, |o| o.lag_time_gap_s) - 0.2).abs() < 1e-12);
        assert_eq!(acceptance(&onsets, |o| o.lead_time_gap_s), 0.0);
    }
}
