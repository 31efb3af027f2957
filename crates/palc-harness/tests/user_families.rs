//! The user families: for random valid parameters, the expected lane change is
//! either refused with a message naming the user and what failed, or it starts on
//! the current lane's centre, ends on the target lane's, stays on the road, is
//! smooth, and starts as the family's start rule says; invalid parameters name
//! their field; and a user defined outside the harness runs in the loop.

use palc_harness::user::ExpectedLaneChange;
use palc_harness::user::{
    Expectation, Family, LateralProfile, MAX_LATERAL_ACCELERATION_MPS2, MAX_LATERAL_JERK_MPS3,
    PerceivedSafety, ProfilePoint, SimulatedUser, SpeedRule, StartRule, Style, StylePreset, User,
    UserError, UserScene, quintic,
};
use palc_harness::{LearnConfig, LearningLoop, NoObserver, Outcome, Setup, prepare};
use proptest::prelude::*;

fn base() -> LearnConfig {
    LearnConfig::from_toml_str(include_str!("../../../configs/learn.toml")).unwrap()
}

fn setup(speed_case: &str, headway_m: f64) -> Setup {
    let config = base().with_cell(palc_harness::CellChoice {
        speed_case: speed_case.to_owned(),
        headway_m,
        seed: 1,
    });
    prepare(&config).unwrap()
}

fn profile() -> impl Strategy<Value = LateralProfile> {
    prop_oneof![
        Just(LateralProfile::Quintic),
        Just(LateralProfile::Cosine),
        (0.3f64..=0.7).prop_map(|peak_fraction| LateralProfile::Asymmetric { peak_fraction }),
        // A recorded-looking profile: a smooth curve sampled every 0.05-0.3 s.
        (1.8f64..5.0, 0.05f64..0.3).prop_map(|(duration, spacing)| {
            let n = (duration / spacing).ceil() as usize;
            let points = (0..=n)
                .map(|i| {
                    let t = (i as f64 * spacing).min(duration);
                    ProfilePoint {
                        time_s: t,
                        offset_m: 3.5 * quintic(t / duration),
                    }
                })
                .collect();
            LateralProfile::Table { points }
        }),
    ]
}

fn family() -> impl Strategy<Value = Family> {
    let start = prop_oneof![
        Just(StartRule::TimeHeadway),
        (4.0f64..12.0).prop_map(|seconds| StartRule::TimeToCollision { seconds }),
        (15.0f64..40.0).prop_map(|metres| StartRule::DistanceGap { metres }),
        (0.0f64..0.5).prop_map(|threshold_mps2| StartRule::Incentive { threshold_mps2 }),
        (4.0f64..12.0).prop_map(|ttc_seconds| StartRule::HeadwayOrTtc { ttc_seconds }),
    ];
    let speed = prop_oneof![
        Just(SpeedRule::Constant),
        (0.1f64..4.0).prop_map(|max_acceleration_mps2| SpeedRule::Accelerating {
            max_acceleration_mps2
        }),
    ];
    let comfort =
        proptest::option::of(
            (0.1f64..0.5, 0.5f64..2.0).prop_map(|(gap, ttc)| PerceivedSafety {
                min_time_gap_s: gap,
                min_ttc_s: Some(ttc),
                onset_m: 0.5,
            }),
        );
    (start, 0.0f64..1.5, profile(), speed, comfort).prop_map(
        |(start, reaction_s, profile, speed, perceived_safety)| Family {
            start,
            reaction_s,
            profile,
            speed,
            perceived_safety,
            ..Family::default()
        },
    )
}

/// The checks every accepted expectation passes.
fn check(expectation: &Expectation, setup: &Setup, family: &Family, style: &Style) {
    let lane_change = &expectation.lane_change;
    let dt = setup.dt;
    // Lane centre to lane centre, on the road.
    assert!(expectation.states[0].l.abs() < 1e-9);
    let end = (lane_change.end_s() / dt).ceil() as usize;
    assert!((expectation.states[end].l - setup.target_l).abs() < 0.011);
    assert!(
        expectation
            .states
            .iter()
            .all(|x| (-1.75..=setup.target_l + 1.75).contains(&x.l))
    );
    // Smooth.
    let (acceleration, jerk) = lane_change.peak_acceleration_and_jerk();
    assert!(acceleration <= MAX_LATERAL_ACCELERATION_MPS2);
    assert!(jerk <= MAX_LATERAL_JERK_MPS3);
    // The start rule holds at the decision, the start is no earlier than the
    // reaction, and nothing moves before the start.
    let scene_set_speed = setup.user_scene().set_speed;
    let decided = &setup.situations[expectation.decision_step];
    assert!(
        family
            .start
            .decides(decided, style.time_headway_s, scene_set_speed)
    );
    if expectation.decision_step > 0 {
        let before = &setup.situations[expectation.decision_step - 1];
        assert!(
            !family
                .start
                .decides(before, style.time_headway_s, scene_set_speed)
        );
    }
    let reaction_steps = (family.reaction_s / dt - 1e-9).ceil() as usize;
    assert!(expectation.start_step >= expectation.decision_step + reaction_steps);
    assert!(
        expectation.states[..=expectation.start_step]
            .iter()
            .all(|x| x.l.abs() < 1e-9)
    );
    assert!((lane_change.start_s - expectation.start_step as f64 * dt).abs() < 1e-9);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn every_family_expects_a_sane_lane_change_or_says_why_not(
        family in family(),
        preset in 0usize..3,
        case in 0usize..4,
        headway in prop_oneof![Just(40.0), Just(50.0)],
    ) {
        let speed_case = ["collector-high", "collector-slow", "arterial-high", "arterial-slow"][case];
        let style = StylePreset::ALL[preset].style();
        family.validate("user.family").unwrap();
        let user = SimulatedUser::new("probe", style, family.clone(), 0.3, None).unwrap();
        let setup = setup(speed_case, headway);
        match user.nominal(&setup.user_scene()) {
            Ok(expectation) => check(&expectation, &setup, &family, &style),
            Err(UserError::Refused { user, refusal }) => {
                prop_assert_eq!(user, "probe");
                prop_assert!(!refusal.to_string().is_empty());
            }
            Err(other) => prop_assert!(false, "unexpected error {other}"),
        }
    }
}

#[test]
fn the_paper_user_is_the_default_family() {
    // The built-in user with the default family expects what the paper's user does.
    let setup = setup("collector-high", 40.0);
    for preset in StylePreset::ALL {
        let style = preset.style();
        let user = SimulatedUser::paper(style).unwrap();
        let expectation = user.nominal(&setup.user_scene()).unwrap();
        let paper = setup.expected(&style).unwrap();
        assert_eq!(expectation.lane_change, paper);
        assert_eq!(
            expectation.lateral(setup.horizon),
            paper.sample(setup.horizon, setup.dt)
        );
    }
}

#[test]
fn most_plausible_families_are_accepted_in_the_grid() {
    // Not a vacuous property: the typical family of each kind is accepted in the
    // uncongested cells of every speed case.
    let families = [
        Family::default(),
        Family {
            start: StartRule::TimeToCollision { seconds: 8.0 },
            ..Family::default()
        },
        Family {
            start: StartRule::DistanceGap { metres: 30.0 },
            ..Family::default()
        },
        Family {
            start: StartRule::HeadwayOrTtc { ttc_seconds: 8.0 },
            ..Family::default()
        },
        Family {
            profile: LateralProfile::Cosine,
            reaction_s: 0.8,
            ..Family::default()
        },
        Family {
            profile: LateralProfile::Asymmetric { peak_fraction: 0.6 },
            speed: SpeedRule::Accelerating {
                max_acceleration_mps2: 1.5,
            },
            ..Family::default()
        },
    ];
    for family in families {
        for case in [
            "collector-high",
            "collector-slow",
            "arterial-high",
            "arterial-slow",
        ] {
            let setup = setup(case, 50.0);
            let user =
                SimulatedUser::new("probe", Style::NEUTRAL, family.clone(), 0.3, None).unwrap();
            let expectation = user
                .nominal(&setup.user_scene())
                .unwrap_or_else(|e| panic!("{case}, {}: {e}", family.describe()));
            check(&expectation, &setup, &family, &Style::NEUTRAL);
        }
    }
}

#[test]
fn invalid_user_tables_name_the_field_value_and_bound() {
    let deviation = 0.3;
    let cases = [
        (
            "[user]\nstyle = \"neutral\"\nfamily = { start = { rule = \"time-to-collision\", seconds = 0.1 } }",
            "user.family.start.seconds",
        ),
        (
            "[user]\nstyle = \"neutral\"\nfamily = { profile = { shape = \"asymmetric\", peak_fraction = 0.9 } }",
            "user.family.profile.peak_fraction",
        ),
        (
            "[user]\nstyle = \"neutral\"\nfamily = { reaction_s = -1.0 }",
            "user.family.reaction_s",
        ),
        (
            "[user]\nstyle = \"neutral\"\nfamily = { start = { rule = \"incentive\", threshold_mps2 = 3.0 } }",
            "user.family.start.threshold_mps2",
        ),
        (
            "[user]\nstyle = \"neutral\"\nfamily = { start = { rule = \"headway-or-ttc\", ttc_seconds = 0.5 } }",
            "user.family.start.ttc_seconds",
        ),
        (
            "[user]\nstyle = \"neutral\"\nspread = { relative = 0.0, seed = 1, parameters = { reaction_s = { absolute = -0.1 } } }",
            "user.spread.parameters.reaction_s.absolute",
        ),
        (
            "[user]\nstyle = \"neutral\"\nfamily = { profile = { shape = \"spline\" } }",
            "user.family.profile",
        ),
    ];
    for (text, field) in cases {
        let err = palc_harness::UserConfig::from_toml_str(text, deviation)
            .unwrap_err()
            .to_string();
        assert!(err.contains(field), "{field}: {err}");
    }
    let parsed = palc_harness::UserConfig::from_toml_str(
        "[user]\nstyle = \"cautious\"\n[user.family]\nprofile = { shape = \"cosine\" }\n",
        deviation,
    )
    .unwrap();
    assert_eq!(parsed.family.unwrap().profile, LateralProfile::Cosine);
}

/// A user defined outside the harness: it expects the standard ALC's own lane
/// change (told to it once, as a recorded driver is given its trace), so the
/// system's very first plan satisfies it.
#[derive(Debug)]
struct LikesTheStandardAlc {
    lane_change: ExpectedLaneChange,
    start_step: usize,
}

impl User for LikesTheStandardAlc {
    fn name(&self) -> &str {
        "likes the standard ALC"
    }

    fn nominal(&self, scene: &UserScene<'_>) -> Result<Expectation, UserError> {
        let paper = SimulatedUser::paper(Style::NEUTRAL)?;
        let mut expectation = paper.nominal(scene)?;
        expectation.lane_change = self.lane_change.clone();
        expectation.start_step = self.start_step;
        for (i, state) in expectation.states.iter_mut().enumerate() {
            state.l = expectation.lane_change.lateral(i as f64 * scene.dt);
        }
        Ok(expectation)
    }

    fn next(&mut self, scene: &UserScene<'_>) -> Result<Expectation, UserError> {
        self.nominal(scene)
    }
}

#[test]
fn a_user_from_outside_the_harness_plugs_into_the_loop() {
    let config = base();
    let setup = prepare(&config).unwrap();
    let user = LikesTheStandardAlc {
        lane_change: setup.standard_lane_change(&config.planning.standard_alc),
        start_step: setup.standard_start_step,
    };
    let run = LearningLoop::with_user(&config, None, Box::new(user)).unwrap();
    let result = run.run(&mut NoObserver).unwrap();
    assert_eq!(result.summary.outcome, Outcome::Personalized);
    assert_eq!(result.summary.counted_takeovers(), 0);
    // And one that is far from it is taught from its takeovers, as the built-in users.
    let late = SimulatedUser::new(
        "cosine",
        Style::AGGRESSIVE,
        Family {
            profile: LateralProfile::Cosine,
            ..Family::default()
        },
        0.3,
        None,
    )
    .unwrap();
    let result = LearningLoop::with_user(&config, None, Box::new(late))
        .unwrap()
        .run(&mut NoObserver)
        .unwrap();
    assert!(result.summary.counted_takeovers() > 0);
    assert!(result.records.iter().any(|r| r.takeover.is_some()));
}

#[test]
fn an_incentive_driver_changes_only_where_the_target_lane_gains() {
    // MOBIL's driver (threshold 0.1 m/s², Kesting et al. 2007) in the test bed,
    // whose target lane moves at the preceding vehicle's speed: on the collector
    // cells the target lane's leader is far enough ahead to gain acceleration once
    // the follower has passed, on arterial-high at 50 m it never is before the
    // ego has closed in (the target lane's leaders are nearer than the own one).
    let family = Family {
        start: StartRule::Incentive {
            threshold_mps2: 0.1,
        },
        ..Family::default()
    };
    let user = SimulatedUser::new("probe", Style::NEUTRAL, family.clone(), 0.3, None).unwrap();
    for case in ["collector-high", "collector-slow"] {
        let setup = setup(case, 50.0);
        let expectation = user.nominal(&setup.user_scene()).unwrap();
        check(&expectation, &setup, &family, &Style::NEUTRAL);
        let decided = &setup.situations[expectation.decision_step];
        let (gain, follower) = palc_user::incentive_mps2(decided, setup.user_scene().set_speed);
        assert!(gain > 0.1 && follower >= -palc_user::INCENTIVE_SAFE_DECELERATION_MPS2);
    }
    let refused = user.nominal(&setup("arterial-high", 50.0).user_scene());
    assert!(
        matches!(
            refused,
            Err(UserError::Refused {
                refusal: palc_user::UserRefusal::StartRuleNeverMet { .. },
                ..
            })
        ),
        "{refused:?}"
    );
}
