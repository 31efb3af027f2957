//! `palc eval` refuses a bad evaluation config before it writes anything, and
//! names the file, the field and the value.

use std::path::{Path, PathBuf};
use std::process::Command;

fn workspace_file(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path)
}

/// Writes the project's evaluation config with `from` replaced by `to` next to
/// a copy of its base config, and runs `palc eval` on it.
fn eval_with(name: &str, from: &str, to: &str) -> (std::process::Output, PathBuf) {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    std::fs::create_dir_all(&dir).unwrap();
    let text = std::fs::read_to_string(workspace_file("configs/reproduce.toml")).unwrap();
    assert!(text.contains(from), "the project config has no `{from}`");
    std::fs::write(dir.join("reproduce.toml"), text.replace(from, to)).unwrap();
    std::fs::copy(workspace_file("configs/learn.toml"), dir.join("learn.toml")).unwrap();
    let out = dir.join("out");
    let _ = std::fs::remove_dir_all(&out);
    let output = Command::new(env!("CARGO_BIN_EXE_palc"))
        .args(["eval", "--quick", "--config"])
        .arg(dir.join("reproduce.toml"))
        .arg("--out")
        .arg(&out)
        .output()
        .expect("palc runs");
    (output, out)
}

#[test]
fn an_unknown_method_is_refused_with_the_file_and_nothing_is_written() {
    let (output, out) = eval_with(
        "eval-bad-method",
        "methods = [\"paper\", \"palc\"]\nstyles",
        "methods = [\"paper\", \"magic\"]\nstyles",
    );
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("reproduce.toml") && stderr.contains("magic"),
        "{stderr}"
    );
    assert!(!out.exists(), "an output directory was created");
}

#[test]
fn a_step_out_of_range_names_the_field_value_and_bound() {
    let (output, out) = eval_with("eval-bad-dt", "dts = [0.1, 0.05]", "dts = [0.1, 2.0]");
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("quick.timing.dts")
            && stderr.contains("2e0")
            && stderr.contains("(0, 0.5]"),
        "{stderr}"
    );
    assert!(!out.exists());
}

#[test]
fn an_unknown_speed_case_lists_the_defined_ones() {
    let (output, _) = eval_with(
        "eval-bad-case",
        "speed_cases = [\"collector-high\", \"arterial-slow\"]",
        "speed_cases = [\"collector-high\", \"autobahn\"]",
    );
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("autobahn")
            && stderr.contains("quick.grid.speed_cases")
            && stderr.contains("arterial-high"),
        "{stderr}"
    );
}

#[test]
fn an_unknown_style_is_refused_with_the_file_and_the_field_path() {
    let (output, out) = eval_with(
        "eval-bad-style",
        "styles = [\"aggressive\", \"neutral\", \"cautious\"]",
        "styles = [\"reckless\"]",
    );
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("reproduce.toml")
            && stderr.contains("reckless")
            && stderr.contains("grid.styles[0]"),
        "{stderr}"
    );
    assert!(!out.exists(), "an output directory was created");
}
