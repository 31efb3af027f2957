//! One closed-loop re-plan at K = 120 (fresh predictions by a rollout of the
//! scene, the zone's bounds, the plan): `cargo bench -p palc-harness --bench replan`.
//! Percentiles: `cargo run --release -p palc-harness --example replan_latency`.

use criterion::{Criterion, criterion_group, criterion_main};

#[path = "common/fixture.rs"]
mod fixture;

fn replan(c: &mut Criterion) {
    let fixture = fixture::Fixture::load();
    assert!(matches!(
        fixture.replan(),
        palc_harness::closed_loop::Replan::Drive(_)
    ));
    c.bench_function("replan_k120", |b| b.iter(|| fixture.replan()));
}

criterion_group!(benches, replan);
criterion_main!(benches);
