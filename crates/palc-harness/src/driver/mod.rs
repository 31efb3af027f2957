//! What palc believes about a driver's start: one model of the decision
//! (palc-user's [`StartModel`](palc_user::StartModel), which the simulated users
//! run forward) and a posterior over its parameters from every scene the driver
//! was seen in (docs/experiments/0068-one-driver-model.md).
//!
//! Each scene in which the user started is kept as what the user saw at every
//! step ([`palc_aggregator::SceneSteps`], recorded with the scene's onset). The
//! estimate ([`DriverEstimate`]) is a posterior over a grid of start models
//! ([`prior`]): the cue the decision is taken on (time headway, time to
//! collision, distance gap, or MOBIL's incentive) with its threshold, or two
//! cues at once (the first of the time headway and the time to collision to
//! fall to its threshold, [`prior::Cue::HeadwayOrTtc`]), the reaction, and the
//! lead and lag gaps accepted. A model's likelihood in a scene
//! compares the start it predicts there, run forward over every step, with the
//! start observed (Gaussian, [`prior::OBSERVATION_SD_S`], or misread anywhere
//! in the scene with [`prior::MISREAD_START_PROBABILITY`]): a model that would have
//! started earlier, or later, is penalized alike, so the steps at which the
//! driver did not start count as much as its start. Scenes combine by
//! multiplying likelihoods. A scene whose observed start is more than
//! [`prior::MISFIT_SDS`] standard deviations from a model's is one that model
//! needs misread; when every model needs more misread starts than one in twenty
//! makes plausible (at 5 %, binomially: 1 of up to 5 scenes, 2 of 10, 5 of 50),
//! the driver is outside the model.
//!
//! Every [`crate::LessonEvent`] hands its observers the evidence with that
//! lesson's start included ([`crate::DriverEvidence`]); the estimate is computed
//! when an observer asks (`palc learn` prints it after every lesson). A run
//! keeps what the estimate believed when its experience was carried in
//! ([`CarriedBelief`], in `RunResult::carried_belief`); the evaluation counts the
//! misfits per user kind. The start carried into a new scene is predicted by
//! the onsets' readings (`crate::onset`'s `GapAcceptanceSet`, a set-membership
//! estimate of a gap-acceptance driver without a reaction), which read the time
//! headway, the time to collision and the distance gap at the start itself; as
//! the predictor for
//! those cues the estimate's most probable model cost more takeovers on the
//! evaluation's grid (docs/experiments/0068-one-driver-model.md). The estimate
//! predicts instead (`start_beyond_readings`): the start step with the largest
//! posterior mass, when 95 % of the posterior lies on models the readings
//! cannot represent (MOBIL's incentive, a reaction after the decision;
//! docs/experiments/0073-a-drive-of-varied-scenes.md, 0079) or 95 % of the
//! predictive within a step of that start (0080); the carry leaves either to
//! the readings where two or more starts no gap held back reveal one threshold
//! of a cue they read: their interval places the start to the step, which the
//! estimate's 0.2 s observation error does not (0089), and a reaction on that
//! cue is then the prior's belief, not the scenes' (0099). Only 95 % on a cue
//! they do not read keeps the estimate's start there. Where no
//! feature the readings read is consistent across the free starts (their own
//! model contradicted), the estimate's most probable start step predicts
//! however unsure it is (0095). Where it puts 95 % on a reaction after a decision
//! on a cue the readings read, the readings' shortest reaction that makes the
//! free starts one threshold places the start, if they find one (0102).

mod estimate;
mod grid;
mod memo;
pub mod prior;
mod scene;

pub use estimate::{DriverEstimate, Prediction};
pub(crate) use scene::{scene_steps, situation};

use palc_aggregator::Onset;
use serde::{Deserialize, Serialize};

use crate::setup::Setup;
use prior::Cue;

/// The cues the onsets' readings read (`crate::onset::GapAcceptanceSet`). The
/// readings read the decision at the start itself: a driver who starts a
/// reaction after deciding is a model they cannot represent either.
pub(crate) const READ_BY_THE_READINGS: [Cue; 3] =
    [Cue::TimeHeadway, Cue::TimeToCollision, Cue::DistanceGap];

/// The usual 95 % credibility, asked of the estimate before it predicts a
/// carried start in place of the readings: either of the posterior on models
/// the readings cannot represent (a cue they do not read, or a reaction), or of
/// the posterior predictive on the predicted start step and its two neighbours
/// (the estimate is sure of the start within a step, whatever the model). One
/// scene never gives it when another cue explains the same start with a longer
/// reaction (a reaction user's start, read as an incentive decision, cost it
/// takeovers at a majority of 50 %).
const CREDIBLE_MASS: f64 = 0.95;

/// The scenes the estimate must have seen before it predicts: one scene is
/// explained by a threshold of every cue, so it cannot single one out.
const MIN_SCENES: usize = 2;

/// What the estimate believed when an experience was carried into a new scene:
/// its dominant cue, that cue's posterior mass, the scenes it had seen and
/// whether it called the driver outside the model. The evaluation counts the
/// misfits per user kind (REPORT.md, "Drivers outside the model").
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CarriedBelief {
    /// Recorded scenes the estimate was computed from.
    pub scenes: usize,
    /// The cue with the largest posterior mass.
    pub cue: Cue,
    /// That cue's posterior mass.
    pub cue_mass: f64,
    /// No start model explained every scene ([`DriverEstimate::outside_model`]).
    pub outside_model: bool,
}

/// What the estimate says when an experience from `onsets` is carried into
/// `setup`, for a lane change of `duration_s`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct CarriedEstimate {
    /// The start (s after the start of the plan) the estimate predicts, when it
    /// places [`CREDIBLE_MASS`] of the posterior on models the readings cannot
    /// represent (a cue they do not read, or a reaction after the decision) or
    /// of the posterior predictive within a step of the start it predicts, from
    /// at least [`MIN_SCENES`] scenes. `None` otherwise (the readings predict),
    /// and for a driver outside the model or a scene the estimate says it does
    /// not start in.
    pub start_s: Option<f64>,
    /// `start_s` rests on [`CREDIBLE_MASS`] of the posterior on cues the
    /// readings do not read. Otherwise the carry leaves the start to the
    /// readings where the scenes reveal their threshold exactly
    /// (`crate::carry`, docs/experiments/0089-the-thresholds-every-scene-allows.md):
    /// a model of their cue without a reaction then places every start seen to
    /// the step, and the estimate's belief in a reaction on that cue is its
    /// prior's, which the scenes do not decide at its 0.2 s resolution
    /// (docs/experiments/0099-a-reaction-the-scenes-do-not-show.md).
    pub on_another_cue: bool,
    /// [`CREDIBLE_MASS`] of the posterior is on a reaction after a decision on
    /// a cue the readings read. The carry then asks the readings for the
    /// shortest reaction that makes the starts one threshold
    /// (docs/experiments/0102-a-reaction-the-starts-reveal.md).
    pub on_a_reaction: bool,
    /// The start (s) of the step with the largest posterior predictive mass,
    /// however small that mass; the carry uses it where the readings' own
    /// model is contradicted (`crate::onset::readings_explain`). `None` below
    /// [`MIN_SCENES`] recorded scenes, for a driver outside the model, and
    /// when the estimate says the driver does not start in this scene.
    pub most_likely_s: Option<f64>,
    /// What the estimate believed; `None` below [`MIN_SCENES`] recorded scenes,
    /// where it is not computed.
    pub belief: Option<CarriedBelief>,
}

/// The estimate's say when an experience from `onsets` is carried into `setup`
/// ([`CarriedEstimate`]).
pub(crate) fn start_beyond_readings(
    setup: &Setup,
    onsets: &[Onset],
    duration_s: f64,
) -> CarriedEstimate {
    // Only onsets that recorded their scene inform the estimate.
    if onsets.iter().filter(|o| o.scene.is_some()).count() < MIN_SCENES {
        return CarriedEstimate::default();
    }
    let Some(estimate) = DriverEstimate::from_onsets(onsets, duration_s) else {
        return CarriedEstimate::default();
    };
    let (cue, mass) = estimate.dominant_cue();
    let belief = Some(CarriedBelief {
        scenes: estimate.scenes(),
        cue,
        cue_mass: mass,
        outside_model: estimate.outside_model(),
    });
    if estimate.outside_model() {
        return CarriedEstimate {
            start_s: None,
            on_another_cue: false,
            on_a_reaction: false,
            most_likely_s: None,
            belief,
        };
    }
    let beyond_the_readings = estimate
        .mass_where(|cue, reaction_s| !READ_BY_THE_READINGS.contains(&cue) || reaction_s > 0.0);
    let steps = scene_steps(setup);
    let safe: Option<Vec<bool>> = steps.steps.iter().map(|s| s.safe).collect();
    let masses = estimate.start_masses(
        &setup.situations,
        setup.dt,
        setup.set_speed,
        safe.as_deref(),
        duration_s,
    );
    // The posterior predictive mass within a step of the predicted start (a
    // step off moves a 2 s lane change by up to 0.4 m, past the takeover's
    // 0.3 m, and a longer one by less).
    let step = estimate::most_likely_step(&masses);
    let within_a_step: f64 = masses[step.saturating_sub(1)..(step + 2).min(masses.len() - 1)]
        .iter()
        .sum();
    let beyond = beyond_the_readings >= CREDIBLE_MASS;
    let predicts = beyond || within_a_step >= CREDIBLE_MASS;
    let most_likely_s = (step < setup.situations.len()).then_some(step as f64 * setup.dt);
    let start_s = most_likely_s.filter(|_| predicts);
    let another_cue = estimate.mass_where(|cue, _| !READ_BY_THE_READINGS.contains(&cue));
    let reaction = estimate
        .mass_where(|cue, reaction_s| READ_BY_THE_READINGS.contains(&cue) && reaction_s > 0.0);
    CarriedEstimate {
        start_s,
        on_another_cue: start_s.is_some() && another_cue >= CREDIBLE_MASS,
        on_a_reaction: reaction >= CREDIBLE_MASS,
        most_likely_s,
        belief,
    }
}
