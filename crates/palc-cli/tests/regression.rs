//! One test per fault of issue 13 ("nothing lost, nothing silent"): each ran the
//! `palc` binary into a panic, a lost or truncated output, a bad input accepted with
//! exit 0 or an error that did not name the input.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

fn workspace_file(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path)
}

fn read(path: &str) -> String {
    std::fs::read_to_string(workspace_file(path)).unwrap()
}

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("regression-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn palc(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_palc"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("palc runs")
}

/// The command failed with a message that contains every one of `needles`, and
/// did not panic.
fn fails_with(output: &Output, needles: &[&str]) {
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success(), "exit 0; stderr: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    for needle in needles {
        assert!(stderr.contains(needle), "`{needle}` not in: {stderr}");
    }
}

fn succeeds(output: &Output) {
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
}

#[cfg(target_os = "linux")]
#[test]
fn zone_fit_to_a_full_disk_is_an_error() {
    let dir = scratch("full-disk");
    let samples = workspace_file("configs/examples/zone-samples.csv");
    let output = palc(
        &[
            "zone",
            "fit",
            "--samples",
            samples.to_str().unwrap(),
            "--out",
            "/dev/full",
        ],
        &dir,
    );
    fails_with(&output, &["/dev/full"]);
}

#[test]
fn a_closed_stdout_ends_learn_quietly_with_the_experience_saved() {
    let dir = scratch("closed-stdout");
    let mut child = Command::new(env!("CARGO_BIN_EXE_palc"))
        .args(["learn", "--save-experience", "e.json", "--record", "r.json"])
        .current_dir(&dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // `| head -1`: read one line, then close the pipe.
    let mut stdout = child.stdout.take().unwrap();
    let mut byte = [0u8; 1];
    while stdout.read(&mut byte).unwrap() == 1 && byte[0] != b'\n' {}
    drop(stdout);
    let mut stderr = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut stderr)
        .unwrap();
    let status = child.wait().unwrap();
    assert!(status.success(), "{status}: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    palc_aggregator::Experience::load(dir.join("e.json")).unwrap();
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("r.json")).unwrap()).unwrap();
    assert!(record.is_object());
}

fn testbed_with(dir: &Path, from: &str, to: &str) -> PathBuf {
    let text = read("configs/testbed.toml");
    assert!(text.contains(from), "{from}");
    let path = dir.join("testbed.toml");
    std::fs::write(&path, text.replace(from, to)).unwrap();
    path
}

#[test]
fn a_huge_position_jitter_is_refused_not_a_panic() {
    let dir = scratch("jitter");
    let config = testbed_with(&dir, "position_jitter_m = 0.5", "position_jitter_m = 1e308");
    let output = palc(
        &[
            "traffic",
            "simulate",
            "--config",
            config.to_str().unwrap(),
            "--out",
            "t.csv",
        ],
        &dir,
    );
    // The number is short (not 300 digits) and the bound is named.
    fails_with(&output, &["testbed.position_jitter_m", "1e308", "[0, 100]"]);
    assert!(!dir.join("t.csv").exists());
}

#[test]
fn too_many_lanes_are_refused() {
    let dir = scratch("lanes");
    let config = testbed_with(&dir, "lanes = 2", "lanes = 4294967295");
    let output = palc(
        &[
            "traffic",
            "simulate",
            "--config",
            config.to_str().unwrap(),
            "--out",
            "t.csv",
        ],
        &dir,
    );
    fails_with(&output, &["road.lanes", "[1, 64]"]);
}

#[test]
fn a_bad_dt_leaves_an_existing_csv_untouched() {
    let dir = scratch("dt");
    std::fs::write(dir.join("existing.csv"), "precious\n").unwrap();
    let config = workspace_file("configs/testbed.toml");
    for dt in ["2", "inf", "NaN", "0"] {
        let output = palc(
            &[
                "traffic",
                "simulate",
                "--config",
                config.to_str().unwrap(),
                "--dt",
                dt,
                "--out",
                "existing.csv",
            ],
            &dir,
        );
        fails_with(&output, &["--dt"]);
        assert_eq!(
            std::fs::read_to_string(dir.join("existing.csv")).unwrap(),
            "precious\n"
        );
    }
    // A good run replaces the file in full and leaves no temporary file behind.
    succeeds(&palc(
        &[
            "traffic",
            "simulate",
            "--config",
            config.to_str().unwrap(),
            "--duration",
            "1",
            "--out",
            "existing.csv",
        ],
        &dir,
    ));
    let names: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
    assert_eq!(names.len(), 1);
    assert!(
        std::fs::read_to_string(dir.join("existing.csv"))
            .unwrap()
            .starts_with("time,id")
    );
}

#[test]
fn too_many_traffic_steps_are_refused_before_the_output_is_touched() {
    let dir = scratch("steps");
    std::fs::write(dir.join("existing.csv"), "precious\n").unwrap();
    let config = workspace_file("configs/testbed.toml");
    // 10^6 steps (MAX_STEPS) are allowed; one more second at dt = 0.1 s is not.
    let output = palc(
        &[
            "traffic",
            "simulate",
            "--config",
            config.to_str().unwrap(),
            "--duration",
            "100001",
            "--dt",
            "0.1",
            "--out",
            "existing.csv",
        ],
        &dir,
    );
    fails_with(&output, &["1000010 steps", "at most 1000000 steps"]);
    assert_eq!(
        std::fs::read_to_string(dir.join("existing.csv")).unwrap(),
        "precious\n"
    );
}

/// The example plan problem with one replacement.
fn plan_with(dir: &Path, from: &str, to: &str) -> Output {
    let text = read("configs/examples/plan-problem.json");
    assert!(text.contains(from), "{from}");
    std::fs::write(dir.join("p.json"), text.replacen(from, to, 1)).unwrap();
    palc(&["plan", "--problem", "p.json", "--out", "out.json"], dir)
}

#[test]
fn a_refused_plan_input_leaves_the_previous_output_untouched() {
    let dir = scratch("plan-untouched");
    let output = plan_with(&dir, "\"phi\": 0.0", "\"phi\": 0.0");
    succeeds(&output);
    let before = std::fs::read(dir.join("out.json")).unwrap();
    assert!(String::from_utf8_lossy(&before).contains("\"solved\""));
    let text = read("configs/examples/plan-problem.json");
    // Negative weights: the planner refuses them as non-convex.
    let weights = text.find("\"weights\"").unwrap();
    let (head, tail) = text.split_at(weights);
    let tail = tail.replacen("0.01", "-50.0", 1);
    std::fs::write(dir.join("p.json"), format!("{head}{tail}")).unwrap();
    let output = palc(&["plan", "--problem", "p.json", "--out", "out.json"], &dir);
    assert!(!output.status.success(), "{output:?}");
    assert_eq!(std::fs::read(dir.join("out.json")).unwrap(), before);
    let output = plan_with(&dir, "\"v\": 20.1168", "\"v\": -20.1168");
    fails_with(&output, &["initial.v"]);
    assert_eq!(std::fs::read(dir.join("out.json")).unwrap(), before);
}

#[test]
fn plan_refuses_unknown_keys_negative_speeds_and_huge_horizons() {
    let dir = scratch("plan");
    let output = plan_with(&dir, "\"phi\": 0.0", "\"phi\": 0.0, \"psi\": 1.0");
    fails_with(&output, &["unknown field `psi`"]);
    let output = plan_with(&dir, "\"v\": 20.1168", "\"v\": -20.1168");
    fails_with(&output, &["initial.v", "-20.1168"]);
    let text = read("configs/examples/plan-problem.json");
    let terminal = text.find("\"terminal\"").unwrap();
    let (head, tail) = text.split_at(terminal);
    let tail = tail.replacen("\"v\": ", "\"v\": -", 1);
    std::fs::write(dir.join("p.json"), format!("{head}{tail}")).unwrap();
    let output = palc(&["plan", "--problem", "p.json", "--out", "out.json"], &dir);
    fails_with(&output, &["terminal.v"]);
    let output = plan_with(&dir, "\"horizon\": 40", "\"horizon\": 1000000");
    fails_with(
        &output,
        &["horizon", &palc_planner::MAX_HORIZON.to_string()],
    );
}

#[test]
fn zone_fit_refuses_duplicate_columns_and_names_line_and_column() {
    let dir = scratch("zone-csv");
    let fit = |text: &str| {
        std::fs::write(dir.join("s.csv"), text).unwrap();
        palc(
            &["zone", "fit", "--samples", "s.csv", "--out", "m.json"],
            &dir,
        )
    };
    let header = "ds_p,dl_p,dist_p,ds_a,dl_a,dist_a,y\n";
    let output = fit("ds_p,dl_p,dist_p,ds_a,dl_a,dist_a,y,ds_p\n1,2,3,4,5,6,1,9\n");
    fails_with(&output, &["`ds_p` appears twice"]);
    let output = fit(&format!("{header}1,2,3,4,5,6,1\n1,2,inf,4,5,6,0\n"));
    fails_with(&output, &["line 3", "`dist_p`", "inf"]);
    assert!(!dir.join("m.json").exists());
}

#[test]
fn a_zone_config_error_is_blamed_on_the_config() {
    let dir = scratch("zone-config");
    std::fs::write(dir.join("zone.toml"), "ridge = -1.0\n").unwrap();
    let samples = workspace_file("configs/examples/zone-samples.csv");
    let output = palc(
        &[
            "zone",
            "fit",
            "--samples",
            samples.to_str().unwrap(),
            "--config",
            "zone.toml",
            "--out",
            "m.json",
        ],
        &dir,
    );
    fails_with(&output, &["zone.toml", "ridge"]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!stderr.contains("zone-samples.csv"), "{stderr}");
}

fn learn_with(dir: &Path, from: &str, to: &str) -> Output {
    let text = read("configs/learn.toml");
    assert!(text.contains(from), "{from}");
    std::fs::write(dir.join("learn.toml"), text.replacen(from, to, 1)).unwrap();
    palc(&["learn", "--config", "learn.toml"], dir)
}

#[test]
fn learn_bounds_the_loop_and_names_a_missing_table() {
    let dir = scratch("learn");
    let output = learn_with(&dir, "success_streak = 3", "success_streak = 1000000");
    fails_with(&output, &["loop.success_streak", "[1, 100]", "learn.toml"]);
    let output = learn_with(&dir, "max_takeovers = 30", "max_takeovers = 1000000");
    fails_with(&output, &["loop.max_takeovers"]);
    let output = learn_with(&dir, "max_takeovers = 30", "max_lane_changes = 1000000");
    fails_with(&output, &["loop.max_lane_changes"]);
    let output = learn_with(&dir, "style = \"neutral\"", "style = \"custom\"");
    fails_with(&output, &["[user.custom] is missing"]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!stderr.contains("NaN"), "{stderr}");
}

#[cfg(unix)]
#[test]
fn a_saved_experience_keeps_its_permissions_and_its_symlink() {
    use std::os::unix::fs::PermissionsExt;
    let dir = scratch("experience-permissions");
    std::fs::create_dir(dir.join("store")).unwrap();
    std::fs::write(dir.join("store/e.json"), "old").unwrap();
    std::fs::set_permissions(
        dir.join("store/e.json"),
        std::fs::Permissions::from_mode(0o600),
    )
    .unwrap();
    std::os::unix::fs::symlink("store/e.json", dir.join("e.json")).unwrap();
    succeeds(&palc(&["learn", "--save-experience", "e.json"], &dir));
    let link = std::fs::symlink_metadata(dir.join("e.json")).unwrap();
    assert!(link.file_type().is_symlink());
    let target = std::fs::metadata(dir.join("store/e.json")).unwrap();
    assert_eq!(target.permissions().mode() & 0o777, 0o600);
    palc_aggregator::Experience::load(dir.join("store/e.json")).unwrap();
}

#[test]
fn user_expect_writes_the_expected_lane_change_of_a_user_file() {
    let dir = scratch("user-expect");
    std::fs::write(
        dir.join("user.toml"),
        "[user]\nstyle = \"neutral\"\n[user.family]\nprofile = { shape = \"cosine\" }\nreaction_s = 0.5\n",
    )
    .unwrap();
    let output = palc(
        &[
            "user",
            "expect",
            "--user",
            "user.toml",
            "--out",
            "expected.csv",
        ],
        &dir,
    );
    succeeds(&output);
    let csv = std::fs::read_to_string(dir.join("expected.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("step,time_s,s_m,v_mps,l_m,phi_rad,phase")
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let l = |row: &Vec<&str>| row[4].parse::<f64>().unwrap();
    assert!(l(&rows[0]).abs() < 1e-9);
    assert!((l(rows.last().unwrap()) - 3.5).abs() < 1e-3);
    assert!(rows.iter().any(|r| r[6] == "changing"));
    // A bad user file names the file and the field; no CSV is left behind.
    std::fs::write(
        dir.join("bad.toml"),
        "[user]\nstyle = \"neutral\"\nfamily = { reaction_s = 9.0 }\n",
    )
    .unwrap();
    let output = palc(
        &["user", "expect", "--user", "bad.toml", "--out", "bad.csv"],
        &dir,
    );
    fails_with(
        &output,
        &["bad.toml", "user.family.reaction_s", "[0.0, 3.0]"],
    );
    assert!(!dir.join("bad.csv").exists());
    // `palc learn --user` reads the same files.
    succeeds(&palc(&["learn", "--user", "user.toml"], &dir));
    let output = palc(&["learn", "--user", "bad.toml"], &dir);
    fails_with(&output, &["bad.toml", "user.family.reaction_s"]);
}

/// Issue 47: `--jobs 100000` spawned threads until the system refused (55 s).
#[test]
fn eval_refuses_jobs_past_the_bound_before_any_work() {
    let dir = scratch("eval-jobs");
    let config = workspace_file("configs/stress/dense-eval.toml");
    for jobs in ["100000", "0"] {
        let output = palc(
            &[
                "eval",
                "--quick",
                "--config",
                config.to_str().unwrap(),
                "--out",
                "out",
                "--jobs",
                jobs,
            ],
            &dir,
        );
        fails_with(&output, &["--jobs", jobs, "1 to 1024"]);
    }
    assert!(!dir.join("out").exists());
}

/// Issue 47: `eval --out` at an existing file ran the whole evaluation before
/// saying "File exists".
#[test]
fn eval_refuses_an_out_that_is_a_file_before_the_runs_and_leaves_it() {
    let dir = scratch("eval-out-file");
    std::fs::write(dir.join("out"), "my file").unwrap();
    let config = workspace_file("configs/stress/dense-eval.toml");
    let output = palc(
        &[
            "eval",
            "--quick",
            "--config",
            config.to_str().unwrap(),
            "--out",
            "out",
        ],
        &dir,
    );
    fails_with(&output, &["out", "not a directory"]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(!stdout.contains("runs"), "runs started: {stdout}");
    assert_eq!(std::fs::read_to_string(dir.join("out")).unwrap(), "my file");
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
}

/// Issue 47: 10^6 seeds in an eval config started 1,000,001 runs.
#[test]
fn eval_refuses_a_config_past_its_run_bound_naming_the_file_and_the_field() {
    let dir = scratch("eval-max-runs");
    let base = workspace_file("configs/stress/dense.toml");
    let seeds: Vec<String> = (0..1_000_000).map(|s| s.to_string()).collect();
    let text = read("configs/stress/dense-eval.toml")
        .replace(
            "base = \"dense.toml\"",
            &format!("base = \"{}\"", base.display()),
        )
        .replace("seeds = [1]", &format!("seeds = [{}]", seeds.join(", ")));
    std::fs::write(dir.join("eval.toml"), &text).unwrap();
    let output = palc(
        &["eval", "--quick", "--config", "eval.toml", "--out", "out"],
        &dir,
    );
    fails_with(&output, &["eval.toml", "max_runs", "100000"]);
    assert!(!dir.join("out").exists());
    // The bound is the config's to raise, or lower.
    std::fs::write(
        dir.join("eval.toml"),
        text.replacen("\n[grid]", "\nmax_runs = 0\n[grid]", 1),
    )
    .unwrap();
    let output = palc(
        &["eval", "--quick", "--config", "eval.toml", "--out", "out"],
        &dir,
    );
    fails_with(&output, &["eval.toml", "`max_runs` is 0", "at least 1"]);
}

/// Issue 47: an input file of any size was read whole (`zone fit --samples
/// /dev/zero` aborted on a 2 GiB allocation).
#[test]
fn an_input_past_the_size_bound_is_refused_naming_the_file_its_size_and_the_bound() {
    let dir = scratch("input-size");
    let large = std::fs::File::create(dir.join("large.json")).unwrap();
    // Sparse: 64 MiB and one byte, without writing them.
    large.set_len(64 * 1024 * 1024 + 1).unwrap();
    let output = palc(
        &["plan", "--problem", "large.json", "--out", "plan.json"],
        &dir,
    );
    fails_with(&output, &["large.json", "67108865 bytes", "67108864 bytes"]);
    assert!(!dir.join("plan.json").exists());
    let output = palc(&["learn", "--config", "large.json"], &dir);
    fails_with(&output, &["large.json", "67108865 bytes", "67108864 bytes"]);
    let output = palc(
        &["zone", "fit", "--samples", "large.json", "--out", "m.json"],
        &dir,
    );
    fails_with(&output, &["large.json", "67108865 bytes", "67108864 bytes"]);
    #[cfg(target_os = "linux")]
    {
        let output = palc(
            &["zone", "fit", "--samples", "/dev/zero", "--out", "m.json"],
            &dir,
        );
        fails_with(&output, &["/dev/zero", "67108864 bytes"]);
    }
    assert!(!dir.join("m.json").exists());
}

/// `configs/learn.toml` with `from` replaced by `to`, written into `dir`.
fn learn_config_with(dir: &Path, from: &str, to: &str) -> PathBuf {
    let text = read("configs/learn.toml");
    assert!(text.contains(from), "{from}");
    let path = dir.join("learn.toml");
    std::fs::write(&path, text.replacen(from, to, 1)).unwrap();
    path
}

/// Issue 47: values that cannot be right were accepted in a learning config
/// (`planning.target_l` off the road reported "Personalized", `[aggregator]`
/// options read only deep in the run, inverted braking bounds). Each is refused
/// at load time, naming the file, the field path, the value and the bound (with
/// the other field of an inconsistency).
#[test]
fn learn_refuses_values_that_cannot_be_right_naming_file_field_value_and_bound() {
    let dir = scratch("learn-cannot-be-right");
    let cases: [(&str, &str, &[&str]); 9] = [
        (
            "[planning]\n",
            "[planning]\ntarget_l = 7.0\n",
            &[
                "planning.target_l",
                "7.0",
                "traffic.road.lane_width_m",
                "3.5",
            ],
        ),
        (
            "[planning]\n",
            "[planning]\ntarget_l = -3.5\n",
            &["planning.target_l", "-3.5"],
        ),
        (
            "[planning]\n",
            "[planning]\ntarget_l = 0.0\n",
            &["planning.target_l", "0.0"],
        ),
        (
            "lane_width_m = 3.5",
            "lane_width_m = 4.0",
            &[
                "planning.target_l",
                "3.5",
                "traffic.road.lane_width_m",
                "4.0",
            ],
        ),
        (
            "min_braking_mps2 = 6.0",
            "min_braking_mps2 = 8.0",
            &[
                "planning.safety.min_braking_mps2",
                "8.0",
                "planning.safety.max_braking_mps2",
            ],
        ),
        (
            "[loop]",
            "[aggregator.correction]\nrule = \"target\"\ntolerance_m = nan\n\n[loop]",
            &["aggregator.correction.tolerance_m", "NaN", ">= 0"],
        ),
        (
            "[loop]",
            "[aggregator.bounds]\ngrid_step = 0.0\n\n[loop]",
            &["aggregator.bounds.grid_step", "0.0", "positive"],
        ),
        (
            "[loop]",
            "[aggregator.bounds]\nlateral_range = [5.0, -1.0]\n\n[loop]",
            &[
                "aggregator.bounds.lateral_range",
                "lateral_range[0] < lateral_range[1]",
            ],
        ),
        (
            "[loop]",
            "[aggregator.zone]\nridge = -1.0\n\n[loop]",
            &["aggregator.zone.ridge", "-1.0", ">= 0"],
        ),
    ];
    for (from, to, needles) in cases {
        let config = learn_config_with(&dir, from, to);
        let output = palc(
            &[
                "learn",
                "--config",
                config.to_str().unwrap(),
                "--save-experience",
                "e.json",
            ],
            &dir,
        );
        let mut needles = needles.to_vec();
        needles.push("learn.toml");
        fails_with(&output, &needles);
        assert!(!dir.join("e.json").exists(), "{to}");
    }
}

/// Issue 47: two speed cases with the same name (the first won) and a vehicle
/// wider than its lane were accepted.
#[test]
fn traffic_refuses_duplicate_speed_cases_and_vehicles_wider_than_their_lane() {
    let dir = scratch("traffic-cannot-be-right");
    let cases: [(&str, &str, &[&str]); 2] = [
        (
            "name = \"collector-slow\"",
            "name = \"collector-high\"",
            &[
                "testbed.speed_cases[1].name",
                "collector-high",
                "testbed.speed_cases[0]",
            ],
        ),
        (
            "width_m = 1.8",
            "width_m = 10.0",
            &["vehicle.width_m", "10.0", "road.lane_width_m", "3.5"],
        ),
    ];
    for (from, to, needles) in cases {
        let config = testbed_with(&dir, from, to);
        let output = palc(
            &[
                "traffic",
                "simulate",
                "--config",
                config.to_str().unwrap(),
                "--out",
                "t.csv",
            ],
            &dir,
        );
        fails_with(&output, needles);
        assert!(!dir.join("t.csv").exists());
    }
}

/// Issue 47: plan bounds with min > max were planned through and reported
/// "solved" (soft bounds).
#[test]
fn plan_refuses_a_bound_with_min_above_max_and_touches_no_output() {
    let dir = scratch("plan-inverted-bound");
    let text = read("configs/examples/plan-problem.json");
    let mut problem: serde_json::Value = serde_json::from_str(&text).unwrap();
    let horizon = problem["problem"]["reference_speed"]
        .as_array()
        .unwrap()
        .len();
    let mut bounds = vec![serde_json::Value::Null; horizon + 1];
    bounds[5] = serde_json::json!({"min": 2.0, "max": 1.0});
    problem["problem"]["lateral_bounds"] = serde_json::Value::Array(bounds);
    std::fs::write(dir.join("p.json"), problem.to_string()).unwrap();
    std::fs::write(dir.join("out.json"), "previous").unwrap();
    let output = palc(&["plan", "--problem", "p.json", "--out", "out.json"], &dir);
    fails_with(
        &output,
        &[
            "p.json",
            "problem.lateral_bounds[5].min",
            "2.0",
            "problem.lateral_bounds[5].max",
            "1.0",
        ],
    );
    assert_eq!(
        std::fs::read_to_string(dir.join("out.json")).unwrap(),
        "previous"
    );
}

/// Issue 47: 10^4 vehicles x 10^6 steps passed both bounds and ran on; the rows
/// (one per vehicle and step) are bounded together, before the output is touched.
#[test]
fn too_many_traffic_rows_are_refused_before_the_output_is_touched() {
    let dir = scratch("rows");
    std::fs::write(dir.join("existing.csv"), "precious\n").unwrap();
    let text = read("configs/platoon.toml");
    for (vehicles, duration, needles) in [
        (
            "vehicles = 10",
            "100000",
            ["1000000 steps of 10 vehicles", "10000010 rows"],
        ),
        (
            "vehicles = 10000",
            "100",
            ["1000 steps of 10000 vehicles", "10010000 rows"],
        ),
    ] {
        // Room on the road for 10^4 vehicles 40 m apart.
        let config = (text.replacen("vehicles = 10", vehicles, 1))
            .replacen("leader_start_s_m = 600.0", "leader_start_s_m = 500000.0", 1)
            .replacen("length_m = 1000.0", "length_m = 600000.0", 1);
        std::fs::write(dir.join("platoon.toml"), config).unwrap();
        let output = palc(
            &[
                "traffic",
                "simulate",
                "--config",
                "platoon.toml",
                "--duration",
                duration,
                "--dt",
                "0.1",
                "--out",
                "existing.csv",
            ],
            &dir,
        );
        fails_with(&output, &[needles[0], needles[1], "at most 10000000 rows"]);
    }
    assert_eq!(
        std::fs::read_to_string(dir.join("existing.csv")).unwrap(),
        "precious\n"
    );
}

/// An evaluation none of whose runs in an experiment could run (e.g.
/// `timing.dts = [1e-300]`) exited 0, its failure a row in REPORT.md. The dense
/// stress scene refuses every run on purpose and says so in `expected_refusals`.
#[test]
fn eval_exits_non_zero_naming_an_experiment_that_measured_nothing() {
    let dir = scratch("eval-idle");
    let base = workspace_file("configs/stress/dense.toml");
    let text = read("configs/stress/dense-eval.toml").replace(
        "base = \"dense.toml\"",
        &format!("base = \"{}\"", base.display()),
    );
    assert!(text.contains("expected_refusals = ["));
    std::fs::write(dir.join("eval.toml"), &text).unwrap();
    let args = ["eval", "--quick", "--config", "eval.toml", "--out", "out"];
    succeeds(&palc(&args, &dir));
    // Without the declaration, the same refusals make every experiment idle.
    let start = text.find("expected_refusals = [").unwrap();
    let end = start + text[start..].find("\n]").unwrap() + 2;
    let undeclared = format!("{}{}", &text[..start], &text[end..]);
    std::fs::write(dir.join("eval.toml"), &undeclared).unwrap();
    let output = palc(&args, &dir);
    fails_with(
        &output,
        &[
            "measured nothing",
            "experiment `grid`: none of its 24 runs ran",
            "most common reason: standard-",
        ],
    );
    // The results are written all the same, the idle experiments named in the report.
    let report = std::fs::read_to_string(dir.join("out/REPORT.md")).unwrap();
    assert!(
        report.contains("Experiments that measured nothing"),
        "{report}"
    );
}

/// An output that cannot be written was found only after the work: `palc learn
/// --save-experience` into a missing directory ran the whole run first.
#[test]
fn outputs_that_cannot_be_written_are_refused_before_the_work() {
    let dir = scratch("outputs-before-work");
    let config = workspace_file("configs/learn.toml");
    let config = config.to_str().unwrap();
    for args in [
        vec![
            "learn",
            "--config",
            config,
            "--save-experience",
            "missing/e.json",
        ],
        vec!["learn", "--config", config, "--record", "."],
        vec![
            "user",
            "expect",
            "--config",
            config,
            "--out",
            "missing/expected.csv",
        ],
    ] {
        let output = palc(&args, &dir);
        let missing = if args.contains(&".") {
            "is a directory"
        } else {
            "missing"
        };
        fails_with(&output, &[missing]);
        let stdout = String::from_utf8_lossy(&output.stdout);
        assert!(
            !stdout.contains("takeover") && !stdout.contains("written"),
            "the work ran first: {stdout}"
        );
    }
    assert_eq!(
        std::fs::read_dir(&dir).unwrap().count(),
        0,
        "a file was left"
    );
}

/// A user file whose user refuses the scenario at run time was not named: the
/// message said what the user refused, not which file it came from.
#[test]
fn a_user_refusal_at_run_time_names_the_user_file() {
    let dir = scratch("user-run-time");
    std::fs::write(
        dir.join("picky.toml"),
        "[user]\nstyle = \"neutral\"\n[user.family]\nmin_lead_gap_s = 9.0\n",
    )
    .unwrap();
    for args in [
        vec!["learn", "--user", "picky.toml"],
        vec!["user", "expect", "--user", "picky.toml", "--out", "e.csv"],
    ] {
        let output = palc(&args, &dir);
        fails_with(&output, &["with the user of picky.toml", "lead 9.00 s"]);
    }
}
