//! Any experience file the loader accepts steers the first plan no further than
//! the road: weights of any scale and sign that pass the planner's convexity
//! check, any step and length, any anchor, any demonstration within the loader's
//! bound. The loader refuses what it must (non-convex weights, a step out of
//! range, a demonstration past ±15 m); what it accepts is planned from by the
//! loop, whose first lane change stays between the road's edges, or is refused
//! with an error, never planned off the road.

use palc_aggregator::Experience;
use palc_harness::{LearnConfig, LearningLoop, Method, NoObserver};
use palc_planner::{FEATURE_COUNT, Weights};
use proptest::prelude::*;
use proptest::test_runner::{RngAlgorithm, TestRng, TestRunner};

fn config() -> LearnConfig {
    let text = include_str!("../../../configs/learn.toml");
    LearnConfig::from_toml_str(text)
        .expect("the default config parses")
        .with_method(Method::Palc)
}

/// A weight over nine decades, negative one time in forty (a file edited by hand,
/// or corrupted), so that most matrices pass the convexity check and are planned.
fn weight() -> impl Strategy<Value = f64> {
    (0u8..40, -4.0f64..5.0).prop_map(|(sign, exponent)| {
        let magnitude = 10f64.powf(exponent);
        if sign == 0 { -magnitude } else { magnitude }
    })
}

/// A column of weights: every weight drawn by [`weight`], then each coupling
/// (`w5`, `w6`, `w7`) set to `ρ` times the largest the Schur complement of the
/// stage's curvature allows with the three couplings alike, `ρ` in `[-1.1, 1.1]`:
/// most columns convex, many close to singular, some not convex at all.
fn column() -> impl Strategy<Value = [f64; FEATURE_COUNT]> {
    use palc_planner::feature::*;
    let couplings = prop::array::uniform3(-1.1f64..1.1);
    (prop::array::uniform10(weight()), couplings).prop_map(|(mut w, rho)| {
        let dist = w[DIST_PRECEDING] + w[DIST_ADJACENT];
        let diagonals = [
            (S_DELTA, dist),
            (L_DELTA, w[L_SQUARED] + dist),
            (PHI_DELTA, w[PHI_SQUARED]),
        ];
        for ((coupling, diagonal), rho) in diagonals.into_iter().zip(rho) {
            // c²/d ≤ w8 / 3 for each of the three: c = 2 ρ √(w8 d / 3) with the
            // coupling entering the cost as c/2.
            let largest = 2.0 * (w[DELTA_SQUARED].max(0.0) * diagonal.max(0.0) / 3.0).sqrt();
            w[coupling] = rho * largest;
        }
        w
    })
}

/// The weights of a file: one column repeated (as most learned files are) or
/// columns of their own.
fn weights() -> impl Strategy<Value = Weights> {
    let columns = (1usize..120, column()).prop_map(|(n, c)| vec![c; n]);
    let varied = prop::collection::vec(column(), 1..40);
    prop_oneof![columns, varied]
        .prop_map(|columns: Vec<[f64; FEATURE_COUNT]>| Weights::from_columns(columns))
}

/// Everything a file holds that steers the first plan: the weights, the step, an
/// anchor within (mostly) the weights' time base and a demonstration no longer than
/// them, within (mostly) the loader's ±15 m.
fn experience() -> impl Strategy<Value = (Weights, f64, Option<f64>, Option<Vec<f64>>)> {
    let step = prop_oneof![Just(0.1), Just(0.05), Just(0.2), 0.001f64..0.5];
    (weights(), step).prop_flat_map(|(weights, dt)| {
        let n = weights.horizon();
        let end = n as f64 * dt;
        (
            Just(weights),
            Just(dt),
            prop::option::of(0.0..end * 1.05),
            prop::option::of(prop_oneof![
                9 => prop::collection::vec(-15.0f64..15.0, 1..n + 2),
                1 => prop::collection::vec(-16.0f64..16.0, 1..n + 2),
            ]),
        )
    })
}

/// The cases drawn (seeded).
const CASES: u32 = 128;

/// How far each case went.
#[derive(Debug, Default)]
struct Reached {
    refused_on_save: usize,
    refused_on_load: usize,
    refused_by_the_loop: usize,
    planned: usize,
}

#[test]
fn an_accepted_experience_plans_its_first_lane_change_on_the_road() {
    let config = config();
    let width = config.traffic.road.lane_width_m;
    let lanes = f64::from(config.traffic.road.lanes);
    let (low, high) = (-width / 2.0, (lanes - 0.5) * width);
    let path = tempfile_dir().join("experience.json");
    let reached = std::cell::RefCell::new(Reached::default());
    // Seeded: the same cases on every run.
    let mut runner = TestRunner::new_with_rng(
        ProptestConfig {
            cases: CASES,
            failure_persistence: None,
            ..ProptestConfig::default()
        },
        TestRng::deterministic_rng(RngAlgorithm::ChaCha),
    );
    let result = runner.run(&experience(), |(weights, dt, anchor, demonstration)| {
        let mut reached = reached.borrow_mut();
        let mut stored = Experience::new("u", "s", "palc", weights, dt)
            .expect("a finite matrix with a step in range");
        stored.anchor_s = anchor;
        stored.demonstration = demonstration;
        if stored.save(&path).is_err() {
            // An anchor past the weights' end, a demonstration past the bound.
            reached.refused_on_save += 1;
            return Ok(());
        }
        let Ok(loaded) = Experience::load(&path) else {
            // Weights the planner's convexity check refuses.
            reached.refused_on_load += 1;
            return Ok(());
        };
        let first = LearningLoop::new(&config, Some(&loaded))
            .and_then(|mut run| run.step(&mut NoObserver).map(|r| r.planned_l.clone()));
        let Ok(planned_l) = first else {
            reached.refused_by_the_loop += 1;
            return Ok(());
        };
        reached.planned += 1;
        for (i, &l) in planned_l.iter().enumerate() {
            prop_assert!(
                l.is_finite() && (low - 1e-6..=high + 1e-6).contains(&l),
                "step {i}: planned l = {l} m, the road is [{low}, {high}] m"
            );
        }
        Ok(())
    });
    let reached = reached.into_inner();
    if let Err(failure) = result {
        panic!("{failure:?}\n{reached:?}");
    }
    // The property is about plans: most cases must reach one.
    assert!(
        reached.planned * 2 >= 96,
        "too few cases planned: {reached:?}"
    );
}

/// A directory for this test's files under Cargo's temporary directory.
fn tempfile_dir() -> std::path::PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("experience-on-road");
    std::fs::create_dir_all(&dir).expect("the temporary directory");
    dir
}
