//! The planner: validation, QP assembly, solve, and the plan with its features.

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use crate::backend::RawStatus;
#[cfg(feature = "clarabel")]
use crate::clarabel_backend::ClarabelBackend;
use crate::qp::{RowTag, StageQp, control_index, pattern_of, state_index};
use crate::riccati::RiccatiBackend;
use crate::validate::validate_problem;
use crate::{
    Backend, Control, Features, LateralBoundsMode, PlanError, PlannerConfig, Problem, State,
    StepRanges, features,
};

/// The extra cost terms added to `w · Φ` (documented in
/// docs/experiments/0019-planner-model-cost-and-reference-acceleration.md).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Extras {
    /// `ρ_a Σ_{i=0}^{K-1} a_i²`.
    pub acceleration: f64,
    /// `Σ_i (X_i - X_i^ref)ᵀ Q^p (X_i - X_i^ref)` over the steps with a reference.
    pub tracking: f64,
    /// `ρ_soft Σ_i σ_i` (soft lateral bounds only).
    pub lateral_slack: f64,
}

impl Extras {
    /// Sum of the extra terms.
    pub fn total(&self) -> f64 {
        self.acceleration + self.tracking + self.lateral_slack
    }
}

/// How the solver finished.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
#[non_exhaustive]
pub enum SolveStatus {
    /// Solved to the requested tolerances.
    Solved,
    /// Solved to clarabel's reduced tolerances only.
    AlmostSolved,
}

/// Statistics of one plan.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct SolveStats {
    /// Solver status.
    pub status: SolveStatus,
    /// Interior-point iterations.
    pub iterations: u32,
    /// Wall time to validate, assemble and set up (or update) the QP (s).
    pub build_seconds: f64,
    /// Wall time of the solve itself (s).
    pub solve_seconds: f64,
    /// Whether the previous plan had the same sparsity pattern, so that the cached
    /// structure was reused: clarabel's solver (values overwritten only) or the
    /// Riccati backend's buffers.
    pub structure_reused: bool,
}

/// An optimal lane-change trajectory.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Plan {
    /// `X_0..X_K`.
    pub states: Vec<State>,
    /// `U_0..U_{K-1}`.
    pub controls: Vec<Control>,
    /// The optimal value of the whole objective, `w · Φ(ψ) + extras`, including the
    /// constants of the squared distances and of the tracking term.
    pub objective: f64,
    /// The learned part `w · Φ(ψ)` (Eq. 15).
    pub learned_cost: f64,
    /// The extra terms.
    pub extras: Extras,
    /// `Φ(ψ)` of Eq. (34) for this trajectory.
    pub features: Features,
    /// Soft-bound violation `σ_i` per step `0..=K` (0 where there is no slack).
    pub lateral_violation: Vec<f64>,
    /// Solver statistics.
    pub stats: SolveStats,
}

/// The lane-change planner (Eqs. 9-23). Reuses its QP structure between plans with the
/// same sparsity pattern, and in closed loop starts from its last plan
/// ([`replan`](Self::replan)).
#[derive(Debug)]
pub struct Planner {
    config: PlannerConfig,
    qp: StageQp,
    #[cfg(feature = "clarabel")]
    clarabel: ClarabelBackend,
    riccati: RiccatiBackend,
    /// What identifies the last plan this planner returned (none after an error).
    last: Option<PlanKey>,
}

/// What identifies a plan among the planner's own: the bits of its objective, its
/// second and last states and its first control. `replan` warm-starts only from the
/// planner's last plan, whose multipliers the backend still holds.
#[derive(Debug, Clone, Copy, PartialEq)]
struct PlanKey {
    objective: u64,
    second: Option<State>,
    last: Option<State>,
    first_control: Option<Control>,
}

impl PlanKey {
    fn of(plan: &Plan) -> Self {
        Self {
            objective: plan.objective.to_bits(),
            second: plan.states.get(1).copied(),
            last: plan.states.last().copied(),
            first_control: plan.controls.first().copied(),
        }
    }
}

impl Planner {
    /// A planner for a validated configuration.
    pub fn new(config: PlannerConfig) -> Result<Self, PlanError> {
        config.validate()?;
        Ok(Self {
            config,
            qp: StageQp::default(),
            #[cfg(feature = "clarabel")]
            clarabel: ClarabelBackend::default(),
            riccati: RiccatiBackend::default(),
            last: None,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &PlannerConfig {
        &self.config
    }

    /// Plans one lane change: minimizes `w · Φ(ψ) + extras` subject to the dynamics,
    /// the boundary conditions and the bounds.
    pub fn plan(&mut self, problem: &Problem) -> Result<Plan, PlanError> {
        self.solve(problem, false)
    }

    /// Re-plans in closed loop: plans `problem`, the problem of `previous` one step
    /// later (the same horizon, weights and bound pattern; `initial` the state
    /// `previous` reaches after one step, positions relative to it as for any plan), as
    /// [`plan`](Self::plan) does, but with the Riccati backend starts the interior point
    /// from `previous` shifted by one step (its trajectory and its multipliers, moved
    /// off the bounds) instead of Mehrotra's cold start: fewer iterations for the same
    /// optimum, to the solver's tolerances.
    ///
    /// The warm start is used only when `previous` is the last plan this planner
    /// returned (the backend still holds its multipliers) and the bound pattern is
    /// unchanged; otherwise, and with [`Backend::Clarabel`], this is `plan(problem)`.
    /// A warm start is a hint, never a risk: when the warm-started solve fails (a
    /// shifted start far from the new optimum can exhaust the iterations, as the
    /// re-plan property test found), the problem is solved again from the cold start,
    /// so `replan` fails only where `plan` would.
    pub fn replan(&mut self, problem: &Problem, previous: &Plan) -> Result<Plan, PlanError> {
        let warm = self.last == Some(PlanKey::of(previous));
        match self.solve(problem, warm) {
            Err(_) if warm => self.solve(problem, false),
            result => result,
        }
    }

    /// Validates, assembles and solves; `warm`: start from the last plan shifted.
    fn solve(&mut self, problem: &Problem, warm: bool) -> Result<Plan, PlanError> {
        self.last = None;
        let plan = self.solve_inner(problem, warm)?;
        self.last = Some(PlanKey::of(&plan));
        Ok(plan)
    }

    fn solve_inner(&mut self, problem: &Problem, warm: bool) -> Result<Plan, PlanError> {
        let start = std::time::Instant::now();
        validate_problem(&self.config, problem)?;
        self.qp.assemble(&self.config, problem);
        let assembled = start.elapsed().as_secs_f64();
        let pattern = pattern_of(problem);
        let raw = match self.config.backend {
            Backend::Riccati => self
                .riccati
                .solve(&self.qp, pattern, &self.config.solver, warm),
            #[cfg(feature = "clarabel")]
            Backend::Clarabel => self
                .clarabel
                .solve(&self.qp, pattern, &self.config.solver)?,
            // `Planner::new` validated the configuration, which refuses this backend.
            #[cfg(not(feature = "clarabel"))]
            Backend::Clarabel => {
                return Err(crate::ConfigError::BackendUnavailable {
                    backend: "clarabel",
                    feature: "clarabel",
                }
                .into());
            }
        };
        let status = match raw.status {
            RawStatus::Solved => SolveStatus::Solved,
            RawStatus::AlmostSolved => SolveStatus::AlmostSolved,
            RawStatus::PrimalInfeasible => return Err(self.infeasible(&raw.multipliers)),
            RawStatus::DualInfeasible => return Err(PlanError::Unbounded),
            RawStatus::Failed(status) => {
                return Err(PlanError::SolverFailed {
                    status,
                    iterations: raw.iterations,
                });
            }
        };
        let k = self.config.horizon;
        let x = &raw.primal;
        let states: Vec<State> = (0..=k)
            .map(|i| {
                let o = state_index(i);
                State::from_array([x[o] + self.qp.origin, x[o + 1], x[o + 2], x[o + 3]])
            })
            .collect();
        let controls: Vec<Control> = (0..k)
            .map(|i| {
                let o = control_index(i);
                Control {
                    a: x[o],
                    delta: x[o + 1],
                }
            })
            .collect();
        let lateral_violation: Vec<f64> = self
            .qp
            .slack_of_step
            .iter()
            .map(|s| s.map_or(0.0, |j| x[self.qp.slack_column(j)]))
            .collect();
        let features = features(&states, &controls, &problem.preceding, &problem.adjacent)?;
        #[allow(
            clippy::expect_used,
            reason = "the problem was validated against the horizon"
        )]
        let learned_cost = problem
            .weights
            .dot(&features)
            .expect("weights and features share the horizon");
        let extras = self.extras(problem, &states, &controls, &lateral_violation);
        Ok(Plan {
            objective: self.qp.objective(x),
            states,
            controls,
            learned_cost,
            extras,
            features,
            lateral_violation,
            stats: SolveStats {
                status,
                iterations: raw.iterations,
                build_seconds: assembled + raw.setup_seconds,
                solve_seconds: raw.solve_seconds,
                structure_reused: raw.reused,
            },
        })
    }

    fn extras(
        &self,
        problem: &Problem,
        states: &[State],
        controls: &[Control],
        violation: &[f64],
    ) -> Extras {
        let dt = self.config.dt;
        let acceleration = self.config.acceleration_penalty
            * (controls.iter().enumerate())
                .map(|(i, u)| (u.a - problem.reference_acceleration(i, dt)).powi(2))
                .sum::<f64>();
        let tracking = problem.tracking.as_ref().map_or(0.0, |t| {
            states
                .iter()
                .zip(&t.reference)
                .filter_map(|(x, r)| r.map(|r| (x.to_array(), r.to_array())))
                .map(|(x, r)| {
                    (0..4)
                        .map(|c| t.weights[c] * (x[c] - r[c]).powi(2))
                        .sum::<f64>()
                })
                .sum()
        });
        let lateral_slack = match self.config.lateral_bounds_mode {
            LateralBoundsMode::Soft { weight } => weight * violation.iter().sum::<f64>(),
            LateralBoundsMode::Hard => 0.0,
        };
        Extras {
            acceleration,
            tracking,
            lateral_slack,
        }
    }

    /// Reads the steps that carry clarabel's primal infeasibility certificate.
    fn infeasible(&self, z: &[f64]) -> PlanError {
        let m_eq = self.qp.m_eq;
        let scale = z.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let threshold = 1e-6 * scale;
        let mut lateral = Vec::new();
        let mut steering = Vec::new();
        for (tag, &zi) in self.qp.row_tags.iter().zip(&z[m_eq..]) {
            if zi.abs() <= threshold {
                continue;
            }
            match *tag {
                RowTag::Lateral(i) => lateral.push(i),
                RowTag::Steering(i) => steering.push(i),
                RowTag::Slack => {}
            }
        }
        lateral.dedup();
        steering.dedup();
        PlanError::Infeasible {
            lateral_steps: StepRanges::from_steps(lateral),
            steering_steps: StepRanges::from_steps(steering),
        }
    }
}
