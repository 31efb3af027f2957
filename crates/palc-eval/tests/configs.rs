//! Every evaluation config the repository ships is accepted by the checks that
//! refuse bad input: each loads with its base config, in full and quick, and
//! expands to fewer runs than its bound.

use std::path::{Path, PathBuf};

use palc_eval::Evaluation;
use palc_eval::plan::DEFAULT_MAX_RUNS;

/// The evaluation configs under `configs/` (those that name a base config).
fn evaluation_configs() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs");
    let mut found = Vec::new();
    for dir in [root.clone(), root.join("stress")] {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let is_toml = path.extension().is_some_and(|e| e == "toml");
            if is_toml
                && (std::fs::read_to_string(&path).unwrap().lines())
                    .any(|line| line.starts_with("base = "))
            {
                found.push(path);
            }
        }
    }
    found.sort();
    found
}

#[test]
fn every_shipped_evaluation_config_loads_and_plans_within_its_bound() {
    let configs = evaluation_configs();
    assert!(configs.len() >= 6, "{configs:?}");
    for path in &configs {
        for quick in [false, true] {
            let evaluation = Evaluation::load(path, quick)
                .unwrap_or_else(|e| panic!("{} (quick: {quick}): {e}", path.display()));
            let plan = evaluation
                .plan()
                .unwrap_or_else(|e| panic!("{} (quick: {quick}): {e}", path.display()));
            assert!(!plan.is_empty() && plan.len() < DEFAULT_MAX_RUNS);
        }
    }
}
