//! A [`Problem`] built field by field, each input checked when it is given.

use crate::validate::{
    check_reference_speed, check_tracking, finite, finite_lateral_bounds, finite_positions,
    finite_state, finite_terminal, finite_weights, forward_speed, length, within_max_position,
};
use crate::{
    LateralBound, PlanError, Position, Problem, StageWeights, State, Terminal, Tracking, Weights,
    check_convexity,
};

/// Builds a [`Problem`] for a horizon of `K` steps and checks each input as it is
/// given: its length against `K`, every number finite, the ranges the planner
/// enforces (speeds `>= 0`, `|s| <=` [`MAX_POSITION`](crate::MAX_POSITION), tracking
/// weights `>= 0`) and the convexity of the weights (Eqs. 16-19). A refusal is the
/// same [`PlanError`] that [`Planner::plan`](crate::Planner::plan) would return, naming
/// the field and, for a number, its index.
///
/// `curvature` defaults to 0 (a straight road), `lateral_bounds` to no bound at any
/// step and `tracking` to none; the other inputs are required.
/// [`Planner::plan`](crate::Planner::plan) still checks the problem against its
/// configuration (the horizon, and for hard bounds the zones that are empty or
/// exclude the initial or terminal position).
///
/// ```
/// use palc_planner::{PlanError, Position, Problem, StageWeights, State, Terminal};
///
/// let k = 30;
/// let builder = Problem::builder(k)
///     .initial(State { s: 0.0, v: 20.0, l: 0.0, phi: 0.0 })?
///     .reference_speed(vec![20.0; k])?;
/// // A wrong length is refused at once, naming the field.
/// let err = builder.clone().preceding(vec![Position::default(); k - 1]).unwrap_err();
/// assert_eq!(
///     err,
///     PlanError::DimensionMismatch { field: "preceding", expected: k, found: k - 1 }
/// );
/// let problem = builder
///     .uniform_weights(StageWeights { phi_squared: 1.0, delta_squared: 10.0, ..StageWeights::ZERO })?
///     .preceding(vec![Position { s: 40.0, l: 0.0 }; k])?
///     .adjacent(vec![Position { s: -30.0, l: 3.5 }; k])?
///     .terminal(Terminal { s: None, v: 20.0, l: 3.5 })?
///     .build()?;
/// assert_eq!(problem.lateral_bounds.len(), k + 1);
/// # Ok::<(), PlanError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
#[must_use = "a builder does nothing until `build` is called"]
pub struct ProblemBuilder {
    horizon: usize,
    initial: Option<State>,
    reference_speed: Option<Vec<f64>>,
    curvature: f64,
    weights: Option<Weights>,
    preceding: Option<Vec<Position>>,
    adjacent: Option<Vec<Position>>,
    terminal: Option<Terminal>,
    lateral_bounds: Option<Vec<Option<LateralBound>>>,
    tracking: Option<Tracking>,
}

impl Problem {
    /// A [`ProblemBuilder`] for a horizon of `horizon` steps (`K`).
    pub fn builder(horizon: usize) -> ProblemBuilder {
        ProblemBuilder::new(horizon)
    }
}

impl ProblemBuilder {
    /// An empty builder for a horizon of `horizon` steps (`K`).
    pub fn new(horizon: usize) -> Self {
        Self {
            horizon,
            initial: None,
            reference_speed: None,
            curvature: 0.0,
            weights: None,
            preceding: None,
            adjacent: None,
            terminal: None,
            lateral_bounds: None,
            tracking: None,
        }
    }

    /// The horizon `K` the inputs are checked against.
    pub fn horizon(&self) -> usize {
        self.horizon
    }

    /// `X_0` of Eq. (20): finite, `v >= 0`, `|s| <=` [`MAX_POSITION`](crate::MAX_POSITION).
    pub fn initial(mut self, initial: State) -> Result<Self, PlanError> {
        finite_state("initial", &initial)?;
        forward_speed("initial.v", initial.v)?;
        within_max_position(|| "initial.s".into(), initial.s)?;
        self.initial = Some(initial);
        Ok(self)
    }

    /// The speed profile `v_i^ref` of Eqs. (12-14): `K` finite speeds `>= 0`.
    pub fn reference_speed(mut self, speeds: Vec<f64>) -> Result<Self, PlanError> {
        length("reference_speed", self.horizon, speeds.len())?;
        check_reference_speed(&speeds)?;
        self.reference_speed = Some(speeds);
        Ok(self)
    }

    /// Road curvature `R` (1/m) of Eq. (14); finite. Defaults to 0.
    pub fn curvature(mut self, curvature: f64) -> Result<Self, PlanError> {
        finite(|| "curvature".into(), curvature)?;
        self.curvature = curvature;
        Ok(self)
    }

    /// The 10 x K weight matrix of Eq. (15): `K` columns, finite, every stage convex.
    pub fn weights(mut self, weights: Weights) -> Result<Self, PlanError> {
        length("weights", self.horizon, weights.horizon())?;
        finite_weights(&weights)?;
        check_convexity(&weights)?;
        self.weights = Some(weights);
        Ok(self)
    }

    /// The same named weights at every stage ([`Weights::uniform`]).
    pub fn uniform_weights(self, stage: StageWeights) -> Result<Self, PlanError> {
        let horizon = self.horizon;
        self.weights(Weights::uniform(horizon, stage))
    }

    /// Predicted preceding vehicle at steps `0..K-1`: `K` finite positions.
    pub fn preceding(mut self, preceding: Vec<Position>) -> Result<Self, PlanError> {
        check_vehicle("preceding", self.horizon, &preceding)?;
        self.preceding = Some(preceding);
        Ok(self)
    }

    /// Predicted adjacent vehicle on the target lane at steps `0..K-1`: `K` finite
    /// positions.
    pub fn adjacent(mut self, adjacent: Vec<Position>) -> Result<Self, PlanError> {
        check_vehicle("adjacent", self.horizon, &adjacent)?;
        self.adjacent = Some(adjacent);
        Ok(self)
    }

    /// The terminal condition of Eq. (21): finite, `v >= 0`.
    pub fn terminal(mut self, terminal: Terminal) -> Result<Self, PlanError> {
        finite_terminal(&terminal)?;
        forward_speed("terminal.v", terminal.v)?;
        if let Some(s) = terminal.s {
            within_max_position(|| "terminal.s".into(), s)?;
        }
        self.terminal = Some(terminal);
        Ok(self)
    }

    /// Lateral bounds of Eq. (22) per step `0..=K`: `K + 1` entries, each given side
    /// finite. Defaults to no bound at any step.
    pub fn lateral_bounds(mut self, bounds: Vec<Option<LateralBound>>) -> Result<Self, PlanError> {
        length("lateral_bounds", self.horizon + 1, bounds.len())?;
        finite_lateral_bounds(&bounds)?;
        self.lateral_bounds = Some(bounds);
        Ok(self)
    }

    /// The tracking term (form of Eq. 25): `K + 1` reference entries, finite, weights
    /// `>= 0`.
    pub fn tracking(mut self, tracking: Tracking) -> Result<Self, PlanError> {
        length(
            "tracking.reference",
            self.horizon + 1,
            tracking.reference.len(),
        )?;
        check_tracking(&tracking)?;
        for (i, r) in tracking.reference.iter().enumerate() {
            if let Some(r) = r {
                within_max_position(|| format!("tracking.reference[{i}].s"), r.s)?;
            }
        }
        self.tracking = Some(tracking);
        Ok(self)
    }

    /// The problem, or [`PlanError::MissingField`] naming the first required input
    /// that was not given.
    pub fn build(self) -> Result<Problem, PlanError> {
        let missing = |field| PlanError::MissingField { field };
        Ok(Problem {
            initial: self.initial.ok_or_else(|| missing("initial"))?,
            reference_speed: self
                .reference_speed
                .ok_or_else(|| missing("reference_speed"))?,
            curvature: self.curvature,
            weights: self.weights.ok_or_else(|| missing("weights"))?,
            preceding: self.preceding.ok_or_else(|| missing("preceding"))?,
            adjacent: self.adjacent.ok_or_else(|| missing("adjacent"))?,
            terminal: self.terminal.ok_or_else(|| missing("terminal"))?,
            lateral_bounds: self
                .lateral_bounds
                .unwrap_or_else(|| vec![None; self.horizon + 1]),
            tracking: self.tracking,
        })
    }
}

fn check_vehicle(
    name: &'static str,
    horizon: usize,
    positions: &[Position],
) -> Result<(), PlanError> {
    length(name, horizon, positions.len())?;
    finite_positions(name, positions)?;
    for (i, p) in positions.iter().enumerate() {
        within_max_position(|| format!("{name}[{i}].s"), p.s)?;
    }
    Ok(())
}
