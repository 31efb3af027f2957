//! `palc eval --shard i/n` and `palc eval merge`: four shard processes merged
//! give the runs of one process, run for run (compute times aside), and a merge
//! of parts that do not belong together is refused with a message naming the
//! mismatch.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn workspace_file(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path)
}

/// A small evaluation with transfer runs (each learns from a grid run, so the
/// shards must keep them together).
fn config(dir: &Path, seed: u64) -> PathBuf {
    let base = workspace_file("configs/learn.toml");
    let text = format!(
        r#"base = "{base}"

[grid]
methods = ["palc"]
speed_cases = ["collector-high", "collector-slow"]
headways_m = [40.0]
styles = ["aggressive", "neutral"]
seeds = [{seed}]

[[users]]
name = "deterministic"

[transfer]
source = "next-speed-case"
users = ["deterministic"]

[drive]
users = ["deterministic"]
lane_changes = 12
seed = {seed}

[timing]
methods = ["palc"]
dts = [0.1]
horizon_margins_s = [1.0]
styles = ["neutral"]
speed_case = "collector-high"
headway_m = 40.0
seed = 1

[example]
method = "palc"
style = "neutral"
speed_case = "collector-high"
headway_m = 40.0
seed = 1

[quick]
users = ["deterministic"]

[quick.grid]
methods = ["palc"]
speed_cases = ["collector-high"]
headways_m = [40.0]
styles = ["neutral"]
seeds = [1]

[quick.timing]
methods = ["palc"]
dts = [0.1]
horizon_margins_s = [1.0]
styles = ["neutral"]
speed_case = "collector-high"
headway_m = 40.0
seed = 1
"#,
        base = base.display()
    );
    let path = dir.join(format!("eval-{seed}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

fn palc(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_palc"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("palc runs")
}

fn succeeds(output: &Output) {
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
}

fn fails_with(output: &Output, needles: &[&str]) {
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success(), "exit 0: {stderr}");
    for needle in needles {
        assert!(stderr.contains(needle), "`{needle}` not in: {stderr}");
    }
}

/// runs.csv without the column of compute times.
fn runs_without_times(dir: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(dir.join("runs.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let timing = header
        .iter()
        .position(|c| *c == "mean_compute_per_iteration_s")
        .unwrap();
    std::iter::once(header.join(","))
        .chain(lines.map(|line| {
            let mut cells: Vec<&str> = line.split(',').collect();
            cells[timing] = "";
            cells.join(",")
        }))
        .collect()
}

#[test]
fn four_shards_merged_equal_one_run_and_mismatched_parts_are_refused() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("shards");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let config = config(&dir, 1);
    let config = config.to_str().unwrap();
    succeeds(&palc(
        &["eval", "--config", config, "--out", "whole", "--jobs", "1"],
        &dir,
    ));
    for i in 0..4 {
        let shard = format!("{i}/4");
        let out = format!("shard-{i}");
        let args = [
            "eval", "--config", config, "--shard", &shard, "--out", &out, "--jobs", "1",
        ];
        succeeds(&palc(&args, &dir));
        assert!(dir.join(&out).join("shard.json").is_file());
    }
    let shards = ["shard-0", "shard-1", "shard-2", "shard-3"];
    let mut merge = vec!["eval", "merge", "--config", config, "--out", "merged"];
    merge.extend(shards);
    succeeds(&palc(&merge, &dir));
    let whole = runs_without_times(&dir.join("whole"));
    assert!(whole.len() > 8, "too few runs to test: {}", whole.len());
    // Two drives (a style each) are chains of 12 runs, each starting from the one before.
    assert_eq!(whole.iter().filter(|r| r.contains(",drive,")).count(), 24);
    assert_eq!(whole, runs_without_times(&dir.join("merged")));
    let refusals = |d: &str| std::fs::read_to_string(dir.join(d).join("refusals.csv")).unwrap();
    assert_eq!(refusals("whole"), refusals("merged"));
    assert!(dir.join("merged/REPORT.md").is_file());

    // A shard missing, a shard twice, a shard of another config.
    let mut missing = vec!["eval", "merge", "--config", config, "--out", "bad"];
    missing.extend(&shards[..3]);
    fails_with(&palc(&missing, &dir), &["shards missing: 3/4"]);
    let mut twice = missing.clone();
    twice.push("shard-2");
    fails_with(&palc(&twice, &dir), &["shard-2", "given twice"]);
    let other = self::config(&dir, 2);
    let other = other.to_str().unwrap();
    let args = [
        "eval", "--config", other, "--shard", "3/4", "--out", "other-3", "--jobs", "1",
    ];
    succeeds(&palc(&args, &dir));
    let mut mixed = missing.clone();
    mixed.push("other-3");
    fails_with(&palc(&mixed, &dir), &["other-3", "config SHA-256"]);
    assert!(
        !dir.join("bad").exists(),
        "a refused merge wrote its output"
    );
}
