//! One run of an evaluation replayed by its run id (`runs.csv`'s `run_id`),
//! after the chain of runs its experience comes from, with its first lane
//! change printed: the safety of the system's, the user's and the planned
//! steps, and the planned, expected and driven lateral paths every 0.5 s.
//! `cargo run --release -p palc-eval --example replay_run RUN_ID [CONFIG] [--quick]`
//! (docs/experiments/0087-outside-the-model-when-misreads-are-implausible.md).
#![allow(clippy::print_stdout)]

use std::path::PathBuf;

use palc_eval::{Evaluation, RunSpec};
use palc_harness::{NoObserver, run};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let quick = args.iter().any(|a| a == "--quick");
    let mut positional = args.iter().filter(|a| *a != "--quick");
    let id = positional
        .next()
        .ok_or("usage: replay_run RUN_ID [CONFIG] [--quick]")?;
    let config = positional
        .next()
        .map_or_else(|| PathBuf::from("configs/reproduce.toml"), PathBuf::from);
    let evaluation = Evaluation::load(&config, quick)?;
    let all: Vec<RunSpec> = evaluation.plan()?.all().cloned().collect();
    let ids = palc_eval::run_id::run_ids(&all);
    let index = (ids.iter().position(|i| i == id))
        .ok_or_else(|| format!("no run `{id}` in {} (quick: {quick})", config.display()))?;
    let target = &all[index];
    // The runs the experience comes from, the first first.
    let mut chain = vec![target];
    while let Some(from) = chain.last().and_then(|s| s.experience_from) {
        let source = all
            .iter()
            .find(|s| s.id == from)
            .ok_or("a source run is missing")?;
        chain.push(source);
    }
    chain.reverse();
    let harness = evaluation.harness();
    let mut experience = None;
    for spec in chain {
        let result = match run(&harness.config(spec)?, experience.as_ref(), &mut NoObserver) {
            Ok(result) => result,
            Err(error) => {
                println!("{}: {error}", spec.label());
                continue;
            }
        };
        if spec.id == target.id {
            let first = result.records.first().ok_or("the run has no lane change")?;
            println!(
                "{}: takeover at {:?} s",
                spec.label(),
                first.takeover.as_ref().map(|t| t.time_s)
            );
            println!("system steps: {:?}", first.safety);
            println!("user steps: {:?}", first.user_safety);
            println!("planned: {:?}", first.planned_safety);
            let every = (0.5 / first.dt).round().max(1.0) as usize;
            for k in (0..first.planned_l.len()).step_by(every) {
                let driven = first.driven_l.get(k).copied().unwrap_or(f64::NAN);
                println!(
                    "{:5.1} s: planned {:6.3} m, expected {:6.3} m, driven {driven:6.3} m",
                    k as f64 * first.dt,
                    first.planned_l[k],
                    first.expected_l[k]
                );
            }
        }
        experience = Some(result.experience);
    }
    Ok(())
}
