//! Every way a scenario config can be wrong is refused with a message that names the field,
//! the value and the bound.

use palc_traffic::{ConfigError, ScenarioConfig, Scene, SpeedCase, TestbedCell};

const TESTBED: &str = r#"
[testbed]
speed_cases = [{ name = "collector-high", ego_mph = 45.0, others_mph = 40.0 }]
adjacent_headways_m = [40.0]
seeds = [1]
"#;

const PLATOON: &str = r#"
[road]
length_m = 500.0
lanes = 1
[platoon]
vehicles = 4
leader_start_s_m = 400.0
headway_m = 40.0
initial_speed_mph = 40.0
desired_speed_mph = 65.0
leader_profile = [{ time_s = 0.0, speed_mph = 40.0 }, { time_s = 10.0, speed_mph = 0.0 }]
"#;

/// Builds the first scene of `text`, returning the error message.
fn error_of(text: &str) -> String {
    let result =
        ScenarioConfig::from_toml_str(text).and_then(|config| Scene::from_config(&config, 0));
    match result {
        Ok(_) => panic!("config was accepted:\n{text}"),
        Err(error) => error.to_string(),
    }
}

/// `base` with the line starting with `key` replaced by `line` (or `line` appended to `table`).
fn with(base: &str, table: &str, key: &str, line: &str) -> String {
    let replaced: Vec<String> = base
        .lines()
        .map(|l| {
            if l.starts_with(&format!("{key} ")) {
                line.to_owned()
            } else {
                l.to_owned()
            }
        })
        .collect();
    let text = replaced.join("\n");
    if text.contains(line) {
        text
    } else {
        text.replace(&format!("[{table}]"), &format!("[{table}]\n{line}"))
    }
}

fn check(text: &str, expected: &[&str]) {
    let message = error_of(text);
    for part in expected {
        assert!(
            message.contains(part),
            "message {message:?} does not contain {part:?}"
        );
    }
}

#[test]
fn the_examples_are_valid() {
    for text in [TESTBED, PLATOON] {
        let config = ScenarioConfig::from_toml_str(text).unwrap();
        Scene::from_config(&config, 0).unwrap();
    }
}

#[test]
fn unknown_fields_and_wrong_units_are_refused() {
    check(
        &with(TESTBED, "testbed", "speed", "speed_kmh = 3.0"),
        &["unknown field `speed_kmh`", "line"],
    );
    check(
        &format!("{TESTBED}\n[road]\nlength_ft = 600.0\n"),
        &["unknown field `length_ft`", "length_m"],
    );
    check(
        &format!("{TESTBED}\n[idm]\nv0 = 30.0\n"),
        &["unknown field `v0`"],
    );
    check(
        &TESTBED.replace("ego_mph = 45.0", "ego_mph = 120.0"),
        &["speed_cases[0].ego_mph` = 120", "km/h"],
    );
    check(
        &TESTBED.replace("ego_mph = 45.0", "ego_mps = 20.1"),
        &["unknown field `ego_mps`"],
    );
}

#[test]
fn negative_lengths_are_refused() {
    check(
        &format!("{TESTBED}\n[road]\nlength_m = -200.0\n"),
        &["`road.length_m` = -200", "above 0"],
    );
    check(
        &format!("{TESTBED}\n[road]\nlane_width_m = 0.0\n"),
        &["`road.lane_width_m` = 0", "above 0"],
    );
    check(
        &format!("{TESTBED}\n[vehicle]\nlength_m = -5.0\n"),
        &["`vehicle.length_m` = -5"],
    );
    check(
        &format!("{TESTBED}\n[idm]\ns0_m = -1.0\n"),
        &["`idm.s0_m` = -1", "at least 0"],
    );
    check(
        &TESTBED.replace("[40.0]", "[-40.0]"),
        &["`testbed.adjacent_headways_m[0]` = -40", "above 0"],
    );
    check(
        &with(
            TESTBED,
            "testbed",
            "position_jitter_m",
            "position_jitter_m = -0.1",
        ),
        &["position_jitter_m` = -0.1"],
    );
    check(
        &with(PLATOON, "platoon", "headway_m", "headway_m = -3.0"),
        &["`platoon.headway_m` = -3"],
    );
}

#[test]
fn not_a_number_is_refused() {
    check(
        &format!("{TESTBED}\n[idm]\nt_s = nan\n"),
        &["`idm.t_s` = NaN"],
    );
    check(
        &format!("{TESTBED}\n[road]\nlength_m = inf\n"),
        &["`road.length_m` = inf"],
    );
}

#[test]
fn speeds_above_v0_that_cannot_be_held_are_refused() {
    check(
        &with(
            PLATOON,
            "platoon",
            "initial_speed_mph",
            "initial_speed_mph = 70.0",
        ),
        &["`platoon.initial_speed_mph`", "above the desired speed v0"],
    );
    // Target-lane followers cannot hold the background speed at v0 equal to it, nor at a
    // headway that needs a negative time gap.
    check(
        &format!("{}\n[idm]\ndesired_speed_ratio = 1.0\n", TESTBED),
        &["`idm.desired_speed_ratio` = 1", "above 1"],
    );
    check(
        &format!(
            "{}\n[idm]\ndesired_speed_ratio = 1.001\n",
            TESTBED.replace("[40.0]", "[30.0]")
        ),
        &[
            "`testbed.adjacent_headways_m` = 30.0 m cannot be held",
            "above",
        ],
    );
    check(
        &TESTBED.replace("others_mph = 40.0", "others_mph = 50.0"),
        &["ego speed 45", "above the others' speed 50"],
    );
}

#[test]
fn overlapping_vehicles_are_refused() {
    // Preceding vehicle 0.1 s ahead of the ego at 45 mph: 2 m front to front, shorter than a car.
    check(
        &with(
            TESTBED,
            "testbed",
            "initial_time_headway_s",
            "initial_time_headway_s = 0.1",
        ),
        &["overlap", "net gap"],
    );
    check(
        &with(PLATOON, "platoon", "headway_m", "headway_m = 4.0"),
        &["overlap on lane", "must be above 0 m"],
    );
}

#[test]
fn vehicles_outside_the_section_are_refused() {
    check(
        &with(
            TESTBED,
            "testbed",
            "initial_time_headway_s",
            "initial_time_headway_s = 9.0",
        ),
        &[
            "outside the road section [0, 200.0]",
            "testbed.initial_time_headway_s",
        ],
    );
    check(
        &with(PLATOON, "platoon", "vehicles", "vehicles = 40"),
        &["outside the road section", "leader_start_s_m"],
    );
    check(
        &with(TESTBED, "testbed", "ego_start_s_m", "ego_start_s_m = 250.0"),
        &["`testbed.ego_start_s_m` = 250"],
    );
}

#[test]
fn scenario_tables_and_lists_are_checked() {
    check(
        "[road]\nlength_m = 200.0\n",
        &["exactly one of the tables [testbed] and [platoon], found neither"],
    );
    check(
        &format!(
            "{TESTBED}{}",
            PLATOON.replace("[road]\nlength_m = 500.0\nlanes = 1\n", "")
        ),
        &["found both"],
    );
    check(
        &TESTBED.replace("seeds = [1]", "seeds = []"),
        &["`testbed.seeds` is empty"],
    );
    check(
        &TESTBED.replace("adjacent_headways_m = [40.0]", "adjacent_headways_m = []"),
        &["adjacent_headways_m` is empty"],
    );
    check(
        &format!("{TESTBED}\n[road]\nlanes = 1\n"),
        &["`road.lanes` = 1", "at least 2 for the test bed"],
    );
    check(
        &with(PLATOON, "platoon", "vehicles", "vehicles = 0"),
        &["`platoon.vehicles` = 0"],
    );
    check(
        &with(PLATOON, "platoon", "lane", "lane = 3"),
        &["`platoon.lane` = 3", "below road.lanes = 1"],
    );
    check(
        &PLATOON.replace("time_s = 10.0", "time_s = 0.0"),
        &["`platoon.leader_profile`: times must be strictly increasing"],
    );
    check(
        &PLATOON.replace("speed_mph = 0.0", "speed_mph = -5.0"),
        &["`platoon.leader_profile[1].speed_mph` = -5"],
    );
    check(
        &with(
            TESTBED,
            "testbed",
            "adjacent_phase",
            "adjacent_phase = [0.8, 0.2]",
        ),
        &["`testbed.adjacent_phase[1]` = 0.2"],
    );
}

#[test]
fn cells_out_of_the_grid_and_bad_cells_are_refused() {
    let config = ScenarioConfig::from_toml_str(TESTBED).unwrap();
    let error = Scene::from_config(&config, 1).unwrap_err();
    assert_eq!(
        error.to_string(),
        "test-bed cell 1 does not exist: the grid has 1 cells"
    );
    let cell = TestbedCell {
        speed_case: SpeedCase::from_mph("bad", f64::NAN, 40.0),
        adjacent_headway: 40.0,
        seed: 1,
    };
    let error = Scene::for_cell(&config, &cell).unwrap_err();
    assert!(
        error.to_string().contains("`speed_case.ego_speed` = NaN"),
        "{error}"
    );
    let platoon = ScenarioConfig::from_toml_str(PLATOON).unwrap();
    assert!(matches!(
        platoon.testbed_cells(),
        Err(ConfigError::NotATestbed)
    ));
    assert!(matches!(
        Scene::for_cell(&platoon, &cell),
        Err(ConfigError::NotATestbed)
    ));
}

#[test]
fn a_wrong_type_in_a_nested_field_names_its_path_line_and_column() {
    let text = PLATOON.replace(
        "{ time_s = 10.0, speed_mph = 0.0 }",
        "{ time_s = 10.0, speed_mph = \"fast\" }",
    );
    let error = ScenarioConfig::from_toml_str(&text).unwrap_err();
    assert!(
        matches!(error, ConfigError::Toml { ref path, .. } if path == "platoon.leader_profile[1].speed_mph"),
        "{error:?}"
    );
    check(
        &text,
        &[
            "`platoon.leader_profile[1].speed_mph`",
            "line 11",
            "invalid type",
        ],
    );
    let text = format!("[road]\nlanes = 2.5\n{TESTBED}");
    check(&text, &["`road.lanes`", "line"]);
}

#[test]
fn a_syntax_error_has_no_field_path_but_a_line() {
    let error = ScenarioConfig::from_toml_str("[road\nlanes = 2").unwrap_err();
    assert!(
        matches!(error, ConfigError::Toml { ref path, .. } if path.is_empty()),
        "{error:?}"
    );
    assert!(error.to_string().contains("line 1"), "{error}");
}
