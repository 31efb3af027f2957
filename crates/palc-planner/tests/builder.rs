//! The problem builder checks each input when it is given, with the same typed errors
//! as the planner, and builds the same problem as a struct literal.

mod common;

use common::lane_change;
use palc_planner::{
    LateralBound, PlanError, Planner, PlannerConfig, Position, Problem, ProblemBuilder,
    StageWeights, State, Terminal, Tracking, Weights,
};

fn config() -> PlannerConfig {
    PlannerConfig {
        horizon: 30,
        ..PlannerConfig::default()
    }
}

/// The builder filled from a finished problem.
fn builder_of(problem: &Problem) -> Result<ProblemBuilder, PlanError> {
    let mut builder = Problem::builder(problem.reference_speed.len())
        .initial(problem.initial)?
        .reference_speed(problem.reference_speed.clone())?
        .curvature(problem.curvature)?
        .weights(problem.weights.clone())?
        .preceding(problem.preceding.clone())?
        .adjacent(problem.adjacent.clone())?
        .terminal(problem.terminal)?
        .lateral_bounds(problem.lateral_bounds.clone())?;
    if let Some(tracking) = &problem.tracking {
        builder = builder.tracking(tracking.clone())?;
    }
    Ok(builder)
}

#[test]
fn builder_builds_the_same_problem_as_a_struct_literal() {
    let config = config();
    let literal = lane_change(&config, 20.0);
    let built = builder_of(&literal).unwrap().build().unwrap();
    assert_eq!(built, literal);
    let mut planner = Planner::new(config).unwrap();
    let a = planner.plan(&literal).unwrap();
    let b = planner.plan(&built).unwrap();
    assert_eq!(a.states, b.states);
}

#[test]
fn named_weights_give_the_fixture_matrix() {
    let config = config();
    let stage = StageWeights {
        l_squared: 0.1,
        phi_squared: 1.0,
        delta_squared: 10.0,
        dist_preceding: 1e-3,
        dist_adjacent: 1e-3,
        ..StageWeights::ZERO
    };
    assert_eq!(
        Weights::uniform(config.horizon, stage),
        lane_change(&config, 20.0).weights
    );
}

#[test]
fn defaults_are_a_straight_road_without_bounds_or_tracking() {
    let literal = lane_change(&config(), 20.0);
    let built = Problem::builder(30)
        .initial(literal.initial)
        .and_then(|b| b.reference_speed(literal.reference_speed.clone()))
        .and_then(|b| b.weights(literal.weights.clone()))
        .and_then(|b| b.preceding(literal.preceding.clone()))
        .and_then(|b| b.adjacent(literal.adjacent.clone()))
        .and_then(|b| b.terminal(literal.terminal))
        .and_then(ProblemBuilder::build)
        .unwrap();
    assert_eq!(built.curvature, 0.0);
    assert_eq!(built.lateral_bounds, vec![None; 31]);
    assert_eq!(built.tracking, None);
}

#[test]
fn a_missing_input_is_named() {
    let literal = lane_change(&config(), 20.0);
    let err = Problem::builder(30)
        .initial(literal.initial)
        .unwrap()
        .build()
        .unwrap_err();
    assert_eq!(
        err,
        PlanError::MissingField {
            field: "reference_speed"
        }
    );
    assert!(err.to_string().contains("reference_speed"));
}

#[test]
fn each_input_is_checked_when_it_is_given() {
    let b = || Problem::builder(30);
    let field_of = |err: PlanError| match err {
        PlanError::DimensionMismatch { field, .. } => field.to_string(),
        PlanError::NonFinite { field, .. } | PlanError::OutOfRange { field, .. } => field,
        PlanError::NonConvex { .. } => "non-convex".to_string(),
        other => panic!("unexpected {other:?}"),
    };
    let cases: Vec<(&str, Result<ProblemBuilder, PlanError>)> = vec![
        (
            "initial.phi",
            b().initial(State {
                phi: f64::NAN,
                ..State::default()
            }),
        ),
        (
            "initial.s",
            b().initial(State {
                s: 2e9,
                ..State::default()
            }),
        ),
        (
            "initial.v",
            b().initial(State {
                v: -1.0,
                ..State::default()
            }),
        ),
        ("reference_speed", b().reference_speed(vec![20.0; 29])),
        ("reference_speed[3]", {
            let mut v = vec![20.0; 30];
            v[3] = -1.0;
            b().reference_speed(v)
        }),
        ("curvature", b().curvature(f64::INFINITY)),
        ("weights", b().weights(Weights::zeros(31))),
        ("weights[2][7]", {
            let mut w = Weights::zeros(30);
            w.columns_mut()[2][7] = f64::NAN;
            b().weights(w)
        }),
        (
            "non-convex",
            b().uniform_weights(StageWeights {
                delta_squared: -1.0,
                ..StageWeights::ZERO
            }),
        ),
        ("adjacent[4].l", {
            let mut p = vec![Position::default(); 30];
            p[4].l = f64::NAN;
            b().adjacent(p)
        }),
        ("preceding[0].s", {
            let mut p = vec![Position::default(); 30];
            p[0].s = -1e10;
            b().preceding(p)
        }),
        (
            "terminal.v",
            b().terminal(Terminal {
                s: None,
                v: f64::NAN,
                l: 3.5,
            }),
        ),
        ("lateral_bounds", b().lateral_bounds(vec![None; 30])),
        ("lateral_bounds[30].max", {
            let mut bounds = vec![None; 31];
            bounds[30] = Some(LateralBound::new(-1.75, f64::INFINITY));
            b().lateral_bounds(bounds)
        }),
        (
            "tracking.weights[2]",
            b().tracking(Tracking {
                weights: [0.0, 0.0, -1.0, 0.0],
                reference: vec![None; 31],
            }),
        ),
        (
            "tracking.reference",
            b().tracking(Tracking {
                weights: [0.0, 0.0, 1.0, 0.0],
                reference: vec![None; 30],
            }),
        ),
    ];
    for (field, result) in cases {
        let err = result.expect_err(field);
        assert_eq!(field_of(err), field);
    }
}
