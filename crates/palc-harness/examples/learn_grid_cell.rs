//! Runs the loop for each style and method in one cell of the test bed and prints
//! the takeovers: `cargo run -p palc-harness --example learn_grid_cell [SPEED_CASE HEADWAY]`.
#![allow(clippy::print_stdout)]

use palc_harness::{CellChoice, LearnConfig, Method, NoObserver, StylePreset, UserConfig, run};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../configs/learn.toml"
    ))?;
    let mut base = LearnConfig::from_toml_str(&text)?;
    let args: Vec<String> = std::env::args().collect();
    if args.len() > 2 {
        let cell = CellChoice {
            speed_case: args[1].clone(),
            headway_m: args[2].parse()?,
            ..base.cell.clone()
        };
        base = base.with_cell(cell);
    }
    for method in Method::ALL {
        for style in StylePreset::ALL {
            let config = (base.clone())
                .with_method(method)
                .with_user(UserConfig::preset(style));
            match run(&config, None, &mut NoObserver) {
                Ok(result) => {
                    let takeovers: Vec<String> = result
                        .records
                        .iter()
                        .map(|r| {
                            r.takeover
                                .map_or("-".to_owned(), |t| format!("{:.1}", t.time_s))
                        })
                        .collect();
                    println!(
                        "{:5} {:10} K={} {:?} takeovers={} final_dev={:.3} [{}]",
                        method.name(),
                        style.name(),
                        result.horizon,
                        result.summary.outcome,
                        result.summary.counted_takeovers(),
                        result.summary.final_max_deviation_m,
                        takeovers.join(" ")
                    );
                }
                Err(e) => println!("{:5} {:10} error: {e}", method.name(), style.name()),
            }
        }
    }
    Ok(())
}
