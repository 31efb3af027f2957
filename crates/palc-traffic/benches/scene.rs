//! Time of one scene step, one test-bed cell construction and one prediction over the
//! paper's longest horizon (K = 120 steps of 0.05 s), on the densest cell (30 m headway).

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use palc_traffic::{EgoState, PredictionModel, ScenarioConfig, Scene};

fn densest_cell() -> (ScenarioConfig, palc_traffic::TestbedCell) {
    let config =
        ScenarioConfig::from_toml_str(include_str!("../../../configs/testbed.toml")).unwrap();
    let cell = config
        .testbed_cells()
        .unwrap()
        .into_iter()
        .find(|c| c.adjacent_headway == 30.0)
        .unwrap();
    (config, cell)
}

fn bench(c: &mut Criterion) {
    let (config, cell) = densest_cell();
    let scene = Scene::for_cell(&config, &cell).unwrap();
    c.bench_function("build_cell", |b| {
        b.iter(|| Scene::for_cell(black_box(&config), black_box(&cell)).unwrap())
    });
    c.bench_function("step", |b| {
        b.iter_batched_ref(
            || scene.clone(),
            |scene| {
                let ego = scene.ego().unwrap().state;
                let next = EgoState {
                    s: ego.s + ego.v * 0.05,
                    l: ego.l,
                    v: ego.v,
                    heading: 0.0,
                };
                scene.step(0.05, next).unwrap();
            },
            criterion::BatchSize::SmallInput,
        )
    });
    for (name, model) in [
        ("predict_constant_k120", PredictionModel::ConstantSpeed),
        ("predict_idm_k120", PredictionModel::IdmRollout),
    ] {
        c.bench_function(name, |b| {
            b.iter(|| black_box(&scene).predict(120, 0.05, model).unwrap())
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
