//! The driving zone filter: a Gaussian discriminant analysis (GDA) model of the
//! user's perceived safe zone and the lateral bounds it implies (paper Eqs. 1-8
//! and 27-32).
//!
//! Each takeover is a lesson: positions driven by the system are labelled
//! [`Label::Safe`] (y = 1) and positions driven by the user [`Label::Unsafe`]
//! (y = 0), or however the caller decides. The crate turns them into:
//!
//! - features (Eq. 1), made in one place: [`features`] / [`features_into`],
//!   with a configurable [`FeatureSet`] (the paper's six by default);
//! - a [`ZoneModel`] that keeps per-class sufficient statistics, so
//!   [`ZoneModel::update`] is online and equals a batch fit, and classifies with
//!   a shared covariance ([`Discriminant::Linear`], the paper's GDA) or one
//!   covariance per class ([`Discriminant::Quadratic`]); posteriors are
//!   computed in log space ([`ZoneModel::posterior_safe`]);
//! - per planning step, the boundary of the zone on the ego's station
//!   ([`step_boundary`]) and the bounds `l_min,i`, `l_max,i`
//!   ([`lateral_bounds`]) by the paper's projection (Eqs. 27-32) or a corrected
//!   one that only returns an interval classified safe ([`Projection`]).
//!
//! The model serializes (serde) with a format version, its configuration and
//! its statistics, so that learned experience can be stored and reused.
//!
//! This crate depends on no other palc crate: plain numbers in, results out.
//!
//! # Example
//!
//! From labelled samples in CSV to the lateral bounds of each planning step; this is
//! `examples/fit_zone.rs` (`cargo run -p palc-zone-filter --example fit_zone`), run
//! here as a doctest.
//!
//! ```
#![doc = include_str!("../examples/fit_zone.rs")]
//! ```
#![deny(missing_docs)]
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

mod bounds;
mod certain_sign;
mod config;
mod error;
mod features;
mod gaussian;
mod model;
mod sample;
mod statistics;

pub use bounds::{
    BoundsConfig, Crossing, Projection, StepBoundary, StepBounds, StepScene, lateral_bounds,
    project, step_boundary,
};
pub use config::{Discriminant, ZoneConfig};
pub use error::ZoneError;
pub use features::{FeatureInput, FeatureSet, MAX_FEATURES, features, features_into};
pub use model::{MODEL_FORMAT_VERSION, ZoneModel};
pub use sample::{Label, Sample};
pub use statistics::ClassStatistics;
