//! The experience store: bit-exact round trips, and files that are corrupt,
//! truncated or from a newer version.

mod common;

use std::fs;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};

use palc_aggregator::{
    AggregatorError, ApprenticeshipState, EXPERIENCE_DT_BOUNDS_S, EXPERIENCE_FORMAT_VERSION,
    Experience, MAX_DEMONSTRATION_OFFSET_M, Onset, OwnLaneChange,
};
use palc_planner::{FEATURE_COUNT, Features, Weights, feature};
use palc_zone_filter::{Label, Sample, ZoneConfig, ZoneModel};
use proptest::prelude::*;

/// A fresh directory under the system's temporary directory, one per call.
fn scratch() -> PathBuf {
    static NEXT: AtomicUsize = AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!(
        "palc-aggregator-test-{}-{}",
        std::process::id(),
        NEXT.fetch_add(1, Ordering::Relaxed)
    ));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    dir
}

fn sample_experience() -> Experience {
    let mut experience = Experience::new(
        "user-7",
        "45-40mph-40m",
        "palc",
        Weights::constant(60, common::STANDARD),
        0.1,
    )
    .unwrap();
    let samples: Vec<Sample> = (0..12)
        .map(|i| {
            let l = 0.3 * i as f64;
            let x = vec![30.0 - l, -l, 30.0, 10.0, 3.5 - l, 10.6 + 0.01 * i as f64];
            Sample::new(x, if i < 6 { Label::Safe } else { Label::Unsafe })
        })
        .collect();
    experience.zone = Some(ZoneModel::fit(ZoneConfig::default(), &samples).unwrap());
    experience.apprenticeship = Some(ApprenticeshipState {
        mu_bar: Features::constant(20, [0.1; FEATURE_COUNT]),
        updates: 3,
    });
    experience.metadata.lessons = 3;
    experience.anchor_s = Some(4.397);
    experience.onsets = vec![Onset {
        scenario: "collector-slow / 50 m / seed 1 / neutral".into(),
        time_s: 4.397,
        time_headway_s: 1.2237,
        ttc_s: Some(5.51),
        gap_m: 24.6,
        lead_time_gap_s: None,
        lag_time_gap_s: Some(0.031),
        rejected_lead_time_gap_s: Some(0.42),
        time_headway_ceiling_s: None,
        accepted_lead_time_gap_s: Some(1.37),
        follower_wait_time_headway_s: Some(0.88),
        observations: 2,
        scene: None,
    }];
    experience.demonstration = Some((0..=20).map(|i| 3.5 * f64::from(i) / 20.0).collect());
    experience
}

fn bits(w: &Weights) -> Vec<u64> {
    w.columns().iter().flatten().map(|x| x.to_bits()).collect()
}

/// Any finite `f64`, including subnormals, -0.0 and extreme exponents.
fn finite() -> impl Strategy<Value = f64> {
    any::<f64>().prop_filter("finite", |x| x.is_finite())
}

/// A weight column a file may hold: any finite values on the rows that do not
/// affect convexity, any non-negative ones on the diagonals, no coupling to δ, so
/// that every stage passes `check_convexity` (a file must).
fn convex_column() -> impl Strategy<Value = [f64; 10]> {
    prop::array::uniform10(finite()).prop_map(|mut w| {
        for j in [feature::L_DELTA, feature::PHI_DELTA, feature::S_DELTA] {
            w[j] = 0.0;
        }
        for j in [
            feature::L_SQUARED,
            feature::PHI_SQUARED,
            feature::DELTA_SQUARED,
            feature::DIST_PRECEDING,
            feature::DIST_ADJACENT,
        ] {
            w[j] = w[j].abs();
        }
        w
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn save_then_load_is_bit_exact(
        columns in prop::collection::vec(convex_column(), 1..40),
        mu in prop::collection::vec(prop::array::uniform10(finite()), 1..5),
        dt in EXPERIENCE_DT_BOUNDS_S.0..=EXPERIENCE_DT_BOUNDS_S.1,
        lessons in any::<u64>(),
        user in "[a-zA-Z0-9 _\\-\u{e9}\u{4e2d}]{0,16}",
        with_zone in any::<bool>(),
    ) {
        let mut experience = Experience::new(user, "scene \"quoted\"", "palc", Weights::from_columns(columns), dt).unwrap();
        experience.metadata.lessons = lessons;
        experience.apprenticeship = Some(ApprenticeshipState { mu_bar: Features::from_columns(mu), updates: lessons });
        if with_zone {
            experience.zone = sample_experience().zone;
        }
        let dir = scratch();
        let path = dir.join("experience.json");
        experience.save(&path).unwrap();
        let loaded = Experience::load(&path).unwrap();
        prop_assert_eq!(bits(&loaded.weights), bits(&experience.weights));
        prop_assert_eq!(loaded.metadata.dt.to_bits(), experience.metadata.dt.to_bits());
        prop_assert_eq!(&loaded, &experience);
        // Saving the loaded experience writes the same bytes.
        let again = dir.join("again.json");
        loaded.save(&again).unwrap();
        prop_assert_eq!(fs::read(&path).unwrap(), fs::read(&again).unwrap());
        fs::remove_dir_all(&dir).unwrap();
    }
}

#[test]
fn an_experience_with_a_byte_order_mark_loads_as_without() {
    let dir = scratch();
    let path = dir.join("experience.json");
    let experience = sample_experience();
    experience.save(&path).unwrap();
    let mut bytes = b"\xEF\xBB\xBF".to_vec();
    bytes.extend(fs::read(&path).unwrap());
    let marked = dir.join("marked.json");
    fs::write(&marked, bytes).unwrap();
    assert_eq!(Experience::load(&marked).unwrap(), experience);
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn save_replaces_the_file_and_leaves_no_temporary_file() {
    let dir = scratch();
    let path = dir.join("experience.json");
    let mut experience = sample_experience();
    experience.save(&path).unwrap();
    experience.metadata.lessons = 4;
    experience.save(&path).unwrap();
    assert_eq!(Experience::load(&path).unwrap().metadata.lessons, 4);
    let names: Vec<_> = fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, vec![std::ffi::OsString::from("experience.json")]);
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn failed_save_leaves_the_previous_file_in_place() {
    let dir = scratch();
    let path = dir.join("experience.json");
    let experience = sample_experience();
    experience.save(&path).unwrap();
    let before = fs::read(&path).unwrap();
    // A non-finite weight cannot be written as JSON: refused before touching the disk.
    let mut bad = experience.clone();
    bad.weights.columns_mut()[3][1] = f64::INFINITY;
    let err = bad.save(&path).unwrap_err();
    assert!(err.to_string().contains("weights[3][1]"), "{err}");
    assert_eq!(fs::read(&path).unwrap(), before);
    // A path that names a directory: the rename fails, nothing is lost.
    let err = experience.save(&dir).unwrap_err();
    assert!(matches!(err, AggregatorError::Io { .. }), "{err}");
    assert_eq!(fs::read(&path).unwrap(), before);
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn truncated_file_is_a_clear_error_and_is_left_in_place() {
    let dir = scratch();
    let path = dir.join("experience.json");
    sample_experience().save(&path).unwrap();
    let full = fs::read(&path).unwrap();
    for cut in [1, full.len() / 3, full.len() / 2, full.len() - 3] {
        fs::write(&path, &full[..cut]).unwrap();
        let err = Experience::load(&path).unwrap_err();
        assert!(matches!(err, AggregatorError::Corrupt { .. }), "{err}");
        let message = err.to_string();
        assert!(message.contains("corrupt or truncated"), "{message}");
        assert!(message.contains("experience.json"), "{message}");
        assert_eq!(fs::read(&path).unwrap(), &full[..cut]);
    }
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn corrupt_files_are_clear_errors() {
    let dir = scratch();
    let path = dir.join("experience.json");
    sample_experience().save(&path).unwrap();
    let text = fs::read_to_string(&path).unwrap();
    let cases = [
        ("not json", "garbage".to_owned()),
        ("binary", "\u{0}\u{1}\u{2}".to_owned()),
        ("no version", text.replace("\"format_version\": 2,", "")),
        (
            "unknown field",
            text.replacen("\"metadata\": {", "\"extra\": 1, \"metadata\": {", 1),
        ),
        (
            "wrong type",
            text.replacen("\"lessons\": 3", "\"lessons\": \"three\"", 1),
        ),
        (
            "negative dt",
            text.replacen("\"dt\": 0.1", "\"dt\": -0.1", 1),
        ),
        (
            "version 0",
            text.replacen("\"format_version\": 2", "\"format_version\": 0", 1),
        ),
        (
            "short column",
            text.replacen("[\n      0.1,\n      0.0,", "[\n      0.1,", 1),
        ),
    ];
    for (what, contents) in cases {
        assert_ne!(contents, text, "{what}: the edit did not apply");
        fs::write(&path, &contents).unwrap();
        let err = Experience::load(&path).unwrap_err();
        assert!(
            matches!(err, AggregatorError::Corrupt { .. }),
            "{what}: {err}"
        );
    }
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn newer_version_is_refused_naming_both_versions() {
    let dir = scratch();
    let path = dir.join("experience.json");
    sample_experience().save(&path).unwrap();
    let text = fs::read_to_string(&path).unwrap();
    // A newer format may change everything else too: only the version is read.
    let newer = text
        .replacen("\"format_version\": 2", "\"format_version\": 7", 1)
        .replacen("\"metadata\"", "\"meta_v7\"", 1);
    fs::write(&path, newer).unwrap();
    let err = Experience::load(&path).unwrap_err();
    match &err {
        AggregatorError::UnsupportedVersion {
            found, supported, ..
        } => {
            assert_eq!(*found, 7);
            assert_eq!(*supported, EXPERIENCE_FORMAT_VERSION);
        }
        other => panic!("expected UnsupportedVersion, got {other}"),
    }
    let message = err.to_string();
    assert!(message.contains("format version 7"), "{message}");
    assert!(
        message.contains(&format!("up to {EXPERIENCE_FORMAT_VERSION}")),
        "{message}"
    );
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_file_without_onsets_loads_with_none() {
    let dir = scratch();
    let path = dir.join("older.json");
    let mut experience = sample_experience();
    experience.save(&path).unwrap();
    let mut json: serde_json::Value = serde_json::from_slice(&fs::read(&path).unwrap()).unwrap();
    let object = json.as_object_mut().unwrap();
    object.remove("anchor_s");
    object.remove("onsets");
    object.remove("demonstration");
    fs::write(&path, serde_json::to_vec(&json).unwrap()).unwrap();
    let loaded = Experience::load(&path).unwrap();
    experience.anchor_s = None;
    experience.onsets.clear();
    experience.demonstration = None;
    assert_eq!(loaded, experience);
}

#[test]
fn the_users_own_lane_change_round_trips_and_a_bad_one_is_refused_on_load() {
    let dir = scratch();
    let path = dir.join("own.json");
    let mut experience = sample_experience();
    experience.own_lane_change = Some(OwnLaneChange {
        progress: vec![0.0, 0.02, 0.3, 0.81, 1.0],
    });
    experience.save(&path).unwrap();
    assert_eq!(Experience::load(&path).unwrap(), experience);
    // Edited to turn back: refused on load, naming the sample and the bound.
    let mut json: serde_json::Value = serde_json::from_slice(&fs::read(&path).unwrap()).unwrap();
    json["own_lane_change"]["progress"][3] = serde_json::json!(0.1);
    fs::write(&path, serde_json::to_vec(&json).unwrap()).unwrap();
    let message = Experience::load(&path).unwrap_err().to_string();
    assert!(message.contains("own_lane_change.progress[3]"), "{message}");
    assert!(message.contains("never turns back"), "{message}");
    // A file without it (every file before it existed) loads with none.
    json.as_object_mut().unwrap().remove("own_lane_change");
    fs::write(&path, serde_json::to_vec(&json).unwrap()).unwrap();
    assert_eq!(Experience::load(&path).unwrap().own_lane_change, None);
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_non_finite_onset_is_refused_naming_it() {
    let mut experience = sample_experience();
    experience.onsets[0].gap_m = f64::INFINITY;
    let message = experience.validate().unwrap_err().to_string();
    assert!(message.contains("onsets[0].gap_m"), "{message}");
}

/// Each value a file may not hold is refused on load, naming the field, the
/// value and its bound; the file is left as it was.
#[test]
fn values_out_of_their_bounds_are_refused_naming_field_value_and_bound() {
    let dir = scratch();
    let path = dir.join("experience.json");
    /// What is spoilt, how, the field named and the bound named.
    type Case = (
        &'static str,
        fn(&mut Experience),
        &'static str,
        &'static str,
    );
    let cases: [Case; 6] = [
        (
            "a step of 1 s",
            |e| e.metadata.dt = 1.0,
            "metadata.dt",
            "0.5",
        ),
        (
            "a step of 0.1 ms",
            |e| e.metadata.dt = 1e-4,
            "metadata.dt",
            "0.001",
        ),
        (
            "an anchor before the plan",
            |e| e.anchor_s = Some(-0.5),
            "anchor_s",
            "[0, 6",
        ),
        (
            "an anchor after the weights",
            |e| e.anchor_s = Some(60.0),
            "anchor_s",
            "[0, 6",
        ),
        (
            "a demonstration longer than the weights",
            |e| e.demonstration = Some(vec![0.0; 62]),
            "demonstration",
            "61 steps",
        ),
        (
            "a demonstration 40 m away",
            |e| e.demonstration.as_mut().unwrap()[7] = 40.0,
            "demonstration[7]",
            "15 m",
        ),
    ];
    for (what, spoil, field, bound) in cases {
        let mut experience = sample_experience();
        spoil(&mut experience);
        // `save` validates too, so the file is written from a serialized copy.
        let message = experience.validate().unwrap_err().to_string();
        assert!(
            message.contains(field) && message.contains(bound),
            "{what}: {message}"
        );
        assert!(experience.save(&path).is_err(), "{what}: saved");
    }
    const { assert!(MAX_DEMONSTRATION_OFFSET_M > 3.75 * 2.0) };
    fs::remove_dir_all(&dir).unwrap();
}

/// A file whose weights would make the planner's cost non-convex is refused on
/// load, as `palc plan` refuses such weights.
#[test]
fn non_convex_weights_in_a_file_are_refused_on_load() {
    let dir = scratch();
    let path = dir.join("experience.json");
    sample_experience().save(&path).unwrap();
    let mut value: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(&path).unwrap()).unwrap();
    // w5 (l·δ) coupled to a zero l² diagonal in the first column.
    let column = &mut value["weights"][0];
    column[feature::L_SQUARED] = 0.0.into();
    column[feature::DIST_PRECEDING] = 0.0.into();
    column[feature::DIST_ADJACENT] = 0.0.into();
    column[feature::L_DELTA] = 1.0.into();
    let edited = serde_json::to_string_pretty(&value).unwrap();
    fs::write(&path, &edited).unwrap();
    let err = Experience::load(&path).unwrap_err();
    assert!(matches!(err, AggregatorError::Corrupt { .. }), "{err}");
    assert!(err.to_string().contains("non-convex"), "{err}");
    assert_eq!(fs::read_to_string(&path).unwrap(), edited);
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn missing_file_is_an_io_error_naming_it() {
    let dir = scratch();
    let err = Experience::load(dir.join("absent.json")).unwrap_err();
    assert!(matches!(err, AggregatorError::Io { .. }), "{err}");
    assert!(err.to_string().contains("absent.json"), "{err}");
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn weights_are_usable_at_another_horizon_and_step() {
    let experience = sample_experience(); // K = 60 at 0.1 s
    let w = experience.weights_for(40, 0.05).unwrap();
    assert_eq!(w.horizon(), 40);
    assert!(palc_planner::check_convexity(&w).is_ok());
    assert!(experience.weights_for(0, 0.05).is_err());
    assert!(experience.weights_for(10, 0.0).is_err());
}

/// A version-1 file (no recorded scenes) still loads: its onsets carry no
/// scene, and the start is then predicted from the onsets' own readings.
#[test]
fn a_version_1_file_loads_without_scenes() {
    let dir = scratch();
    let path = dir.join("experience.json");
    let mut experience = sample_experience();
    experience.onsets[0].scene = None;
    experience.save(&path).unwrap();
    let text = fs::read_to_string(&path).unwrap();
    assert!(!text.contains("\"scene\""));
    fs::write(
        &path,
        text.replacen("\"format_version\": 2", "\"format_version\": 1", 1),
    )
    .unwrap();
    let loaded = Experience::load(&path).unwrap();
    assert_eq!(loaded, experience);
    fs::remove_dir_all(&dir).unwrap();
}

/// An onset's recorded scene round-trips bit for bit, and a non-finite value in
/// it is refused naming the step.
#[test]
fn a_recorded_scene_round_trips_and_is_checked() {
    let dir = scratch();
    let path = dir.join("experience.json");
    let mut experience = sample_experience();
    let step = |i: u32| palc_aggregator::SeenStep {
        ego_speed: 20.1,
        preceding: Some((44.0 - 0.1 * f64::from(i), 17.9)),
        target_lead: Some((6.0 + 0.3 * f64::from(i), 17.9)),
        target_lag: if i < 3 { None } else { Some((-1.5, 17.9)) },
        safe: None,
    };
    experience.onsets[0].scene = Some(palc_aggregator::SceneSteps {
        dt: 0.1,
        set_speed_mps: 20.1,
        steps: (0..6).map(step).collect(),
    });
    experience.save(&path).unwrap();
    assert_eq!(Experience::load(&path).unwrap(), experience);
    experience.onsets[0].scene.as_mut().unwrap().steps[4].ego_speed = f64::NAN;
    let message = experience.validate().unwrap_err().to_string();
    assert!(
        message.contains("onsets[0].scene.steps[4].ego_speed"),
        "{message}"
    );
    fs::remove_dir_all(&dir).unwrap();
}
