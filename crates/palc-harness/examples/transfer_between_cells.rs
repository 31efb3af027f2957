//! Carries the experience of each grid cell (seed 1) into the cell of the next
//! speed case (or, with `headway`, of the next headway), once per representation,
//! and prints the takeovers against learning from scratch:
//! `cargo run --release -p palc-harness --example transfer_between_cells [headway]`.
//! With `chain-speed` or `chain-headway`, one user instead drives the speed cases
//! (or headways) in sequence, carrying its experience (seeds 1 and 2).
#![allow(clippy::print_stdout)]

use palc_aggregator::{AggregatorOptions, Representation};
use palc_harness::{CellChoice, LearnConfig, NoObserver, StylePreset, UserConfig, run};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../configs/learn.toml"
    ))?;
    let base = LearnConfig::from_toml_str(&text)?;
    let testbed = base
        .traffic
        .testbed
        .clone()
        .ok_or("learn.toml has a test bed")?;
    let cases: Vec<String> = testbed.speed_cases.iter().map(|c| c.name.clone()).collect();
    let headways = testbed.adjacent_headways_m.clone();
    let mode = std::env::args().nth(1).unwrap_or_default();
    if let Some(axis) = mode.strip_prefix("chain-") {
        return chain(&base, &cases, &headways, axis == "headway");
    }
    let by_headway = mode == "headway";
    let representations = [Representation::TimeIndexed, Representation::RelativeOnset];
    let (mut scratch_sum, mut sums, mut cells) = (0, [0; 2], 0);
    for style in StylePreset::ALL {
        for (h, &headway) in headways.iter().enumerate() {
            for (c, case) in cases.iter().enumerate() {
                let cell = |case: &str, headway_m: f64| {
                    (base.clone())
                        .with_cell(CellChoice {
                            speed_case: case.into(),
                            headway_m,
                            seed: 1,
                        })
                        .with_user(UserConfig::preset(style))
                };
                let (source_case, source_headway) = if by_headway {
                    (case.as_str(), headways[(h + 1) % headways.len()])
                } else {
                    (cases[(c + 1) % cases.len()].as_str(), headway)
                };
                let target = cell(case, headway);
                // Cells the paper's premise does not hold in are refused; skip them.
                let Ok(source) = run(&cell(source_case, source_headway), None, &mut NoObserver)
                else {
                    continue;
                };
                let Ok(scratch) = run(&target, None, &mut NoObserver) else {
                    continue;
                };
                let mut line = format!(
                    "{:10} {case:15} {headway:4} m <- {source_case:15} {source_headway:4} m: scratch {}",
                    style.name(),
                    scratch.summary.counted_takeovers()
                );
                scratch_sum += scratch.summary.counted_takeovers();
                for (r, representation) in representations.into_iter().enumerate() {
                    let mut config = target.clone();
                    config.aggregator = Some(AggregatorOptions {
                        representation,
                        ..AggregatorOptions::default()
                    });
                    let carried = run(&config, Some(&source.experience), &mut NoObserver)?;
                    let takeovers = carried.summary.counted_takeovers();
                    sums[r] += takeovers;
                    line += &format!(", {representation:?} {takeovers}");
                }
                println!("{line}");
                cells += 1;
            }
        }
    }
    let mean = |sum: usize| sum as f64 / cells.max(1) as f64;
    println!(
        "{cells} cells: mean takeovers from scratch {:.2}, time-indexed {:.2}, relative onset {:.2}",
        mean(scratch_sum),
        mean(sums[0]),
        mean(sums[1])
    );
    Ok(())
}

/// One user drives a grid row in grid order (the speed cases at each headway, or
/// with `by_headway` the headways in each speed case), seeds 1 and 2, each scene
/// started from the experience of the one before; prints the mean takeovers after
/// the first scene (the evaluation's accumulation experiment, deterministic users).
fn chain(
    base: &LearnConfig,
    cases: &[String],
    headways: &[f64],
    by_headway: bool,
) -> Result<(), Box<dyn std::error::Error>> {
    let rows: Vec<Vec<(String, f64)>> = if by_headway {
        (cases.iter())
            .map(|c| headways.iter().map(|&h| (c.clone(), h)).collect())
            .collect()
    } else {
        (headways.iter())
            .map(|&h| cases.iter().map(|c| (c.clone(), h)).collect())
            .collect()
    };
    let (mut sum, mut scenes) = (0, 0);
    for seed in [1, 2] {
        for style in StylePreset::ALL {
            for row in &rows {
                let mut experience = None;
                for (i, (case, headway_m)) in row.iter().enumerate() {
                    let config = (base.clone())
                        .with_cell(CellChoice {
                            speed_case: case.clone(),
                            headway_m: *headway_m,
                            seed,
                        })
                        .with_user(UserConfig::preset(style));
                    // A refused scene ends the chain, as in the evaluation.
                    let Ok(result) = run(&config, experience.as_ref(), &mut NoObserver) else {
                        break;
                    };
                    let takeovers = result.summary.counted_takeovers();
                    println!(
                        "seed {seed} {:10} {case:15} {headway_m:4} m, scene {}: {takeovers}",
                        style.name(),
                        i + 1
                    );
                    if i > 0 {
                        sum += takeovers;
                        scenes += 1;
                    }
                    experience = Some(result.experience);
                }
            }
        }
    }
    println!(
        "{scenes} scenes after the first: mean takeovers {:.2}",
        sum as f64 / scenes.max(1) as f64
    );
    Ok(())
}
