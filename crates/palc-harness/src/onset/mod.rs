//! The user's start of a lane change in relative space: observed in a lesson,
//! predicted in a new scene (docs/experiments/0042-observing-the-users-start.md,
//! docs/experiments/0043-predicting-the-start.md).
//!
//! A takeover shows the user's own lateral profile from the takeover on. Its start
//! is found by fitting a lane-change model through two crossings of it ([`Shape`](shape::Shape)):
//! the paper's quintic or a half-sine lateral speed, each symmetric or skewed (its
//! lateral speed peaking earlier or later than mid-move), keeping the model closest
//! to the profile up to the upper crossing. With `x(p)` the inverse of the model's
//! `p(x)` (for the quintic `10x³ − 15x⁴ + 6x⁵`), crossings of the fractions
//! `p_a < p_b` of the lane change at `t_a` and `t_b` give the duration
//! `D = (t_b − t_a) / (x(p_b) − x(p_a))` and the start `t_a − x(p_a) · D`. The
//! crossings are interpolated between steps, so the start is found to a fraction
//! of a step; a profile outside the models (a table, a seventh-order polynomial)
//! biases it by a few percent of its duration. Once a lesson has shown the user's
//! whole lane change from rest, its own shape ([`OwnShape`]) is fitted beside the
//! models in later lessons. When neither explains what the user drove within a
//! centimetre, the start is that of the onset's own power law fitted to the part
//! of the onset seen (`power.rs`), when that law explains it. A start fitted at
//! a step where a target-lane vehicle is alongside moves to the first step from
//! which none is, if that step is not past the takeover
//! ([`start_clear_of_vehicles_beside`]): nobody moves into a vehicle beside them.
//!
//! The relative state at that start ([`Onset`](palc_aggregator::Onset): time
//! headway, time to collision and gap to the vehicle ahead, and a target-lane
//! gap when it held the user back) is what carries, recorded with what the user
//! saw at every step of the scene (`observed.rs`; what the driver estimate of
//! `crate::driver` reads). In a new scene the start is predicted with the
//! structure of a gap-acceptance driver: the user decides when one cue of the
//! vehicle ahead (`cues.rs`) falls to its threshold, then starts at the first
//! step from there where the target-lane gaps are at least the ones it needs.
//! [`GapAcceptanceSet`] keeps what every onset allows of that model, and its
//! start is the one most of the set leads to in the new scene
//! ([`GapAcceptanceSet::predicted_start_s`]).
//!
//! What one scene cannot show is bounded from what the user refused: a lead gap
//! refused after the decision (a scene's onset learned with earlier scenes'
//! decision threshold) bounds the lead gap the user needs from below, the largest
//! rejected gap of gap-acceptance models; and when every onset was held back by
//! a follower alongside, the headway just before a vehicle first came alongside
//! (the leader of a vehicle passing backwards, or the follower) bounds the
//! decision from above (the user had not started there). A start at a headway
//! below the standard ALC's decision headway, with the follower's gap opening
//! into it, is read as a wait for that gap (every user decides before the
//! standard ALC does: the paper's premise); two or more such waits need the
//! middle of the follower's gaps all their scenes allow, and where the starts of
//! two or more scenes, read as decisions, reveal one threshold, waits are read
//! as decisions (the scenes need no follower's gap). A lead gap the user
//! accepted bounds the one it needs from above; until it has accepted one
//! smaller than the standard ALC's requirement, that requirement is assumed (the
//! system's own, not fitted to any user).

mod cues;
mod fit;
mod gap_acceptance;
mod observed;
mod own_shape;
mod power;
mod shape;
#[cfg(test)]
mod test_scenes;

pub(crate) use fit::UserLaneChange;
pub use gap_acceptance::GapAcceptanceSet;
pub(crate) use observed::{onset_at, start_clear_of_vehicles_beside};
pub(crate) use own_shape::OwnShape;
#[cfg(test)]
pub(crate) use shape::Shape;
