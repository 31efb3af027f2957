//! Property tests of the GDA model's invariants (issue: posteriors, permutation,
//! affine invariance, label swap, online = batch, linear boundary).

use palc_zone_filter::{Discriminant, FeatureSet, Label, Sample, ZoneConfig, ZoneModel};
use proptest::prelude::*;

const D: usize = 4;

fn config(discriminant: Discriminant, ridge: f64) -> ZoneConfig {
    ZoneConfig {
        feature_set: FeatureSet::NoDistance,
        discriminant,
        ridge,
        quadratic_pooling: 0.0,
    }
}

fn discriminant() -> impl Strategy<Value = Discriminant> {
    prop_oneof![Just(Discriminant::Linear), Just(Discriminant::Quadratic)]
}

/// Two classes of 6..30 points each in 4 dimensions, the safe class shifted.
fn samples() -> impl Strategy<Value = Vec<Sample>> {
    let point = || prop::array::uniform4(-5.0..5.0f64);
    (
        prop::collection::vec(point(), 6..30),
        prop::collection::vec(point(), 6..30),
        prop::array::uniform4(-3.0..3.0f64),
    )
        .prop_map(|(safe, unsafe_, shift)| {
            let mut all: Vec<Sample> = safe
                .into_iter()
                .map(|x| {
                    Sample::new(
                        x.iter().zip(&shift).map(|(a, b)| a + b).collect(),
                        Label::Safe,
                    )
                })
                .collect();
            all.extend(
                unsafe_
                    .into_iter()
                    .map(|x| Sample::new(x.to_vec(), Label::Unsafe)),
            );
            all
        })
}

fn query() -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(-8.0..8.0f64, D)
}

fn close(a: f64, b: f64, tolerance: f64) -> bool {
    (a - b).abs() <= tolerance * (1.0 + a.abs().max(b.abs()))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn posteriors_are_probabilities_that_sum_to_one(
        samples in samples(), x in query(), kind in discriminant()
    ) {
        let model = ZoneModel::fit(config(kind, 1e-6), &samples).unwrap();
        let p1 = model.posterior_safe(&x).unwrap();
        let p0 = model.posterior_unsafe(&x).unwrap();
        prop_assert!((0.0..=1.0).contains(&p1) && (0.0..=1.0).contains(&p0));
        prop_assert!((p1 + p0 - 1.0).abs() <= 1e-12);
        // Far from both means the posterior is still a number.
        let far: Vec<f64> = x.iter().map(|v| v * 1e6).collect();
        let p_far = model.posterior_safe(&far).unwrap();
        prop_assert!((0.0..=1.0).contains(&p_far));
    }

    #[test]
    fn predictions_do_not_depend_on_sample_order(
        samples in samples(), x in query(), kind in discriminant(), rotate in 0usize..100
    ) {
        let mut permuted = samples.clone();
        permuted.reverse();
        let len = permuted.len();
        permuted.rotate_left(rotate % len);
        let a = ZoneModel::fit(config(kind, 1e-6), &samples).unwrap().log_odds_safe(&x).unwrap();
        let b = ZoneModel::fit(config(kind, 1e-6), &permuted).unwrap().log_odds_safe(&x).unwrap();
        prop_assert!(close(a, b, 1e-9), "{a} vs {b}");
    }

    #[test]
    fn predictions_are_invariant_under_invertible_affine_maps(
        samples in samples(),
        x in query(),
        kind in discriminant(),
        mixing in prop::collection::vec(-0.2..0.2f64, D * D),
        scales in prop::collection::vec(0.01..100.0f64, D),
        offset in prop::collection::vec(-50.0..50.0f64, D),
    ) {
        // A = diag(scales) (I + M) with |M| entries <= 0.2: diagonally dominant, invertible.
        let map = |v: &[f64]| -> Vec<f64> {
            (0..D)
                .map(|r| {
                    let mixed: f64 = (0..D)
                        .map(|c| (if r == c { 1.0 } else { 0.0 } + mixing[r * D + c]) * v[c])
                        .sum();
                    scales[r] * mixed + offset[r]
                })
                .collect()
        };
        let mapped: Vec<Sample> = samples.iter().map(|s| Sample::new(map(&s.x), s.y)).collect();
        // The ridge is not affine invariant (only scale invariant), so it is off here.
        let a = ZoneModel::fit(config(kind, 0.0), &samples).unwrap().log_odds_safe(&x).unwrap();
        let b = ZoneModel::fit(config(kind, 0.0), &mapped).unwrap().log_odds_safe(&map(&x)).unwrap();
        prop_assert!(close(a, b, 1e-6), "{a} vs {b}");
    }

    #[test]
    fn per_feature_scaling_does_not_change_predictions_even_with_a_ridge(
        samples in samples(),
        x in query(),
        kind in discriminant(),
        scales in prop::collection::vec(1e-3..1e3f64, D),
    ) {
        let map = |v: &[f64]| -> Vec<f64> { v.iter().zip(&scales).map(|(a, s)| a * s).collect() };
        let mapped: Vec<Sample> = samples.iter().map(|s| Sample::new(map(&s.x), s.y)).collect();
        let a = ZoneModel::fit(config(kind, 1e-3), &samples).unwrap().log_odds_safe(&x).unwrap();
        let b = ZoneModel::fit(config(kind, 1e-3), &mapped).unwrap().log_odds_safe(&map(&x)).unwrap();
        prop_assert!(close(a, b, 1e-8), "{a} vs {b}");
    }

    #[test]
    fn swapping_labels_swaps_classes(samples in samples(), x in query(), kind in discriminant()) {
        let swapped: Vec<Sample> = samples.iter().map(|s| Sample::new(s.x.clone(), s.y.flipped())).collect();
        let model = ZoneModel::fit(config(kind, 1e-6), &samples).unwrap();
        let swapped_model = ZoneModel::fit(config(kind, 1e-6), &swapped).unwrap();
        let a = model.log_odds_safe(&x).unwrap();
        let b = swapped_model.log_odds_safe(&x).unwrap();
        prop_assert!(close(a, -b, 1e-9), "{a} vs {b}");
        prop_assert!((model.posterior_safe(&x).unwrap() - swapped_model.posterior_unsafe(&x).unwrap()).abs() <= 1e-12);
        if a.abs() > 1e-9 {
            prop_assert_eq!(model.classify(&x).unwrap(), swapped_model.classify(&x).unwrap().flipped());
        }
    }

    #[test]
    fn online_updates_equal_a_batch_fit(
        samples in samples(), x in query(), kind in discriminant(), cuts in prop::collection::vec(0usize..100, 0..5)
    ) {
        let batch = ZoneModel::fit(config(kind, 1e-6), &samples).unwrap();
        let mut bounds: Vec<usize> = cuts.iter().map(|c| c % samples.len()).collect();
        bounds.push(0);
        bounds.push(samples.len());
        bounds.sort_unstable();
        let mut online = ZoneModel::new(config(kind, 1e-6)).unwrap();
        for pair in bounds.windows(2) {
            online.update(&samples[pair[0]..pair[1]]).unwrap();
        }
        for (b, o) in [
            (batch.safe_statistics(), online.safe_statistics()),
            (batch.unsafe_statistics(), online.unsafe_statistics()),
        ] {
            prop_assert_eq!(b.count, o.count);
            for (u, v) in b.mean.iter().chain(&b.scatter).zip(o.mean.iter().chain(&o.scatter)) {
                prop_assert!(close(*u, *v, 1e-10), "{u} vs {v}");
            }
        }
        let a = batch.log_odds_safe(&x).unwrap();
        let b = online.log_odds_safe(&x).unwrap();
        prop_assert!(close(a, b, 1e-8), "{a} vs {b}");
    }

    #[test]
    fn the_shared_covariance_boundary_is_linear_in_feature_space(
        samples in samples(), x in query(), z in query(), t in -2.0..3.0f64
    ) {
        let model = ZoneModel::fit(config(Discriminant::Linear, 1e-6), &samples).unwrap();
        let mix: Vec<f64> = x.iter().zip(&z).map(|(a, b)| t * a + (1.0 - t) * b).collect();
        let expected = t * model.log_odds_safe(&x).unwrap() + (1.0 - t) * model.log_odds_safe(&z).unwrap();
        let found = model.log_odds_safe(&mix).unwrap();
        prop_assert!(close(found, expected, 1e-9), "{found} vs {expected}");
    }

    #[test]
    fn batch_posteriors_equal_single_posteriors(samples in samples(), kind in discriminant()) {
        let model = ZoneModel::fit(config(kind, 1e-6), &samples).unwrap();
        let rows: Vec<f64> = samples.iter().flat_map(|s| s.x.clone()).collect();
        let mut out = vec![0.0; samples.len()];
        model.posteriors_safe_into(&rows, &mut out).unwrap();
        for (s, p) in samples.iter().zip(&out) {
            prop_assert_eq!(*p, model.posterior_safe(&s.x).unwrap());
        }
    }

    #[test]
    fn serialization_round_trips(samples in samples(), x in query(), kind in discriminant()) {
        let model = ZoneModel::fit(config(kind, 1e-6), &samples).unwrap();
        let json = serde_json::to_string(&model).unwrap();
        let back: ZoneModel = serde_json::from_str(&json).unwrap();
        let a = model.log_odds_safe(&x).unwrap();
        let b = back.log_odds_safe(&x).unwrap();
        prop_assert!(close(a, b, 1e-9), "{a} vs {b}");
    }
}
