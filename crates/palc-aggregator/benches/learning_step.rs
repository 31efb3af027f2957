//! One learning step (expert, correction with its inner plans, new plan) per method,
//! at the paper's largest horizon and a typical one.

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use palc_aggregator::{AggregatorOptions, Experience, learn_from_lesson};
use palc_planner::{Planner, Weights};

fn learning_step(c: &mut Criterion) {
    let mut group = c.benchmark_group("learn_from_lesson");
    for (horizon, dt) in [(60, 0.1), (120, 0.05)] {
        let mut planner = Planner::new(common::config(horizon, dt)).unwrap();
        let template = common::template(horizon, dt);
        let lesson = common::lesson(&mut planner, &template, horizon / 5, 0.5);
        let experience = Experience::new(
            "u",
            "bench",
            "bench",
            Weights::constant(horizon, common::STANDARD),
            dt,
        )
        .unwrap();
        for (name, options) in [
            ("palc", AggregatorOptions::default()),
            ("paper", AggregatorOptions::paper()),
        ] {
            group.bench_function(BenchmarkId::new(name, format!("K{horizon}")), |b| {
                b.iter(|| {
                    learn_from_lesson(&mut planner, &experience, &lesson, &template, &options)
                        .unwrap()
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, learning_step);
criterion_main!(benches);
