//! Road, vehicles and Intelligent Driver Model (IDM) background traffic for personalized
//! automated lane change (PALC).
//!
//! This crate holds the paper's test bed (Section III.A): a two-lane road in Frenet
//! coordinates ([`Road`]), vehicles following the IDM ([`IdmParams`], integrated by the
//! ballistic [`ballistic_step`]), the grid of speed cases, adjacent headways and seeds
//! ([`TestbedCell`]), a [`Scene`] that advances with the ego's state supplied from outside,
//! and predictions of the preceding and adjacent vehicles over a planning horizon
//! ([`Scene::predict`]) that the zone filter and the planner consume as plain numbers.
//!
//! Everything inside is SI; the paper's mph appear only in configs ([`ScenarioConfig`]).
//!
//! ```
//! use palc_traffic::{EgoState, PredictionModel, Scene, ScenarioConfig};
//!
//! let config = ScenarioConfig::from_toml_str(r#"
//!     [testbed]
//!     speed_cases = [{ name = "collector-high", ego_mph = 45.0, others_mph = 40.0 }]
//!     adjacent_headways_m = [40.0]
//!     seeds = [7]
//! "#)?;
//! let mut scene = Scene::from_config(&config, 0)?;
//! let ego = scene.ego().unwrap().state;
//! // The harness drives the ego; here it keeps its lane at constant speed for one step.
//! let dt = 0.1;
//! scene.step(dt, EgoState { s: ego.s + ego.v * dt, l: ego.l, v: ego.v, heading: 0.0 })?;
//! let prediction = scene.predict(40, dt, PredictionModel::ConstantSpeed)?;
//! assert_eq!(prediction.adjacent.len(), 41);
//! assert!(prediction.adjacent[0][1] > 3.0); // the adjacent vehicle is on the target lane
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![deny(missing_docs)]
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

mod config;
mod error;
mod idm;
mod lag;
mod observed;
mod platoon;
mod prediction;
mod road;
mod scene;
mod testbed;
pub mod units;
mod validate;
mod vehicle;

pub use config::{
    FollowerConfig, IdmConfig, LagAcceleratingConfig, MAX_LAG_ACCELERATION_MPS2, PlatoonConfig,
    PrecedingBrakingConfig, ProfilePointConfig, RoadConfig, ScenarioConfig, SpeedCaseConfig,
    TestbedConfig, TomlParseError, VehicleConfig, parse_toml,
};
pub use error::{ConfigError, SceneError};
pub use idm::{BallisticStep, DesiredGap, IdmParams, MIN_INTERACTION_GAP, ballistic_step};
pub use observed::Observed;
pub use prediction::{MAX_HORIZON_STEPS, Prediction, PredictionModel};
pub use road::{Lane, MAX_LANES, Road};
pub use scene::{MAX_DT, MAX_VEHICLES, Scene};
pub use testbed::{
    MAX_POSITION_JITTER_M, MAX_PRECEDING_DECELERATION_MPS2, PAPER_ADJACENT_HEADWAYS, SpeedCase,
    TestbedCell,
};
pub use validate::MAX_SPEED_MPH;
pub use vehicle::{Driver, EgoState, SpeedProfile, Vehicle, VehicleId, VehicleState};
