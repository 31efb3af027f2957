//! Drivers of personalized automated lane change (PALC): what a driver
//! expects of a lane change, when it takes over, and how it drives after a
//! takeover.
//!
//! A user is anything that implements [`User`]: the built-in [`SimulatedUser`]
//! or an embedder's own (a recorded driver, a person at a driving simulator,
//! another simulator's driver model). It sees a scenario only through a
//! [`UserScene`] (plain numbers: the step, what it sees at each step with the
//! ego keeping its lane, the ego's motion, the target lane's centre), so a
//! driver model compiles and is tested without the loop that runs it
//! (`palc-harness`). The loop asks a user for the lane change it expects in a
//! scenario ([`User::next`]), lets it judge the plan step by step as it is
//! driven ([`User::takes_over`]), and lets it drive after a takeover
//! ([`User::acceleration_after_takeover`], along its expected lateral path).
//!
//! The built-in user is the paper's (Section III.A: three styles, each a time
//! headway and a lane-change duration; NOTES.md, "The user model") refined by a
//! [`Family`] of rules chosen in TOML (`[user.family]`):
//!
//! | part | rules |
//! | --- | --- |
//! | start ([`StartRule`]) | time headway (the paper's), time to collision, distance gap; then gap acceptance on the target lane (lead and lag time gaps) |
//! | reaction | a delay between the decision and the start |
//! | lateral profile ([`LateralProfile`]) | quintic (the paper's), cosine, asymmetric, a table of points |
//! | speed ([`SpeedRule`]) | the ego ACC's (the paper's constant speed), accelerating towards the target lane's speed |
//! | takeover ([`TakeoverRule`]) | lateral deviation beyond 0.3 m (the paper's), and a perceived-safety bound on the target lane's gaps ([`PerceivedSafety`]) |
//! | spread ([`Spread`]) | any numeric parameter drawn per lane change, relative or absolute, seeded |
//!
//! Every expectation of the built-in user is checked for sanity (inside the search
//! window, from lane centre to lane centre, between the two lanes, bounded lateral
//! acceleration and jerk), or the user refuses the scenario with a typed
//! [`UserRefusal`] naming what failed.
#![deny(missing_docs)]
#![warn(clippy::print_stdout, clippy::print_stderr)]
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

mod error;
mod expectation;
mod family;
mod point;
mod profile;
mod recorded;
mod scene;
mod simulated;
mod situation;
mod spread;
mod start;
mod style;

use palc_planner::State;

pub use error::{UserError, UserRefusal, within};
pub use expectation::{
    Expectation, ExpectedLaneChange, MAX_LATERAL_ACCELERATION_MPS2, MAX_LATERAL_JERK_MPS3,
    SMOOTHNESS_STEP_S, TakeoverCause, TakeoverRule,
};
pub use family::{
    ACCELERATION_BOUNDS_MPS2, COMFORT_TIME_GAP_BOUNDS_S, COMFORT_TTC_BOUNDS_S,
    DISTANCE_START_BOUNDS_M, Family, INCENTIVE_SAFE_DECELERATION_MPS2, INCENTIVE_START_BOUNDS_MPS2,
    MAX_REACTION_S, ONSET_BOUNDS_M, PerceivedSafety, SETTLED_M, SpeedRule, StartRule,
    TTC_START_BOUNDS_S, incentive_mps2,
};
pub use profile::{
    LateralProfile, MAX_TABLE_POINTS, PEAK_FRACTION_BOUNDS, ProfilePoint, TABLE_END_TOLERANCE_M,
    quintic,
};
pub use recorded::{
    DEFAULT_NOISE_M, MIN_MOVE_M, NOISE_BOUNDS_M, OUTLIER_NOISE_FACTOR, RecordedFit, RecordedProfile,
};
pub use scene::{SafeDistance, UserScene};
pub use simulated::{MAX_DRAWS, SimulatedUser};
pub use situation::Situation;
pub use spread::{Draw, MAX_ABSOLUTE_SPREAD, MAX_RELATIVE_SPREAD, ParameterSpread, Spread};
pub use start::{NoStart, StartModel};
pub use style::{MAX_GAP_ACCEPTANCE_S, Style, StylePreset};

/// A user of the lesson-learning loop: what it expects, when it takes over, how
/// it drives after a takeover.
///
/// Implement it to bring a user of your own into the loop (in `palc-harness`,
/// `LearningLoop::with_user`); the provided methods apply the expectation's own
/// [`TakeoverRule`] and speed rule, so a user that only computes expectations
/// needs only the three required methods. `Send`, so that loops run on threads
/// and users come from other languages.
///
/// ```
/// use palc_user::{Expectation, SimulatedUser, Style, User, UserError, UserScene};
///
/// /// A user who expects the neutral style's lane change half a second later.
/// #[derive(Debug)]
/// struct Late(SimulatedUser);
///
/// impl User for Late {
///     fn name(&self) -> &str {
///         "late"
///     }
///     fn nominal(&self, scene: &UserScene<'_>) -> Result<Expectation, UserError> {
///         let mut expectation = self.0.nominal(scene)?;
///         expectation.lane_change.start_s += 0.5;
///         for (i, state) in expectation.states.iter_mut().enumerate() {
///             state.l = expectation.lane_change.lateral(i as f64 * scene.dt);
///         }
///         Ok(expectation)
///     }
///     fn next(&mut self, scene: &UserScene<'_>) -> Result<Expectation, UserError> {
///         self.nominal(scene)
///     }
/// }
/// # let _ = Late(SimulatedUser::paper(Style::NEUTRAL)?);
/// # Ok::<(), UserError>(())
/// ```
pub trait User: std::fmt::Debug + Send {
    /// The user's name in messages.
    fn name(&self) -> &str;

    /// The lane change the user expects in `scene` with its nominal parameters:
    /// the ceiling of a user with spread is this trajectory's takeover rate.
    ///
    /// # Errors
    /// [`UserError::Refused`] when the user has no sane lane change in the scenario.
    fn nominal(&self, scene: &UserScene<'_>) -> Result<Expectation, UserError>;

    /// The lane change the user expects in the next lane change (a user with
    /// spread draws its parameters anew).
    ///
    /// # Errors
    /// As [`User::nominal`].
    fn next(&mut self, scene: &UserScene<'_>) -> Result<Expectation, UserError>;

    /// Whether the user's parameters vary between lane changes.
    fn has_spread(&self) -> bool {
        false
    }

    /// Whether the user takes over at `step` of a drive, the ego at `ego` (plan
    /// frame) seeing `seen`; by default the expectation's [`TakeoverRule`].
    fn takes_over(
        &self,
        expectation: &Expectation,
        step: usize,
        ego: &State,
        seen: &Situation,
    ) -> Option<TakeoverCause> {
        expectation.judge(step, ego, seen)
    }

    /// The user's longitudinal acceleration at `step` after a takeover, driving
    /// at `speed`, when the ego ACC would command `acc` (which keeps the distance to
    /// whatever is ahead). By default the ACC's; an accelerating user heads for the
    /// target lane's speed from its start (the speed gap times 1/s, bounded by its
    /// largest acceleration), never above the ACC's command.
    fn acceleration_after_takeover(
        &self,
        expectation: &Expectation,
        step: usize,
        speed: f64,
        acc: f64,
    ) -> f64 {
        expectation.acceleration_after_takeover(step, speed, acc)
    }
}

/// The takeover rule (paper, Section III.A): the user takes over at the first
/// step where the planned lateral position deviates from the expected one by
/// more than `threshold` (0.3 m in the paper).
pub fn first_takeover(planned_l: &[f64], expected_l: &[f64], threshold: f64) -> Option<usize> {
    planned_l
        .iter()
        .zip(expected_l)
        .position(|(p, e)| (p - e).abs() > threshold)
}

/// Largest `|planned − expected|` over the steps.
pub fn max_deviation(planned_l: &[f64], expected_l: &[f64]) -> f64 {
    planned_l
        .iter()
        .zip(expected_l)
        .map(|(p, e)| (p - e).abs())
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn takeover_is_the_first_step_beyond_the_threshold() {
        let planned = [0.0, 0.1, 0.5, 0.9];
        let expected = [0.0, 0.2, 0.9, 0.0];
        assert_eq!(first_takeover(&planned, &expected, 0.3), Some(2));
        assert_eq!(first_takeover(&planned[..2], &expected[..2], 0.3), None);
        assert!((max_deviation(&planned, &expected) - 0.9).abs() < 1e-12);
    }
}
