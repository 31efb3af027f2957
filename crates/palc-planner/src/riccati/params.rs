//! The named constants of the Riccati backend: the regularization of the recursion
//! and every threshold of the interior point (start, step, refinement, stopping and
//! infeasibility rules), each with the reason for its value.
//!
//! The user-facing tolerances (`tol_gap_abs`, `tol_gap_rel`, `tol_feas`, `max_iter`)
//! come from [`SolverSettings`](crate::SolverSettings); the constants here are the
//! solver's own and are not meant to be tuned per problem.

// ---------------------------------------------------------------------------------
// The Riccati recursion (`recursion.rs`).
// ---------------------------------------------------------------------------------

/// Static regularization added to every `R̄` (absolute, on top of
/// [`CONTROL_REGULARIZATION_RELATIVE`]): keeps the recursion defined when the
/// acceleration has no cost of its own.
pub(crate) const CONTROL_REGULARIZATION: f64 = 1e-10;
/// Regularization of each diagonal entry of `R̄`, relative to that entry: a few units in
/// its last place, enough to keep a `2 x 2` block that is positive semidefinite in
/// exact arithmetic from rounding to a negative determinant, and too small to move a
/// Newton step measurably. Relative to the larger entry instead, an active steering
/// bound (a steering entry of 1e20) swamped the acceleration's entry and a warm
/// re-plan stalled off the optimum (`recursion.rs`, its test).
pub(crate) const CONTROL_REGULARIZATION_RELATIVE: f64 = 1e-13;
/// Regularization of the terminal Schur complement `-W_0`, relative to each row's own
/// diagonal. Without an acceleration cost the rows of `s_K` and `v_K` are of order
/// 1 / CONTROL_REGULARIZATION, ten orders of magnitude above those of `l_K` and `φ_K`;
/// a regularization relative to the largest row (as before) moved the lateral rows by
/// 1e-14 times that ratio of their size, the terminal refinement could not restore them,
/// and the interior point stalled or stopped off the optimum (188 of 384 curved lane
/// changes without acceleration penalty and with a fixed `s_K`, issue 12).
pub(crate) const TERMINAL_REGULARIZATION: f64 = 1e-14;
/// A row whose diagonal is below this fraction of the largest one (a terminal row that
/// no control reaches, e.g. `l_K` at `K = 1`) is regularized as if it had this size,
/// so that `-W_0` stays invertible and the infeasibility certificate finite.
pub(crate) const TERMINAL_FLOOR: f64 = 1e-10;
/// Newton steps on the terminal multiplier after the first forward pass, at most.
pub(crate) const TERMINAL_REFINEMENTS: usize = 2;
/// Terminal residual (relative to `1 + ‖x_K‖∞ + ‖e‖∞`) below which no refinement is
/// done: rounding in the forward pass alone reaches about 1e-14.
pub(crate) const TERMINAL_TOLERANCE: f64 = 1e-12;

// ---------------------------------------------------------------------------------
// The starting point of the interior point (`ipm/mod.rs`).
// ---------------------------------------------------------------------------------

/// Mehrotra's shift of `s` and `λ` into the positive orthant: `v += max(-1.5 min v, 0)`,
/// so that the most negative entry ends at half its magnitude above zero.
pub(crate) const START_SHIFT: f64 = 1.5;
/// Mean complementarity `sᵀλ / m` of the shifted start below which it is treated as
/// zero (then `s` and `λ` are moved by [`START_UNIT_SHIFT`]): Mehrotra's balancing
/// step divides by `Σ s` and `Σ λ`.
pub(crate) const START_COMPLEMENTARITY: f64 = 1e-8;
/// Mehrotra's balancing step: `s += ½ sᵀλ / Σλ`, `λ += ½ sᵀλ / Σs`.
pub(crate) const START_BALANCE: f64 = 0.5;
/// The shift of `s` and `λ` when the start has no complementarity to balance.
pub(crate) const START_UNIT_SHIFT: f64 = 1.0;
/// Warm start (re-plan): the duality gap `sᵀλ` the shifted previous solution is moved
/// to, relative to `1 + |objective|` of the previous plan (every row gets
/// `s λ >= μ = gap / m`). The previous solution sits on the boundary (`μ` near the
/// tolerance); an iterate that close to it cannot follow an active set that changed
/// with the shift, and one much further away gives up the start's advantage. Chosen on
/// the closed-loop benchmark (`benches/plan.rs`, `closed_loop`).
pub(crate) const WARM_GAP: f64 = 1e-4;

// ---------------------------------------------------------------------------------
// The steps (`ipm/step.rs`).
// ---------------------------------------------------------------------------------

/// Mehrotra's centring `σ = (μ_aff / μ)^3`: the cube, his heuristic, centres little
/// after a good predictor and much after a poor one.
pub(crate) const CENTERING_EXPONENT: i32 = 3;
/// Fraction of the step to the boundary of the positive orthant.
pub(crate) const STEP_FRACTION: f64 = 0.995;
/// Largest fraction of the step to the boundary, taken when the centring is below
/// `1 - MAX_STEP_FRACTION`.
pub(crate) const MAX_STEP_FRACTION: f64 = 0.9999;
/// Largest factor by which one corrected step may grow the mean complementarity `μ` once
/// the iterate's residuals meet the tolerance; a step that grows it more is recomputed
/// without Mehrotra's second-order term `Δs_aff ∘ Δλ_aff` (centring only, the same
/// factorization). After a short predictor that product can be several times `μ`: on a
/// feasible aggregator plan (issue 12, K = 27) a steering bound with `s = 2.5e-5`,
/// `Δs = -5.8e-4`, `Δλ = 241` (predictor 0.043, `μ = 0.047`) made the corrected step
/// double `μ`, and the iterates cycled with period 4 for 100 iterations at a relative
/// gap of 1e-2 with the residuals at 1e-15. Once only the gap is left to close, a step
/// that increases `μ` is a step back; 1 is the loosest bound that says so. Not applied
/// before the residuals meet the tolerance: on an infeasible problem `μ` grows with the
/// multipliers that become the certificate, and both this rule without that condition
/// and dropping the term after every predictor shorter than 0.1 stopped infeasible
/// problems on `InsufficientProgress` instead of `Infeasible`.
pub(crate) const MU_GROWTH: f64 = 1.0;

// ---------------------------------------------------------------------------------
// Iterative refinement of the Newton step (`ipm/kkt.rs`).
// ---------------------------------------------------------------------------------

/// A step that leaves more than this many times the `(1 - α)` share of the dual
/// residual that an exact Newton step leaves switches iterative refinement on.
pub(crate) const REFINE_SHORTFALL: f64 = 10.0;
/// The expected reduction `1 - α` is floored at this value in the refinement test: a
/// full step (`α` near 1) cannot be expected to leave less than this share of the
/// residual in floating point.
pub(crate) const REFINE_MIN_REDUCTION: f64 = 1e-3;
/// Refinement is not switched on once the dual residual is below this fraction of
/// `tol_feas`: the shortfall then is rounding, not a lost Newton step.
pub(crate) const REFINE_RESIDUAL_FLOOR: f64 = 0.1;

// ---------------------------------------------------------------------------------
// Termination (`ipm/info.rs`).
// ---------------------------------------------------------------------------------

/// Relative tolerance of the infeasibility certificate: `‖Aᵀy + Gᵀλ‖∞ <= TOL · -(bᵀy + hᵀλ)`
/// (clarabel's `tol_infeas_rel`). A feasible problem can pass it only if its solutions
/// have `‖x‖₁ >= 1 / TOL`. The multipliers grow to 1e13 before rounding in `Aᵀy + Gᵀλ`
/// stops the ratio near 1e-9, so a tighter tolerance is not reachable.
pub(crate) const INFEASIBILITY_TOLERANCE: f64 = 1e-8;
/// clarabel's reduced gap tolerance (`reduced_tol_gap_abs`, `reduced_tol_gap_rel`),
/// used when the iterations stop (`AlmostSolved`).
pub(crate) const REDUCED_GAP: f64 = 5e-5;
/// clarabel's reduced feasibility tolerance (`reduced_tol_feas`).
pub(crate) const REDUCED_FEAS: f64 = 1e-4;
/// clarabel's reduced infeasibility tolerance (`reduced_tol_infeas_rel`): an
/// infeasibility certificate at this tolerance is accepted when the iterations stop.
pub(crate) const REDUCED_INFEASIBILITY: f64 = 5e-5;
/// Iterations without a better iterate, once one meets the reduced tolerances, after
/// which the best is returned (`AlmostSolved`): a healthy interior point improves at
/// every step near the optimum, and continuing only lets `W = λ / s` grow until the
/// Newton steps lose all accuracy.
pub(crate) const STAGNATION: u32 = 5;
/// A step shorter than this makes no progress in double precision (the iterate moves
/// by less than the rounding of its own residuals).
pub(crate) const STALLED_STEP: f64 = 1e-8;
/// Consecutive steps shorter than [`STALLED_STEP`] after which the iterations stop
/// (`InsufficientProgress`): one or two can follow a poor predictor, three in a row
/// mean that the Newton direction no longer points into the interior.
pub(crate) const STALL_LIMIT: u32 = 3;
