//! The driving experience aggregator: expert trajectories and reward correction of
//! the planner's weights (paper Eqs. 24-26 and 33-36), and the experience store that
//! carries what was learned into new scenarios.
//!
//! One lesson (a takeover) goes through [`learn_from_lesson`]:
//!
//! 1. the zone model (from `palc-zone-filter`) is updated with the lesson's samples
//!    and projected onto lateral bounds, when [`AggregatorOptions::use_zone`] is set;
//! 2. an [`ExpertGenerator`] builds the expert problem, planned by the same
//!    [`palc_planner::Planner`] with its tracking term: [`ZoneCentreExpert`] (the paper,
//!    Eqs. 24-26) or [`LessonExpert`] (the lesson's demonstration, re-planned);
//! 3. a [`RewardCorrection`] rule returns one new weight matrix:
//!    [`ApprenticeshipRule`] (Abbeel & Ng's projection method, Eqs. 33-36),
//!    [`IncrementalRule`] (projected feature-matching steps from the current
//!    weights with backtracking) or [`TargetRule`] (iterative learning of each
//!    stage's lateral target, the default), changing only the [`LearnableRows`];
//! 4. the next lane change is planned with the new weights.
//!
//! Sign convention: the planner *minimizes* the cost `J = w · Φ(ψ)` (Eq. 15); every
//! weight in this crate is a cost weight. Features are compared in scaled units
//! `Φ_j / σ_j` ([`FeatureScale`]). Every returned weight matrix lies in the
//! [`ConvexSet`] ([`project_convex`]), so the planner's QP stays convex. What was
//! learned is an [`Experience`], saved and loaded without ever losing data, with a
//! format version; its weights carry over to another horizon and step by
//! [`resample_weights`].
//!
//! ```
//! use palc_aggregator::{AggregatorOptions, Experience, Lesson, learn_from_lesson};
//! use palc_planner::{LateralBound, Planner, PlannerConfig, Position, Problem, State, Terminal, Weights};
//!
//! let config = PlannerConfig { horizon: 20, dt: 0.2, ..PlannerConfig::default() };
//! let (k, v) = (config.horizon, 20.0);
//! let standard = Weights::constant(k, [0.1, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 10.0, 0.0, 0.0]);
//! let template = Problem {
//!     initial: State { s: 0.0, v, l: 0.0, phi: 0.0 },
//!     reference_speed: vec![v; k],
//!     curvature: 0.0,
//!     weights: standard.clone(),
//!     preceding: (0..k).map(|i| Position { s: 40.0 + 18.0 * 0.2 * i as f64, l: 0.0 }).collect(),
//!     adjacent: (0..k).map(|i| Position { s: -30.0 + 20.0 * 0.2 * i as f64, l: 3.5 }).collect(),
//!     terminal: Terminal { s: None, v, l: 3.5 },
//!     lateral_bounds: vec![Some(LateralBound::new(-1.75, 5.25)); k + 1],
//!     tracking: None,
//! };
//! let mut planner = Planner::new(config)?;
//! let planned = planner.plan(&template)?;
//! // The user took over at step 5 and moved over earlier: here, a plan that pulls harder.
//! let mut user = template.clone();
//! user.weights = Weights::constant(k, [0.1, -0.6, 1.0, 0.0, 0.0, 0.0, 0.0, 10.0, 0.0, 0.0]);
//! let user_states = planner.plan(&user)?.states;
//! let takeover_step = 5;
//! let executed = (0..=k)
//!     .map(|i| if i < takeover_step { planned.states[i] } else { user_states[i] })
//!     .collect();
//! let lesson = Lesson {
//!     planned,
//!     executed,
//!     demonstration: None,
//!     takeover_step,
//!     samples: vec![],
//!     step_scenes: vec![],
//! };
//!
//! let experience = Experience::new("user-1", "45-40mph", "palc", standard, 0.2)?;
//! let options = AggregatorOptions::default(); // lesson expert, target rule on w1, w2
//! let outcome = learn_from_lesson(&mut planner, &experience, &lesson, &template, &options)?;
//! assert_eq!(outcome.experience.metadata.lessons, 1);
//! let (before, after) = (outcome.correction.error_before.unwrap(), outcome.correction.error_after.unwrap());
//! assert!(after <= before);
//! # Ok::<(), palc_aggregator::AggregatorError>(())
//! ```
#![deny(missing_docs)]
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

mod convex;
mod correction;
mod error;
mod experience;
mod expert;
pub mod input;
mod lesson;
mod onset;
mod options;
pub mod output;
mod own_lane_change;
mod resample;
mod rows;
mod scale;
mod step;

pub use convex::{ConvexSet, project_convex};

/// Tuning constants of the convex projection, for tests and for those who study it.
pub mod advanced {
    pub use crate::convex::{DIAGONAL_ZERO_RATIO, SCHUR_MARGIN};
}
pub use correction::{
    ApprenticeshipRule, ApprenticeshipState, CorrectionInput, CorrectionOutcome, CorrectionRule,
    IncrementalRule, RewardCorrection, TargetRule,
};
pub use error::AggregatorError;
pub use experience::{
    EXPERIENCE_DT_BOUNDS_S, EXPERIENCE_FORMAT_VERSION, Experience, ExperienceMetadata,
    MAX_DEMONSTRATION_OFFSET_M,
};
pub use expert::{ExpertGenerator, ExpertInput, ExpertKind, LessonExpert, ZoneCentreExpert};
pub use lesson::Lesson;
pub use onset::{Onset, SceneSteps, SeenStep};
pub use options::{AggregatorOptions, Representation};
pub use own_lane_change::{
    MAX_OWN_LANE_CHANGE_SAMPLES, MIN_OWN_LANE_CHANGE_SAMPLES, OwnLaneChange,
};
pub use resample::{resample_weights, resample_weights_shifted};
pub use rows::LearnableRows;
pub use scale::{FeatureScale, feature_error};
pub use step::{CorrectionReport, StepOutcome, Timings, learn_from_lesson, plan_problem};
