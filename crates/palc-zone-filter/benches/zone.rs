//! Benchmarks of the zone filter: fit on 10,000 samples, classify 1,000,000
//! points, and the lateral bounds of a K = 120 step horizon.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use palc_zone_filter::{
    BoundsConfig, Discriminant, FeatureInput, FeatureSet, Label, Projection, Sample, StepScene,
    ZoneConfig, ZoneModel, features,
};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

const SEED: u64 = 7;

/// A lane change at 20 m/s with the preceding vehicle at 18 m/s and the
/// adjacent one at 22 m/s; system samples safe, user samples 1 m further left.
fn lesson_samples(n: usize, rng: &mut ChaCha8Rng) -> Vec<Sample> {
    (0..n)
        .map(|k| {
            let t = 5.0 * rng.random::<f64>();
            let safe = k % 2 == 0;
            let l = 3.5 * (t / 5.0) + if safe { 0.0 } else { 1.0 } + 0.2 * rng.random::<f64>();
            let input = FeatureInput {
                ego_s: 20.0 * t,
                ego_l: l,
                ego_speed: 20.0,
                preceding: [30.0 + 18.0 * t, 0.0],
                adjacent: [10.0 + 22.0 * t, 3.5],
            };
            let y = if safe { Label::Safe } else { Label::Unsafe };
            Sample::new(features(FeatureSet::Paper, &input).expect("finite"), y)
        })
        .collect()
}

fn config(discriminant: Discriminant) -> ZoneConfig {
    ZoneConfig {
        discriminant,
        ..ZoneConfig::default()
    }
}

fn bench_zone(c: &mut Criterion) {
    let mut rng = ChaCha8Rng::seed_from_u64(SEED);
    let samples = lesson_samples(10_000, &mut rng);
    let points: Vec<f64> = lesson_samples(1_000_000, &mut rng)
        .into_iter()
        .flat_map(|s| s.x)
        .collect();
    let mut out = vec![0.0; 1_000_000];
    let scenes: Vec<StepScene> = (0..120)
        .map(|i| {
            let t = 0.05 * i as f64;
            StepScene {
                ego_s: 20.0 * t,
                reference_l: 3.5 * t / 6.0,
                ego_speed: 20.0,
                preceding: [30.0 + 18.0 * t, 0.0],
                adjacent: [10.0 + 22.0 * t, 3.5],
            }
        })
        .collect();

    for discriminant in [Discriminant::Linear, Discriminant::Quadratic] {
        let name = format!("{discriminant:?}").to_lowercase();
        c.bench_function(&format!("fit_10k_samples/{name}"), |b| {
            b.iter(|| ZoneModel::fit(config(discriminant), black_box(&samples)).expect("fit"))
        });
        let model = ZoneModel::fit(config(discriminant), &samples).expect("fit");
        let mut group = c.benchmark_group(format!("classify_1m_points/{name}"));
        group.sample_size(10);
        group.bench_function("posteriors_safe_into", |b| {
            b.iter(|| {
                model
                    .posteriors_safe_into(black_box(&points), &mut out)
                    .expect("classify")
            })
        });
        group.finish();
        for projection in [Projection::Paper, Projection::SafeInterval] {
            let bounds = BoundsConfig {
                projection,
                ..BoundsConfig::default()
            };
            c.bench_function(
                &format!("lateral_bounds_k120/{name}/{projection:?}").to_lowercase(),
                |b| {
                    b.iter(|| {
                        palc_zone_filter::lateral_bounds(&model, black_box(&scenes), &bounds)
                            .expect("bounds")
                    })
                },
            );
        }
    }
}

criterion_group!(benches, bench_zone);
criterion_main!(benches);
