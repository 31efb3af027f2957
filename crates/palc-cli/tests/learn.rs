//! `palc learn` says what it believes about the driver after every lesson and
//! after the run: the posterior's most probable model and the gap-acceptance
//! drivers the starts allow.

use std::path::Path;
use std::process::Command;

#[test]
fn learn_prints_what_the_starts_allow_after_each_lesson_and_the_run() {
    let config = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/learn.toml");
    let output = Command::new(env!("CARGO_BIN_EXE_palc"))
        .args(["learn", "--config"])
        .arg(&config)
        .output()
        .expect("palc runs");
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let takeovers = stdout.lines().filter(|l| l.contains("takeover at")).count();
    assert!(takeovers >= 1, "the standard plan is taken over: {stdout}");
    let allowed = |prefix: &str| {
        (stdout.lines())
            .filter(|l| l.trim_start().starts_with(prefix))
            .filter(|l| l.contains("decides on the time-headway at"))
            .filter(|l| l.contains("a follower's gap of"))
            .count()
    };
    assert_eq!(
        allowed("the starts allow a driver who"),
        takeovers,
        "{stdout}"
    );
    assert_eq!(
        allowed("after the run, the starts allow a driver who"),
        1,
        "{stdout}"
    );
}
