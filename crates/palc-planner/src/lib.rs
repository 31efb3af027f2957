//! The lane-change trajectory planner: a linear time-varying model predictive
//! controller solved as a sparse convex quadratic program (paper Eqs. 9-23 and 34).
//!
//! The state is `X = [s, v, l, φ]` and the control `U = [a, δ]`; the dynamics are the
//! kinematic bicycle linearized around a reference speed profile and discretized by
//! forward Euler (Eqs. 11-14, in the physically consistent order of the reading notes):
//! `s' = v`, `v' = a`, `l' = v_ref φ`, `φ' = (v_ref / l_fr) δ - v_ref R`.
//! The cost is `w · Φ(ψ)` of Eqs. (15) and (34), with the squared distances to the
//! predicted preceding and adjacent vehicles, plus documented [`Extras`]: an
//! acceleration penalty, an optional tracking term (the form of Eq. 25) and the
//! slack penalty of soft lateral bounds.
//!
//! Two backends solve the same assembled QP ([`Backend`]): the default, a Mehrotra
//! predictor-corrector interior point whose Newton systems are solved by a
//! time-varying Riccati recursion over the stages (the structure the paper exploits
//! with Pontryagin's principle), and the general sparse solver `clarabel`, kept as the
//! reference. Property tests hold them to the same optimum.
//!
//! Main types: [`PlannerConfig`] (fixed between plans), [`Problem`] (one plan's input),
//! [`Planner`] (caches the QP structure), [`Plan`] (trajectory, objective, features,
//! statistics), [`Weights`] and [`Features`] (10 x K), [`features`] (the one feature map)
//! and [`check_convexity`]. Every refusal is a [`PlanError`].
//!
//! This crate depends on no other palc crate: plain numbers in, results out.
//! Pass `s` relative to the ego's position at the start of the plan (`initial.s = 0`)
//! so that the `s δ` feature (w7) does not depend on where on the road the plan begins.
//!
//! Build the problem with [`Problem::builder`] (each input checked as it is given) or as
//! a struct literal; name the weights of a stage with [`StageWeights`].
//!
//! # Features
//!
//! - `clarabel` (default): the reference backend [`Backend::Clarabel`]. Without it the
//!   crate has no solver dependency, and [`PlannerConfig::validate`] refuses
//!   `Backend::Clarabel` with [`ConfigError::BackendUnavailable`].
//! - `serde` (default): `Serialize` and `Deserialize` for the configuration, problem and
//!   plan types.
//!
//! # Example
//!
//! A lane change with hard and with soft lateral bounds, printed as CSV; this is
//! `examples/plan_lane_change.rs` (`cargo run -p palc-planner --example
//! plan_lane_change`), run here as a doctest.
//!
//! ```
#![doc = include_str!("../examples/plan_lane_change.rs")]
//! ```
#![deny(missing_docs)]
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

mod backend;
mod builder;
#[cfg(feature = "clarabel")]
mod clarabel_backend;
mod config;
mod convexity;
mod dynamics;
mod error;
mod features;
mod planner;
mod problem;
mod qp;
mod riccati;
#[cfg(feature = "clarabel")]
mod sparse_qp;
mod validate;
mod weights;

pub use builder::ProblemBuilder;
pub use config::{
    Backend, LateralBoundsMode, MAX_HORIZON, MAX_ITER_RANGE, PlannerConfig, SolverSettings,
    TOLERANCE_RANGE,
};
pub use convexity::check_convexity;
pub use error::{ConfigError, NumericalCause, PlanError, SolverFailure, StepRanges};
pub use features::{features, stage_features};
pub use planner::{Extras, Plan, Planner, SolveStats, SolveStatus};
pub use problem::{
    Control, LateralBound, MAX_POSITION, Position, Problem, State, Terminal, Tracking,
};
pub use weights::{FEATURE_COUNT, Features, StageWeights, Weights, feature};
