//! The lesson-learning loop (paper Section II.A and Fig. 2): plan, execute in
//! traffic, let the user take over, learn, repeat.
//!
//! The loop ties the other crates together: [`palc_traffic`] moves the background
//! traffic, [`palc_planner`] plans each lane change, a [`User`] (the `palc-user`
//! crate, re-exported as [`user`]) judges it step by step, and on a takeover
//! [`palc_aggregator`] (with [`palc_zone_filter`]) learns from the lesson. Two
//! methods run side by side ([`Method`]): the paper's, with only its equation
//! errors corrected, and palc's; how each turns a lesson into a demonstration and
//! carries experience is an [`advanced::Personalization`]. A scenario that does
//! not fit the planning set-up is refused with a typed [`Refusal`].
//!
//! The loop is an executor, [`LearningLoop`]: `new` prepares a scenario, `step`
//! drives one lane change and learns from a takeover, `termination` applies the
//! stopping rules and `run` steps until they end the run; [`run`] is its one-call
//! form. An [`Observer`] sees every lane change, every lesson as a [`LessonEvent`]
//! (what the aggregator produced, or why it could not learn) and the
//! [`RunSummary`], whose [`RunSummary::counted_takeovers`] is the paper's count.
//! Configs are built from TOML or from a base with [`LearnConfig::with_cell`],
//! [`LearnConfig::with_user`] and [`LearnConfig::with_method`]; users are
//! [`StylePreset`]s or custom styles.
//!
//! ```no_run
//! use palc_harness::{LearnConfig, NoObserver, run};
//!
//! let text = std::fs::read_to_string("configs/learn.toml")?;
//! let config = LearnConfig::from_toml_str(&text)?;
//! let result = run(&config, None, &mut NoObserver)?;
//! println!("{:?} after {} takeovers", result.summary.outcome, result.summary.counted_takeovers());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![deny(missing_docs)]
#![warn(clippy::print_stdout, clippy::print_stderr)]
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

mod acc;
mod carry;
pub mod closed_loop;
pub mod config;
mod drive;
pub mod driver;
mod error;
mod guard;
mod learning_loop;
mod lesson;
pub mod live;
mod method;
mod observer;
mod onset;
mod personalization;
pub mod record;
mod refusal;
pub mod safety;
mod scenario;
mod scene_lessons;
mod setup;
mod standard_alc;
mod violation;
mod world;

/// The users: the [`User`] trait, its plain view of a scenario and the built-in
/// simulated users (the `palc-user` crate).
pub use palc_user as user;

pub use config::{CellChoice, LearnConfig, UserConfig};
pub use error::HarnessError;
pub use learning_loop::{LearningLoop, run};
pub use method::Method;
pub use observer::{DriverEvidence, LessonEvent, NoObserver, Observer};
pub use palc_user::{StylePreset, User, UserScene};
pub use record::{LaneChangeRecord, Outcome, RunResult, RunSummary};
pub use refusal::Refusal;
pub use scenario::prepare;
pub use setup::Setup;
pub use world::{PalcTraffic, World, WorldError};

/// The loop's building blocks, for those who drive their own loop or test one
/// part of it: the planning problem of a scenario, the execution of a plan with a
/// user, the safety check of a plan, the ego's ACC leader and the lesson labels.
/// [`LearningLoop`] composes them; most embedders need only that.
pub mod advanced {
    pub use crate::acc::acc_leader;
    pub use crate::carry::{Carried, Names};
    pub use crate::drive::{Drive, execute, execute_in, judge, plan_safety, problem};
    pub use crate::method::{Driver, label};
    pub use crate::onset::GapAcceptanceSet;
    pub use crate::personalization::{
        Demonstration, LessonPaths, Personalization, RelativeOnset, Replay, SceneAveraged,
        for_options,
    };
    pub use crate::scenario::{aggregator_options, expectation};
}
