//! Termination: the stopping tolerances, the convergence measures of an iterate, how
//! the interior point ended, and the bookkeeping of the iterations (the best iterate,
//! the best infeasibility certificate, stalled and stagnant steps).
//!
//! The stopping rule is clarabel's, on the unscaled data: relative primal and dual
//! residuals below `tol_feas` and an absolute or relative gap below `tol_gap_abs` or
//! `tol_gap_rel`. A primal infeasibility certificate `(y, λ)` has
//! `Aᵀy + Gᵀλ = 0` and `bᵀy + hᵀλ < 0` (Farkas): no `x` has `A x = b` and `G x <= h`.

use super::super::params::{
    REDUCED_FEAS, REDUCED_GAP, REDUCED_INFEASIBILITY, STAGNATION, STALL_LIMIT, STALLED_STEP,
};
use crate::SolverFailure;

/// Stopping tolerances (from [`SolverSettings`](crate::SolverSettings)).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Tolerances {
    /// Most iterations.
    pub max_iter: u32,
    /// Absolute duality gap.
    pub gap_abs: f64,
    /// Relative duality gap.
    pub gap_rel: f64,
    /// Relative primal and dual residuals.
    pub feas: f64,
}

/// How the interior point ended.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Outcome {
    /// The stopping rule holds at the requested tolerances.
    Solved,
    /// The best iterate meets clarabel's reduced tolerances only.
    AlmostSolved,
    /// The multipliers hold an infeasibility certificate.
    PrimalInfeasible,
    /// Stopped without a solution.
    Failed(SolverFailure),
}

/// Convergence measures of one iterate.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Measures {
    /// `‖(r_eq, r_in)‖∞ / max(1, ‖b, h‖∞ + ‖x‖∞ + ‖s‖∞)`.
    pub res_primal: f64,
    /// `‖r_dual‖∞ / max(1, ‖q‖∞ + ‖x‖∞ + ‖(y, λ)‖∞)`.
    pub res_dual: f64,
    /// `|p - d|` of the primal and dual objectives.
    pub gap_abs: f64,
    /// `|p - d| / max(1, min(|p|, |d|))`.
    pub gap_rel: f64,
    /// `bᵀy + hᵀλ` (negative for a certificate).
    pub certificate_value: f64,
    /// `‖Aᵀy + Gᵀλ‖∞`.
    pub certificate_residual: f64,
    /// The primal objective `½ xᵀPx + qᵀx + c`.
    pub objective: f64,
}

impl Measures {
    /// How far from the stopping rule: at most 1 when it is met.
    pub fn merit(&self, tol: &Tolerances) -> f64 {
        let gap = (self.gap_abs / tol.gap_abs).min(self.gap_rel / tol.gap_rel);
        (self.res_primal / tol.feas)
            .max(self.res_dual / tol.feas)
            .max(gap)
    }

    /// Whether the stopping rule holds at these tolerances.
    pub fn meets(&self, gap_abs: f64, gap_rel: f64, feas: f64) -> bool {
        (self.gap_abs < gap_abs || self.gap_rel < gap_rel)
            && self.res_primal < feas
            && self.res_dual < feas
    }

    /// Whether the stopping rule holds at clarabel's reduced tolerances.
    pub fn meets_reduced(&self) -> bool {
        self.meets(REDUCED_GAP, REDUCED_GAP, REDUCED_FEAS)
    }

    /// Whether `(y, λ)` is an infeasibility certificate at relative `tolerance`.
    pub fn infeasible(&self, tolerance: f64) -> bool {
        self.certificate_value < 0.0
            && self.certificate_residual <= tolerance * -self.certificate_value
    }

    /// `‖Aᵀy + Gᵀλ‖∞ / -(bᵀy + hᵀλ)`: the quality of the certificate, smaller better.
    pub fn certificate_ratio(&self) -> f64 {
        self.certificate_residual / -self.certificate_value
    }
}

/// The bookkeeping of one run of the iterations.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Progress {
    /// Consecutive steps shorter than [`STALLED_STEP`].
    stalled: u32,
    /// Iterations since the best iterate was last improved.
    since_best: u32,
    /// The measures of the best iterate that meets the reduced tolerances, and its
    /// merit.
    pub best: Option<(Measures, f64)>,
    /// The ratio of the best certificate at the reduced tolerance so far.
    pub certificate_ratio: f64,
    /// Whether iterative refinement is on (it stays on once switched on).
    pub refining: bool,
    /// The dual residual before the last step and that step's length.
    pub previous: Option<(f64, f64)>,
}

impl Default for Progress {
    fn default() -> Self {
        Self {
            stalled: 0,
            since_best: 0,
            best: None,
            certificate_ratio: f64::INFINITY,
            refining: false,
            previous: None,
        }
    }
}

impl Progress {
    /// Records the measures of the current iterate; returns whether it is the new best
    /// (it meets the reduced tolerances with a smaller merit than every earlier one).
    pub fn offer_best(&mut self, measures: Measures, tol: &Tolerances) -> bool {
        let merit = measures.merit(tol);
        // Only an iterate that meets the reduced tolerances can be returned.
        let better = self.best.is_none_or(|(_, best)| merit < best);
        if measures.meets_reduced() && better {
            self.best = Some((measures, merit));
            self.since_best = 0;
            true
        } else {
            self.since_best += 1;
            false
        }
    }

    /// Records a certificate at the reduced tolerance; returns whether it is the best
    /// so far.
    pub fn offer_certificate(&mut self, measures: &Measures) -> bool {
        let ratio = measures.certificate_ratio();
        if ratio < self.certificate_ratio {
            self.certificate_ratio = ratio;
            true
        } else {
            false
        }
    }

    /// Whether a best iterate meets the reduced tolerances.
    pub fn has_best(&self) -> bool {
        self.best.is_some()
    }

    /// Whether the best certificate meets the reduced infeasibility tolerance.
    pub fn has_certificate(&self) -> bool {
        self.certificate_ratio <= REDUCED_INFEASIBILITY
    }

    /// Records the length of a step.
    pub fn record_step(&mut self, res_dual: f64, alpha: f64) {
        self.stalled = if alpha < STALLED_STEP {
            self.stalled + 1
        } else {
            0
        };
        self.previous = Some((res_dual, alpha));
    }

    /// Why the iterations must stop now, if they must: the iteration limit, or no
    /// progress (stalled steps, or no better iterate for [`STAGNATION`] iterations
    /// after one met the reduced tolerances).
    pub fn stop_reason(&self, iterations: u32, tol: &Tolerances) -> Option<SolverFailure> {
        let stagnant = self.since_best >= STAGNATION && self.has_best();
        if self.stalled >= STALL_LIMIT || stagnant {
            Some(SolverFailure::InsufficientProgress)
        } else if iterations >= tol.max_iter {
            Some(SolverFailure::MaxIterations)
        } else {
            None
        }
    }
}
