//! Property tests of the learning step: convexity under every rule, monotone feature
//! error of the incremental rule, and the lesson expert's consistency.

mod common;

use palc_aggregator::{
    AggregatorOptions, ApprenticeshipRule, CorrectionRule, Experience, ExpertKind, IncrementalRule,
    LearnableRows, LessonExpert, TargetRule, ZoneCentreExpert, feature_error, learn_from_lesson,
};
use palc_planner::{FEATURE_COUNT, Planner, Problem, Weights, check_convexity};
use proptest::prelude::*;

const DT: f64 = 0.2;

fn rows_strategy() -> impl Strategy<Value = LearnableRows> {
    prop::collection::vec(any::<bool>(), FEATURE_COUNT).prop_map(|mask| {
        LearnableRows::from_indices(mask.iter().enumerate().filter(|(_, m)| **m).map(|(j, _)| j))
    })
}

fn rule_strategy() -> impl Strategy<Value = CorrectionRule> {
    prop_oneof![
        Just(CorrectionRule::Apprenticeship(ApprenticeshipRule::default())),
        (0.05f64..4.0, 1usize..8).prop_map(|(step_size, max_inner_solves)| {
            CorrectionRule::Incremental(IncrementalRule {
                step_size,
                max_inner_solves,
                min_step_size: 1e-3 * step_size,
            })
        }),
        (0.1f64..=1.0, 1usize..8).prop_map(|(gain, max_inner_solves)| {
            CorrectionRule::Target(TargetRule {
                gain,
                max_inner_solves,
                tolerance_m: 0.005,
            })
        }),
    ]
}

/// Options: any rule and rows; the zone-centre expert only with the zone.
fn options_strategy() -> impl Strategy<Value = AggregatorOptions> {
    (rule_strategy(), rows_strategy(), any::<bool>()).prop_map(|(correction, rows, zone)| {
        // The target rule moves w2: it needs row 1.
        let rows = match correction {
            CorrectionRule::Target(_) => {
                LearnableRows::from_indices(rows.indices().chain(std::iter::once(1)))
            }
            _ => rows,
        };
        AggregatorOptions {
            expert: if zone {
                ExpertKind::ZoneCentre(ZoneCentreExpert::default())
            } else {
                ExpertKind::Lesson(LessonExpert::default())
            },
            correction,
            learnable_rows: rows,
            use_zone: zone,
            ..AggregatorOptions::default()
        }
    })
}

/// Prior weights: the standard ones with a random relative perturbation of every
/// entry (may be non-convex: the step projects them).
fn prior_strategy(horizon: usize) -> impl Strategy<Value = Weights> {
    prop::collection::vec(-0.5f64..0.5, FEATURE_COUNT).prop_map(move |noise| {
        let mut column = common::STANDARD;
        for (j, n) in noise.iter().enumerate() {
            column[j] += n * (0.1 + column[j].abs());
        }
        Weights::constant(horizon, column)
    })
}

struct Case {
    planner: Planner,
    template: Problem,
    experience: Experience,
}

fn case(horizon: usize, prior: Weights) -> Case {
    let planner = Planner::new(common::config(horizon, DT)).unwrap();
    let template = common::template(horizon, DT);
    let experience = Experience::new("u", "scene", "test", prior, DT).unwrap();
    Case {
        planner,
        template,
        experience,
    }
}

proptest! {
    // A fixed seed keeps CI reproducible. With the maximum-likelihood zone (ridge 0),
    // other seeds can draw a zone-centre expert whose plan the Riccati backend stops
    // at `MaxIterations` (e.g. K = 24, takeover at 0.354 K, pulls 0.263 and 0.05, the
    // paper's options, no learnable rows); such a case is recorded in
    // docs/experiments/0027-agreement-with-clarabel.md. Since the fixes of
    // `the_large_budget_zone_centre_case_solves`, seeds 11 and 20261202 passed 20,000
    // cases each (docs/experiments/0035-breakdowns-and-cycles.md); the seed stays
    // fixed for CI.
    #![proptest_config(ProptestConfig {
        rng_seed: proptest::test_runner::RngSeed::Fixed(20261201),
        ..ProptestConfig::with_cases(32)
    })]

    /// Every rule returns weights that make the QP convex, for any lesson, over two
    /// lessons in a row (the second exercises the apprenticeship state).
    #[test]
    fn weights_stay_convex_under_every_rule(
        horizon in 20usize..=30,
        takeover_fraction in 0.05f64..0.8,
        pulls in (0.05f64..1.5, 0.05f64..1.5),
        options in options_strategy(),
        prior in prior_strategy(30),
    ) {
        let mut c = case(horizon, prior);
        let mut experience = c.experience.clone();
        for pull in [pulls.0, pulls.1] {
            let (problem, _) = palc_aggregator::plan_problem(
                &c.planner, &experience, &c.template, &[], &AggregatorOptions::default(),
            ).unwrap();
            let takeover = ((horizon as f64 * takeover_fraction) as usize).max(1);
            let lesson = common::lesson(&mut c.planner, &problem, takeover, pull);
            let outcome = learn_from_lesson(
                &mut c.planner, &experience, &lesson, &c.template, &options,
            ).unwrap();
            prop_assert!(check_convexity(&outcome.experience.weights).is_ok(),
                "{:?}", check_convexity(&outcome.experience.weights));
            prop_assert_eq!(outcome.experience.weights.horizon(), horizon);
            // The next plan is the plan of the next problem (a rule's best iterate
            // is returned as it was solved, not solved again).
            let replanned = c.planner.plan(&outcome.problem).unwrap();
            prop_assert_eq!(&outcome.plan.states, &replanned.states);
            // Rows outside the learnable set keep their (projected) prior values
            // unless convexity needed a coupling shrunk.
            let prior = palc_aggregator::project_convex(
                &experience.weights_for(horizon, DT).unwrap(),
                &options.convex_set,
                &options.learnable_rows,
            ).unwrap();
            for j in [1usize, 3] {
                if !options.learnable_rows.contains(j) {
                    prop_assert!(outcome.experience.weights.row(j).eq(prior.row(j)));
                }
            }
            experience = outcome.experience;
        }
        prop_assert_eq!(experience.metadata.lessons, 2);
    }

    /// With the incremental rule, the new plan's feature error against the expert never
    /// exceeds that of the plan with the previous weights (same problem).
    #[test]
    fn incremental_never_increases_the_feature_error(
        horizon in 20usize..=32,
        takeover_fraction in 0.05f64..0.8,
        pull in 0.05f64..1.5,
        step_size in 0.01f64..20.0,
        rows in rows_strategy(),
        prior in prior_strategy(32),
    ) {
        let mut c = case(horizon, prior);
        let options = AggregatorOptions {
            correction: CorrectionRule::Incremental(IncrementalRule {
                step_size,
                ..IncrementalRule::default()
            }),
            learnable_rows: rows,
            ..AggregatorOptions::default()
        };
        let (problem, _) = palc_aggregator::plan_problem(
            &c.planner, &c.experience, &c.template, &[], &options,
        ).unwrap();
        let takeover = ((horizon as f64 * takeover_fraction) as usize).max(1);
        let lesson = common::lesson(&mut c.planner, &problem, takeover, pull);
        let outcome = learn_from_lesson(
            &mut c.planner, &c.experience, &lesson, &c.template, &options,
        ).unwrap();
        let before = outcome.correction.error_before.unwrap();
        let after = outcome.correction.error_after.unwrap();
        prop_assert!(after <= before, "after {after} > before {before}");
        // Independently: re-plan the returned problem with the previous weights.
        let previous = c.planner.plan(&problem).unwrap();
        let error = |f| feature_error(f, &outcome.expert.features, &options.feature_scale, &rows).unwrap();
        let previous_error = error(&previous.features);
        let new_error = error(&outcome.plan.features);
        prop_assert!(new_error <= previous_error + 1e-7 * (1.0 + previous_error),
            "new {new_error} > previous {previous_error}");
        prop_assert!((new_error - after).abs() <= 1e-7 * (1.0 + after));
    }

    /// With the target rule, the new plan's lateral path is never further from the
    /// expert's (root mean square) than the plan with the previous weights, the
    /// weights stay convex, and only row `w2` changes.
    #[test]
    fn the_target_rule_never_moves_the_plan_away_from_the_expert(
        horizon in 20usize..=32,
        takeover_fraction in 0.05f64..0.8,
        pull in 0.05f64..1.5,
        gain in 0.1f64..=1.0,
        prior in prior_strategy(32),
    ) {
        let mut c = case(horizon, prior);
        let options = AggregatorOptions {
            correction: CorrectionRule::Target(TargetRule { gain, ..TargetRule::default() }),
            ..AggregatorOptions::default()
        };
        let (problem, _) = palc_aggregator::plan_problem(
            &c.planner, &c.experience, &c.template, &[], &options,
        ).unwrap();
        let takeover = ((horizon as f64 * takeover_fraction) as usize).max(1);
        let lesson = common::lesson(&mut c.planner, &problem, takeover, pull);
        let outcome = learn_from_lesson(
            &mut c.planner, &c.experience, &lesson, &c.template, &options,
        ).unwrap();
        let lateral = |plan: &palc_planner::Plan| {
            let n = plan.states.len() - 1;
            let sum: f64 = (0..n)
                .map(|i| (plan.states[i].l - outcome.expert.states[i].l).powi(2))
                .sum();
            (sum / n as f64).sqrt()
        };
        let previous = c.planner.plan(&problem).unwrap();
        prop_assert!(lateral(&outcome.plan) <= lateral(&previous) + 1e-9,
            "new {} > previous {}", lateral(&outcome.plan), lateral(&previous));
        prop_assert!(check_convexity(&outcome.experience.weights).is_ok());
        for j in (0..FEATURE_COUNT).filter(|&j| j != 1) {
            prop_assert!(outcome.experience.weights.row(j).eq(problem.weights.row(j)), "row {j} changed");
        }
    }

    /// The lesson expert satisfies the planner's dynamics and stays within 0.05 m of
    /// the executed trajectory (which follows the model and ends at the terminal state).
    #[test]
    fn lesson_expert_is_consistent_and_close_to_the_executed_trajectory(
        horizon in 20usize..=40,
        takeover_fraction in 0.0f64..0.9,
        pull in 0.0f64..2.0,
        prior in prior_strategy(40),
    ) {
        let mut c = case(horizon, prior);
        let options = AggregatorOptions::default();
        let (problem, _) = palc_aggregator::plan_problem(
            &c.planner, &c.experience, &c.template, &[], &options,
        ).unwrap();
        let takeover = (horizon as f64 * takeover_fraction) as usize;
        let lesson = common::lesson(&mut c.planner, &problem, takeover, pull);
        let outcome = learn_from_lesson(
            &mut c.planner, &c.experience, &lesson, &c.template, &options,
        ).unwrap();
        let config = c.planner.config();
        let residual = common::dynamics_residual(&outcome.expert, &problem, config.dt, config.wheelbase);
        prop_assert!(residual < 1e-6, "dynamics residual {residual}");
        let worst = outcome.expert.states.iter().zip(&lesson.executed)
            .map(|(e, x)| (e.l - x.l).abs())
            .fold(0.0, f64::max);
        prop_assert!(worst <= 0.05, "expert strays {worst} m from the executed trajectory");
    }
}

/// The case a random seed of `weights_stay_convex_under_every_rule` drew (ML zone,
/// zone-centre expert, apprenticeship rule, rows 2, 3, 8, 9 learnable): the plan of the
/// lesson's user (`common::lesson`, second lesson, pull 0.05) ends at `MaxIterations`
/// after 100 Riccati iterations although it is feasible: from iteration 20 on the
/// residuals are at 1e-15 and the iterates cycle with period 4 at a relative gap of
/// 1e-2, a short predictor (0.043) on a steering bound followed each time by a
/// corrector whose second-order term doubles `μ`. Solved in 15 iterations since the
/// corrector drops that term after a predictor shorter than 0.1.
#[test]
fn the_large_budget_zone_centre_case_solves() {
    let (horizon, takeover_fraction, pulls) = (27, 0.5011578492556915, [0.6900270908148921, 0.05]);
    let options = AggregatorOptions {
        expert: ExpertKind::ZoneCentre(ZoneCentreExpert::default()),
        correction: CorrectionRule::Apprenticeship(ApprenticeshipRule::default()),
        learnable_rows: LearnableRows::from_indices([2, 3, 8, 9]),
        use_zone: true,
        ..AggregatorOptions::default()
    };
    let column = [
        0.1,
        0.04779139502567625,
        1.2963078168889344,
        0.0,
        0.0,
        0.0,
        -0.03492572818974425,
        8.579506514089212,
        0.0362856556428705,
        0.017264691515860752,
    ];
    let mut c = case(horizon, Weights::constant(30, column));
    let mut experience = c.experience.clone();
    for pull in pulls {
        let (problem, _) = palc_aggregator::plan_problem(
            &c.planner,
            &experience,
            &c.template,
            &[],
            &AggregatorOptions::default(),
        )
        .unwrap();
        let takeover = ((horizon as f64 * takeover_fraction) as usize).max(1);
        let lesson = common::lesson(&mut c.planner, &problem, takeover, pull);
        let outcome =
            learn_from_lesson(&mut c.planner, &experience, &lesson, &c.template, &options).unwrap();
        assert!(check_convexity(&outcome.experience.weights).is_ok());
        experience = outcome.experience;
    }
}
