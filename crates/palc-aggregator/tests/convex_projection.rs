//! Property tests of the projection onto the convex set, checked by the planner's
//! own convexity test.

use palc_aggregator::advanced::DIAGONAL_ZERO_RATIO;
use palc_aggregator::{ConvexSet, LearnableRows, project_convex, resample_weights};
use palc_planner::{FEATURE_COUNT, Weights, check_convexity};
use proptest::prelude::*;

/// Entries over many orders of magnitude and both signs.
fn entry() -> impl Strategy<Value = f64> {
    prop_oneof![
        -1e3f64..1e3,
        -1.0f64..1.0,
        (-8i32..8, any::<bool>()).prop_map(|(e, neg)| if neg { -1.0 } else { 1.0 } * 10f64.powi(e)),
        Just(0.0),
    ]
}

fn weights(max_horizon: usize) -> impl Strategy<Value = Weights> {
    prop::collection::vec(prop::array::uniform10(entry()), 1..max_horizon)
        .prop_map(Weights::from_columns)
}

fn rows() -> impl Strategy<Value = LearnableRows> {
    prop::collection::vec(any::<bool>(), FEATURE_COUNT).prop_map(|mask| {
        LearnableRows::from_indices(mask.iter().enumerate().filter(|(_, m)| **m).map(|(j, _)| j))
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn projection_is_convex_idempotent_and_keeps_the_bounds(
        w in weights(12),
        learnable in rows(),
        epsilon in prop_oneof![Just(1e-6), 1e-9f64..1.0],
    ) {
        let set = ConvexSet { min_curvature: epsilon };
        let p = project_convex(&w, &set, &learnable).unwrap();
        prop_assert!(check_convexity(&p).is_ok(), "{:?}", check_convexity(&p));
        for column in p.columns() {
            for j in [0, 2, 7] {
                prop_assert!(column[j] >= epsilon);
            }
            prop_assert!(column[8] >= 0.0 && column[9] >= 0.0);
        }
        // Rows that are not part of the convexity conditions never change.
        for j in [1, 3] {
            prop_assert!(p.row(j).eq(w.row(j)));
        }
        // Couplings only shrink towards zero, keeping their sign.
        for (pc, wc) in p.columns().iter().zip(w.columns()) {
            for j in [4, 5, 6] {
                prop_assert!(pc[j].abs() <= wc[j].abs());
                prop_assert!(pc[j] == 0.0 || pc[j].signum() == wc[j].signum());
            }
        }
        let again = project_convex(&p, &set, &learnable).unwrap();
        prop_assert_eq!(again, p);
    }

    /// With learnable couplings, a fixed coupling keeps its value whenever the fixed
    /// couplings alone leave the block convex with some margin.
    #[test]
    fn fixed_couplings_keep_their_values_when_possible(
        w in weights(6),
        learnable in rows(),
    ) {
        let set = ConvexSet::default();
        let p = project_convex(&w, &set, &learnable).unwrap();
        for (pc, wc) in p.columns().iter().zip(w.columns()) {
            // The block after the bounds, as the projection sees it.
            let dist = wc[8].max(0.0) + wc[9].max(0.0);
            let d = [dist, wc[0].max(1e-6) + dist, wc[2].max(1e-6)];
            let c = [wc[6] / 2.0, wc[4] / 2.0, wc[5] / 2.0];
            let r = wc[7].max(1e-6);
            let scale = d.iter().chain(&c).fold(r, |m, x| m.max(x.abs()));
            let fixed = [!learnable.contains(6), !learnable.contains(4), !learnable.contains(5)];
            let clear = (0..3).all(|j| !fixed[j] || c[j] == 0.0 || d[j] > DIAGONAL_ZERO_RATIO * scale);
            let used: f64 = (0..3).filter(|&j| fixed[j] && c[j] != 0.0).map(|j| c[j] * c[j] / d[j]).sum();
            if clear && used < (1.0 - 1e-6) * r {
                for (j, row) in [(0, 6), (1, 4), (2, 5)] {
                    if fixed[j] {
                        prop_assert_eq!(pc[row], wc[row], "row {}", row);
                    }
                }
            }
        }
    }

    /// Resampling convex weights to any horizon and step keeps them convex.
    #[test]
    fn resampling_keeps_weights_convex(
        w in weights(30),
        from_dt in 0.01f64..0.5,
        horizon in 1usize..150,
        to_dt in 0.01f64..0.5,
    ) {
        let convex = project_convex(&w, &ConvexSet::default(), &LearnableRows::ALL).unwrap();
        let r = resample_weights(&convex, from_dt, horizon, to_dt).unwrap();
        prop_assert_eq!(r.horizon(), horizon);
        // Mathematically PSD: Schur complement of the arrow block, no relative tolerance.
        for c in r.columns() {
            let d = [c[8] + c[9], c[0] + c[8] + c[9], c[2]];
            let k = [c[6] / 2.0, c[4] / 2.0, c[5] / 2.0];
            let mut schur = c[7];
            for j in 0..3 {
                prop_assert!(d[j] >= 0.0);
                if d[j] == 0.0 {
                    prop_assert_eq!(k[j], 0.0);
                } else {
                    schur -= k[j] * k[j] / d[j];
                }
            }
            prop_assert!(schur >= -1e-12 * c[7], "schur {schur} with w8 {}", c[7]);
        }
        // And accepted by the planner once projected again, as the step does.
        let p = project_convex(&r, &ConvexSet::default(), &LearnableRows::NONE).unwrap();
        prop_assert!(check_convexity(&p).is_ok(), "{:?}", check_convexity(&p));
    }
}
