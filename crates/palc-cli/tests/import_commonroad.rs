//! `palc import commonroad` and `palc export commonroad` end to end: the
//! committed NGSIM scenario imports to the committed file's counts, bad input is
//! a clear error with nothing written, and an exported scene imports back.

use std::path::{Path, PathBuf};
use std::process::Command;

use palc_commonroad::import::RecordedLaneChanges;

fn workspace_file(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path)
}

fn tmp(name: &str) -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join(name)
}

fn palc(args: &[&str], files: &[&Path]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_palc"))
        .args(args)
        .args(files)
        .output()
        .expect("palc runs")
}

#[test]
fn the_committed_scenario_imports_to_a_file_that_reads_back() {
    let out = tmp("import-us101-4.json");
    let _ = std::fs::remove_file(&out);
    let scenario = workspace_file("fixtures/recorded/USA_US101-4_1_T-1.xml");
    let output = palc(
        &["import", "commonroad"],
        &[&scenario, Path::new("--out"), &out],
    );
    assert!(output.status.success(), "{output:?}");
    let file = RecordedLaneChanges::read(&out).unwrap();
    assert_eq!(file.counts.vehicles, 22);
    assert_eq!(file.lane_changes.len(), file.counts.lane_changes);
    let said = String::from_utf8_lossy(&output.stdout) + String::from_utf8_lossy(&output.stderr);
    assert!(said.contains("22 vehicles"), "{said}");
}

#[test]
fn malformed_or_unsupported_scenarios_are_errors_and_nothing_is_written() {
    let cases = [
        (
            "malformed.xml",
            "<commonRoad commonRoadVersion=\"2020a\"><lanelet",
            "malformed.xml",
        ),
        (
            "old.xml",
            "<commonRoad commonRoadVersion=\"2018b\" timeStepSize=\"0.1\"></commonRoad>",
            "2018b",
        ),
        ("other.xml", "<osm></osm>", "other.xml"),
    ];
    for (name, text, expected) in cases {
        let scenario = tmp(name);
        std::fs::write(&scenario, text).unwrap();
        let out = tmp(&format!("{name}.json"));
        let _ = std::fs::remove_file(&out);
        let output = palc(
            &["import", "commonroad"],
            &[&scenario, Path::new("--out"), &out],
        );
        assert!(!output.status.success(), "{name}: {output:?}");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(stderr.contains(expected), "{name}: {stderr}");
        assert!(!stderr.contains("panicked"), "{name}: {stderr}");
        assert!(!out.exists(), "{name}: an output was written");
    }
}

#[test]
fn an_exported_scene_imports_back() {
    let dir = tmp("export-default");
    let _ = std::fs::remove_dir_all(&dir);
    let config = workspace_file("configs/learn.toml");
    let output = palc(
        &["export", "commonroad", "--config"],
        &[&config, Path::new("--out"), &dir],
    );
    assert!(output.status.success(), "{output:?}");
    let scenario = std::fs::read_dir(&dir)
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .find(|path| {
            let name = path.file_name().unwrap().to_string_lossy();
            name.ends_with(".xml") && !name.starts_with("solution_")
        })
        .expect("a scenario was written");
    let out = dir.join("imported.json");
    let output = palc(
        &["import", "commonroad"],
        &[&scenario, Path::new("--out"), &out],
    );
    assert!(output.status.success(), "{output:?}");
    let file = RecordedLaneChanges::read(&out).unwrap();
    // Every background vehicle is read; they keep their lanes in the test bed's scenes.
    assert!(file.counts.vehicles > 0);
    assert_eq!(
        file.counts.skipped_incomplete + file.counts.skipped_non_finite,
        0
    );
}
