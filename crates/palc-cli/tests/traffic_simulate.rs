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

#[test]
fn values_are_written_in_full_precision_and_json_matches_csv() {
    // Issue 12, item 2: four decimals (5e-5 rounding) could not be compared at 1e-6.
    let args = ["--duration", "3", "--dt", "0.1"];
    let output = simulate("configs/platoon.toml", &args, "precision.csv");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let rows = read_rows("precision.csv");
    let decimals = |text: &str| text.split('.').nth(1).map_or(0, str::len);
    assert!(
        rows.iter().any(|r| decimals(&r[3]) > 4),
        "positions are still rounded"
    );
    let mut json_args = args.to_vec();
    json_args.extend(["--format", "json"]);
    let output = simulate("configs/platoon.toml", &json_args, "precision.json");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let path = Path::new(env!("CARGO_TARGET_TMPDIR")).join("precision.json");
    let json: Vec<serde_json::Value> =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    assert_eq!(json.len(), rows.len());
    for (row, object) in rows.iter().zip(&json) {
        for (i, key) in ["time", "id", "lane", "s", "l", "v", "a"]
            .iter()
            .enumerate()
        {
            // Both are the shortest round-trip forms of the same f64: equal bit for bit.
            assert_eq!(field(row, i), object[key].as_f64().unwrap(), "{key}");
        }
    }
}
