//! Per-plan time (validate, assemble, update or build, solve, extract) of the
//! lane-change QP for K in {40, 60, 80, 120} and dt in {0.1, 0.05}.
//!
//! `reused`: one planner, problems whose values change between calls (the loop's case).
//! `fresh`: a new planner per plan (symbolic analysis and equilibration every time).

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use palc_planner::{Planner, PlannerConfig, Problem};

#[path = "../fixtures/lane_change.rs"]
mod lane_change_fixture;
use lane_change_fixture::lane_change as problem;

fn bench_plan(c: &mut Criterion) {
    let mut group = c.benchmark_group("plan");
    for dt in [0.1, 0.05] {
        for k in [40, 60, 80, 120] {
            let config = PlannerConfig {
                horizon: k,
                dt,
                ..PlannerConfig::default()
            };
            let problems: Vec<Problem> = [18.0, 20.0, 22.0, 26.0]
                .iter()
                .map(|&v| problem(&config, v))
                .collect();
            let id = format!("K={k},dt={dt}");
            let mut planner = Planner::new(config.clone()).unwrap();
            let mut n = 0;
            group.bench_function(BenchmarkId::new("reused", &id), |b| {
                b.iter(|| {
                    n += 1;
                    black_box(planner.plan(&problems[n % problems.len()]).unwrap())
                })
            });
            group.bench_function(BenchmarkId::new("fresh", &id), |b| {
                b.iter(|| {
                    n += 1;
                    let mut planner = Planner::new(config.clone()).unwrap();
                    black_box(planner.plan(&problems[n % problems.len()]).unwrap())
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench_plan);
criterion_main!(benches);
