//! The built-in user on a scene built by hand, without the loop: an ego at
//! 25 m/s closing on a preceding vehicle at 20 m/s, with an empty target lane
//! or a target-lane leader just ahead. Every number below follows from the
//! scene's kinematics and the paper's styles (Section III.A).

use palc_user::{
    Family, SafeDistance, SimulatedUser, Situation, Style, StylePreset, User, UserError,
    UserRefusal, UserScene,
};

const DT: f64 = 0.1;
const EGO_V: f64 = 25.0;
const PRECEDING_V: f64 = 20.0;
/// The net gap to the preceding vehicle at step 0 (m): a 2.2 s time headway.
const GAP0: f64 = 2.2 * EGO_V;

/// `n + 1` steps of the ego keeping its lane at constant speed, closing on the
/// preceding vehicle; `lead` is the target lane's leader's `(gap at step 0, speed)`.
fn scene_steps(n: usize, lead: Option<(f64, f64)>) -> (Vec<Situation>, Vec<[f64; 2]>) {
    let situations = (0..=n)
        .map(|i| {
            let t = i as f64 * DT;
            let gap = GAP0 - (EGO_V - PRECEDING_V) * t;
            Situation {
                time_headway_s: gap / EGO_V,
                preceding_gap_m: gap,
                preceding_speed: Some(PRECEDING_V),
                target_lead_gap_m: lead.map(|(g, v)| g + (v - EGO_V) * t),
                target_lag_gap_m: None,
                ego_speed: EGO_V,
                target_lead_speed: lead.map(|(_, v)| v),
                target_lag_speed: None,
            }
        })
        .collect();
    let lane_keeping = (0..=n).map(|i| [EGO_V * i as f64 * DT, EGO_V]).collect();
    (situations, lane_keeping)
}

fn scene<'a>(situations: &'a [Situation], lane_keeping: &'a [[f64; 2]]) -> UserScene<'a> {
    UserScene {
        dt: DT,
        situations,
        lane_keeping,
        set_speed: EGO_V,
        target_l: 3.5,
        safe_gaps: None,
    }
}

#[test]
fn each_style_starts_at_its_headway_and_ends_on_the_target_lane() {
    let (situations, lane_keeping) = scene_steps(200, None);
    let scene = scene(&situations, &lane_keeping);
    let mut starts = Vec::new();
    for preset in StylePreset::ALL {
        let style = preset.style();
        let user = SimulatedUser::paper(style).unwrap();
        let expectation = user.nominal(&scene).unwrap();
        // The headway falls by 0.2 s per second: the first step at or below the
        // style's headway.
        let expected_step = situations
            .iter()
            .position(|s| s.time_headway_s <= style.time_headway_s)
            .unwrap();
        assert_eq!(expectation.start_step, expected_step, "{preset}");
        assert_eq!(expectation.decision_step, expected_step, "{preset}");
        let lane_change = &expectation.lane_change;
        assert!((lane_change.duration_s - style.lane_change_duration_s).abs() < 1e-12);
        assert!((lane_change.lateral(lane_change.end_s()) - 3.5).abs() < 1e-9);
        assert!(lane_change.lateral(lane_change.start_s).abs() < 1e-9);
        assert_eq!(expectation.states.len(), situations.len());
        starts.push(expectation.start_step);
    }
    // The cautious user (longest headway) starts first, the aggressive last.
    assert!(starts[2] < starts[1] && starts[1] < starts[0], "{starts:?}");
}

#[test]
fn a_user_who_never_decides_in_the_window_refuses_it_with_its_rule() {
    // Ten steps: the headway stays above every style's.
    let (situations, lane_keeping) = scene_steps(10, None);
    let user = SimulatedUser::paper(Style::NEUTRAL).unwrap();
    match user.nominal(&scene(&situations, &lane_keeping)) {
        Err(UserError::Refused { user, refusal }) => {
            assert_eq!(user, "paper");
            assert_eq!(refusal.kind(), "start-rule-never-met");
            assert!(
                matches!(refusal, UserRefusal::StartRuleNeverMet { window_s, .. }
                if (window_s - 1.0).abs() < 1e-12)
            );
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_close_target_lane_leader_delays_the_start_until_its_gap_is_accepted() {
    // A leader 5 m ahead at 26 m/s: the lead gap opens at 1 m/s and the neutral
    // user needs 0.6 s × 25 m/s = 15 m of it, 10 s in, after its decision at 4.9 s.
    let (situations, lane_keeping) = scene_steps(200, Some((5.0, 26.0)));
    let user = SimulatedUser::paper(Style::NEUTRAL).unwrap();
    let expectation = user.nominal(&scene(&situations, &lane_keeping)).unwrap();
    let open = situations
        .iter()
        .position(|s| s.target_lead_gap_m.unwrap() >= 15.0)
        .unwrap();
    assert!(expectation.decision_step < open);
    assert_eq!(expectation.start_step, open);
}

#[test]
fn waiting_for_safe_gaps_starts_no_earlier_and_keeps_the_safe_distance() {
    // A leader 5 m ahead at 30 m/s, and an ego that brakes at only 3 m/s²: the
    // safe distance to the leader, 48 m, opens 8.6 s in, after the neutral user
    // would have started (its decision at 4.9 s, the 15 m it accepts long open).
    let (situations, lane_keeping) = scene_steps(300, Some((5.0, 30.0)));
    let rss = SafeDistance {
        response_time_s: 0.5,
        max_acceleration_mps2: 1.5,
        min_braking_mps2: 3.0,
        max_braking_mps2: 6.0,
    };
    let user = SimulatedUser::paper(Style::NEUTRAL).unwrap();
    let plain = user.nominal(&scene(&situations, &lane_keeping)).unwrap();
    let safe_scene = UserScene {
        safe_gaps: Some(rss),
        ..scene(&situations, &lane_keeping)
    };
    let safe = user.nominal(&safe_scene).unwrap();
    assert!(safe.start_step > plain.start_step);
    assert!(rss.target_gaps_safe(&situations[safe.start_step]));
    assert!(!rss.target_gaps_safe(&situations[safe.start_step - 1]));
}

#[test]
fn a_user_is_send_so_loops_can_run_on_threads() {
    fn send<T: Send>(_: &T) {}
    let user: Box<dyn User> = Box::new(
        SimulatedUser::new("probe", Style::CAUTIOUS, Family::default(), 0.3, None).unwrap(),
    );
    send(&user);
    let handle = std::thread::spawn(move || user.name().to_owned());
    assert_eq!(handle.join().unwrap(), "probe");
}

mod properties {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

        /// Any valid style on the closing scene starts where its headway is first
        /// reached, ends on the target lane and never leaves the two lanes; moving
        /// the whole scene along the road changes the start by nothing.
        #[test]
        fn a_style_starts_at_its_headway_wherever_the_scene_is(
            headway in 0.9f64..2.0,
            duration in 1.5f64..4.0,
            shift in -500.0f64..500.0,
        ) {
            let (situations, lane_keeping) = scene_steps(300, None);
            let style = Style {
                time_headway_s: headway,
                lane_change_duration_s: duration,
                ..Style::NEUTRAL
            };
            let user = SimulatedUser::paper(style).unwrap();
            let expectation = user.nominal(&scene(&situations, &lane_keeping)).unwrap();
            let first = situations.iter().position(|s| s.time_headway_s <= headway).unwrap();
            prop_assert_eq!(expectation.start_step, first);
            let lane_change = &expectation.lane_change;
            prop_assert!((lane_change.lateral(lane_change.end_s()) - 3.5).abs() < 1e-9);
            prop_assert!(expectation.states.iter().all(|x| (-1.75..=5.25).contains(&x.l)));
            let shifted: Vec<[f64; 2]> =
                lane_keeping.iter().map(|&[s, v]| [s + shift, v]).collect();
            let moved = user.nominal(&scene(&situations, &shifted)).unwrap();
            prop_assert_eq!(moved.start_step, expectation.start_step);
            prop_assert_eq!(&moved.lane_change, &expectation.lane_change);
        }

        /// The RSS safe distance grows with the rear vehicle's speed and shrinks
        /// with the front one's, and is never negative.
        #[test]
        fn the_safe_distance_is_monotone_and_never_negative(
            rear in 0.0f64..50.0,
            front in 0.0f64..50.0,
            faster in 0.0f64..10.0,
        ) {
            let rss = SafeDistance {
                response_time_s: 0.5,
                max_acceleration_mps2: 1.5,
                min_braking_mps2: 6.0,
                max_braking_mps2: 6.0,
            };
            let d = rss.distance(rear, front);
            prop_assert!(d >= 0.0);
            prop_assert!(rss.distance(rear + faster, front) >= d);
            prop_assert!(rss.distance(rear, front + faster) <= d);
        }
    }
}

/// A 3.5 m, 3 s quintic lane change sampled at 10 Hz with 5 cm of noise (a
/// deterministic hash, roughly uniform with that standard deviation), the last
/// point on the target lane's centre as a table requires.
fn noisy_samples() -> Vec<palc_user::ProfilePoint> {
    let noise = |i: usize| {
        let x = ((i as f64 + 1.0) * 12.9898).sin() * 43_758.545_3;
        (x - x.floor() - 0.5) * 12f64.sqrt() * 0.05
    };
    (0..=30)
        .map(|i| {
            let t = i as f64 * 0.1;
            let edge = i == 0 || i == 30;
            palc_user::ProfilePoint {
                time_s: t,
                offset_m: 3.5 * palc_user::quintic(t / 3.0) + if edge { 0.0 } else { noise(i) },
            }
        })
        .collect()
}

#[test]
fn a_noisy_recording_is_refused_as_a_table_and_driven_smoothed_as_recorded() {
    let (situations, lane_keeping) = scene_steps(200, None);
    let scene = scene(&situations, &lane_keeping);
    let style = Style {
        lane_change_duration_s: 3.0,
        ..Style::NEUTRAL
    };
    let table = Family {
        profile: palc_user::LateralProfile::Table {
            points: noisy_samples(),
        },
        ..Family::default()
    };
    let user = SimulatedUser::new("table", style, table, 0.3, None).unwrap();
    match user.nominal(&scene) {
        Err(UserError::Refused {
            refusal: UserRefusal::NotSmooth {
                acceleration_mps2, ..
            },
            ..
        }) => assert!(acceleration_mps2 > 10.0, "{acceleration_mps2}"),
        other => panic!("a table of noisy samples is driven as is: {other:?}"),
    }
    let recorded = Family {
        profile: palc_user::LateralProfile::Recorded(palc_user::RecordedProfile::new(
            noisy_samples(),
            0.05,
        )),
        ..Family::default()
    };
    let user = SimulatedUser::new("recorded", style, recorded, 0.3, None).unwrap();
    let expectation = user.nominal(&scene).unwrap();
    let (acceleration, _) = expectation.lane_change.peak_acceleration_and_jerk();
    // The quintic's own peak is 5.77 × 3.5 m / (3 s)² = 2.24 m/s².
    assert!(acceleration < 4.0, "{acceleration}");
}
