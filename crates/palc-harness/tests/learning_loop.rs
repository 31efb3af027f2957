//! Integration tests of the lesson-learning loop on the default scenario of
//! `configs/learn.toml` (issue: harness, "Tests").

use palc_harness::user::Style;
use palc_harness::{
    CellChoice, LearnConfig, Method, NoObserver, Outcome, RunResult, StylePreset, UserConfig, run,
};

fn config(method: Method, style: &str) -> LearnConfig {
    let text = include_str!("../../../configs/learn.toml");
    let config = LearnConfig::from_toml_str(text).expect("the default config parses");
    let user = UserConfig {
        style: style.parse().expect("a valid style name"),
        ..config.user.clone()
    };
    config.with_method(method).with_user(user)
}

fn learn(config: &LearnConfig) -> RunResult {
    run(config, None, &mut NoObserver).expect("the default scenario runs")
}

#[test]
fn palc_personalizes_every_style_in_the_default_scenario() {
    for style in ["aggressive", "neutral", "cautious"] {
        let result = learn(&config(Method::Palc, style));
        assert_eq!(
            result.summary.outcome,
            Outcome::Personalized,
            "{style}: {:?}",
            result.summary
        );
        assert!(
            result.summary.counted_takeovers() < 30,
            "{style}: {:?}",
            result.summary
        );
        // The paper's criterion: the run ends on three takeover-free lane changes.
        let tail = &result.records[result.records.len() - 3..];
        assert!(tail.iter().all(|r| r.takeover.is_none()), "{style}");
        assert!(tail.iter().all(|r| r.max_deviation_m <= 0.3), "{style}");
    }
}

#[test]
fn the_same_seed_gives_the_same_run() {
    let config = config(Method::Palc, "neutral");
    let (a, b) = (learn(&config), learn(&config));
    assert_eq!(a.summary, b.summary);
    assert_eq!(a.records.len(), b.records.len());
    for (x, y) in a.records.iter().zip(&b.records) {
        assert_eq!(x.planned_l, y.planned_l);
        assert_eq!(x.driven_l, y.driven_l);
        assert_eq!(x.takeover, y.takeover);
    }
}

#[test]
fn a_user_who_expects_the_standard_alc_never_takes_over() {
    let mut config = config(Method::Palc, "custom");
    config.user.custom = Some(config.planning.standard_alc);
    let result = learn(&config);
    assert_eq!(result.summary.outcome, Outcome::Personalized);
    assert_eq!(result.summary.takeovers, 0);
    assert!(result.records.iter().all(|r| r.takeover.is_none()));
}

#[test]
fn after_success_the_learned_plan_is_not_taken_over_again() {
    let config = config(Method::Palc, "aggressive");
    let first = learn(&config);
    assert_eq!(first.summary.outcome, Outcome::Personalized);
    let again = run(&config, Some(&first.experience), &mut NoObserver).unwrap();
    assert_eq!(again.summary.takeovers, 0, "{:?}", again.summary);
}

#[test]
fn the_paper_method_runs_and_reports_its_outcome() {
    // The paper's method is tested for running correctly, not for converging: its
    // outcome is a finding, reported as measured.
    let result = learn(&config(Method::Paper, "neutral"));
    assert!(result.summary.takeovers <= 30);
    assert!(!result.records.is_empty());
    for record in &result.records {
        assert!((0.0..=1.0).contains(&record.perceived_safety_ratio));
        assert_eq!(
            record.perceived_safety_ratio == 1.0,
            record.takeover.is_none()
        );
    }
    if result.summary.outcome == Outcome::CapReached {
        assert_eq!(result.summary.counted_takeovers(), 30);
    }
}

#[test]
fn a_user_with_spread_is_judged_against_the_nominal_ceiling() {
    let mut config = config(Method::Palc, "neutral");
    config.user.spread = Some(palc_harness::user::Spread {
        relative: 0.02,
        seed: 11,
        parameters: Default::default(),
    });
    let result = learn(&config);
    let summary = result.summary;
    assert!((0.0..=1.0).contains(&summary.ceiling_takeover_rate));
    assert!(result.records.iter().all(|r| r.with_spread));
    if summary.outcome == Outcome::Personalized {
        let margin = config.stopping.spread_margin;
        assert!(summary.final_takeover_rate <= summary.ceiling_takeover_rate + margin + 1e-12);
    }
    // The evaluation phase after learning: the frozen plan against new draws.
    let frozen = summary
        .frozen
        .expect("a user with spread is evaluated frozen");
    assert_eq!(frozen.lane_changes, config.stopping.frozen_lane_changes);
    assert!(frozen.takeovers <= frozen.lane_changes);
    assert!(frozen.ceiling_takeovers <= frozen.lane_changes);
    assert_eq!(result.records.len(), summary.lane_changes);
}

#[test]
fn draws_that_take_two_gaps_are_planned_into_the_gap_most_take() {
    // collector-slow / 30 m / seed 3: about three in four of an aggressive user's
    // draws (5 % spread) start into the target lane's gap at 9.7 s, the others
    // into the gap at 5.1 s. Every lesson is a draw that took the other gap than
    // the plan, so lessons counted alone alternate between the gaps and the run
    // ended in the minority gap after 24 takeovers, its plan taken over in 41 of 50
    // frozen lane changes (the nominal plan: 10). The lane changes the user
    // accepted count too (scene_lessons.rs).
    let text = include_str!("../../../configs/learn.toml");
    let config = LearnConfig::from_toml_str(text).expect("the default config parses");
    let mut config = config
        .with_cell(CellChoice {
            speed_case: "collector-slow".into(),
            headway_m: 30.0,
            seed: 3,
        })
        .with_user(UserConfig::preset(StylePreset::Aggressive));
    config.user.spread = Some(palc_harness::user::Spread {
        relative: 0.05,
        seed: 3,
        parameters: Default::default(),
    });
    let result = learn(&config);
    let (start, end) = (5.1, 9.7);
    // The gap a lateral path goes into: the nearer of the two to its 10 % crossing.
    let gap_of = |l: &[f64], dt: f64| {
        let crossing = l.iter().position(|&l| l >= 0.35).expect("a lane change") as f64 * dt;
        if (crossing - start).abs() < (crossing - end).abs() {
            start
        } else {
            end
        }
    };
    let records = &result.records;
    let later = (records.iter())
        .filter(|r| gap_of(&r.expected_l, r.dt) == end)
        .count();
    assert!(2 * later > records.len(), "most draws take the later gap");
    let last = records.last().expect("lane changes");
    assert_eq!(
        gap_of(&last.planned_l, last.dt),
        end,
        "{:?}",
        result.summary
    );
    let frozen = result.summary.frozen.expect("an evaluation phase");
    assert!(
        frozen.takeovers <= frozen.ceiling_takeovers + 5,
        "{frozen:?}"
    );
}

#[test]
fn a_deterministic_user_has_no_evaluation_phase_and_none_can_be_asked_for() {
    let result = learn(&config(Method::Palc, "neutral"));
    assert_eq!(result.summary.frozen, None);
    let mut config = config(Method::Palc, "neutral");
    config.user.spread = Some(palc_harness::user::Spread {
        relative: 0.02,
        seed: 11,
        parameters: Default::default(),
    });
    config.stopping.frozen_lane_changes = 0;
    assert_eq!(learn(&config).summary.frozen, None);
    config.stopping.frozen_lane_changes = 1_001;
    let err = run(&config, None, &mut NoObserver).unwrap_err().to_string();
    assert!(err.contains("loop.frozen_lane_changes"), "{err}");
}

#[test]
fn a_wrong_type_in_a_nested_field_names_its_path_and_line() {
    let text = include_str!("../../../configs/learn.toml");
    let text = text.replacen("time_headway_s = 1.0", "time_headway_s = \"1 s\"", 1);
    let err = LearnConfig::from_toml_str(&text).unwrap_err().to_string();
    assert!(
        err.contains("`planning.standard_alc.time_headway_s`")
            && err.contains("line 25")
            && err.contains("invalid type"),
        "{err}"
    );
    let text = include_str!("../../../configs/learn.toml").replacen("lanes = 2", "lanes = -2", 1);
    let err = LearnConfig::from_toml_str(&text).unwrap_err().to_string();
    assert!(err.contains("`traffic.road.lanes`"), "{err}");
}

#[test]
fn invalid_configs_are_refused_naming_the_field() {
    let mut bad = config(Method::Palc, "neutral");
    bad.planning.takeover_threshold_m = -0.3;
    let err = run(&bad, None, &mut NoObserver).unwrap_err().to_string();
    assert!(err.contains("planning.takeover_threshold_m"), "{err}");

    let text = include_str!("../../../configs/learn.toml")
        .replace("style = \"neutral\"", "style = \"reckless\"");
    let err = LearnConfig::from_toml_str(&text).unwrap_err().to_string();
    for name in [
        "reckless",
        "`aggressive`",
        "`neutral`",
        "`cautious`",
        "`custom`",
    ] {
        assert!(err.contains(name), "{err}");
    }

    let mut bad = config(Method::Palc, "neutral");
    bad.standard_weights.lateral_stiffness = 0.0;
    let err = run(&bad, None, &mut NoObserver).unwrap_err().to_string();
    assert!(err.contains("standard_weights.lateral_stiffness"), "{err}");
    bad.standard_weights.lateral_stiffness = 1.0;
    bad.standard_weights.steering = f64::NAN;
    let err = run(&bad, None, &mut NoObserver).unwrap_err().to_string();
    assert!(err.contains("standard_weights.steering"), "{err}");

    // A window of 1e9 s at dt = 0.1 s would be 1e10 steps to allocate.
    let mut bad = config(Method::Palc, "neutral");
    bad.planning.search_window_s = 1e9;
    let err = run(&bad, None, &mut NoObserver).unwrap_err().to_string();
    assert!(
        err.contains("planning.search_window_s") && err.contains("at most"),
        "{err}"
    );

    let mut bad = config(Method::Palc, "neutral");
    bad.cell.speed_case = "autobahn".to_owned();
    let err = run(&bad, None, &mut NoObserver).unwrap_err().to_string();
    assert!(err.contains("autobahn"), "{err}");

    let custom = Style {
        time_headway_s: f64::NAN,
        ..Style::NEUTRAL
    };
    let mut bad = config(Method::Palc, "custom");
    bad.user.custom = Some(custom);
    let err = run(&bad, None, &mut NoObserver).unwrap_err().to_string();
    assert!(err.contains("user.custom.time_headway_s"), "{err}");
}

/// Counts what the loop tells an observer.
#[derive(Default)]
struct Tally {
    lane_changes: Vec<palc_harness::LaneChangeRecord>,
    learned: Vec<usize>,
    failed: Vec<usize>,
    expert_lengths: Vec<usize>,
    finished: Option<palc_harness::RunSummary>,
}

impl palc_harness::Observer for Tally {
    fn lane_change(&mut self, record: &palc_harness::LaneChangeRecord) {
        self.lane_changes.push(record.clone());
    }

    fn lesson(&mut self, event: &palc_harness::LessonEvent<'_>) {
        match event {
            palc_harness::LessonEvent::Learned {
                lane_change,
                outcome,
                ..
            } => {
                self.learned.push(*lane_change);
                self.expert_lengths.push(outcome.expert.states.len());
            }
            palc_harness::LessonEvent::Failed { lane_change, .. } => self.failed.push(*lane_change),
        }
    }

    fn finished(&mut self, summary: &palc_harness::RunSummary) {
        self.finished = Some(summary.clone());
    }
}

#[test]
fn observers_see_one_lesson_event_per_takeover_learned_from() {
    for (method, style) in [(Method::Palc, "cautious"), (Method::Paper, "neutral")] {
        let config = config(method, style);
        let mut tally = Tally::default();
        let result = run(&config, None, &mut tally).unwrap();
        let summary = &result.summary;
        assert_eq!(tally.finished.as_ref(), Some(summary));
        assert_eq!(tally.lane_changes.len(), result.records.len());
        // Every takeover is learned from, except the one that reaches the cap.
        let learned_from = if summary.takeovers >= summary.cap {
            summary.takeovers - 1
        } else {
            summary.takeovers
        };
        assert_eq!(
            tally.learned.len() + tally.failed.len(),
            learned_from,
            "{method:?}"
        );
        assert_eq!(tally.failed.len(), summary.learning_failures);
        let with_error: Vec<usize> = (result.records.iter())
            .filter(|r| r.learning_error.is_some())
            .map(|r| r.index)
            .collect();
        assert_eq!(tally.failed, with_error);
        // Each event names a taken-over lane change, in order.
        let mut events: Vec<usize> = tally.learned.iter().chain(&tally.failed).copied().collect();
        events.sort_unstable();
        events.dedup();
        assert_eq!(events.len(), learned_from);
        assert!(events.iter().all(|&i| result.records[i].takeover.is_some()));
        assert!(
            tally
                .expert_lengths
                .iter()
                .all(|&n| n == result.horizon + 1)
        );
    }
}

/// The estimate a lesson event gave: its scenes, misfit and line.
type Estimated = (usize, bool, String);

/// Records what each lesson event says palc believes about the driver.
#[derive(Default)]
struct Beliefs {
    /// Per lesson: the onsets the event carried and the estimate.
    seen: Vec<(usize, Option<Estimated>)>,
}

impl palc_harness::Observer for Beliefs {
    fn lesson(&mut self, event: &palc_harness::LessonEvent<'_>) {
        let (palc_harness::LessonEvent::Learned { driver, .. }
        | palc_harness::LessonEvent::Failed { driver, .. }) = event;
        let estimate = event.driver_estimate();
        self.seen.push((
            driver.onsets.len(),
            estimate.map(|e| (e.scenes(), e.outside_model(), e.describe())),
        ));
    }
}

#[test]
fn every_lesson_event_says_what_palc_believes_about_the_driver_with_that_lesson() {
    let config = config(Method::Palc, "neutral");
    let mut beliefs = Beliefs::default();
    let result = run(&config, None, &mut beliefs).unwrap();
    assert!(result.summary.takeovers >= 1);
    assert!(!beliefs.seen.is_empty());
    // The first lesson's start is already in the event: one scene, recorded
    // with what the user saw, and a headway user is inside the model.
    let (onsets, estimate) = &beliefs.seen[0];
    assert_eq!(*onsets, 1);
    let (scenes, outside, line) = estimate.as_ref().expect("the scene was recorded");
    assert_eq!(*scenes, 1);
    assert!(!outside, "{line}");
    assert!(line.contains("decides on the"), "{line}");
    // The run's experience holds the same onsets the last event carried.
    let (last_onsets, _) = beliefs.seen.last().unwrap();
    assert_eq!(*last_onsets, result.experience.onsets.len());
}

#[test]
fn stepping_the_loop_by_hand_gives_the_run() {
    let config = config(Method::Palc, "aggressive");
    let whole = learn(&config);
    let mut by_hand = palc_harness::LearningLoop::new(&config, None).unwrap();
    let mut indices = Vec::new();
    while by_hand.termination().is_none() {
        indices.push(by_hand.step(&mut NoObserver).unwrap().index);
    }
    assert_eq!(by_hand.termination(), Some(whole.summary.outcome));
    assert_eq!(indices, (0..whole.records.len()).collect::<Vec<_>>());
    for (x, y) in by_hand.records().iter().zip(&whole.records) {
        assert_eq!(x.planned_l, y.planned_l);
        assert_eq!(x.takeover, y.takeover);
    }
    assert_eq!(by_hand.experience().weights, whole.experience.weights);
}

#[test]
fn averaging_lessons_changes_nothing_for_a_user_who_repeats_the_lane_change() {
    // With the incremental rule a deterministic user needs several lessons, so the
    // mean is taken; since every lesson shows the same lane change, it is the same.
    for style in ["aggressive", "cautious"] {
        let mut options = Method::Palc.aggregator_options();
        options.correction = palc_aggregator::CorrectionRule::Incremental(
            palc_aggregator::IncrementalRule::default(),
        );
        let mut last_only = config(Method::Palc, style);
        last_only.aggregator = Some(palc_aggregator::AggregatorOptions {
            average_lessons: false,
            ..options.clone()
        });
        let mut averaged = last_only.clone();
        averaged.aggregator = Some(options);
        let (a, b) = (learn(&last_only), learn(&averaged));
        assert!(a.summary.takeovers >= 2, "{style}: {:?}", a.summary);
        assert_eq!(a.summary.takeovers, b.summary.takeovers, "{style}");
        assert!(
            (a.summary.final_max_deviation_m - b.summary.final_max_deviation_m).abs() < 0.02,
            "{style}: {} against {}",
            a.summary.final_max_deviation_m,
            b.summary.final_max_deviation_m
        );
    }
}

/// `follow_user_speed`: a user who slows to the target lane's speed once it has
/// started takes over the first lane change and drives at its own speed; the
/// next plan slows down with it from the takeover on, to the speed the user
/// ended at, while without the option it keeps the scenario's speed. A user who
/// keeps the scenario's speed leaves the plans as they were.
#[test]
fn the_plans_follow_the_speed_the_user_drove() {
    let slowing = |follow_user_speed: bool| {
        let mut config = config(Method::Palc, "neutral");
        config.user = UserConfig::from_toml_str(
            "[user]\nstyle = \"neutral\"\nfamily = { speed = { rule = \"accelerating\", max_acceleration_mps2 = 1.5 } }",
            config.planning.takeover_threshold_m,
        )
        .unwrap();
        config.aggregator = Some(palc_aggregator::AggregatorOptions {
            follow_user_speed,
            ..Method::Palc.aggregator_options()
        });
        let mut run = palc_harness::LearningLoop::new(&config, None).unwrap();
        let first = run.step(&mut NoObserver).unwrap().clone();
        let takeover = first
            .takeover
            .expect("the standard ALC's plan is taken over");
        (run.next_plan().clone(), takeover.step)
    };
    let ((followed, step), (kept, _)) = (slowing(true), slowing(false));
    let scenario_speed = kept.states[0].v;
    let end = |plan: &palc_planner::Plan| plan.states.last().unwrap().v;
    assert!((end(&kept) - scenario_speed).abs() < 1e-3, "{}", end(&kept));
    assert!(
        end(&followed) < scenario_speed - 1.0,
        "ends at {} m/s, the scenario at {scenario_speed}",
        end(&followed)
    );
    // Before the takeover the two plans move alike.
    let before = step.saturating_sub(20);
    assert!((followed.states[before].v - kept.states[before].v).abs() < 0.2);

    // A user at the scenario's speed: the same plans with and without the option.
    let keeping = |follow_user_speed: bool| {
        let mut config = config(Method::Palc, "neutral");
        config.aggregator = Some(palc_aggregator::AggregatorOptions {
            follow_user_speed,
            ..Method::Palc.aggregator_options()
        });
        learn(&config)
    };
    let (a, b) = (keeping(true), keeping(false));
    assert_eq!(a.summary.takeovers, b.summary.takeovers);
    for (x, y) in a.records.iter().zip(&b.records) {
        assert_eq!(x.planned_l, y.planned_l);
    }
}

#[test]
fn a_run_keeps_what_the_estimate_believed_once_two_scenes_were_recorded() {
    let in_cell = |method: Method, speed_case: &str, headway_m: f64| {
        config(method, "neutral").with_cell(CellChoice {
            speed_case: speed_case.into(),
            headway_m,
            seed: 1,
        })
    };
    let chain = |method: Method| {
        let first = learn(&in_cell(method, "collector-high", 40.0));
        let second = run(
            &in_cell(method, "arterial-slow", 50.0),
            Some(&first.experience),
            &mut NoObserver,
        )
        .unwrap();
        let third = run(
            &in_cell(method, "collector-slow", 30.0),
            Some(&second.experience),
            &mut NoObserver,
        )
        .unwrap();
        [first, second, third]
    };
    let [scratch, one, two] = chain(Method::Palc);
    // From scratch and with one recorded scene the estimate is not consulted.
    assert_eq!(scratch.carried_belief, None);
    assert_eq!(one.carried_belief, None);
    let recorded = (one.experience.onsets.iter())
        .filter(|o| o.scene.is_some())
        .count();
    assert_eq!(recorded, 2);
    let belief = two.carried_belief.expect("two recorded scenes");
    assert_eq!(belief.scenes, 2);
    // The paper's neutral user decides on its time headway: inside the model.
    assert!(!belief.outside_model, "{belief:?}");
    assert!(belief.cue_mass > 0.0 && belief.cue_mass <= 1.0);
    // `paper` carries its weights in their own time base: no estimate.
    let [_, _, paper] = chain(Method::Paper);
    assert_eq!(paper.carried_belief, None);
}
