//! What palc believes about a driver's start: one model of the decision
//! (palc-user's [`StartModel`](palc_user::StartModel), which the simulated users
//! run forward) and a posterior over its parameters from every scene the driver
//! was seen in (docs/experiments/0068-one-driver-model.md).
//!
//! Each scene in which the user started is kept as what the user saw at every
//! step ([`palc_aggregator::SceneSteps`], recorded with the scene's onset). The
//! estimate ([`DriverEstimate`]) is a posterior over a grid of start models
//! ([`prior`]): the cue the decision is taken on (time headway, time to
//! collision, distance gap, or MOBIL's incentive) with its threshold, the
//! reaction, and the lead and lag gaps accepted. A model's likelihood in a scene
//! compares the start it predicts there, run forward over every step, with the
//! start observed (Gaussian, [`prior::OBSERVATION_SD_S`]): a model that would have
//! started earlier, or later, is penalized alike, so the steps at which the
//! driver did not start count as much as its start. Scenes combine by
//! multiplying likelihoods. When no model explains every scene to within
//! [`prior::MISFIT_SDS`] standard deviations, the driver is outside the model.
//!
//! `palc learn` prints the estimate after a run. The start carried into a new
//! scene is still predicted by the onsets' readings (`crate::onset`): as the
//! predictor, the estimate's most probable model (and, separately, a refusal to
//! carry a start for a driver outside the model) cost more takeovers on the
//! evaluation's grid (docs/experiments/0068-one-driver-model.md).

mod estimate;
pub mod prior;
mod scene;

pub use estimate::{DriverEstimate, Prediction};
pub(crate) use scene::scene_steps;
