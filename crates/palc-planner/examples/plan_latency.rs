//! Percentiles of the per-plan time (validate, assemble, solve, extract) over many
//! plans, both backends measured in the same run and interleaved plan by plan, with
//! the speed-up of the Riccati backend over clarabel:
//! `cargo run --release -p palc-planner --example plan_latency`.
//!
//! Environment knobs (unset = the defaults): `HARD=0|1` (hard lateral bounds; default
//! both modes), `PLANS=600`, and for clarabel's settings study `EQUILIBRATE=0|1`,
//! `REFINE=0|1`, `REUSE=0|1`, `TOL=1e-8` (the tolerance applies to both backends).

use std::time::Instant;

use palc_planner::{Backend, LateralBoundsMode, Planner, PlannerConfig, Problem, SolverSettings};

#[path = "../fixtures/lane_change.rs"]
mod lane_change_fixture;
use lane_change_fixture::lane_change as problem;

fn flag(name: &str, default: bool) -> bool {
    std::env::var(name).map_or(default, |v| v != "0")
}

fn number(name: &str, default: f64) -> f64 {
    std::env::var(name)
        .ok()
        .and_then(|t| t.parse().ok())
        .unwrap_or(default)
}

/// The `q` quantile (nearest rank) of `v`, sorted in place.
fn percentile(v: &mut [f64], q: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * q).round() as usize]
}

fn main() {
    let tol = number("TOL", 1e-8);
    let plans = number("PLANS", 600.0) as usize;
    let defaults = SolverSettings::default();
    let solver = SolverSettings {
        equilibrate_enable: flag("EQUILIBRATE", defaults.equilibrate_enable),
        iterative_refinement_enable: flag("REFINE", defaults.iterative_refinement_enable),
        reuse_structure: flag("REUSE", defaults.reuse_structure),
        tol_gap_abs: tol,
        tol_gap_rel: tol,
        tol_feas: tol,
        ..defaults
    };
    let modes = match std::env::var("HARD").as_deref() {
        Ok("1") => vec![LateralBoundsMode::Hard],
        Ok("0") => vec![PlannerConfig::default().lateral_bounds_mode],
        _ => vec![
            LateralBoundsMode::Hard,
            PlannerConfig::default().lateral_bounds_mode,
        ],
    };
    println!("{solver:?}, {plans} plans per row (the first 100 of each backend discarded)");
    println!(
        "{:<24} {:>4} {:>5} | {:>9} {:>9} {:>5} | {:>9} {:>9} {:>5} | {:>7}",
        "lateral bounds",
        "K",
        "dt",
        "ric p50",
        "ric p99",
        "iters",
        "cla p50",
        "cla p99",
        "iters",
        "speedup"
    );
    for mode in modes {
        for dt in [0.1, 0.05] {
            for k in [40, 60, 80, 120] {
                let config = |backend| PlannerConfig {
                    horizon: k,
                    dt,
                    solver: solver.clone(),
                    backend,
                    lateral_bounds_mode: mode,
                    ..PlannerConfig::default()
                };
                let problems: Vec<Problem> = [18.0, 20.0, 22.0, 26.0]
                    .iter()
                    .map(|&v| problem(&config(Backend::Riccati), v))
                    .collect();
                let mut planners = [
                    Planner::new(config(Backend::Riccati)).unwrap(),
                    Planner::new(config(Backend::Clarabel)).unwrap(),
                ];
                let mut times = [Vec::new(), Vec::new()];
                let mut iterations = [0, 0];
                for n in 0..plans + 100 {
                    for (b, planner) in planners.iter_mut().enumerate() {
                        let start = Instant::now();
                        let plan = planner.plan(&problems[n % problems.len()]).unwrap();
                        let elapsed = start.elapsed().as_secs_f64() * 1e3;
                        if n >= 100 {
                            times[b].push(elapsed);
                            iterations[b] = iterations[b].max(plan.stats.iterations);
                        }
                    }
                }
                let [ric, cla] = &mut times;
                let (r50, r99) = (percentile(ric, 0.5), percentile(ric, 0.99));
                let (c50, c99) = (percentile(cla, 0.5), percentile(cla, 0.99));
                println!(
                    "{:<24} {k:>4} {dt:>5} | {r50:>9.3} {r99:>9.3} {:>5} | {c50:>9.3} {c99:>9.3} {:>5} | {:>6.1}x",
                    format!("{mode:?}"),
                    iterations[0],
                    iterations[1],
                    c50 / r50
                );
            }
        }
    }
}
