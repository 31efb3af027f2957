//! Planner configuration: horizon, step, vehicle, extra cost terms and solver settings.

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use crate::ConfigError;

/// Largest horizon K: the QP's memory grows linearly with K (a few kB a step).
pub const MAX_HORIZON: usize = 10_000;

/// How the lateral bounds of Eq. (22) enter the QP.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(
    feature = "serde",
    serde(rename_all = "snake_case", deny_unknown_fields)
)]
#[non_exhaustive]
pub enum LateralBoundsMode {
    /// Hard constraints, as in the paper; inconsistent zones are refused as infeasible.
    Hard,
    /// Soft constraints: each bounded step gets one slack `σ_i >= 0` with
    /// `l_min - σ_i <= l_i <= l_max + σ_i` and cost `weight · σ_i`, so the penalty is
    /// `weight · max(l_min - l_i, l_i - l_max, 0)`: the L1 distance of `l_i` to the zone
    /// (for an empty zone, the larger of the two violations). Learned zones are often mutually inconsistent and
    /// a lane change must still be planned.
    Soft {
        /// Cost per metre of violation (per step); must be `> 0`.
        weight: f64,
    },
}

/// The QP backend. Both solve the same assembled QP and return the same [`Plan`](crate::Plan)
/// and [`PlanError`](crate::PlanError)s (one exception: the Riccati backend does not look
/// for a certificate of unboundedness, see docs/experiments/0026-riccati-interior-point.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
#[non_exhaustive]
pub enum Backend {
    /// A Mehrotra predictor-corrector interior point whose Newton systems are solved by
    /// a time-varying Riccati recursion over the stages (fixed-size 4 x 4 and 2 x 2
    /// blocks, no allocation inside the iterations). It reads the tolerances and
    /// `max_iter` of [`SolverSettings`]; the other settings are clarabel's. The default:
    /// it agrees with clarabel in the property tests and, on the benchmark lane change
    /// at K = 120, plans about 5-6 times faster (`benches/plan.rs`,
    /// `examples/plan_latency.rs`; figures in docs/experiments/0028-planner-speed.md).
    #[default]
    Riccati,
    /// The general sparse interior-point solver of the `clarabel` crate, kept as the
    /// reference. It needs the `clarabel` cargo feature (on by default); without it,
    /// [`PlannerConfig::validate`] and [`Planner::new`](crate::Planner::new) refuse it
    /// with [`ConfigError::BackendUnavailable`].
    Clarabel,
}

/// Settings passed to the QP solver; the defaults were chosen by measurement
/// (see the crate documentation and
/// docs/experiments/0021-qp-form-and-solver-settings.md). Both backends read
/// `max_iter` and the three tolerances; the last three fields are clarabel's.
///
/// [`PlannerConfig::validate`] holds every number to a documented range:
/// `max_iter` in [`MAX_ITER_RANGE`], each tolerance in [`TOLERANCE_RANGE`].
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct SolverSettings {
    /// Maximum interior-point iterations, in [`MAX_ITER_RANGE`].
    pub max_iter: u32,
    /// Absolute duality-gap tolerance, in [`TOLERANCE_RANGE`].
    pub tol_gap_abs: f64,
    /// Relative duality-gap tolerance, in [`TOLERANCE_RANGE`].
    pub tol_gap_rel: f64,
    /// Primal and dual feasibility tolerance, in [`TOLERANCE_RANGE`].
    pub tol_feas: f64,
    /// Ruiz equilibration of the problem data when the solver is built (kept while the
    /// structure is reused). On by default: without it the optimum is measurably less
    /// accurate (`s` is large next to `φ`), for a saving of about 0.2 ms at K = 120.
    pub equilibrate_enable: bool,
    /// Iterative refinement of every KKT solve. Off by default: it tripled the time per
    /// plan at K = 120 (7.3 ms vs 2.0 ms) with the same iteration count, and every
    /// accuracy property test passes without it.
    pub iterative_refinement_enable: bool,
    /// Keep the solver (symbolic factorization, scaling) between plans with the same
    /// sparsity pattern and only overwrite the values.
    pub reuse_structure: bool,
}

/// Allowed `max_iter`: at least one iteration; at most 10 000, a hundred times the
/// default and far beyond the 10-40 iterations both backends take on the lane
/// changes of the test suite, so that a runaway setting cannot stall a plan.
pub const MAX_ITER_RANGE: std::ops::RangeInclusive<u32> = 1..=10_000;

/// Allowed solver tolerances. Below 1e-14 a relative test asks for less than
/// about 50 ulp of the objective, which neither backend reaches in double
/// precision (they stop at `MaxIterations`); above 1e-2 a "solved" plan may be
/// 1 % off its optimum, and a tolerance of 1e308 would report "solved" after 0
/// iterations.
pub const TOLERANCE_RANGE: std::ops::RangeInclusive<f64> = 1e-14..=1e-2;

impl Default for SolverSettings {
    fn default() -> Self {
        Self {
            max_iter: 100,
            tol_gap_abs: 1e-8,
            tol_gap_rel: 1e-8,
            tol_feas: 1e-8,
            equilibrate_enable: true,
            iterative_refinement_enable: false,
            reuse_structure: true,
        }
    }
}

/// Everything about the planner that stays fixed between plans.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct PlannerConfig {
    /// Horizon `K` (number of stages); states are `X_0..X_K`.
    pub horizon: usize,
    /// Step `Δt` (s) of the forward-Euler discretization (Eqs. 12-14).
    pub dt: f64,
    /// Distance `l_fr` between the front and rear axles (m).
    pub wheelbase: f64,
    /// Weight `ρ_a` of the extra cost `ρ_a Σ (a_i - a_i^ref)²` (m⁻² s⁴), `a^ref` the
    /// acceleration of the problem's reference speed profile
    /// ([`Problem::reference_acceleration`](crate::Problem::reference_acceleration); 0 at
    /// constant speed). The printed cost leaves the acceleration free, which makes the
    /// optimum non-unique and, with `w9` or `w10` non-zero, absurd; see
    /// docs/experiments/0019-planner-model-cost-and-reference-acceleration.md.
    pub acceleration_penalty: f64,
    /// Lowest front wheel angle `δ_min` (rad) of Eq. (23).
    pub steering_min: f64,
    /// Highest front wheel angle `δ_max` (rad) of Eq. (23).
    pub steering_max: f64,
    /// Hard (paper) or soft lateral bounds.
    pub lateral_bounds_mode: LateralBoundsMode,
    /// QP backend.
    pub backend: Backend,
    /// Solver settings.
    pub solver: SolverSettings,
}

impl Default for PlannerConfig {
    fn default() -> Self {
        Self {
            horizon: 60,
            dt: 0.1,
            wheelbase: 2.8,
            acceleration_penalty: 1.0,
            steering_min: -0.5,
            steering_max: 0.5,
            lateral_bounds_mode: LateralBoundsMode::Soft { weight: 100.0 },
            backend: Backend::Riccati,
            solver: SolverSettings::default(),
        }
    }
}

impl PlannerConfig {
    /// Checks every field; the error names the field, its value and the bound.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let check = |field: &'static str, value: f64, ok: bool, bound: &'static str| {
            if ok {
                Ok(())
            } else {
                Err(ConfigError::OutOfRange {
                    field,
                    value,
                    bound,
                })
            }
        };
        if self.horizon == 0 || self.horizon > MAX_HORIZON {
            return Err(ConfigError::OutOfRange {
                field: "horizon",
                value: self.horizon as f64,
                bound: "in [1, 10000] (MAX_HORIZON)",
            });
        }
        let positive = "finite and > 0";
        check(
            "dt",
            self.dt,
            self.dt.is_finite() && self.dt > 0.0,
            positive,
        )?;
        check(
            "wheelbase",
            self.wheelbase,
            self.wheelbase.is_finite() && self.wheelbase > 0.0,
            positive,
        )?;
        check(
            "acceleration_penalty",
            self.acceleration_penalty,
            self.acceleration_penalty.is_finite() && self.acceleration_penalty >= 0.0,
            "finite and >= 0",
        )?;
        check(
            "steering_min",
            self.steering_min,
            self.steering_min.is_finite(),
            "finite",
        )?;
        check(
            "steering_max",
            self.steering_max,
            self.steering_max.is_finite() && self.steering_max >= self.steering_min,
            "finite and >= steering_min",
        )?;
        if let LateralBoundsMode::Soft { weight } = self.lateral_bounds_mode {
            check(
                "lateral_bounds_mode.soft.weight",
                weight,
                weight.is_finite() && weight > 0.0,
                positive,
            )?;
        }
        let s = &self.solver;
        check(
            "solver.max_iter",
            f64::from(s.max_iter),
            MAX_ITER_RANGE.contains(&s.max_iter),
            "an integer in [1, 10000]",
        )?;
        for (field, value) in [
            ("solver.tol_gap_abs", s.tol_gap_abs),
            ("solver.tol_gap_rel", s.tol_gap_rel),
            ("solver.tol_feas", s.tol_feas),
        ] {
            check(
                field,
                value,
                TOLERANCE_RANGE.contains(&value),
                "in [1e-14, 1e-2]",
            )?;
        }
        if self.backend == Backend::Clarabel && !cfg!(feature = "clarabel") {
            return Err(ConfigError::BackendUnavailable {
                backend: "clarabel",
                feature: "clarabel",
            });
        }
        Ok(())
    }
}
