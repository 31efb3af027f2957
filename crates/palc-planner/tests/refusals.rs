//! Every refusal is a typed error naming what is wrong.

mod common;

use common::lane_change;
use palc_planner::{
    ConfigError, LateralBound, LateralBoundsMode, MAX_ITER_RANGE, PlanError, Planner,
    PlannerConfig, SolverSettings, StepRanges, TOLERANCE_RANGE, Tracking, check_convexity,
};
use proptest::prelude::*;

fn config(k: usize, mode: LateralBoundsMode) -> PlannerConfig {
    PlannerConfig {
        horizon: k,
        dt: 0.1,
        lateral_bounds_mode: mode,
        ..PlannerConfig::default()
    }
}

#[test]
fn invalid_config_names_the_field() {
    let bad = PlannerConfig {
        dt: -0.1,
        ..PlannerConfig::default()
    };
    let err = Planner::new(bad).unwrap_err();
    assert!(matches!(
        err,
        PlanError::Config(ConfigError::OutOfRange { field: "dt", .. })
    ));
    assert!(err.to_string().contains("dt"));
    let bad = PlannerConfig {
        steering_min: 0.3,
        steering_max: 0.2,
        ..PlannerConfig::default()
    };
    assert!(matches!(
        Planner::new(bad).unwrap_err(),
        PlanError::Config(ConfigError::OutOfRange {
            field: "steering_max",
            ..
        })
    ));
    let bad = PlannerConfig {
        lateral_bounds_mode: LateralBoundsMode::Soft { weight: 0.0 },
        ..PlannerConfig::default()
    };
    assert!(Planner::new(bad).is_err());
    let bad = PlannerConfig {
        horizon: 0,
        ..PlannerConfig::default()
    };
    assert!(Planner::new(bad).is_err());
}

/// Without the `clarabel` feature the reference backend is a configuration error, not
/// a compile error or a panic; with it, the same configuration builds a planner.
#[test]
fn clarabel_backend_needs_its_feature() {
    let config = PlannerConfig {
        backend: palc_planner::Backend::Clarabel,
        ..PlannerConfig::default()
    };
    if cfg!(feature = "clarabel") {
        assert!(Planner::new(config).is_ok());
    } else {
        let err = Planner::new(config).unwrap_err();
        assert!(matches!(
            err,
            PlanError::Config(ConfigError::BackendUnavailable {
                backend: "clarabel",
                feature: "clarabel",
            })
        ));
        assert!(err.to_string().contains("`clarabel` feature"));
    }
}

/// The default backend's failures are typed, with a readable message.
#[test]
fn an_iteration_limit_is_a_typed_failure() {
    let config = PlannerConfig {
        horizon: 30,
        solver: SolverSettings {
            max_iter: 2,
            ..SolverSettings::default()
        },
        ..PlannerConfig::default()
    };
    let problem = lane_change(&config, 20.0);
    let err = Planner::new(config).unwrap().plan(&problem).unwrap_err();
    assert_eq!(
        err,
        PlanError::SolverFailed {
            status: palc_planner::SolverFailure::MaxIterations,
            iterations: 2,
        }
    );
    assert_eq!(
        err.to_string(),
        "qp solver failed with status max iterations after 2 iterations"
    );
}

#[test]
fn mismatched_dimensions_are_refused() {
    let c = config(30, LateralBoundsMode::Hard);
    let mut planner = Planner::new(c.clone()).unwrap();
    let mut p = lane_change(&c, 20.0);
    p.reference_speed.pop();
    assert_eq!(
        planner.plan(&p).unwrap_err(),
        PlanError::DimensionMismatch {
            field: "reference_speed",
            expected: 30,
            found: 29
        }
    );
    let mut p = lane_change(&c, 20.0);
    p.lateral_bounds.pop();
    assert!(matches!(
        planner.plan(&p).unwrap_err(),
        PlanError::DimensionMismatch {
            field: "lateral_bounds",
            expected: 31,
            found: 30
        }
    ));
    let mut p = lane_change(&c, 20.0);
    p.adjacent.push(p.adjacent[0]);
    assert!(matches!(
        planner.plan(&p).unwrap_err(),
        PlanError::DimensionMismatch {
            field: "adjacent",
            ..
        }
    ));
}

#[test]
fn non_finite_input_is_refused_with_its_index() {
    let c = config(30, LateralBoundsMode::Hard);
    let mut planner = Planner::new(c.clone()).unwrap();
    let mut p = lane_change(&c, 20.0);
    p.weights.columns_mut()[7][3] = f64::NAN;
    let err = planner.plan(&p).unwrap_err();
    assert!(matches!(&err, PlanError::NonFinite { field, .. } if field == "weights[7][3]"));
    let mut p = lane_change(&c, 20.0);
    p.preceding[4].s = f64::INFINITY;
    assert!(
        matches!(planner.plan(&p).unwrap_err(), PlanError::NonFinite { field, .. } if field == "preceding[4].s")
    );
    let mut p = lane_change(&c, 20.0);
    p.lateral_bounds[2] = Some(LateralBound {
        min: Some(f64::NEG_INFINITY),
        max: None,
    });
    assert!(
        matches!(planner.plan(&p).unwrap_err(), PlanError::NonFinite { field, .. } if field == "lateral_bounds[2].min")
    );
    let mut p = lane_change(&c, 20.0);
    p.reference_speed[0] = -1.0;
    assert!(matches!(
        planner.plan(&p).unwrap_err(),
        PlanError::OutOfRange { .. }
    ));
    let mut p = lane_change(&c, 20.0);
    p.tracking = Some(Tracking {
        weights: [0.0, 0.0, -1.0, 0.0],
        reference: vec![None; 31],
    });
    assert!(
        matches!(planner.plan(&p).unwrap_err(), PlanError::OutOfRange { field, .. } if field == "tracking.weights[2]")
    );
}

#[test]
fn non_convex_weights_name_the_stage_and_block() {
    let c = config(30, LateralBoundsMode::Hard);
    let base = lane_change(&c, 20.0).weights;
    let cases: [(usize, f64, &str); 5] = [
        (0, -1.0, "Q[l,l]"),
        (2, -0.5, "Q[phi,phi]"),
        (7, -0.1, "R[delta,delta]"),
        (5, 10.0, "Schur"),
        (6, 0.5, "Schur"),
    ];
    for (row, value, block_start) in cases {
        let mut w = base.clone();
        w.columns_mut()[12][row] = value;
        match check_convexity(&w).unwrap_err() {
            PlanError::NonConvex {
                stage,
                column,
                block,
                ..
            } => {
                assert_eq!((stage, column), (13, 12));
                assert!(block.starts_with(block_start), "{block} for row {row}");
            }
            other => panic!("unexpected {other:?}"),
        }
    }
    // A coupling with no curvature on its state can never be convex.
    let mut w = base.clone();
    w.columns_mut()[3][8] = 0.0;
    w.columns_mut()[3][9] = 0.0;
    w.columns_mut()[3][6] = 1e-3;
    assert!(matches!(
        check_convexity(&w).unwrap_err(),
        PlanError::NonConvex { stage: 4, block, .. } if block.starts_with("s-delta")
    ));
    let mut p = lane_change(&c, 20.0);
    p.weights.columns_mut()[0][0] = -5.0;
    let err = Planner::new(c).unwrap().plan(&p).unwrap_err();
    assert!(err.to_string().contains("stage 1"), "{err}");
}

#[test]
fn unreachable_bound_is_infeasible_and_located() {
    let c = config(40, LateralBoundsMode::Hard);
    let mut p = lane_change(&c, 20.0);
    // l_1 = l_0 + dt v φ_0 = 0 is fixed by X_0, so l_1 >= 0.5 cannot hold.
    p.lateral_bounds[1] = Some(LateralBound::new(0.5, 1.0));
    match Planner::new(c).unwrap().plan(&p).unwrap_err() {
        PlanError::Infeasible { lateral_steps, .. } => {
            assert!(lateral_steps.contains(1), "{lateral_steps}");
        }
        other => panic!("unexpected {other:?}"),
    }
}

#[test]
fn boundary_outside_hard_zone_is_refused() {
    let c = config(20, LateralBoundsMode::Hard);
    let mut p = lane_change(&c, 20.0);
    p.lateral_bounds[20] = Some(LateralBound::new(-1.75, 1.75));
    assert!(matches!(
        Planner::new(c).unwrap().plan(&p).unwrap_err(),
        PlanError::BoundaryOutsideZone {
            which: "terminal",
            step: 20,
            ..
        }
    ));
}

#[test]
fn soft_bounds_plan_through_an_inconsistent_zone() {
    let c = config(40, LateralBoundsMode::Soft { weight: 10.0 });
    let mut p = lane_change(&c, 20.0);
    for step in 10..15 {
        p.lateral_bounds[step] = Some(LateralBound::new(2.0, 1.0));
    }
    let plan = Planner::new(c).unwrap().plan(&p).unwrap();
    for step in 10..15 {
        // One slack per step: σ = max(l - l_max, l_min - l), at least half the overlap.
        let l = plan.states[step].l;
        let expected = (l - 1.0).max(2.0 - l);
        assert!((plan.lateral_violation[step] - expected).abs() < 1e-5);
        assert!(expected >= 0.5);
    }
    assert!(plan.extras.lateral_slack >= 5.0 * 10.0 * 0.5 - 1e-4);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    #[test]
    fn empty_hard_zones_are_reported_not_planned(
        (k, steps) in (20usize..60).prop_flat_map(|k| {
            (Just(k), prop::collection::btree_set(0..=k, 1..6))
        }),
        gap in 0.01..2.0f64,
    ) {
        let c = config(k, LateralBoundsMode::Hard);
        let mut p = lane_change(&c, 20.0);
        let steps: Vec<usize> = steps.into_iter().collect();
        for &s in &steps {
            p.lateral_bounds[s] = Some(LateralBound::new(1.0 + gap, 1.0));
        }
        let err = Planner::new(c).unwrap().plan(&p).unwrap_err();
        prop_assert_eq!(err, PlanError::ZoneTooNarrow { steps: StepRanges::from_steps(steps) });
    }

    #[test]
    fn unreachable_zones_are_reported_not_planned(
        k in 30usize..60,
        start in 1usize..4,
        min in 0.3..1.5f64,
    ) {
        // From l = 0 with φ = 0, l_1 = 0 and l_2 = dt v φ_1 with |φ_1| bounded by the
        // steering bound; asking for l >= min at step `start` that early is infeasible
        // whenever min exceeds what the steering bound allows.
        let c = PlannerConfig { steering_min: -0.01, steering_max: 0.01, ..config(k, LateralBoundsMode::Hard) };
        let mut p = lane_change(&c, 20.0);
        for s in start..start + 3 {
            p.lateral_bounds[s] = Some(LateralBound::new(min, 3.0));
        }
        let reachable = 20.0 * 0.1 * (20.0 * 0.1 / 2.8 * 0.01) * (start as f64) * (start as f64);
        prop_assume!(min > reachable + 0.05);
        let err = Planner::new(c).unwrap().plan(&p).unwrap_err();
        prop_assert!(matches!(err, PlanError::Infeasible { .. }), "{:?}", err);
    }
}

#[test]
fn step_ranges_print_compactly() {
    let r = StepRanges::from_steps([1, 2, 3, 7, 9, 10]);
    assert_eq!(r.to_string(), "1..=3, 7, 9..=10");
    assert_eq!(StepRanges::default().to_string(), "none");
}

#[test]
fn solver_settings_outside_their_documented_ranges_are_refused() {
    // Issue 12, item 5: a tolerance of 1e308 used to report "solved" after 0 iterations.
    let with = |solver: SolverSettings| PlannerConfig {
        solver,
        ..PlannerConfig::default()
    };
    let defaults = SolverSettings::default();
    let cases = [
        (
            "solver.tol_gap_abs",
            SolverSettings {
                tol_gap_abs: 1e308,
                ..defaults.clone()
            },
        ),
        (
            "solver.tol_gap_rel",
            SolverSettings {
                tol_gap_rel: 0.5,
                ..defaults.clone()
            },
        ),
        (
            "solver.tol_feas",
            SolverSettings {
                tol_feas: 1e-300,
                ..defaults.clone()
            },
        ),
        (
            "solver.tol_feas",
            SolverSettings {
                tol_feas: f64::NAN,
                ..defaults.clone()
            },
        ),
        (
            "solver.max_iter",
            SolverSettings {
                max_iter: 0,
                ..defaults.clone()
            },
        ),
        (
            "solver.max_iter",
            SolverSettings {
                max_iter: 1_000_000,
                ..defaults.clone()
            },
        ),
    ];
    for (field, solver) in cases {
        let err = Planner::new(with(solver)).unwrap_err();
        assert!(
            matches!(err, PlanError::Config(ConfigError::OutOfRange { field: f, .. }) if f == field),
            "{field}: {err}"
        );
        assert!(err.to_string().contains(field), "{err}");
    }
    assert_eq!(
        Planner::new(with(SolverSettings {
            tol_gap_abs: 1e308,
            ..defaults.clone()
        }))
        .unwrap_err()
        .to_string(),
        "config field `solver.tol_gap_abs` = 1e308 is out of range: must be in [1e-14, 1e-2]"
    );
    // The ends of the ranges are accepted.
    for solver in [
        SolverSettings {
            max_iter: *MAX_ITER_RANGE.end(),
            tol_gap_abs: *TOLERANCE_RANGE.start(),
            tol_gap_rel: *TOLERANCE_RANGE.end(),
            tol_feas: *TOLERANCE_RANGE.start(),
            ..defaults.clone()
        },
        SolverSettings {
            max_iter: *MAX_ITER_RANGE.start(),
            ..defaults.clone()
        },
    ] {
        assert!(Planner::new(with(solver)).is_ok());
    }
}

#[test]
fn positions_beyond_the_representable_range_are_refused() {
    // Issue 12, item 4: at 1e15 m the planner reported "solved" with objective -3.5e13.
    let config = config(30, LateralBoundsMode::Soft { weight: 100.0 });
    let mut problem = lane_change(&config, 20.0);
    for p in problem
        .preceding
        .iter_mut()
        .chain(problem.adjacent.iter_mut())
    {
        p.s += 1e15;
    }
    problem.initial.s += 1e15;
    let err = Planner::new(config.clone())
        .unwrap()
        .plan(&problem)
        .unwrap_err();
    assert!(
        matches!(&err, PlanError::OutOfRange { field, .. } if field == "initial.s"),
        "{err}"
    );
    let mut problem = lane_change(&config, 20.0);
    problem.adjacent[7].s = -2e9;
    let err = Planner::new(config).unwrap().plan(&problem).unwrap_err();
    assert!(
        matches!(&err, PlanError::OutOfRange { field, .. } if field == "adjacent[7].s"),
        "{err}"
    );
}
