//! The study server's tick with re-planning (`[planning.closed_loop]` on): one
//! planning step of a live lane change, its record line, and at a lane change's
//! end its lesson and the synced record: `cargo bench -p palc-drive --bench tick`.
//! Percentiles (the goal: p99 under 2 ms at 20 Hz):
//! `cargo run --release -p palc-drive --example tick_latency`.

use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
use palc_drive::control::Control;
use palc_drive::{Phase, Protocol, Session};

const PROTOCOL: &str = r#"
participant = "bench"
[[scene]]
speed_case = "collector-high"
headway_m = 40.0
seed = 1
max_lane_changes = 100
success_streak = 100
"#;

fn session(dir: &std::path::Path) -> Session {
    let path = dir.join("study.toml");
    std::fs::write(&path, PROTOCOL).unwrap();
    let (protocol, mut base) = Protocol::load(&path).unwrap();
    base.planning.closed_loop.enabled = true;
    Session::open(protocol, base, &dir.join("out"), false).unwrap()
}

fn tick(c: &mut Criterion) {
    c.bench_function("tick_closed_loop", |b| {
        b.iter_custom(|iterations| {
            // Only the ticks are timed; a session that is done is replaced.
            let mut total = Duration::ZERO;
            let mut dir = tempfile::tempdir().unwrap();
            let mut session = session(dir.path());
            for _ in 0..iterations {
                if session.phase() == Phase::Done {
                    dir = tempfile::tempdir().unwrap();
                    session = self::session(dir.path());
                }
                if session.phase() != Phase::Driving {
                    session.start().unwrap();
                }
                let started = Instant::now();
                std::hint::black_box(session.tick(Control::default()).unwrap());
                total += started.elapsed();
            }
            total
        })
    });
}

criterion_group!(benches, tick);
criterion_main!(benches);
