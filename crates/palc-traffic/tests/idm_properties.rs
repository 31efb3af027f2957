//! Properties any IDM implementation must have (issue 2, item 3), tested on the scene's
//! ballistic integration.

mod common;

use common::{net_gaps, platoon, road, vehicle};
use palc_traffic::{
    DesiredGap, Driver, IdmParams, ScenarioConfig, Scene, SpeedProfile, ballistic_step,
};
use proptest::prelude::*;

fn idm_params() -> impl Strategy<Value = IdmParams> {
    (
        0.8..2.0f64,
        1.0..3.0f64,
        0.5..2.5f64,
        1.0..3.0f64,
        prop_oneof![Just(4.0), 1.0..6.0f64],
        prop_oneof![Just(DesiredGap::Clamped), Just(DesiredGap::Treiber2000)],
    )
        .prop_map(|(t, s0, a, b, delta, desired_gap)| IdmParams {
            v0: 1.0,
            t,
            s0,
            a,
            b,
            delta,
            desired_gap,
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// A platoon that starts in equilibrium never collides when its leader brakes at up to b,
    /// down to any lower speed including a stop.
    #[test]
    fn no_collision_when_the_leader_brakes_at_up_to_b(
        idm in idm_params(),
        v0 in 10.0..35.0f64,
        speed_fraction in 0.3..0.95f64,
        end_fraction in 0.0..1.0f64,
        decel_fraction in 0.1..=1.0f64,
        dt in prop_oneof![Just(0.05), Just(0.1), Just(0.2)],
    ) {
        let idm = IdmParams { v0, ..idm };
        let v = speed_fraction * v0;
        let v_end = end_fraction * v;
        let decel = decel_fraction * idm.b;
        let profile = SpeedProfile::new(vec![(0.0, v), (2.0, v), (2.0 + (v - v_end) / decel, v_end)]).unwrap();
        let gap = idm.equilibrium_gap(v).unwrap();
        let mut scene = platoon(profile, idm, &[(gap, v); 5]);
        for _ in 0..(60.0 / dt) as usize {
            scene.step_autonomous(dt).unwrap();
            let min_gap = net_gaps(&scene).into_iter().fold(f64::INFINITY, f64::min);
            prop_assert!(min_gap > 0.0, "collision at t = {}: min net gap {}", scene.time(), min_gap);
            prop_assert!(scene.collisions().is_empty());
        }
    }

    /// Speeds stay within [0, v0] (tolerance 1e-9 m/s) from any non-overlapping start with
    /// speeds up to v0, behind a leader whose scripted speed stays below v0.
    #[test]
    fn speeds_stay_between_zero_and_v0(
        idm in idm_params(),
        v0 in 5.0..40.0f64,
        starts in proptest::collection::vec((0.5..80.0f64, 0.0..=1.0f64), 1..6),
        profile_speeds in proptest::collection::vec(0.0..=1.0f64, 1..5),
        dt in prop_oneof![Just(0.05), Just(0.1), Just(0.2), Just(0.5)],
    ) {
        let idm = IdmParams { v0, ..idm };
        let points = profile_speeds.iter().enumerate().map(|(i, f)| (5.0 * i as f64, f * v0)).collect();
        let followers: Vec<(f64, f64)> = starts.iter().map(|&(gap, f)| (gap, f * v0)).collect();
        let mut scene = platoon(SpeedProfile::new(points).unwrap(), idm, &followers);
        for _ in 0..(40.0 / dt) as usize {
            scene.step_autonomous(dt).unwrap();
            for vehicle in scene.vehicles() {
                prop_assert!(vehicle.state.v >= 0.0);
                prop_assert!(vehicle.state.v <= v0 + 1e-9, "speed {} above v0 {}", vehicle.state.v, v0);
                prop_assert!(vehicle.state.s.is_finite() && vehicle.state.a.is_finite());
            }
        }
    }

    /// Behind a leader at constant speed v the gap settles at the closed-form equilibrium
    /// s_e(v) = (s0 + v T) / sqrt(1 - (v/v0)^delta): exactly when started there, and within
    /// 1 % after 400 s when started up to 10 % away from it.
    #[test]
    fn stationary_gap_is_the_equilibrium_gap(
        idm in idm_params(),
        v0 in 10.0..35.0f64,
        speed_fraction in 0.2..0.9f64,
        offset in -0.1..0.1f64,
    ) {
        let idm = IdmParams { v0, ..idm };
        let v = speed_fraction * v0;
        let gap = idm.equilibrium_gap(v).unwrap();
        let profile = SpeedProfile::new(vec![(0.0, v)]).unwrap();
        let dt = 0.1;

        let mut steady = platoon(profile.clone(), idm, &[(gap, v), (gap, v)]);
        for _ in 0..600 {
            steady.step_autonomous(dt).unwrap();
        }
        for g in net_gaps(&steady) {
            prop_assert!((g - gap).abs() < 1e-6 * gap, "steady gap {} vs s_e {}", g, gap);
        }

        let mut perturbed = platoon(profile, idm, &[(gap * (1.0 + offset), v), (gap, v)]);
        for _ in 0..4000 {
            perturbed.step_autonomous(dt).unwrap();
        }
        for g in net_gaps(&perturbed) {
            prop_assert!((g - gap).abs() < 0.01 * gap, "gap {} did not settle at s_e {}", g, gap);
        }
    }

    /// On a free road the IDM acceleration tends to a as the speed tends to 0: exactly a from
    /// standstill, within a (v/v0)^delta at low speed, and the speed rises monotonically to v0.
    #[test]
    fn free_road_acceleration_approaches_a(
        idm in idm_params(),
        v0 in 5.0..40.0f64,
        low in 0.0..0.1f64,
    ) {
        let idm = IdmParams { v0, ..idm };
        prop_assert!((idm.free_acceleration(0.0) - idm.a).abs() < 1e-12);
        let v = low * v0;
        prop_assert!((idm.a - idm.acceleration_behind(v, None)).abs() <= idm.a * low.powf(idm.delta) + 1e-12);

        let mut scene = Scene::new(road(), vec![vehicle(0, 0.0, 0.0, Driver::Idm(idm))], 9.0).unwrap();
        scene.step_autonomous(0.1).unwrap();
        prop_assert!((scene.vehicles()[0].state.a - idm.a).abs() < 1e-9);
        let mut previous = scene.vehicles()[0].state.v;
        for _ in 0..3000 {
            scene.step_autonomous(0.1).unwrap();
            let v = scene.vehicles()[0].state.v;
            prop_assert!(v >= previous - 1e-12);
            previous = v;
        }
        prop_assert!(previous > 0.97 * v0 && previous <= v0 + 1e-9, "speed {} after 300 s, v0 {}", previous, v0);
    }

    /// The ballistic update never gives negative speed nor negative distance, and a vehicle
    /// that stops inside the step travels exactly its stopping distance v^2 / (2 |acc|).
    #[test]
    fn ballistic_update_never_reverses(v in 0.0..40.0f64, acc in -20.0..5.0f64, dt in 0.001..=1.0f64) {
        let step = ballistic_step(v, acc, dt);
        prop_assert!(step.speed >= 0.0);
        prop_assert!(step.distance >= 0.0);
        if v + acc * dt < 0.0 {
            prop_assert_eq!(step.speed, 0.0);
            prop_assert!((step.distance - v * v / (-2.0 * acc)).abs() < 1e-9);
        } else {
            prop_assert!((step.speed - (v + acc * dt)).abs() < 1e-12);
            prop_assert!((step.distance - (v * dt + 0.5 * acc * dt * dt)).abs() < 1e-9);
        }
    }
}

/// A standing vehicle close behind a standing leader stays put (its IDM acceleration is
/// negative) instead of rolling backwards.
#[test]
fn a_stopped_vehicle_never_moves_backwards() {
    let idm = IdmParams::treiber_2000(20.0);
    let profile = SpeedProfile::new(vec![(0.0, 0.0)]).unwrap();
    let mut scene = platoon(profile, idm, &[(0.5, 0.0)]);
    let start = scene.vehicles()[1].state.s;
    for _ in 0..100 {
        scene.step_autonomous(0.1).unwrap();
        assert_eq!(scene.vehicles()[1].state.s, start);
        assert_eq!(scene.vehicles()[1].state.v, 0.0);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// At the equilibrium gap `s_e(v)` behind a leader at the same speed the IDM
    /// acceleration is zero, for both forms of `s*` (issue 12, item 2).
    #[test]
    fn the_equilibrium_gap_has_zero_acceleration(
        idm in idm_params(),
        v0 in 5.0..40.0f64,
        fraction in 0.0..0.95f64,
    ) {
        let idm = IdmParams { v0, ..idm };
        let v = fraction * v0;
        let gap = idm.equilibrium_gap(v).unwrap();
        let acc = idm.acceleration(v, gap, 0.0);
        prop_assert!(acc.abs() <= 1e-12 * idm.a.max(1.0), "{acc:e} at v = {v}, gap = {gap}");
    }

    /// The two forms of `s*` agree while the follower is not slower than its leader
    /// and differ exactly by the clamp otherwise; `treiber2000` is the printed formula.
    #[test]
    fn the_two_desired_gaps_differ_only_by_the_clamp(
        idm in idm_params(),
        v in 0.0..40.0f64,
        dv in -30.0..30.0f64,
    ) {
        let printed = IdmParams { desired_gap: DesiredGap::Treiber2000, ..idm };
        let clamped = IdmParams { desired_gap: DesiredGap::Clamped, ..idm };
        let dynamic = v * idm.t + v * dv / (2.0 * (idm.a * idm.b).sqrt());
        prop_assert_eq!(printed.desired_gap(v, dv), idm.s0 + dynamic);
        prop_assert_eq!(clamped.desired_gap(v, dv), idm.s0 + dynamic.max(0.0));
        if dynamic >= 0.0 {
            prop_assert_eq!(printed.desired_gap(v, dv), clamped.desired_gap(v, dv));
        }
    }
}

#[test]
fn the_desired_gap_is_chosen_in_the_idm_table() {
    let text = |form: &str| {
        format!(
            "[road]\nlength_m = 500.0\nlanes = 1\n[idm]\ndesired_gap = \"{form}\"\n\
             [platoon]\nvehicles = 2\nlane = 0\nleader_start_s_m = 100.0\nheadway_m = 40.0\n\
             initial_speed_mph = 20.0\ndesired_speed_mph = 60.0\n\
             leader_profile = [{{ time_s = 0.0, speed_mph = 40.0 }}]\n"
        )
    };
    for (form, expected) in [
        ("treiber2000", DesiredGap::Treiber2000),
        ("clamped", DesiredGap::Clamped),
    ] {
        let config = ScenarioConfig::from_toml_str(&text(form)).unwrap();
        assert_eq!(config.idm.desired_gap, expected);
    }
    assert_eq!(
        palc_traffic::IdmConfig::default().desired_gap,
        DesiredGap::Clamped
    );
    assert!(ScenarioConfig::from_toml_str(&text("sumo")).is_err());
}
