//! The accelerating-lag stress scene (`configs/stress/accelerating-lag.toml`): a
//! target-lane vehicle that accelerates into the gap once the ego starts its lane
//! change; with `planning.safety.enforce` the safety layer must refuse the lane
//! change into that closing gap and record why.

use palc_harness::safety::Role;
use palc_harness::{LearnConfig, LearningLoop, NoObserver, StylePreset, UserConfig, Violation};

fn config(style: StylePreset, speed_case: &str, headway_m: f64, enforce: bool) -> LearnConfig {
    let text = include_str!("../../../configs/stress/accelerating-lag.toml");
    let mut config = LearnConfig::from_toml_str(text).unwrap();
    config.cell.speed_case = speed_case.to_owned();
    config.cell.headway_m = headway_m;
    config.planning.safety.enforce = enforce;
    config.stopping.max_takeovers = 6;
    config.with_user(UserConfig::preset(style))
}

/// The first refusal recorded in a run of at most `lane_changes` lane changes.
fn first_refusal(config: &LearnConfig, lane_changes: usize) -> Option<(usize, Violation)> {
    let mut run = LearningLoop::new(config, None).ok()?;
    for _ in 0..lane_changes {
        if run.termination().is_some() {
            break;
        }
        let record = run.step(&mut NoObserver).unwrap();
        if let Some(violation) = record.safety_refusal {
            return Some((record.index, violation));
        }
    }
    None
}

#[test]
#[ignore = "exploration"]
fn explore() {
    for case in [
        "collector-high",
        "collector-slow",
        "arterial-high",
        "arterial-slow",
    ] {
        for headway in [50.0, 45.0, 40.0, 35.0, 30.0] {
            for style in StylePreset::ALL {
                let c = config(style, case, headway, true);
                let found = first_refusal(&c, 8);
                println!("{case} {headway} {style:?}: {found:?}");
            }
        }
    }
}
