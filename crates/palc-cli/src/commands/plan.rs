//! `palc plan --problem <file.json> [--out <file.json>]`: plan one lane change with the
//! MPC of `palc-planner` (paper Eqs. 9-23) and write the trajectory as JSON.
//!
//! Input (JSON object; example: configs/examples/plan-problem.json):
//! - `config`: the fields of `PlannerConfig`, each optional (defaults in brackets):
//!   `horizon` K \[60\], `dt` s [0.1], `wheelbase` m [2.8], `acceleration_penalty` [1.0],
//!   `steering_min`/`steering_max` rad [-0.5/0.5],
//!   `lateral_bounds_mode`: `"hard"` or `{"soft": {"weight": w}}` [soft, 100],
//!   `backend`: `"riccati"` \[default\] or `"clarabel"`, `solver`: `{max_iter, tol_gap_abs, tol_gap_rel, tol_feas,
//!   equilibrate_enable, iterative_refinement_enable, reuse_structure}`.
//! - `problem`: `initial` `{s, v, l, phi}` (X_0, s relative to the ego's start is
//!   recommended); `reference_speed` (K numbers, m/s); `curvature` (1/m, optional);
//!   `weights` (K arrays of 10: column i-1 weighs stage i of Eq. 15);
//!   `preceding`, `adjacent` (K objects `{s, l}`, steps 0..K-1);
//!   `terminal` `{s (optional), v, l}` (phi_K = 0); `lateral_bounds` (K+1 entries, each
//!   `null` or `{min, max}` with either side optional); `tracking` (optional,
//!   `{weights: [q_s, q_v, q_l, q_phi], reference: K+1 entries of null or {s, v, l, phi}}`).
//!
//! Output (JSON object): `status` (`solved`, `almost_solved`, or on refusal `infeasible`,
//! `non_convex`, `unbounded`, `solver_failed`, `invalid_input`); on success `states`
//! (K+1), `controls` (K, `{a, delta}`), `objective` (= `learned_cost` + extras total),
//! `learned_cost` (w · Φ), `extras` `{acceleration, tracking, lateral_slack}`,
//! `features` (K arrays of 10, Eq. 34), `lateral_violation` (K+1), `stats`
//! `{status, iterations, build_seconds, solve_seconds, structure_reused}`; on refusal
//! `message`. A refusal exits with an error: one of the problem (`infeasible`,
//! `unbounded`, `solver_failed`) after writing the output, one of the input
//! (`invalid_input`, `non_convex` weights) on stderr alone, with `--out` untouched.

use std::path::PathBuf;

use anyhow::{Context, bail};
use clap::Args;
use palc_aggregator::output;
use palc_planner::{Plan, PlanError, Planner, PlannerConfig, Problem, SolveStatus};
use serde::{Deserialize, Serialize};

use crate::console;

/// Plan one lane change from a JSON problem.
#[derive(Debug, Args)]
pub struct PlanArgs {
    /// The problem: JSON with `config` (PlannerConfig fields) and `problem` (see
    /// configs/examples/plan-problem.json).
    #[arg(long)]
    problem: PathBuf,
    /// Where to write the plan (JSON); stdout without it.
    #[arg(long)]
    out: Option<PathBuf>,
}

/// The input file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct PlanInput {
    #[serde(default)]
    pub(crate) config: PlannerConfig,
    pub(crate) problem: Problem,
}

/// The output file.
#[derive(Debug, Serialize)]
struct PlanOutput {
    status: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    message: Option<String>,
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    plan: Option<Plan>,
}

fn refusal_status(error: &PlanError) -> &'static str {
    match error {
        PlanError::ZoneTooNarrow { .. }
        | PlanError::BoundaryOutsideZone { .. }
        | PlanError::Infeasible { .. } => "infeasible",
        PlanError::NonConvex { .. } => "non_convex",
        PlanError::Unbounded => "unbounded",
        PlanError::SolverFailed { .. } => "solver_failed",
        _ => "invalid_input",
    }
}

/// Runs `palc plan`.
pub fn run(args: PlanArgs) -> anyhow::Result<()> {
    let path = &args.problem;
    let bytes = palc_aggregator::input::read(path)?;
    let input: PlanInput = crate::parse::json(bytes.as_slice())
        .with_context(|| format!("cannot read the plan problem in {}", path.display()))?;
    // A bound with min > max allows no `l`; soft bounds would plan through it and
    // report "solved", so the input is refused (the planner's hard mode says
    // `ZoneTooNarrow` itself, for bounds a zone filter computed).
    let inverted = (input.problem.lateral_bounds.iter().enumerate()).find_map(|(i, b)| {
        let (min, max) = (b.as_ref()?.min?, b.as_ref()?.max?);
        (min > max).then_some((i, min, max))
    });
    if let Some((i, min, max)) = inverted {
        bail!(
            "{}: `problem.lateral_bounds[{i}].min` is {min:?}, expected at most `problem.lateral_bounds[{i}].max` = {max:?}",
            path.display()
        );
    }
    let result = Planner::new(input.config).and_then(|mut planner| planner.plan(&input.problem));
    let output = match &result {
        Ok(plan) => PlanOutput {
            status: match plan.stats.status {
                SolveStatus::Solved => "solved",
                _ => "almost_solved",
            },
            message: None,
            plan: Some(plan.clone()),
        },
        Err(error) => PlanOutput {
            status: refusal_status(error),
            message: Some(error.to_string()),
            plan: None,
        },
    };
    if let Err(error) = &result {
        if matches!(output.status, "invalid_input" | "non_convex") {
            // An input that cannot be planned is not an outcome: no file is touched.
            bail!("{}: {error}", path.display());
        }
    }
    let mut bytes = serde_json::to_vec_pretty(&output)?;
    bytes.push(b'\n');
    match &args.out {
        Some(out) => output::write(out, &bytes)?,
        None => console::data(&bytes).context("cannot write the plan to stdout")?,
    }
    if let Err(error) = result {
        bail!("{}: {error}", path.display());
    }
    Ok(())
}
