//! Percentiles of the time of one closed-loop re-plan at K = 120 (fresh
//! predictions, zone bounds, plan), over many re-plans:
//! `cargo run --release -p palc-harness --example replan_latency` (`REPLANS=1000`).

use std::time::Instant;

#[path = "../benches/common/fixture.rs"]
mod fixture;

fn main() {
    let replans = std::env::var("REPLANS")
        .ok()
        .and_then(|t| t.parse().ok())
        .unwrap_or(1000usize);
    let fixture = fixture::Fixture::load();
    let mut times = Vec::with_capacity(replans);
    let mut planning = Vec::with_capacity(replans);
    for _ in 0..replans {
        let start = Instant::now();
        let outcome = fixture.replan();
        times.push(start.elapsed().as_secs_f64() * 1e3);
        let palc_harness::closed_loop::Replan::Drive(plan) = outcome else {
            panic!("the re-plan is not driven: {outcome:?}");
        };
        planning.push((plan.stats.build_seconds + plan.stats.solve_seconds) * 1e3);
    }
    for (what, mut times) in [("re-plan", times), ("of which the plan", planning)] {
        times.sort_by(f64::total_cmp);
        let q = |q: f64| times[((times.len() - 1) as f64 * q).round() as usize];
        println!(
            "{what} at K = {}: {} re-plans, p50 {:.3} ms, p90 {:.3} ms, p99 {:.3} ms, max {:.3} ms",
            fixture::REPLAN_STEPS,
            times.len(),
            q(0.5),
            q(0.9),
            q(0.99),
            q(1.0)
        );
    }
}
