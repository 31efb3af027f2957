//! Live mode: a driver who decides in real time (a person at a keyboard, a
//! scripted participant) next to the users who expect a trajectory.
//!
//! A [`LiveLaneChange`] drives one lane change step by step. Before a takeover
//! the system drives its plan under the longitudinal guard and, with
//! `[planning.closed_loop]` on, re-plans every period as
//! [`crate::closed_loop::ClosedLoop::drive`] does (`system.rs`).
//! At every step the live driver sees a [`LiveView`] (the state the system is
//! about to drive, the scene, the ACC's command) and answers with a
//! [`LiveInput`]: whether it takes over and, from then on, its controls, a
//! lateral-speed command and an optional acceleration, both within physical
//! [`LiveLimits`]. What it drove is the lesson, exactly as a simulated user's:
//! [`crate::LearningLoop::finish_live`] records and learns from it.
//!
//! A simulated user is judged the same way step by step in
//! [`crate::advanced::execute`]; the live path leaves that path untouched.

mod input;
mod lane_change;
pub(crate) mod system;

pub use input::{
    LiveDriver, LiveInput, LiveLimits, LiveView, MAX_LATERAL_SPEED_BOUND_MPS,
    MAX_LONGITUDINAL_BOUND_MPS2,
};
pub use lane_change::{LiveLaneChange, LiveStatus};
