//! Per-plan time (validate, assemble, update or build, solve, extract) of the
//! lane-change QP for both backends, K in {40, 60, 80, 120}, dt in {0.1, 0.05}, hard
//! and soft lateral bounds.
//!
//! `reused`: one planner, problems whose values change between calls (the loop's case).
//! `fresh`: a new planner per plan (clarabel: symbolic analysis and equilibration every
//! time; riccati: buffers allocated every time).
//!
//! Percentiles (p50, p99) and the speed-up in one run:
//! `cargo run --release -p palc-planner --example plan_latency`.
//!
//! `closed_loop` (K = 120, dt = 0.05, the Riccati backend): a plan with hard and with
//! soft lateral bounds (`hard`, `soft`), and the closed loop's re-plan (`warm_hard`,
//! `warm_soft`): a chain of 40 problems, each one step after the last
//! (`lane_change_fixture::shifted`), re-planned with `Planner::replan` from the plan of
//! the one before; the chain restarts with a cold plan every 40 plans, outside the
//! measurement (only re-plans are timed). Criterion's median is the p50.

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use palc_planner::{Backend, LateralBoundsMode, Planner, PlannerConfig, Problem};

#[path = "../fixtures/lane_change.rs"]
mod lane_change_fixture;
use lane_change_fixture::{lane_change as problem, shifted};

fn bench_plan(c: &mut Criterion) {
    let mut group = c.benchmark_group("plan");
    group
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3));
    for (mode_name, mode) in [
        ("hard", LateralBoundsMode::Hard),
        ("soft", LateralBoundsMode::Soft { weight: 100.0 }),
    ] {
        for dt in [0.1, 0.05] {
            for k in [40, 60, 80, 120] {
                for (backend_name, backend) in [
                    ("riccati", Backend::Riccati),
                    ("clarabel", Backend::Clarabel),
                ] {
                    let config = PlannerConfig {
                        horizon: k,
                        dt,
                        backend,
                        lateral_bounds_mode: mode,
                        ..PlannerConfig::default()
                    };
                    let problems: Vec<Problem> = [18.0, 20.0, 22.0, 26.0]
                        .iter()
                        .map(|&v| problem(&config, v))
                        .collect();
                    let id = format!("{backend_name},{mode_name},K={k},dt={dt}");
                    let mut planner = Planner::new(config.clone()).unwrap();
                    let mut n = 0;
                    group.bench_function(BenchmarkId::new("reused", &id), |b| {
                        b.iter(|| {
                            n += 1;
                            black_box(planner.plan(&problems[n % problems.len()]).unwrap())
                        })
                    });
                    if k == 120 {
                        group.bench_function(BenchmarkId::new("fresh", &id), |b| {
                            b.iter(|| {
                                n += 1;
                                let mut planner = Planner::new(config.clone()).unwrap();
                                black_box(planner.plan(&problems[n % problems.len()]).unwrap())
                            })
                        });
                    }
                }
            }
        }
    }
    group.finish();
}

/// Plans in closed loop at K = 120, dt = 0.05: cold plans and warm re-plans.
fn bench_closed_loop(c: &mut Criterion) {
    const CHAIN: usize = 40;
    let mut group = c.benchmark_group("closed_loop");
    group
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3));
    for (mode_name, mode) in [
        ("hard", LateralBoundsMode::Hard),
        ("soft", LateralBoundsMode::Soft { weight: 100.0 }),
    ] {
        let config = PlannerConfig {
            horizon: 120,
            dt: 0.05,
            backend: Backend::Riccati,
            lateral_bounds_mode: mode,
            ..PlannerConfig::default()
        };
        let mut planner = Planner::new(config.clone()).unwrap();
        let problems: Vec<Problem> = [18.0, 20.0, 22.0, 26.0]
            .iter()
            .map(|&v| problem(&config, v))
            .collect();
        let mut n = 0;
        group.bench_function(mode_name, |b| {
            b.iter(|| {
                n += 1;
                black_box(planner.plan(&problems[n % problems.len()]).unwrap())
            })
        });
        // The chain of the closed loop, planned once.
        let mut chain = vec![problem(&config, 20.0)];
        let mut previous = planner.plan(&chain[0]).unwrap();
        for _ in 1..CHAIN {
            let next = shifted(chain.last().unwrap(), &previous);
            previous = planner.replan(&next, &previous).unwrap();
            chain.push(next);
        }
        // Only the re-plans are timed: the chain's first problem is planned cold,
        // outside the measurement, each time the chain starts again.
        let mut previous = planner.plan(&chain[0]).unwrap();
        let mut n = 0;
        group.bench_function(format!("warm_{mode_name}"), |b| {
            b.iter_custom(|iterations| {
                let mut timed = Duration::ZERO;
                for _ in 0..iterations {
                    n = n % (CHAIN - 1) + 1;
                    if n == 1 {
                        previous = planner.plan(&chain[0]).unwrap();
                    }
                    let start = Instant::now();
                    let plan = planner.replan(&chain[n], &previous).unwrap();
                    timed += start.elapsed();
                    previous = black_box(plan);
                }
                timed
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench_closed_loop, bench_plan);
criterion_main!(benches);
