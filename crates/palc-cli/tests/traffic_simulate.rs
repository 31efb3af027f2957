//! `palc traffic simulate` on the example configs: it runs and writes the documented CSV.

use std::path::{Path, PathBuf};
use std::process::Command;

fn workspace_file(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path)
}

fn simulate(config: &str, extra: &[&str], out: &str) -> std::process::Output {
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join(out);
    Command::new(env!("CARGO_BIN_EXE_palc"))
        .args(["traffic", "simulate", "--config"])
        .arg(workspace_file(config))
        .args(extra)
        .arg("--out")
        .arg(out)
        .output()
        .expect("palc runs")
}

fn read_rows(out: &str) -> Vec<csv::StringRecord> {
    let path = Path::new(env!("CARGO_TARGET_TMPDIR")).join(out);
    let mut reader = csv::Reader::from_path(path).unwrap();
    assert_eq!(
        reader.headers().unwrap(),
        vec!["time", "id", "lane", "s", "l", "v", "a"]
    );
    reader.records().map(Result::unwrap).collect()
}

fn field(row: &csv::StringRecord, i: usize) -> f64 {
    row[i].parse().unwrap()
}

#[test]
fn testbed_writes_one_row_per_vehicle_per_step() {
    let output = simulate(
        "configs/testbed.toml",
        &["--duration", "5", "--dt", "0.1"],
        "testbed.csv",
    );
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let rows = read_rows("testbed.csv");
    let vehicles = rows.iter().filter(|r| field(r, 0) == 0.0).count();
    // Cell 0 (50 m headway): ego, preceding, follower and four target-lane vehicles.
    assert_eq!(vehicles, 7);
    assert_eq!(rows.len(), vehicles * 51);
    let last = &rows[rows.len() - vehicles..];
    assert!(last.iter().all(|r| (field(r, 0) - 5.0).abs() < 1e-9));
    // The ego (id 0) starts on lane 0 at 45 mph; target-lane vehicles sit at l = 3.5.
    assert_eq!((&rows[0][1], &rows[0][2]), ("0", "0"));
    assert!((field(&rows[0], 5) - 20.1168).abs() < 1e-3);
    assert!(
        rows.iter()
            .filter(|r| &r[2] == "1")
            .all(|r| field(r, 4) == 3.5)
    );
    assert!(rows.iter().all(|r| field(r, 5) >= 0.0));
}

#[test]
fn platoon_stops_without_collision_and_restarts() {
    let output = simulate("configs/platoon.toml", &["--duration", "90"], "platoon.csv");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let rows = read_rows("platoon.csv");
    assert_eq!(rows.len(), 10 * 901);
    for step in rows.chunks(10) {
        // Rows are in id order: leader first, each follower behind the previous one.
        for pair in step.windows(2) {
            let net_gap = field(&pair[0], 3) - 5.0 - field(&pair[1], 3);
            assert!(net_gap > 0.0, "collision at t = {}", &pair[0][0]);
        }
    }
    let min_speed = rows
        .iter()
        .map(|r| field(r, 5))
        .fold(f64::INFINITY, f64::min);
    assert_eq!(min_speed, 0.0);
    assert!(rows[rows.len() - 10..].iter().all(|r| field(r, 5) > 5.0));
}

#[test]
fn a_bad_config_fails_with_the_file_and_field_named() {
    let bad = Path::new(env!("CARGO_TARGET_TMPDIR")).join("bad.toml");
    std::fs::write(&bad, "[road]\nlength_m = -1.0\n[testbed]\nspeed_cases = []\nadjacent_headways_m = []\nseeds = []\n")
        .unwrap();
    let output = Command::new(env!("CARGO_BIN_EXE_palc"))
        .args(["traffic", "simulate", "--config"])
        .arg(&bad)
        .args(["--out", "/dev/null"])
        .output()
        .unwrap();
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("bad.toml") && stderr.contains("`road.length_m` = -1"),
        "{stderr}"
    );

    let output = simulate("configs/testbed.toml", &["--dt", "0"], "never.csv");
    assert!(!output.status.success());
    assert!(String::from_utf8_lossy(&output.stderr).contains("--dt"));
}
