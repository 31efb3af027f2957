//! The input of one plan: initial state, reference speeds, weights, predicted
//! vehicles, terminal state, lateral bounds and an optional tracking term.

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use crate::Weights;

/// The state `X_i = [s, v, l, φ]` of Eq. (9), in the order of NOTES item 3.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct State {
    /// Longitudinal (Frenet) position (m).
    pub s: f64,
    /// Longitudinal speed (m/s).
    pub v: f64,
    /// Lateral position, positive to the left (m).
    pub l: f64,
    /// Heading relative to the road (rad).
    pub phi: f64,
}

impl State {
    /// The state as the vector `[s, v, l, φ]`.
    pub fn to_array(self) -> [f64; 4] {
        [self.s, self.v, self.l, self.phi]
    }

    /// A state from the vector `[s, v, l, φ]`.
    pub fn from_array(x: [f64; 4]) -> Self {
        Self {
            s: x[0],
            v: x[1],
            l: x[2],
            phi: x[3],
        }
    }
}

/// The control `U_i = [a, δ]` of Eq. (10).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Control {
    /// Longitudinal acceleration (m/s²).
    pub a: f64,
    /// Front wheel angle (rad).
    pub delta: f64,
}

/// A predicted position of another vehicle in the Frenet frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Position {
    /// Longitudinal position (m), in the same origin as the ego's `s`.
    pub s: f64,
    /// Lateral position (m).
    pub l: f64,
}

/// The terminal condition of Eq. (21): `X_K = [s_K, v_K, l_K, 0]`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Terminal {
    /// Target longitudinal position; `None` leaves `s_K` free (the paper fixes it,
    /// but a caller rarely knows it in advance).
    #[cfg_attr(feature = "serde", serde(default))]
    pub s: Option<f64>,
    /// Target speed after the lane change (m/s).
    pub v: f64,
    /// Target lateral position (m), e.g. 3.5 for the centre of the target lane.
    pub l: f64,
}

/// Lateral bounds at one step (Eq. 22); either side may be absent.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct LateralBound {
    /// Lowest allowed `l` (m); `None` means unbounded below.
    #[cfg_attr(feature = "serde", serde(default))]
    pub min: Option<f64>,
    /// Highest allowed `l` (m); `None` means unbounded above.
    #[cfg_attr(feature = "serde", serde(default))]
    pub max: Option<f64>,
}

impl LateralBound {
    /// A two-sided bound `min <= l <= max`.
    pub fn new(min: f64, max: f64) -> Self {
        Self {
            min: Some(min),
            max: Some(max),
        }
    }
}

/// The tracking term `Σ_i (X_i - X_i^ref)ᵀ Q^p (X_i - X_i^ref)` (the form of Eq. 25),
/// with diagonal `Q^p`; the aggregator plans expert trajectories with it.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Tracking {
    /// Diagonal of `Q^p` for `[s, v, l, φ]`; each entry must be `>= 0`.
    /// Eq. (26) tracks only `l`: `[0, 0, q_l, 0]`.
    pub weights: [f64; 4],
    /// Reference state per step `i = 0..=K` (length `K + 1`); `None` skips the step.
    /// Step 0 is fixed by `X_0`, so its entry only adds a constant.
    pub reference: Vec<Option<State>>,
}

/// The largest `|s|` (m) a [`Problem`] may hold (initial, predicted, terminal and
/// tracking positions); beyond it the planner refuses with
/// [`PlanError::OutOfRange`](crate::PlanError::OutOfRange). The QP is built relative to
/// `initial.s`, so the optimum does not depend on the origin up to this bound (property
/// test); at 1e9 m a double still resolves 1.2e-7 m, and beyond it the input positions
/// themselves lose the resolution that the relative offsets need (0.125 m at 1e15 m,
/// where the planner used to report "solved" with an objective of -3.5e13).
pub const MAX_POSITION: f64 = 1e9;

/// One planning problem for a horizon of `K` steps.
///
/// Pass `s` relative to the ego's position at the start of the plan (`initial.s = 0`,
/// other vehicles shifted by the same amount): the feature `s δ` (w7) then does not
/// depend on where on the road the plan begins. The planner itself takes `s` as given,
/// assembles its QP relative to `initial.s` and refuses `|s| >` [`MAX_POSITION`].
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Problem {
    /// `X_0` of Eq. (20).
    pub initial: State,
    /// Speed profile `v_i^ref` for `i = 0..K-1` (length `K`) around which the lateral
    /// dynamics are linearized (Eqs. 12-14); must be `>= 0`. It is also the intended
    /// longitudinal motion: the acceleration penalty acts on `a_i - a_i^ref`, with
    /// `a^ref` the profile's own acceleration ([`Problem::reference_acceleration`]).
    pub reference_speed: Vec<f64>,
    /// Road curvature `R` (1/m) of Eq. (14); 0 on a straight road.
    #[cfg_attr(feature = "serde", serde(default))]
    pub curvature: f64,
    /// The 10 x K weight matrix of Eq. (15).
    pub weights: Weights,
    /// Predicted preceding vehicle at steps `0..K-1` (length `K`).
    pub preceding: Vec<Position>,
    /// Predicted adjacent vehicle on the target lane at steps `0..K-1` (length `K`).
    pub adjacent: Vec<Position>,
    /// Terminal condition of Eq. (21).
    pub terminal: Terminal,
    /// Lateral bounds per step `i = 0..=K` (length `K + 1`), `None` for no bound.
    pub lateral_bounds: Vec<Option<LateralBound>>,
    /// Optional tracking term (form of Eq. 25).
    #[cfg_attr(feature = "serde", serde(default))]
    pub tracking: Option<Tracking>,
}

impl Problem {
    /// The acceleration of the reference speed profile at control `i` (m/s²): the
    /// forward difference `(v_{i+1}^ref - v_i^ref) / Δt`, towards the terminal speed
    /// at the last step; 0 for a constant profile that ends at its own speed, and past
    /// the horizon.
    ///
    /// The acceleration penalty of [`PlannerConfig`](crate::PlannerConfig) is
    /// `ρ_a Σ_i (a_i - a_i^ref)²`, so a plan follows the reference longitudinal motion
    /// (e.g. an ACC's speed while the ego keeps its lane) except where the learned cost
    /// (`w7`, `w9`, `w10`) asks otherwise; the paper's constant speeds give `a^ref = 0`
    /// and the penalty of Eq. (34)'s repair, `ρ_a Σ a_i²`.
    pub fn reference_acceleration(&self, i: usize, dt: f64) -> f64 {
        let Some(&here) = self.reference_speed.get(i) else {
            return 0.0;
        };
        let next = (self.reference_speed.get(i + 1).copied()).unwrap_or(self.terminal.v);
        (next - here) / dt
    }
}
