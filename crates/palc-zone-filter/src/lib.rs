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
//! ```
//! use palc_zone_filter::{
//!     BoundsConfig, FeatureInput, FeatureSet, Label, Sample, StepBounds, StepScene,
//!     ZoneConfig, ZoneModel, features, lateral_bounds,
//! };
//!
//! // Preceding vehicle 30 m ahead in the ego lane, adjacent vehicle 10 m ahead in the target lane.
//! let sample_at = |ego_l: f64, y| -> Result<Sample, palc_zone_filter::ZoneError> {
//!     let input = FeatureInput {
//!         ego_s: 0.0,
//!         ego_l,
//!         ego_speed: 20.0,
//!         preceding: [30.0, 0.0],
//!         adjacent: [10.0, 3.5],
//!     };
//!     Ok(Sample::new(features(FeatureSet::Paper, &input)?, y))
//! };
//! // The user took over when the system moved beyond about 1 m to the left.
//! let mut samples = Vec::new();
//! for k in 0..=10 {
//!     let l = -0.5 + 0.1 * k as f64;
//!     samples.push(sample_at(l, Label::Safe)?);
//!     samples.push(sample_at(l + 1.6, Label::Unsafe)?);
//! }
//! let model = ZoneModel::fit(ZoneConfig::default(), &samples)?;
//! assert!(model.is_informative());
//!
//! let step = StepScene {
//!     ego_s: 0.0,
//!     reference_l: 0.0,
//!     ego_speed: 20.0,
//!     preceding: [30.0, 0.0],
//!     adjacent: [10.0, 3.5],
//! };
//! let bounds = lateral_bounds(&model, &[step], &BoundsConfig::default())?;
//! let StepBounds::Bounded { min, max } = bounds[0] else {
//!     panic!("expected a bounded step, got {:?}", bounds[0]);
//! };
//! assert!(min <= 0.0 && 0.0 <= max && max < 1.75);
//! # Ok::<(), palc_zone_filter::ZoneError>(())
//! ```
#![warn(missing_docs)]
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

mod bounds;
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
