//! The driver estimate: the posterior from the scenes a user was seen in, and
//! the start it predicts in a new scene (what carrying an experience costs):
//! `cargo bench -p palc-harness --bench driver_estimate`.

use criterion::{Criterion, criterion_group, criterion_main};
use palc_harness::driver::{DriverEstimate, Prediction};
use palc_harness::{CellChoice, LearnConfig, NoObserver, prepare, run};

fn config(speed_case: &str, headway_m: f64) -> LearnConfig {
    let text = include_str!("../../../configs/learn.toml");
    LearnConfig::from_toml_str(text)
        .expect("the shipped config")
        .with_cell(CellChoice {
            speed_case: speed_case.into(),
            headway_m,
            seed: 1,
        })
}

fn estimate(c: &mut Criterion) {
    // The paper's neutral user seen in two scenes, predicted in a third.
    let first = run(&config("collector-high", 40.0), None, &mut NoObserver).expect("a run");
    let second = run(
        &config("arterial-slow", 50.0),
        Some(&first.experience),
        &mut NoObserver,
    )
    .expect("a run");
    let onsets = &second.experience.onsets;
    let target = prepare(&config("collector-slow", 30.0)).expect("a scene");
    let duration_s = 2.1;
    let posterior = DriverEstimate::from_onsets(onsets, duration_s).expect("recorded scenes");
    let predict = |estimate: &DriverEstimate| {
        estimate.predict(
            &target.situations,
            target.dt,
            target.set_speed,
            None,
            duration_s,
        )
    };
    assert!(matches!(predict(&posterior), Prediction::Start(_)));
    let mut group = c.benchmark_group("driver_estimate");
    group.bench_function(format!("posterior_{}_scenes", posterior.scenes()), |b| {
        b.iter(|| DriverEstimate::from_onsets(onsets, duration_s))
    });
    group.bench_function("predict", |b| b.iter(|| predict(&posterior)));
    group.finish();
}

criterion_group!(benches, estimate);
criterion_main!(benches);
