//! Percentiles of the per-plan time (build + solve) over many plans, for the settings
//! study in the crate docs: `cargo run --release -p palc-planner --example plan_latency`.
//!
//! Environment knobs (for measuring solver settings, unset = the defaults):
//! `BACKEND=riccati|clarabel`, `HARD=0|1` (hard lateral bounds),
//! `EQUILIBRATE=0|1`, `REFINE=0|1`, `REUSE=0|1`, `TOL=1e-6`.

use std::time::Instant;

use palc_planner::{Backend, LateralBoundsMode, Planner, PlannerConfig, Problem, SolverSettings};

#[path = "../fixtures/lane_change.rs"]
mod lane_change_fixture;
use lane_change_fixture::lane_change as problem;

fn flag(name: &str, default: bool) -> bool {
    std::env::var(name).map_or(default, |v| v != "0")
}

fn main() {
    let tol: f64 = std::env::var("TOL")
        .ok()
        .and_then(|t| t.parse().ok())
        .unwrap_or(1e-8);
    let defaults = SolverSettings::default();
    let solver = SolverSettings {
        equilibrate_enable: flag("EQUILIBRATE", defaults.equilibrate_enable),
        iterative_refinement_enable: flag("REFINE", defaults.iterative_refinement_enable),
        reuse_structure: flag("REUSE", defaults.reuse_structure),
        tol_gap_abs: tol,
        tol_gap_rel: tol,
        tol_feas: tol,
        ..SolverSettings::default()
    };
    let backend = match std::env::var("BACKEND").as_deref() {
        Ok("clarabel") => Backend::Clarabel,
        Ok("riccati") => Backend::Riccati,
        _ => PlannerConfig::default().backend,
    };
    let lateral_bounds_mode = if flag("HARD", false) {
        LateralBoundsMode::Hard
    } else {
        PlannerConfig::default().lateral_bounds_mode
    };
    println!("{backend:?} {lateral_bounds_mode:?} {solver:?}");
    println!(
        "{:>4} {:>5} {:>9} {:>9} {:>6} {:>9} {:>9}",
        "K", "dt", "p50 ms", "p99 ms", "iters", "build p50", "solve p50"
    );
    for dt in [0.1, 0.05] {
        for k in [40, 60, 80, 120] {
            let config = PlannerConfig {
                horizon: k,
                dt,
                solver: solver.clone(),
                backend,
                lateral_bounds_mode,
                ..PlannerConfig::default()
            };
            let problems: Vec<Problem> = [18.0, 20.0, 22.0, 26.0]
                .iter()
                .map(|&v| problem(&config, v))
                .collect();
            let mut planner = Planner::new(config).unwrap();
            let mut times = Vec::new();
            let mut builds = Vec::new();
            let mut solves = Vec::new();
            let mut iterations = 0;
            for n in 0..600 {
                let start = Instant::now();
                let plan = planner.plan(&problems[n % problems.len()]).unwrap();
                let elapsed = start.elapsed().as_secs_f64() * 1e3;
                if n >= 100 {
                    times.push(elapsed);
                    builds.push(plan.stats.build_seconds * 1e3);
                    solves.push(plan.stats.solve_seconds * 1e3);
                    iterations = iterations.max(plan.stats.iterations);
                }
            }
            let p = |v: &mut Vec<f64>, q: f64| {
                v.sort_by(f64::total_cmp);
                v[((v.len() - 1) as f64 * q).round() as usize]
            };
            println!(
                "{k:>4} {dt:>5} {:>9.3} {:>9.3} {iterations:>6} {:>9.3} {:>9.3}",
                p(&mut times, 0.5),
                p(&mut times, 0.99),
                p(&mut builds, 0.5),
                p(&mut solves, 0.5)
            );
        }
    }
}
