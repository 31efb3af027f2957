//! CommonRoad 2020a scenarios in and out of palc.
//!
//! - [`import`]: reads scenario XML (lanelets with their adjacency, dynamic
//!   obstacles with their trajectories), finds every lane change of the
//!   recorded vehicles and describes each as a [`import::RecordedLaneChange`]:
//!   the lateral trace relative to the start lane's centre, the speed, the lane
//!   width and the start's context (headway, gaps and closing speeds).
//! - [`export`]: writes a palc scene as a scenario (two lanelets, the other
//!   vehicles as dynamic obstacles, a planning problem) and a lane change as a
//!   solution file (the kinematic single-track model, KS).
//!
//! The crate depends on no other palc crate: it speaks of lanes, vehicles and
//! trajectories in plain numbers, and the command line maps palc's scenes onto
//! them.

#![deny(missing_docs)]
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

pub mod export;
pub mod import;
