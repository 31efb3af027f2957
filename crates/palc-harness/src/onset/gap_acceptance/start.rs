//! The start a [`GapAcceptanceSet`] predicts in a new scene
//! ([`GapAcceptanceSet::predicted_start_s`]): the forward model run over the
//! thresholds the set allows.

use std::collections::BTreeMap;

use palc_user::{Situation, StartModel};

use super::decision::DecisionRange;
use super::{GapAcceptanceSet, assumed_lead_gap_s};
use crate::driver::prior::Cue;
use crate::onset::cues::{cue_value, lag_time_gap, lead_time_gap};
use crate::setup::{Setup, target_gaps_safe};

impl GapAcceptanceSet {
    /// The user's start (s after the start of the plan) predicted in `setup`:
    /// the first step at which the decision cue has fallen to its threshold,
    /// then the first step from there at which the target-lane gaps are at least
    /// the ones the driver needs (for the leader, also at least the standard
    /// ALC's lead gap or the smallest one the user accepted, whichever is
    /// smaller). When the onsets bound the time headway's threshold to an
    /// interval (`decision::decision_range`; from below also by the standard
    /// ALC's decision headway, which every user's is above: the paper's
    /// premise), each threshold of it gives a start, and the start given by the
    /// largest part of the interval is predicted, the earliest of those within
    /// one step's fall of the headway of each other: a uniform belief over what
    /// the scenes allow, not a choice of one end. Taking the upper end (the
    /// earliest start, as for a free onset) started users held back in dense
    /// scenes up to 20 s early in sparser ones. Under the safety layer the gaps
    /// are also at the safe distance at every step of the carried lane change
    /// (`duration_s` from the start, on the lane-keeping prediction): a start
    /// whose lane change the layer would refuse is not predicted. `None` when the
    /// prediction does not start within the search window.
    pub fn predicted_start_s(&self, setup: &Setup, duration_s: f64) -> Option<f64> {
        let DecisionRange {
            feature,
            lowest,
            highest: threshold,
            reaction_s,
            ..
        } = self.decision;
        let reaction = StartModel::steps_of_reaction(reaction_s, setup.dt);
        // What the user needs from the leader: at least what held it back or
        // what it refused; of the rest, what the system itself requires until
        // the user has accepted a smaller gap (what it accepted bounds its
        // requirement from above). The system's requirement is the standard
        // ALC's lead gap, or, under the safety layer, the safe distance, which
        // `accepts` below requires anyway.
        let safety = &setup.safety;
        let assumed = assumed_lead_gap_s(setup, self.smallest_accepted_lead_s);
        let lead = self.lead_at_least_s.max(assumed);
        let lag = self.lag_s;
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
            Cue::TimeHeadway => lowest.max(setup.standard_alc.time_headway_s),
            _ => lowest,
        };
        let mut weight = BTreeMap::<usize, f64>::new();
        let mut start = None;
        let decisions = decision_steps(setup, feature, (lowest.min(threshold), threshold));
        // The interval is resolved in steps: parts within one step's fall of the
        // feature are equal, and a start wins only by more than that.
        let resolution = decisions.iter().map(|&(_, w)| w).fold(0.0, f64::max);
        for (decided, width) in decisions {
            // The driver starts its reaction after deciding at the earliest.
            let earliest = decided + reaction;
            // The first accepted step from an earlier decision is the first from
            // this one too, unless this decision comes after it; with none from an
            // earlier decision there is none from a later one.
            if start.is_none_or(|s| s < earliest) {
                start = (earliest..situations.len()).find(|&i| accepts(i));
            }
            let Some(start) = start else { break };
            *weight.entry(start).or_default() += width;
        }
        // The start most thresholds lead to; the earliest of equals (with a free
        // fall of the feature every step's thresholds start at their own step, and
        // the earliest is the one the interval's upper end, the ceiling, gives).
        let (start, _) = (weight.into_iter()).fold(
            None,
            |best: Option<(usize, f64)>, (start, w)| match best {
                Some((_, b)) if b + resolution >= w => best,
                _ => Some((start, w)),
            },
        )?;
        Some(start as f64 * setup.dt)
    }
}

/// The steps at which thresholds of `feature` in `range` decide, each with the
/// length of the part of `range` that decides there: a threshold decides at the
/// first step at which the feature has fallen to it (behind a positive time
/// headway). A range of one value decides at one step, with weight 1.
fn decision_steps(setup: &Setup, feature: Cue, (lowest, highest): (f64, f64)) -> Vec<(usize, f64)> {
    let value = |s: &Situation| cue_value(feature, s);
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
    use crate::onset::test_scenes::{
        arterial_setup, learn_scene, onset, onset_of_a_reacting_driver,
    };

    /// The first step at which a threshold of the time headway decides, by its
    /// definition: the slower reference of [`decision_steps`].
    fn deciding_step(setup: &Setup, threshold: f64) -> Option<usize> {
        (setup.situations.iter())
            .position(|s| s.time_headway_s > 0.0 && s.time_headway_s <= threshold)
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
            GapAcceptanceSet::from_onsets(&[seen.clone(), refusing])?.predicted_start_s(&setup, 2.0)
        };
        let at_accepted = with_refused(accepted);
        assert!(at_accepted.is_some());
        for refused in [0.5 * (accepted + high), high, 10.0 * high] {
            assert_eq!(with_refused(refused), at_accepted, "refused {refused} s");
        }
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
            let steps = decision_steps(setup, Cue::TimeHeadway, range);
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

    #[test]
    fn one_threshold_decides_at_one_step() {
        let setup = arterial_setup();
        let one = decision_steps(setup, Cue::TimeHeadway, (1.5, 1.5));
        assert_eq!(one, vec![(deciding_step(setup, 1.5).unwrap(), 1.0)]);
    }

    /// A driver of a 0.8 s reaction, its threshold and reaction found from three
    /// scenes, starts in a new one (the target lane empty) where it does: 8
    /// steps after its decision, where the same threshold without the reaction
    /// starts.
    #[test]
    fn a_set_with_a_reaction_starts_where_the_driver_does() {
        let mut setup = learn_scene();
        for situation in &mut setup.situations {
            (situation.target_lead_gap_m, situation.target_lag_gap_m) = (None, None);
        }
        let onsets: Vec<palc_aggregator::Onset> = [(20.0, 0.5), (30.0, 8.0), (12.0, 6.0)]
            .iter()
            .map(|&(speed, closing)| onset_of_a_reacting_driver(speed, closing, 1.3, 8))
            .collect();
        let set = GapAcceptanceSet::from_onsets(&onsets).unwrap();
        let reacting = set.with_reaction().unwrap();
        let driver = StartModel {
            rule: palc_user::StartRule::TimeHeadway,
            time_headway_s: 1.3,
            reaction_s: 0.8,
            min_lead_gap_s: 0.0,
            min_lag_gap_s: 0.0,
        };
        let (decided, started) = driver
            .start_step(&setup.situations, setup.dt, setup.set_speed, |_| true)
            .unwrap();
        assert_eq!(started, decided + 8);
        let close = |a: f64, b: usize| (a - b as f64 * setup.dt).abs() < 1e-9;
        let predicted = reacting.predicted_start_s(&setup, 2.0).unwrap();
        assert!(
            close(predicted, started),
            "{predicted} against step {started}"
        );
        let instant = GapAcceptanceSet {
            decision: DecisionRange {
                reaction_s: 0.0,
                ..reacting.decision
            },
            ..reacting
        };
        let predicted = instant.predicted_start_s(&setup, 2.0).unwrap();
        assert!(
            close(predicted, decided),
            "{predicted} against step {decided}"
        );
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(64))]

        /// A set of one threshold and reaction, in a scene whose target lane is
        /// empty, starts where palc-user's start model of that threshold and
        /// reaction does (the slower reference: the model run forward step by
        /// step), or nowhere where it never decides.
        #[test]
        fn a_one_threshold_set_starts_where_its_start_model_does(
            threshold in 0.5f64..3.0,
            reaction in 0usize..15,
        ) {
            let mut setup = learn_scene();
            for situation in &mut setup.situations {
                (situation.target_lead_gap_m, situation.target_lag_gap_m) = (None, None);
            }
            let reaction_s = reaction as f64 * setup.dt;
            let set = GapAcceptanceSet {
                decision: DecisionRange {
                    reaction_s,
                    ..DecisionRange::one(Cue::TimeHeadway, threshold, 0)
                },
                lead_at_least_s: 0.0,
                smallest_accepted_lead_s: f64::INFINITY,
                lag_s: 0.0,
                reacting: None,
            };
            let model = StartModel {
                rule: palc_user::StartRule::TimeHeadway,
                time_headway_s: threshold,
                reaction_s,
                min_lead_gap_s: 0.0,
                min_lag_gap_s: 0.0,
            };
            let reference = model
                .start_step(&setup.situations, setup.dt, setup.set_speed, |_| true)
                .ok()
                .map(|(_, start)| start as f64 * setup.dt);
            // The set holds the standard ALC's decision headway as the lowest
            // threshold (the paper's premise); above it the two agree. A
            // threshold met at the scene's first step is one the model would
            // have started on before the scene (no start), the set at once.
            proptest::prop_assume!(threshold >= setup.standard_alc.time_headway_s);
            proptest::prop_assume!(!setup.situations[0].decides_at(threshold));
            let predicted = set.predicted_start_s(&setup, 2.0);
            match (predicted, reference) {
                (Some(p), Some(r)) => proptest::prop_assert!((p - r).abs() < 1e-9, "{} against {}", p, r),
                (p, r) => proptest::prop_assert_eq!(p, r),
            }
        }
    }
}
