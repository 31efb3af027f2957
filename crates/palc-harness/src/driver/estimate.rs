//! The posterior over start models and the start it predicts in a new scene.

use std::sync::Arc;

use palc_aggregator::Onset;
use palc_user::{Situation, StartModel};

use super::grid::{Grid, SceneView, combination};
use super::memo::{self, Accumulated, Posterior};
use super::prior::{
    self, Cue, LAG_GAPS_S, LEAD_GAPS_S, MISFIT_SDS, MISREAD_START_PROBABILITY, OBSERVATION_SD_S,
    REACTIONS_S,
};
use super::scene::situations;

/// Below this, `f64::exp` returns +0 (its smallest subnormal result is at
/// about -745.13), so a weight this far below the top is 0 without the call.
const EXP_UNDERFLOW: f64 = -746.0;

/// How far each start step of a scene lies from the observed start, and the
/// log-likelihood it costs: computed once per step (a scene has a few hundred)
/// rather than once per hypothesis (2.7 million), with the same arithmetic.
struct Misfit {
    /// `(error_s, penalty)` per start step; the last entry is for [`NEVER`](super::grid::NEVER).
    per_step: Vec<(f64, f64)>,
}

impl Misfit {
    /// The misfits of the `steps` start steps of a scene at step `dt` whose
    /// observed start is `observed_s`.
    fn new(steps: usize, dt: f64, observed_s: f64) -> Misfit {
        // An observed start is the model's, within the Gaussian of
        // OBSERVATION_SD_S, or misread, anywhere in the scene: the likelihood
        // relative to a start observed exactly, so that an exact start costs 0.
        let misread = MISREAD_START_PROBABILITY;
        let span_s = (steps as f64 * dt).max(dt);
        let anywhere = misread * OBSERVATION_SD_S * (2.0 * std::f64::consts::PI).sqrt() / span_s;
        let exact = (1.0 - misread + anywhere).ln();
        let penalty = |error: f64| {
            let gaussian = (-0.5 * (error / OBSERVATION_SD_S).powi(2)).exp();
            exact - ((1.0 - misread) * gaussian + anywhere).ln()
        };
        let per_step = (0..steps)
            .map(|step| (f64::from(step as u32) * dt - observed_s).abs())
            .chain([f64::INFINITY])
            .map(|error| (error, penalty(error)))
            .collect();
        Misfit { per_step }
    }

    /// The error (s) and penalty of a start at `start` ([`NEVER`](super::grid::NEVER) for none).
    #[inline]
    fn of(&self, start: u32) -> (f64, f64) {
        let last = self.per_step.len() - 1;
        self.per_step[(start as usize).min(last)]
    }
}

impl Accumulated {
    /// Adds the scene of `onset` (which has one) to the posterior: each
    /// hypothesis's start there, run forward, against the observed start.
    fn read(&mut self, grid: &Grid, onset: &Onset, duration_s: f64) {
        let Some(scene) = &onset.scene else { return };
        let seen = situations(scene);
        let safe: Option<Vec<bool>> = scene.steps.iter().map(|s| s.safe).collect();
        let view = SceneView::new(
            &seen,
            scene.dt,
            scene.set_speed_mps,
            safe.as_deref(),
            duration_s,
        );
        let misfit = Misfit::new(seen.len(), scene.dt, onset.time_s);
        let (worst, far_scenes, log_posterior) = (
            &mut self.worst,
            &mut self.far_scenes,
            &mut self.log_posterior,
        );
        grid.for_each_start(&view, |hypotheses, start| {
            let (error, penalty) = misfit.of(start);
            for far in &mut worst[hypotheses.clone()] {
                *far = far.max(error);
            }
            if error > MISFIT_SDS * OBSERVATION_SD_S {
                for count in &mut far_scenes[hypotheses.clone()] {
                    *count = count.saturating_add(1);
                }
            }
            for lp in &mut log_posterior[hypotheses] {
                *lp -= penalty;
            }
        });
        self.scenes += 1;
    }
}

/// What the estimate predicts in a scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Prediction {
    /// The start (s after the start of the plan) with the largest posterior mass.
    Start(f64),
    /// Most of the posterior never starts in this scene.
    NoStart,
    /// No start model explains every scene the driver was seen in.
    OutsideModel,
}

/// The posterior over start models, given the scenes a driver started in.
#[derive(Debug, Clone)]
pub struct DriverEstimate {
    grid: Grid,
    /// The posterior as accumulated over the scenes, with its weights (shared
    /// with the memo).
    posterior: Arc<Posterior>,
}

impl DriverEstimate {
    /// The estimate from the onsets that recorded their scene; `None` when none
    /// did. Under the safety layer a start must keep the safe distance for a
    /// lane change of `duration_s`.
    pub fn from_onsets(onsets: &[Onset], duration_s: f64) -> Option<DriverEstimate> {
        let seen: Vec<&Onset> = onsets.iter().filter(|o| o.scene.is_some()).collect();
        if seen.is_empty() {
            return None;
        }
        let grid = Grid::new();
        // A posterior of the first scenes, kept from an earlier estimate, is
        // extended with the rest: the same sum, in the same order.
        let kept = memo::longest_beginning(&seen, duration_s);
        let posterior = match kept {
            Some((kept, read)) if read == seen.len() => kept,
            kept => {
                let (mut accumulated, read) = match kept {
                    Some((kept, read)) => (kept.accumulated.clone(), read),
                    None => (
                        Accumulated {
                            log_posterior: prior(&grid),
                            worst: vec![0.0f64; grid.len()],
                            far_scenes: vec![0; grid.len()],
                            scenes: 0,
                        },
                        0,
                    ),
                };
                for onset in &seen[read..] {
                    accumulated.read(&grid, onset, duration_s);
                }
                let posterior = Arc::new(summarized(accumulated));
                memo::keep(&seen, duration_s, Arc::clone(&posterior));
                posterior
            }
        };
        Some(DriverEstimate { grid, posterior })
    }

    /// Whether every start model needs more of the observed starts misread
    /// (more than [`MISFIT_SDS`] standard deviations from its own) than the
    /// likelihood's misread probability makes plausible for the scenes seen
    /// (`plausible_misreads`): the observations contradict every hypothesis.
    pub fn outside_model(&self) -> bool {
        usize::from(self.posterior.fewest_far) > plausible_misreads(self.scenes())
    }

    /// Scenes the estimate has seen.
    pub fn scenes(&self) -> usize {
        self.posterior.accumulated.scenes
    }

    /// The posterior's most probable start model: among equals, the first of
    /// the grid, which is the least demanding (shortest reaction, smallest
    /// gaps) and, within a cue, the one that decides latest, at the start
    /// itself unless a scene showed a wait.
    pub fn most_probable(&self) -> StartModel {
        self.grid.model(self.most_probable_index())
    }

    fn most_probable_index(&self) -> usize {
        let (h, _) = (self.posterior.accumulated.log_posterior.iter().enumerate()).fold(
            (0, f64::NEG_INFINITY),
            |best, (h, &lp)| {
                if lp > best.1 + 1e-12 { (h, lp) } else { best }
            },
        );
        h
    }

    /// What the estimate believes, in one line: the most probable start model,
    /// the posterior mass of its cue and the scenes seen; or that the driver is
    /// outside the model, with the closest any model came.
    pub fn describe(&self) -> String {
        if self.outside_model() {
            return format!(
                "outside the model: every start model is more than {:.2} s from {} or more of the \
                 starts, more than one in twenty misread makes plausible (scenes seen: {}, the \
                 closest within {:.2} s of every start)",
                MISFIT_SDS * OBSERVATION_SD_S,
                self.posterior.fewest_far,
                self.scenes(),
                self.posterior.closest_s
            );
        }
        let h = self.most_probable_index();
        let cue = self.grid.cue(h);
        let model = self.grid.model(h);
        let decision = match (cue, model.rule) {
            (Cue::HeadwayOrTtc, palc_user::StartRule::HeadwayOrTtc { ttc_seconds }) => format!(
                "the time headway at {:.2} s or the time to collision at {ttc_seconds:.2} s",
                model.time_headway_s
            ),
            _ => {
                let threshold = self.grid.threshold(h % self.grid.thresholds).1;
                let unit = match cue {
                    Cue::DistanceGap => "m",
                    Cue::Incentive => "m/s²",
                    _ => "s",
                };
                format!("the {} at {threshold:.2} {unit}", cue.name())
            }
        };
        let mass = (self.cue_masses().into_iter())
            .find(|(name, _)| *name == cue.name())
            .map_or(0.0, |(_, mass)| mass);
        format!(
            "decides on {decision} (posterior mass of the cue {mass:.2}), \
             reacts in {:.1} s, accepts lead gaps from {:.1} s and lag gaps from {:.2} s \
             (scenes seen: {})",
            model.reaction_s,
            model.min_lead_gap_s,
            model.min_lag_gap_s,
            self.scenes()
        )
    }

    /// The cue with the largest posterior mass, and that mass.
    pub fn dominant_cue(&self) -> (Cue, f64) {
        let masses = self.cue_masses();
        let (i, mass) =
            (masses.iter().enumerate()).fold((0, f64::NEG_INFINITY), |best, (i, &(_, m))| {
                if m > best.1 { (i, m) } else { best }
            });
        (Cue::ALL[i], mass)
    }

    /// The posterior mass of each cue.
    pub fn cue_masses(&self) -> Vec<(&'static str, f64)> {
        let nt = self.grid.thresholds;
        // One pass in hypothesis order: the total and each cue's mass add their
        // weights in the order of a sum over the weights (the cues' thresholds
        // are consecutive, in the order of the cues).
        let mut total = -0.0;
        let mut masses = vec![-0.0; self.grid.cues.len()];
        for c in 0..Grid::combinations() {
            for ((_, first, thresholds), mass) in self.grid.cues.iter().zip(&mut masses) {
                let start = c * nt + first;
                for &weight in &self.posterior.weights[start..start + thresholds.len()] {
                    total += weight;
                    *mass += weight;
                }
            }
        }
        let mut paired = -0.0;
        for &weight in &self.posterior.weights[self.grid.single()..] {
            total += weight;
            paired += weight;
        }
        let cues = (self.grid.cues.iter().map(|(cue, _, _)| *cue)).chain([Cue::HeadwayOrTtc]);
        (cues.zip(masses.into_iter().chain([paired])))
            .map(|(cue, mass)| (cue.name(), if total > 0.0 { mass / total } else { 0.0 }))
            .collect()
    }

    /// The posterior mass of the start models for which `holds(cue, reaction_s)`.
    pub fn mass_where(&self, holds: impl Fn(Cue, f64) -> bool) -> f64 {
        let nt = self.grid.thresholds;
        let (mut total, mut mass) = (0.0, 0.0);
        for c in 0..Grid::combinations() {
            let (reaction_s, _, _) = combination(c);
            for (cue, first, thresholds) in &self.grid.cues {
                let start = c * nt + first;
                let cue_mass: f64 = self.posterior.weights[start..start + thresholds.len()]
                    .iter()
                    .sum();
                total += cue_mass;
                if holds(*cue, reaction_s) {
                    mass += cue_mass;
                }
            }
        }
        // The two-cue decisions, without reaction.
        let paired: f64 = self.posterior.weights[self.grid.single()..].iter().sum();
        total += paired;
        if holds(Cue::HeadwayOrTtc, 0.0) {
            mass += paired;
        }
        if total > 0.0 { mass / total } else { 0.0 }
    }

    /// The start predicted in a scene (`situations` at step `dt`, the ego's set
    /// speed, the safety layer's verdict per step when it is on, a lane change
    /// of `duration_s`): the start step with the largest posterior mass, the
    /// earliest of equals ([`DriverEstimate::start_masses`]).
    pub fn predict(
        &self,
        situations: &[Situation],
        dt: f64,
        set_speed_mps: f64,
        safe: Option<&[bool]>,
        duration_s: f64,
    ) -> Prediction {
        if self.outside_model() {
            return Prediction::OutsideModel;
        }
        let masses = self.start_masses(situations, dt, set_speed_mps, safe, duration_s);
        match most_likely_step(&masses) {
            step if step == situations.len() => Prediction::NoStart,
            step => Prediction::Start(step as f64 * dt),
        }
    }

    /// The posterior predictive of the start step in a scene (as
    /// [`DriverEstimate::predict`] takes it): the posterior mass of the models
    /// that start at each step, the last entry for those that never start;
    /// summing to 1.
    pub fn start_masses(
        &self,
        situations: &[Situation],
        dt: f64,
        set_speed_mps: f64,
        safe: Option<&[bool]>,
        duration_s: f64,
    ) -> Vec<f64> {
        let view = SceneView::new(situations, dt, set_speed_mps, safe, duration_s);
        let mut masses = vec![0.0; situations.len() + 1];
        self.grid.for_each_start(&view, |hypotheses, start| {
            let at = (start as usize).min(situations.len());
            masses[at] += self.posterior.weights[hypotheses].iter().sum::<f64>();
        });
        let total: f64 = masses.iter().sum();
        if total > 0.0 {
            masses.iter_mut().for_each(|m| *m /= total);
        }
        masses
    }
}

/// The most scenes of `scenes` whose starts may all have been misread without
/// contradicting the misread probability ([`MISREAD_START_PROBABILITY`]): the
/// largest `k` such that `k` or more misread starts among `scenes` have a
/// probability of at least 5 % (one minus the usual 95 % credibility).
pub(crate) fn plausible_misreads(scenes: usize) -> usize {
    let p = MISREAD_START_PROBABILITY;
    // P(X = k) of the binomial, k from 0; the tail P(X >= k) as 1 minus the
    // mass below k.
    let mut below = 0.0;
    let mut pmf = (1.0 - p).powi(scenes as i32);
    let mut plausible = 0;
    for k in 0..=scenes {
        if 1.0 - below >= 1.0 - super::CREDIBLE_MASS {
            plausible = k;
        } else {
            break;
        }
        below += pmf;
        pmf *= (scenes - k) as f64 / (k + 1) as f64 * p / (1.0 - p);
    }
    plausible
}

/// The index of the largest of `masses`, the first of equals.
pub(crate) fn most_likely_step(masses: &[f64]) -> usize {
    let (step, _) = (masses.iter().enumerate()).fold((0, f64::NEG_INFINITY), |best, (i, &m)| {
        if m > best.1 { (i, m) } else { best }
    });
    step
}

/// The posterior weight of a hypothesis of log posterior `lp`, scaled so that
/// the largest (`top`) is 1.
#[inline]
/// `accumulated` with its weights, its closest and its fewest far scenes
/// (`MISFIT_SDS` standard deviations away).
fn summarized(accumulated: Accumulated) -> Posterior {
    let closest_s = (accumulated.worst.iter().copied()).fold(f64::INFINITY, f64::min);
    let fewest_far = (accumulated.far_scenes.iter().copied()).min().unwrap_or(0);
    let top = (accumulated.log_posterior.iter().copied()).fold(f64::NEG_INFINITY, f64::max);
    let weights = (accumulated.log_posterior.iter())
        .map(|&lp| weight(lp, top))
        .collect();
    Posterior {
        accumulated,
        weights,
        closest_s,
        fewest_far,
    }
}

fn weight(lp: f64, top: f64) -> f64 {
    let below_top = lp - top;
    // `exp` is exactly +0 below its underflow (about -745.13): the many
    // hypotheses far from the top skip the call.
    if !top.is_finite() || below_top < EXP_UNDERFLOW {
        0.0
    } else {
        below_top.exp()
    }
}

/// The log prior: each cue [`prior::cue_mass`], uniform over its thresholds
/// (the two-cue decision's: over its pairs); the reaction (none for two cues)
/// and the accepted gaps independent, each exponential on its grid with scale
/// [`prior::DEMAND_SCALE_S`].
fn prior(grid: &Grid) -> Vec<f64> {
    let per_threshold: Vec<f64> = (grid.cues.iter())
        .flat_map(|(cue, _, thresholds)| {
            let log_mass = prior::cue_mass(*cue).ln() - (thresholds.len() as f64).ln();
            std::iter::repeat_n(log_mass, thresholds.len())
        })
        .collect();
    let demand = |values: &[f64]| -> Vec<f64> {
        let log = |x: f64| -x / prior::DEMAND_SCALE_S;
        let norm = values.iter().map(|&x| log(x).exp()).sum::<f64>().ln();
        values.iter().map(|&x| log(x) - norm).collect()
    };
    let (reactions, leads, lags) = (
        demand(&REACTIONS_S),
        demand(&LEAD_GAPS_S),
        demand(&LAG_GAPS_S),
    );
    let mut log_prior = Vec::with_capacity(grid.len());
    for reaction in &reactions {
        for lead in &leads {
            for lag in &lags {
                let combination = reaction + lead + lag;
                log_prior.extend(per_threshold.iter().map(|t| t + combination));
            }
        }
    }
    // The two-cue decisions: uniform over the pairs, no reaction.
    let per_pair = prior::cue_mass(Cue::HeadwayOrTtc).ln() - (grid.pairs.len() as f64).ln();
    for lead in &leads {
        for lag in &lags {
            log_prior.extend(std::iter::repeat_n(per_pair + lead + lag, grid.pairs.len()));
        }
    }
    log_prior
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Scenes of the default config at seed 1, each prepared once.
    fn scenes() -> &'static [crate::setup::Setup] {
        static SETUPS: std::sync::OnceLock<Vec<crate::setup::Setup>> = std::sync::OnceLock::new();
        SETUPS.get_or_init(|| {
            let text = include_str!("../../../../configs/learn.toml");
            let base = crate::config::LearnConfig::from_toml_str(text).unwrap();
            [
                ("collector-high", 40.0),
                ("arterial-slow", 50.0),
                ("collector-slow", 30.0),
                ("arterial-high", 45.0),
            ]
            .into_iter()
            .map(|(speed_case, headway_m)| {
                let config = base.clone().with_cell(crate::config::CellChoice {
                    speed_case: speed_case.into(),
                    headway_m,
                    seed: 1,
                });
                crate::scenario::prepare(&config).unwrap()
            })
            .collect()
        })
    }

    /// The onset of a driver of `model` in `setup`, observed exactly; `None`
    /// when it does not start there.
    fn observed(model: &StartModel, setup: &crate::setup::Setup) -> Option<Onset> {
        let (_, start) = model
            .start_step(&setup.situations, setup.dt, setup.set_speed, |_| true)
            .ok()?;
        Some(Onset {
            scenario: setup.label.clone(),
            time_s: start as f64 * setup.dt,
            time_headway_s: 1.0,
            ttc_s: None,
            gap_m: 1.0,
            lead_time_gap_s: None,
            lag_time_gap_s: None,
            rejected_lead_time_gap_s: None,
            time_headway_ceiling_s: None,
            accepted_lead_time_gap_s: None,
            follower_wait_time_headway_s: None,
            observations: 1,
            scene: Some(super::super::scene_steps(setup)),
        })
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(24))]

        /// A driver whose start model lies in the grid keeps the largest
        /// likelihood after any sequence of its observations, and so a
        /// posterior mass of at least its prior's share: the estimate never
        /// rules the truth out, and never calls such a driver outside the model.
        #[test]
        fn a_driver_of_the_grid_is_never_ruled_out(
            h in 0usize..2_000_000,
            order in proptest::sample::subsequence(vec![0usize, 1, 2, 3], 1..=4),
        ) {
            let grid = Grid::new();
            let h = h % grid.len();
            let model = grid.model(h);
            let onsets: Vec<Onset> = (order.iter())
                .filter_map(|&i| observed(&model, &scenes()[i]))
                .collect();
            if let Some(estimate) = DriverEstimate::from_onsets(&onsets, 2.0) {
                proptest::prop_assert!(!estimate.outside_model());
                let log_likelihood = estimate.posterior.accumulated.log_posterior[h] - prior(&grid)[h];
                proptest::prop_assert!(
                    log_likelihood.abs() < 1e-9,
                    "{:?}: log likelihood {}", model, log_likelihood
                );
            }
        }
    }

    #[test]
    fn an_estimate_extended_from_a_kept_one_is_the_one_computed_afresh() {
        let grid = Grid::new();
        let model = grid.model(12_345);
        let onsets: Vec<Onset> = (scenes().iter())
            .filter_map(|setup| observed(&model, setup))
            .collect();
        assert!(onsets.len() >= 3, "the test needs three scenes");
        let afresh = |onsets: &[Onset]| {
            let mut accumulated = Accumulated {
                log_posterior: prior(&grid),
                worst: vec![0.0; grid.len()],
                far_scenes: vec![0; grid.len()],
                scenes: 0,
            };
            for onset in onsets {
                accumulated.read(&grid, onset, 2.0);
            }
            accumulated
        };
        // The first two scenes are kept, the third extends them.
        let kept = DriverEstimate::from_onsets(&onsets[..2], 2.0).unwrap();
        let extended = DriverEstimate::from_onsets(&onsets, 2.0).unwrap();
        for (estimate, onsets) in [(kept, &onsets[..2]), (extended, &onsets[..])] {
            let fresh = afresh(onsets);
            assert_eq!(estimate.scenes(), fresh.scenes);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert!(
                bits(&estimate.posterior.accumulated.log_posterior) == bits(&fresh.log_posterior)
            );
            let closest = fresh.worst.iter().copied().fold(f64::INFINITY, f64::min);
            assert_eq!(estimate.posterior.closest_s.to_bits(), closest.to_bits());
        }
    }

    #[test]
    fn a_driver_no_start_model_explains_is_outside_the_model() {
        // A headway driver seen in the scenes of `more_scenes` is explained.
        // One start said to be at a scene's first step, where no model starts, is
        // one misread start: plausible. Starts at the first step in more of them
        // than one in twenty misread makes plausible contradict every model.
        let setups = more_scenes();
        let model = StartModel {
            rule: palc_user::StartRule::TimeHeadway,
            time_headway_s: 1.2,
            reaction_s: 0.0,
            min_lead_gap_s: 0.0,
            min_lag_gap_s: 0.0,
        };
        let mut onsets: Vec<Onset> = (setups.iter())
            .filter_map(|setup| observed(&model, setup))
            .collect();
        let n = onsets.len();
        assert!(n >= 5, "the test needs five scenes, got {n}");
        let plausible = plausible_misreads(n);
        assert!(plausible < n);
        let consistent = DriverEstimate::from_onsets(&onsets, 2.0).unwrap();
        assert!(!consistent.outside_model(), "{}", consistent.describe());
        for misread in 0..=plausible {
            let estimate = DriverEstimate::from_onsets(&onsets, 2.0).unwrap();
            assert!(
                !estimate.outside_model(),
                "{misread} misread: {}",
                estimate.describe()
            );
            onsets[misread].time_s = 0.0;
        }
        let contradicted = DriverEstimate::from_onsets(&onsets, 2.0).unwrap();
        assert!(contradicted.outside_model(), "{}", contradicted.describe());
        let (seen, dt, speed) = (&setups[0].situations, setups[0].dt, setups[0].set_speed);
        assert_eq!(
            contradicted.predict(seen, dt, speed, None, 2.0),
            Prediction::OutsideModel
        );
    }

    #[test]
    fn the_plausible_misreads_are_the_binomials_5_percent_tail() {
        // One in twenty misread: k or more of n have a probability of at least 5 %.
        let expected = [(1, 1), (2, 1), (5, 1), (10, 2), (20, 3), (50, 5), (100, 9)];
        for (scenes, plausible) in expected {
            assert_eq!(plausible_misreads(scenes), plausible, "{scenes} scenes");
        }
        assert_eq!(plausible_misreads(0), 0);
    }

    /// The scenes of the default config among every speed case, two headways and
    /// two seeds that the loop prepares (some refuse: the standard ALC never starts).
    fn more_scenes() -> Vec<crate::setup::Setup> {
        let text = include_str!("../../../../configs/learn.toml");
        let base = crate::config::LearnConfig::from_toml_str(text).unwrap();
        let cases = [
            "collector-high",
            "collector-slow",
            "arterial-high",
            "arterial-slow",
        ];
        (cases.iter())
            .flat_map(|case| [30.0, 50.0].map(|h| (case, h)))
            .flat_map(|(case, headway_m)| [1, 2].map(|seed| (case, headway_m, seed)))
            .filter_map(|(case, headway_m, seed)| {
                let cell = crate::config::CellChoice {
                    speed_case: (*case).into(),
                    headway_m,
                    seed,
                };
                crate::scenario::prepare(&base.clone().with_cell(cell)).ok()
            })
            .collect()
    }

    #[test]
    fn the_estimate_predicts_a_driver_the_readings_cannot_read_once_the_scenes_single_it_out() {
        use super::super::start_beyond_readings;
        let setups = more_scenes();
        let driver = |cue: Cue, threshold: f64| {
            let (rule, time_headway_s) = cue.rule(threshold);
            StartModel {
                rule,
                time_headway_s,
                reaction_s: 0.0,
                min_lead_gap_s: 0.0,
                min_lag_gap_s: 0.0,
            }
        };
        let incentive = driver(Cue::Incentive, 0.3);
        let onsets: Vec<(usize, Onset)> = (0..setups.len())
            .filter_map(|i| observed(&incentive, &setups[i]).map(|o| (i, o)))
            .collect();
        let (last, seen) = onsets
            .split_last()
            .expect("the incentive driver starts somewhere");
        let (target, expected) = (last.0, last.1.time_s);
        let seen: Vec<Onset> = seen.iter().map(|(_, o)| o.clone()).collect();
        // One scene is explained by a threshold of every cue: the readings predict.
        assert_eq!(
            start_beyond_readings(&setups[target], &seen[..1], 2.0).start_s,
            None
        );
        let estimate = DriverEstimate::from_onsets(&seen, 2.0).unwrap();
        assert_eq!(
            estimate.dominant_cue().0,
            Cue::Incentive,
            "{}",
            estimate.describe()
        );
        assert!(
            estimate.dominant_cue().1 >= super::super::CREDIBLE_MASS,
            "{}",
            estimate.describe()
        );
        let carried = start_beyond_readings(&setups[target], &seen, 2.0);
        let predicted = carried
            .start_s
            .expect("the scenes single the incentive out");
        assert!(carried.on_another_cue);
        let dt = setups[target].dt;
        assert!(
            (predicted - expected).abs() < dt / 2.0,
            "{predicted} against {expected}"
        );
        // The estimate's most probable start is the one it predicts; from one
        // scene it has none.
        assert_eq!(carried.most_likely_s, Some(predicted));
        assert_eq!(
            start_beyond_readings(&setups[target], &seen[..1], 2.0).most_likely_s,
            None
        );
        // A headway driver seen in the other scenes: the estimate is sure of its
        // start in the last one within a step, and predicts it; its starts also
        // reveal one threshold of the time headway, from which the readings
        // place the start to the step (the carry's choice between the two).
        let headway = driver(Cue::TimeHeadway, 1.2);
        let seen: Vec<Onset> = (setups.iter())
            .filter_map(|s| observed(&headway, s))
            .collect();
        assert!(seen.len() >= 3);
        let (last, before) = seen.split_last().unwrap();
        let target = (setups.iter())
            .position(|s| s.label == last.scenario)
            .unwrap();
        let dt = setups[target].dt;
        let carried = start_beyond_readings(&setups[target], before, 2.0);
        let predicted = carried.start_s.expect("sure of the start within a step");
        assert!(!carried.on_another_cue);
        assert!(
            (predicted - last.time_s).abs() < dt / 2.0,
            "{predicted} against {}",
            last.time_s
        );
        let set = crate::onset::GapAcceptanceSet::from_onsets(before).unwrap();
        assert!(set.revealed_exactly());
        let predicted =
            (set.predicted_start_s(&setups[target], 2.0)).expect("the set predicts a start");
        assert!(
            (predicted - last.time_s).abs() < dt / 2.0,
            "{predicted} against {}",
            last.time_s
        );
        let carried = start_beyond_readings(&setups[0], &seen, 2.0);
        // What the estimate believed is kept: a headway driver inside the model.
        let belief = carried.belief.expect("two recorded scenes or more");
        assert_eq!(belief.scenes, seen.len());
        assert!(!belief.outside_model);
    }

    #[test]
    fn a_driver_on_two_cues_is_inside_the_model_and_singled_out() {
        // The two-cue driver of the grid nearest a headway of 1.5 s or a time to
        // collision of 8 s, whichever comes first, accepting any gap.
        let grid = Grid::new();
        let (h, _) = (grid.single()..grid.single() + grid.pairs.len())
            .map(|h| {
                let model = grid.model(h);
                let palc_user::StartRule::HeadwayOrTtc { ttc_seconds } = model.rule else {
                    unreachable!("the pairs' block holds two-cue models");
                };
                (
                    h,
                    (model.time_headway_s - 1.5).abs() + (ttc_seconds - 8.0).abs() / 8.0,
                )
            })
            .fold(
                (0, f64::INFINITY),
                |best, (h, d)| if d < best.1 { (h, d) } else { best },
            );
        let driver = grid.model(h);
        assert_eq!((driver.min_lead_gap_s, driver.min_lag_gap_s), (0.0, 0.0));
        let setups = more_scenes();
        let onsets: Vec<Onset> = (setups.iter())
            .filter_map(|setup| observed(&driver, setup))
            .collect();
        // Each cue alone misses some of these starts: the scenes need both.
        for cue in [Cue::TimeHeadway, Cue::TimeToCollision] {
            let threshold = match (cue, driver.rule) {
                (Cue::TimeToCollision, palc_user::StartRule::HeadwayOrTtc { ttc_seconds }) => {
                    ttc_seconds
                }
                _ => driver.time_headway_s,
            };
            let (rule, time_headway_s) = cue.rule(threshold);
            let alone = StartModel {
                rule,
                time_headway_s,
                ..driver
            };
            let differs = (setups.iter()).any(|setup| {
                observed(&alone, setup).map(|o| o.time_s)
                    != observed(&driver, setup).map(|o| o.time_s)
            });
            assert!(differs, "{cue:?} alone starts as the driver in every scene");
        }
        let estimate = DriverEstimate::from_onsets(&onsets, 2.0).unwrap();
        assert!(!estimate.outside_model(), "{}", estimate.describe());
        let (cue, mass) = estimate.dominant_cue();
        assert_eq!(cue, Cue::HeadwayOrTtc, "{}", estimate.describe());
        assert!(
            mass >= super::super::CREDIBLE_MASS,
            "{}",
            estimate.describe()
        );
        let said = estimate.describe();
        assert!(
            said.starts_with("decides on the time headway at")
                && said.contains("or the time to collision at"),
            "{said}"
        );
        let log_likelihood = estimate.posterior.accumulated.log_posterior[h] - prior(&grid)[h];
        assert!(log_likelihood.abs() < 1e-9, "{log_likelihood}");
    }

    #[test]
    fn a_driver_who_starts_a_reaction_after_deciding_is_the_estimates_to_predict() {
        use super::super::start_beyond_readings;
        let setups = more_scenes();
        let reacting = StartModel {
            rule: palc_user::StartRule::TimeHeadway,
            time_headway_s: 1.2,
            reaction_s: 0.8,
            min_lead_gap_s: 0.0,
            min_lag_gap_s: 0.0,
        };
        let onsets: Vec<(usize, Onset)> = (0..setups.len())
            .filter_map(|i| observed(&reacting, &setups[i]).map(|o| (i, o)))
            .collect();
        let (last, seen) = onsets.split_last().expect("the driver starts somewhere");
        let seen: Vec<Onset> = seen.iter().map(|(_, o)| o.clone()).collect();
        assert!(seen.len() >= 3, "the test needs three scenes");
        let estimate = DriverEstimate::from_onsets(&seen, 2.0).unwrap();
        let reacts = estimate.mass_where(|_, reaction_s| reaction_s > 0.0);
        assert!(
            reacts >= super::super::CREDIBLE_MASS,
            "{reacts}: {}",
            estimate.describe()
        );
        let predicted = start_beyond_readings(&setups[last.0], &seen, 2.0).start_s;
        let predicted = predicted.expect("the scenes single the reaction out");
        assert!(
            (predicted - last.1.time_s).abs() < setups[last.0].dt / 2.0,
            "{predicted} against {}",
            last.1.time_s
        );
    }

    #[test]
    fn the_mass_of_a_set_of_models_and_of_the_rest_make_the_whole() {
        let setups = scenes();
        let model = Grid::new().model(12_345);
        let seen: Vec<Onset> = (setups.iter())
            .filter_map(|s| observed(&model, s))
            .collect();
        let estimate = DriverEstimate::from_onsets(&seen, 2.0).unwrap();
        for (name, mass) in estimate.cue_masses() {
            let by_cue = estimate.mass_where(|cue, _| cue.name() == name);
            assert!(
                (by_cue - mass).abs() < 1e-9,
                "{name}: {by_cue} against {mass}"
            );
        }
        let slow = estimate.mass_where(|_, reaction_s| reaction_s >= 0.5);
        let quick = estimate.mass_where(|_, reaction_s| reaction_s < 0.5);
        assert!((slow + quick - 1.0).abs() < 1e-9, "{slow} + {quick}");
        // The posterior predictive of the start in a scene sums to 1, and the
        // prediction is its largest step.
        let (scene, dt, speed) = (&setups[0].situations, setups[0].dt, setups[0].set_speed);
        let masses = estimate.start_masses(scene, dt, speed, None, 2.0);
        assert!((masses.iter().sum::<f64>() - 1.0).abs() < 1e-9);
        let step = most_likely_step(&masses);
        assert!(masses.iter().all(|&m| m <= masses[step]));
        assert_eq!(
            estimate.predict(scene, dt, speed, None, 2.0),
            if step == scene.len() {
                Prediction::NoStart
            } else {
                Prediction::Start(step as f64 * dt)
            }
        );
    }
}
