//! Percentiles of the study server's tick with re-planning (`[planning.closed_loop]`
//! on, re-planning every 0.2 s), over 2,000 ticks of lane changes without a
//! takeover and, apart, of lane changes taken over at their 10th step; each
//! lane change's last tick includes the lesson and the synced record:
//! `cargo run --release -p palc-drive --example tick_latency`.

use std::time::Instant;

use palc_drive::control::Control;
use palc_drive::{Phase, Protocol, Session};

const PROTOCOL: &str = r#"
participant = "latency"
[[scene]]
speed_case = "collector-high"
headway_m = 40.0
seed = 1
max_lane_changes = 100
success_streak = 100
"#;

/// Tick times (ms) of `ticks` ticks, taking over at step `take_over_at` if given.
fn measure(ticks: usize, take_over_at: Option<usize>) -> Vec<f64> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("study.toml");
    std::fs::write(&path, PROTOCOL).unwrap();
    let (protocol, mut base) = Protocol::load(&path).unwrap();
    base.planning.closed_loop.enabled = true;
    let mut session = Session::open(protocol, base, &dir.path().join("out"), false).unwrap();
    let mut times = Vec::with_capacity(ticks);
    let mut step = 0;
    while times.len() < ticks {
        if session.phase() != Phase::Driving {
            session.start().unwrap();
            step = 0;
        }
        let control = Control {
            take_over: take_over_at.is_some_and(|at| step >= at),
            lateral: 256,
            speed: 0,
        };
        let started = Instant::now();
        let frame = session.tick(control).unwrap();
        times.push(started.elapsed().as_secs_f64() * 1e3);
        step += 1;
        if frame.phase == Phase::Done {
            break;
        }
    }
    times.sort_by(f64::total_cmp);
    times
}

fn main() {
    for (label, take_over_at) in [("no takeover", None), ("takeover at step 10", Some(10))] {
        let times = measure(2000, take_over_at);
        let at = |q: f64| times[((times.len() - 1) as f64 * q).round() as usize];
        println!(
            "{label}: {} ticks, p50 {:.3} ms, p90 {:.3} ms, p99 {:.3} ms, max {:.3} ms",
            times.len(),
            at(0.5),
            at(0.9),
            at(0.99),
            at(1.0)
        );
    }
}
