//! The test bed built from configs/testbed.toml: geometry, reproducibility, predictions and
//! the reaction of background vehicles to the externally driven ego.

use palc_traffic::{
    EgoState, Lane, PredictionModel, ScenarioConfig, Scene, SceneError, TestbedCell, VehicleId,
    units::mph_to_mps,
};
use proptest::prelude::*;

fn testbed() -> ScenarioConfig {
    let text = include_str!("../../../configs/testbed.toml");
    ScenarioConfig::from_toml_str(text).expect("configs/testbed.toml is valid")
}

fn bits(scene: &Scene) -> Vec<[u64; 5]> {
    scene
        .vehicles()
        .iter()
        .map(|v| {
            let s = v.state;
            [
                s.s.to_bits(),
                s.l.to_bits(),
                s.v.to_bits(),
                s.a.to_bits(),
                s.heading.to_bits(),
            ]
        })
        .collect()
}

/// The ego drives straight at constant speed.
fn cruise(scene: &Scene, dt: f64) -> EgoState {
    let ego = scene.ego().unwrap().state;
    EgoState {
        s: ego.s + ego.v * dt,
        l: ego.l,
        v: ego.v,
        heading: 0.0,
    }
}

#[test]
fn the_paper_grid_has_sixty_cells_per_seed_and_every_cell_builds() {
    let config = testbed();
    let cells = config.testbed_cells().unwrap();
    assert_eq!(cells.len(), 4 * 5 * 3);
    for cell in &cells {
        let scene = Scene::for_cell(&config, cell).unwrap();
        assert!(scene.collisions().is_empty());
        assert_eq!(scene.vehicles()[0].id, VehicleId(0));
    }
}

#[test]
fn a_cell_places_ego_preceding_and_adjacent_as_documented() {
    let config = testbed();
    let cells = config.testbed_cells().unwrap();
    let cell = cells
        .iter()
        .find(|c| c.speed_case.name == "arterial-slow" && c.adjacent_headway == 30.0)
        .unwrap();
    let scene = Scene::for_cell(&config, cell).unwrap();
    let (ego, preceding, adjacent) = (
        scene.ego().unwrap(),
        scene.preceding().unwrap(),
        scene.adjacent().unwrap(),
    );

    assert_eq!((ego.lane, ego.state.l), (Lane(0), 0.0));
    assert!((ego.state.v - mph_to_mps(65.0)).abs() < 1e-12);
    assert_eq!((preceding.lane, preceding.state.l), (Lane(0), 0.0));
    assert!((preceding.state.v - mph_to_mps(55.0)).abs() < 1e-12);
    assert!(((preceding.state.s - ego.state.s) / ego.state.v - 3.0).abs() < 1e-9);
    assert_eq!((adjacent.lane, adjacent.state.l), (Lane(1), 3.5));
    let lead = adjacent.state.s - ego.state.s;
    assert!(
        (0.2 * 30.0 - 0.5..=0.8 * 30.0 + 0.5).contains(&lead),
        "adjacent lead {lead}"
    );

    // Target-lane vehicles are one headway apart, up to the jitter, and fill the section.
    let mut lane1: Vec<f64> = scene
        .vehicles()
        .iter()
        .filter(|v| v.lane == Lane(1))
        .map(|v| v.state.s)
        .collect();
    lane1.sort_by(f64::total_cmp);
    for pair in lane1.windows(2) {
        assert!((pair[1] - pair[0] - 30.0).abs() <= 1.0 + 1e-9);
    }
    assert!(lane1.len() >= 6);
}

#[test]
fn the_background_holds_its_speed_and_headway_while_the_ego_stays_out_of_its_lane() {
    let config = testbed();
    for cell in config
        .testbed_cells()
        .unwrap()
        .iter()
        .filter(|c| c.seed == 1)
    {
        let mut scene = Scene::for_cell(&config, cell).unwrap();
        let v_bg = cell.speed_case.background_speed;
        for _ in 0..100 {
            let ego = cruise(&scene, 0.1);
            scene.step(0.1, ego).unwrap();
        }
        for vehicle in scene.vehicles().iter().filter(|v| v.lane == Lane(1)) {
            assert!(
                (vehicle.state.v - v_bg).abs() < 0.02 * v_bg,
                "{:?} at {} m/s in {cell:?}",
                vehicle.id,
                vehicle.state.v
            );
        }
        let preceding = scene.preceding().unwrap();
        assert!((preceding.state.v - v_bg).abs() < 1e-9);
    }
}

#[test]
fn target_lane_vehicles_react_to_the_ego_once_it_overlaps_their_lane() {
    let config = testbed();
    let cell = &config.testbed_cells().unwrap()[0];
    let base = Scene::for_cell(&config, cell).unwrap();
    // The target-lane vehicle just behind the ego.
    let ego_s = base.ego().unwrap().state.s;
    let behind = base
        .vehicles()
        .iter()
        .filter(|v| v.lane == Lane(1) && v.state.s < ego_s)
        .max_by(|a, b| a.state.s.total_cmp(&b.state.s))
        .unwrap()
        .id;
    let mut in_lane0 = base.clone();
    let mut on_marking = base.clone();
    let ego = cruise(&base, 0.1);
    in_lane0.step(0.1, ego).unwrap();
    on_marking.step(0.1, EgoState { l: 1.75, ..ego }).unwrap();
    assert_ne!(
        in_lane0.leader_of(behind).map(|(id, _)| id),
        Some(VehicleId(0))
    );
    assert_eq!(
        on_marking.leader_of(behind).map(|(id, _)| id),
        Some(VehicleId(0))
    );
    // The ego's follower on lane 0 still sees the ego on the marking.
    assert_eq!(
        on_marking.leader_of(VehicleId(2)).map(|(id, _)| id),
        Some(VehicleId(0))
    );
    let far_left = {
        let mut scene = base.clone();
        scene.step(0.1, EgoState { l: 3.5, ..ego }).unwrap();
        scene
    };
    assert_ne!(
        far_left.leader_of(VehicleId(2)).map(|(id, _)| id),
        Some(VehicleId(0))
    );
}

#[test]
fn predictions_have_k_plus_one_points_and_agree_in_steady_traffic() {
    let config = testbed();
    let cell = &config.testbed_cells().unwrap()[0];
    let scene = Scene::for_cell(&config, cell).unwrap();
    let (k, dt) = (60, 0.05);
    let constant = scene
        .predict(k, dt, PredictionModel::ConstantSpeed)
        .unwrap();
    let rollout = scene.predict(k, dt, PredictionModel::IdmRollout).unwrap();
    let p = scene.preceding().unwrap().state;
    assert_eq!(constant.preceding.len(), k + 1);
    assert_eq!(rollout.adjacent.len(), k + 1);
    for i in 0..=k {
        let expected = p.s + p.v * i as f64 * dt;
        assert!((constant.preceding[i][0] - expected).abs() < 1e-9);
        assert_eq!(constant.preceding[i][1], 0.0);
        assert_eq!(constant.adjacent[i][1], 3.5);
        // The preceding vehicle is a free vehicle at v0: the rollout keeps it at constant speed.
        assert!((rollout.preceding[i][0] - expected).abs() < 1e-6);
        // The adjacent vehicle is near equilibrium: within the jitter's effect after 3 s.
        assert!((rollout.adjacent[i][0] - constant.adjacent[i][0]).abs() < 0.5);
    }
    // Predicting does not advance the scene.
    assert_eq!(scene.time(), 0.0);
}

#[test]
fn invalid_steps_and_predictions_are_refused() {
    let config = testbed();
    let mut scene = Scene::from_config(&config, 0).unwrap();
    let ego = cruise(&scene, 0.1);
    assert!(matches!(
        scene.step(0.0, ego),
        Err(SceneError::InvalidTimeStep { .. })
    ));
    assert!(matches!(
        scene.step(f64::NAN, ego),
        Err(SceneError::InvalidTimeStep { .. })
    ));
    let bad = scene.step(0.1, EgoState { v: -1.0, ..ego }).unwrap_err();
    assert_eq!(
        bad.to_string(),
        "ego state `v` = -1.0 is out of range: it must be finite and at least 0"
    );
    assert!(matches!(
        scene.step(
            0.1,
            EgoState {
                l: f64::INFINITY,
                ..ego
            }
        ),
        Err(SceneError::InvalidEgoState { field: "l", .. })
    ));
    assert!(matches!(
        scene.predict(usize::MAX, 0.1, PredictionModel::ConstantSpeed),
        Err(SceneError::HorizonTooLong { .. })
    ));
    let platoon =
        ScenarioConfig::from_toml_str(include_str!("../../../configs/platoon.toml")).unwrap();
    let mut platoon = Scene::from_config(&platoon, 0).unwrap();
    assert!(matches!(platoon.step(0.1, ego), Err(SceneError::NoEgo)));
    assert!(matches!(
        platoon.predict(10, 0.1, PredictionModel::ConstantSpeed),
        Err(SceneError::MissingVehicle { role: "preceding" })
    ));
}

#[test]
fn different_seeds_give_different_scenes() {
    let config = testbed();
    let cells = config.testbed_cells().unwrap();
    let a = Scene::for_cell(&config, &cells[0]).unwrap();
    let b = Scene::for_cell(
        &config,
        &TestbedCell {
            seed: cells[0].seed + 1,
            ..cells[0].clone()
        },
    )
    .unwrap();
    assert_ne!(bits(&a), bits(&b));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// The same cell and seed give bit-identical scenes, and they stay identical when stepped.
    #[test]
    fn same_seed_gives_bit_identical_scenes(case in 0usize..4, headway in 0usize..5, seed in any::<u64>()) {
        let config = testbed();
        let cells = config.testbed_cells().unwrap();
        let cell = TestbedCell { seed, ..cells[case * 15 + headway * 3].clone() };
        let mut a = Scene::for_cell(&config, &cell).unwrap();
        let mut b = Scene::for_cell(&config, &cell).unwrap();
        prop_assert_eq!(bits(&a), bits(&b));
        let mut c = a.clone();
        for _ in 0..50 {
            a.step_autonomous(0.1).unwrap();
            b.step_autonomous(0.1).unwrap();
            c.step_autonomous(0.1).unwrap();
        }
        prop_assert_eq!(bits(&a), bits(&b));
        prop_assert_eq!(bits(&a), bits(&c));
        prop_assert!(a.collisions().is_empty());
    }
}

/// The braking stress scene: the preceding vehicle holds the background speed until
/// the braking starts, loses `deceleration_mps2` each second, and holds the final
/// speed; a braking outside its bounds is refused naming the field.
#[test]
fn the_preceding_vehicle_of_the_braking_scene_follows_its_profile() {
    let mut config = testbed();
    let testbed = config.testbed.as_mut().unwrap();
    testbed.preceding_braking = Some(palc_traffic::PrecedingBrakingConfig {
        start_s: 2.0,
        deceleration_mps2: 4.0,
        final_speed_ratio: 0.5,
    });
    let mut scene = Scene::from_config(&config, 0).unwrap();
    let v_bg = scene.preceding().unwrap().state.v;
    let speed_at = |scene: &Scene| scene.preceding().unwrap().state.v;
    let dt = 0.1;
    let mut speeds = vec![speed_at(&scene)];
    for _ in 0..100 {
        let next = cruise(&scene, dt);
        scene.step(dt, next).unwrap();
        speeds.push(speed_at(&scene));
    }
    assert!((speeds[20] - v_bg).abs() < 1e-9, "{}", speeds[20]);
    assert!((speeds[30] - (v_bg - 4.0)).abs() < 1e-9, "{}", speeds[30]);
    assert!((speeds[100] - 0.5 * v_bg).abs() < 1e-9, "{}", speeds[100]);

    let testbed = config.testbed.as_mut().unwrap();
    testbed.preceding_braking = Some(palc_traffic::PrecedingBrakingConfig {
        start_s: 2.0,
        deceleration_mps2: 40.0,
        final_speed_ratio: 0.5,
    });
    let err = Scene::from_config(&config, 0).unwrap_err().to_string();
    assert!(
        err.contains("testbed.preceding_braking.deceleration_mps2"),
        "{err}"
    );
}
