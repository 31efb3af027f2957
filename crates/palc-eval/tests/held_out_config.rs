//! `configs/reproduce-held-out.toml` runs `palc` on seeds no figure of the
//! reproduction uses; it is a check of generalization only while it runs the
//! reproduction's users and experiments on other seeds.

use std::path::PathBuf;

use palc_eval::config::EvalConfig;
use palc_harness::Method;

fn config(name: &str) -> EvalConfig {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../configs")
        .join(name);
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    EvalConfig::from_toml_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn the_held_out_evaluation_runs_the_reproductions_users_on_other_seeds() {
    let reproduction = config("reproduce.toml");
    let held_out = config("reproduce-held-out.toml");
    assert_eq!(held_out.base, reproduction.base);
    assert_eq!(held_out.users, reproduction.users);
    assert_eq!(held_out.transfer, reproduction.transfer);
    assert_eq!(held_out.grid.styles, reproduction.grid.styles);
    assert_eq!(held_out.grid.methods, [Method::Palc]);
    // The reproduction's seeds are the base config's testbed seeds (1 and 2) unless
    // its grid names others; the held-out seeds must be none of them, in the full
    // run and in the quick subset.
    let used: Vec<u64> = (reproduction.grid.seeds.clone().into_iter().flatten())
        .chain(reproduction.quick.grid.seeds.clone().into_iter().flatten())
        .chain([1, 2])
        .collect();
    let held = held_out
        .grid
        .seeds
        .clone()
        .expect("the held-out config names its seeds");
    assert!(!held.is_empty());
    let quick = held_out
        .quick
        .grid
        .seeds
        .clone()
        .expect("the quick subset names its seeds");
    for seed in held.iter().chain(&quick) {
        assert!(
            !used.contains(seed),
            "seed {seed} is one the reproduction uses"
        );
    }
}
