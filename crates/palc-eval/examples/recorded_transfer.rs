//! Where recorded drivers' starts are placed
//! (docs/experiments/0082-an-onset-extrapolated-from-what-was-seen.md):
//! `cargo run --release -p palc-eval --example recorded_transfer [anchors|transfer] [CONFIG] [USER]`.
//!
//! - `anchors` (the default): every grid run of the user kind (`recorded-us101`
//!   of `configs/reproduce.toml` by default) learned from scratch; the start the
//!   run's experience is anchored at against the driver's own start, the last
//!   step its expected path is at rest.
//! - `transfer`: every transfer run; the carried plan's crossing of a tenth of
//!   the lane against the driver's, the takeovers, and the source's anchor
//!   against the driver's start there (what the plan's error would be with an
//!   exact anchor is summed up last;
//!   docs/experiments/0096-an-onset-past-its-acceleration-peak.md).
//!
//! Each prints one line per run and the spread of the errors.
#![allow(clippy::print_stdout)]

use std::path::PathBuf;

use palc_eval::plan::Experiment;
use palc_eval::{Evaluation, RunSpec};
use palc_harness::{Method, NoObserver, run};

/// The driver's own start in a lane change: the last step its expected path
/// is exactly where it began (a simulated user's path is at rest until then).
fn own_start_s(expected_l: &[f64], dt: f64) -> Option<f64> {
    let first = *expected_l.first()?;
    let moved = expected_l.iter().position(|&l| l != first)?;
    Some(moved.checked_sub(1)? as f64 * dt)
}

/// The time (s) at which `path` first reaches `level`, linear between steps.
fn crossing_s(path: &[f64], dt: f64, level: f64) -> Option<f64> {
    let i = path.iter().position(|&l| l >= level)?;
    let Some(before) = i.checked_sub(1) else {
        return Some(0.0);
    };
    let (a, b) = (path[before], path[i]);
    Some((before as f64 + (level - a) / (b - a)) * dt)
}

/// How many of `errors` (s) lie within 0.05, 0.15 and 0.3 s, and their median size.
fn spread(errors: &mut [f64]) -> String {
    errors.sort_by(|a, b| a.abs().total_cmp(&b.abs()));
    let within = |bound: f64| errors.iter().filter(|e| e.abs() <= bound).count();
    let median = errors.get(errors.len() / 2).map_or(f64::NAN, |e| e.abs());
    format!(
        "{} runs: within 0.05 s {}, 0.15 s {}, 0.3 s {}; median |error| {median:.3} s",
        errors.len(),
        within(0.05),
        within(0.15),
        within(0.3)
    )
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let mode = args.next().unwrap_or_else(|| "anchors".into());
    let config = args
        .next()
        .map_or_else(|| PathBuf::from("configs/reproduce.toml"), PathBuf::from);
    let user = args.next().unwrap_or_else(|| "recorded-us101".into());
    let evaluation = Evaluation::load(&config, false)?;
    let all: Vec<RunSpec> = evaluation.plan()?.all().cloned().collect();
    let runs = |experiment: Experiment| {
        (all.iter()).filter(move |s| {
            s.experiment == experiment && s.method == Method::Palc && s.user.name == user
        })
    };
    let harness = evaluation.harness();
    let f = |x: Option<f64>| x.map_or("-".to_owned(), |x| format!("{x:.2}"));
    let mut errors = Vec::new();
    // (`transfer`) the plans' errors had the source's anchor been the driver's start.
    let mut errors_with_exact_anchors = Vec::new();
    match mode.as_str() {
        "anchors" => {
            for spec in runs(Experiment::Grid) {
                let Ok(result) = run(&harness.config(spec)?, None, &mut NoObserver) else {
                    continue;
                };
                let first = &result.records[0];
                let own = own_start_s(&first.expected_l, first.dt);
                let anchor = result.experience.anchor_s;
                let error = own.zip(anchor).map(|(own, anchor)| anchor - own);
                errors.extend(error);
                // Where the first lesson came: its time, and whether the plan
                // was ahead of the driver (the standard ALC started first).
                let takeover = first.takeover.as_ref();
                let ahead = takeover.map(|t| first.planned_l[t.step] > first.expected_l[t.step]);
                println!(
                    "{}: own start {} anchor {} error {} | takeover at {} plan ahead {}",
                    spec.label(),
                    f(own),
                    f(anchor),
                    f(error),
                    f(takeover.map(|t| t.time_s)),
                    ahead.map_or("-", |a| if a { "yes" } else { "no" })
                );
            }
        }
        "transfer" => {
            for spec in runs(Experiment::Transfer) {
                let source_spec = all.iter().find(|s| Some(s.id) == spec.experience_from);
                let Some(source_spec) = source_spec else {
                    continue;
                };
                let Ok(source) = run(&harness.config(source_spec)?, None, &mut NoObserver) else {
                    continue;
                };
                let experience = Some(&source.experience);
                let Ok(target) = run(&harness.config(spec)?, experience, &mut NoObserver) else {
                    continue;
                };
                let first = &target.records[0];
                let tenth = |path: &[f64]| {
                    let end = first.expected_l.last().copied().unwrap_or(0.0);
                    crossing_s(path, first.dt, 0.1 * end)
                };
                let error = tenth(&first.planned_l)
                    .zip(tenth(&first.expected_l))
                    .map(|(planned, own)| planned - own);
                errors.extend(error);
                // How the source's start was read: a wait for the follower
                // (the headway it started at, the follower's gap learned).
                let onset = source.experience.onsets.last();
                let wait = onset.and_then(|o| o.follower_wait_time_headway_s);
                let lag = onset.and_then(|o| o.lag_time_gap_s);
                // The anchor the plan was carried by, against the driver's own
                // start in the source: an anchor `δ` early puts the plan `δ`
                // late, however well the start is predicted.
                let source_first = &source.records[0];
                let anchor_error = (source.experience.anchor_s)
                    .zip(own_start_s(&source_first.expected_l, source_first.dt))
                    .map(|(anchor, own)| anchor - own);
                if let Some(with_exact_anchor) = error.zip(anchor_error).map(|(e, a)| e + a) {
                    errors_with_exact_anchors.push(with_exact_anchor);
                }
                println!(
                    "{} <- {}: own start {} | plan at 10 % of the lane {} off | takeovers {} | \
                     follower wait at {} lag {} | source anchor {} off",
                    spec.label(),
                    source_spec.speed_case.name,
                    f(own_start_s(&first.expected_l, first.dt)),
                    f(error),
                    target.summary.takeovers,
                    f(wait),
                    f(lag),
                    f(anchor_error)
                );
            }
        }
        other => return Err(format!("unknown mode `{other}`: `anchors` or `transfer`").into()),
    }
    println!("{}", spread(&mut errors));
    if !errors_with_exact_anchors.is_empty() {
        let spread = spread(&mut errors_with_exact_anchors);
        println!("with the source's anchor at the driver's start: {spread}");
    }
    Ok(())
}
