//! Unit tests of the learning step: an empty zone, an infeasible expert problem,
//! bad options and lessons, and learning in a fixed scene.

mod common;

use palc_aggregator::{
    AggregatorError, AggregatorOptions, Experience, ExpertKind, LessonExpert, ZoneCentreExpert,
    learn_from_lesson, plan_problem,
};
use palc_planner::{
    LateralBound, LateralBoundsMode, PlanError, Planner, PlannerConfig, Weights, check_convexity,
};
use palc_zone_filter::StepBounds;

const K: usize = 30;
const DT: f64 = 0.2;

fn setup(config: PlannerConfig) -> (Planner, palc_planner::Problem, Experience) {
    let planner = Planner::new(config).unwrap();
    let template = common::template(K, DT);
    let experience = Experience::new(
        "u",
        "scene",
        "test",
        Weights::constant(K, common::STANDARD),
        DT,
    )
    .unwrap();
    (planner, template, experience)
}

#[test]
fn empty_zone_bounds_nothing_and_the_zone_centre_expert_tracks_nothing() {
    let (mut planner, template, experience) = setup(common::config(K, DT));
    let mut lesson = common::lesson(&mut planner, &template, 8, 0.5);
    lesson.samples.clear();
    let options = AggregatorOptions {
        expert: ExpertKind::ZoneCentre(ZoneCentreExpert::default()),
        use_zone: true,
        ..AggregatorOptions::default()
    };
    let outcome =
        learn_from_lesson(&mut planner, &experience, &lesson, &template, &options).unwrap();
    let bounds = outcome.zone_bounds.as_ref().unwrap();
    assert_eq!(bounds.len(), K + 1);
    assert!(bounds.iter().all(|b| *b == StepBounds::Unconstrained));
    let zone = outcome.experience.zone.as_ref().unwrap();
    assert!(!zone.is_informative());
    // Nothing to track: the expert is the plan with the current weights, in the road.
    assert_eq!(outcome.expert.extras.tracking, 0.0);
    assert_eq!(outcome.problem.lateral_bounds, template.lateral_bounds);
    let current = palc_planner::Problem {
        weights: experience.weights.clone(),
        ..outcome.problem.clone()
    };
    let plain = planner.plan(&current).unwrap();
    for (e, p) in outcome.expert.states.iter().zip(&plain.states) {
        assert!((e.l - p.l).abs() < 1e-6, "expert {} vs plan {}", e.l, p.l);
    }
    assert!(check_convexity(&outcome.experience.weights).is_ok());
}

#[test]
fn one_class_zone_is_not_informative_and_learning_goes_on() {
    let (mut planner, template, experience) = setup(common::config(K, DT));
    let mut lesson = common::lesson(&mut planner, &template, 8, 0.5);
    lesson
        .samples
        .retain(|s| s.y == palc_zone_filter::Label::Safe);
    let options = AggregatorOptions {
        use_zone: true,
        ..AggregatorOptions::default()
    };
    let outcome =
        learn_from_lesson(&mut planner, &experience, &lesson, &template, &options).unwrap();
    assert!(!outcome.experience.zone.as_ref().unwrap().is_informative());
    assert_eq!(outcome.experience.metadata.lessons, 1);
}

#[test]
fn infeasible_expert_problem_is_a_clear_error_and_the_experience_is_unchanged() {
    let config = PlannerConfig {
        lateral_bounds_mode: LateralBoundsMode::Hard,
        ..common::config(K, DT)
    };
    let (mut planner, mut template, experience) = setup(config);
    let lesson = common::lesson(&mut planner, &template, 8, 0.5);
    // The road is narrower than a lane change at step 10: the lesson expert (which
    // keeps the template's bounds) cannot be planned.
    template.lateral_bounds[10] = Some(LateralBound::new(2.0, 1.0));
    let before = experience.clone();
    let options = AggregatorOptions {
        expert: ExpertKind::Lesson(LessonExpert::default()),
        ..AggregatorOptions::default()
    };
    let err =
        learn_from_lesson(&mut planner, &experience, &lesson, &template, &options).unwrap_err();
    match &err {
        AggregatorError::ExpertFailed { expert, source } => {
            assert_eq!(*expert, "lesson");
            assert!(
                matches!(source, PlanError::ZoneTooNarrow { .. }),
                "{source}"
            );
        }
        other => panic!("expected ExpertFailed, got {other}"),
    }
    let message = err.to_string();
    assert!(message.contains("expert trajectory (lesson)"), "{message}");
    assert!(message.contains("10"), "{message}");
    assert_eq!(experience, before);
}

#[test]
fn infeasible_terminal_under_steering_bounds_is_reported_by_the_solver() {
    let config = PlannerConfig {
        steering_min: -1e-4,
        steering_max: 1e-4,
        ..common::config(K, DT)
    };
    let (mut planner, template, experience) = setup(config.clone());
    // The lesson comes from a planner that can steer.
    let mut free = Planner::new(common::config(K, DT)).unwrap();
    let lesson = common::lesson(&mut free, &template, 8, 0.5);
    let err = learn_from_lesson(
        &mut planner,
        &experience,
        &lesson,
        &template,
        &AggregatorOptions::default(),
    )
    .unwrap_err();
    assert!(
        matches!(
            err,
            AggregatorError::ExpertFailed {
                source: PlanError::Infeasible { .. },
                ..
            }
        ),
        "{err}"
    );
}

#[test]
fn zone_centre_expert_without_zone_is_refused() {
    let (mut planner, template, experience) = setup(common::config(K, DT));
    let lesson = common::lesson(&mut planner, &template, 8, 0.5);
    let options = AggregatorOptions {
        expert: ExpertKind::ZoneCentre(ZoneCentreExpert::default()),
        use_zone: false,
        ..AggregatorOptions::default()
    };
    let err =
        learn_from_lesson(&mut planner, &experience, &lesson, &template, &options).unwrap_err();
    assert!(err.to_string().contains("use_zone = true"), "{err}");
}

#[test]
fn lesson_of_the_wrong_length_is_refused() {
    let (mut planner, template, experience) = setup(common::config(K, DT));
    let mut lesson = common::lesson(&mut planner, &template, 8, 0.5);
    lesson.executed.pop();
    let err = learn_from_lesson(
        &mut planner,
        &experience,
        &lesson,
        &template,
        &AggregatorOptions::default(),
    )
    .unwrap_err();
    assert_eq!(
        err.to_string(),
        format!("lesson field `executed` has length {K}, expected {}", K + 1)
    );
}

#[test]
fn non_finite_executed_state_is_refused() {
    let (mut planner, template, experience) = setup(common::config(K, DT));
    let mut lesson = common::lesson(&mut planner, &template, 8, 0.5);
    lesson.executed[4].l = f64::NAN;
    let err = learn_from_lesson(
        &mut planner,
        &experience,
        &lesson,
        &template,
        &AggregatorOptions::default(),
    )
    .unwrap_err();
    assert!(err.to_string().contains("executed[4].l"), "{err}");
}

#[test]
fn experience_from_another_horizon_is_resampled() {
    let (mut planner, template, _) = setup(common::config(K, DT));
    // Learned at K = 60, dt = 0.1 (the same 6 s).
    let experience = Experience::new(
        "u",
        "scene",
        "test",
        Weights::constant(60, common::STANDARD),
        0.1,
    )
    .unwrap();
    let lesson = common::lesson(&mut planner, &template, 8, 0.5);
    let outcome = learn_from_lesson(
        &mut planner,
        &experience,
        &lesson,
        &template,
        &AggregatorOptions::default(),
    )
    .unwrap();
    assert_eq!(outcome.experience.weights.horizon(), K);
    assert_eq!(outcome.experience.metadata.dt, DT);
}

/// The default method learns a user's earlier lane change in a fixed scene: the plan's
/// largest lateral distance to what the user drove shrinks lesson after lesson.
#[test]
fn incremental_rule_learns_an_earlier_lane_change() {
    let (mut planner, template, mut experience) = setup(common::config(K, DT));
    let options = AggregatorOptions::default();
    let mut deviations = Vec::new();
    for _ in 0..3 {
        let (problem, _) = plan_problem(&planner, &experience, &template, &[], &options).unwrap();
        let lesson = common::lesson(&mut planner, &problem, 6, 0.5);
        let outcome =
            learn_from_lesson(&mut planner, &experience, &lesson, &template, &options).unwrap();
        let deviation = |states: &[palc_planner::State]| {
            states
                .iter()
                .zip(&lesson.executed)
                .map(|(a, b)| (a.l - b.l).abs())
                .fold(0.0, f64::max)
        };
        deviations.push((
            deviation(&lesson.planned.states),
            deviation(&outcome.plan.states),
        ));
        experience = outcome.experience;
    }
    // Each lesson's new plan is much closer to the executed trajectory than the plan
    // that was taken over, and the first plan was far from it.
    assert!(deviations[0].0 > 1.0, "{deviations:?}");
    for (old, new) in &deviations {
        assert!(new < &(0.5 * old), "{deviations:?}");
    }
    assert!(deviations[2].1 < 0.1, "{deviations:?}");
}
