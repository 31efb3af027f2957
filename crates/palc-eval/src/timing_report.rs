//! REPORT.md's compute-time section (Fig. 13): the timing experiment's rows, one
//! per step and horizon, and every learning iteration of the grid against
//! `palc`'s target.
//!
//! A lane change without a takeover learns nothing and costs next to nothing, so
//! the timing experiment's rows (12 lane changes each, about one in four
//! learning) give a p95 that is the largest of three learning iterations. The
//! grid's learning iterations (every lane change with a takeover, thousands of
//! them at the grid's horizons) are the stable measure of what one learning
//! iteration costs.

use std::fmt::Write as _;

use palc_harness::{Method, record::Timings};

use crate::plan::Experiment;
use crate::results::{Iteration, RunRow};
use crate::stats::{self, Timing};
use crate::views;

/// `palc`'s target for the mean of a whole learning iteration (zone fit, bounds,
/// expert, correction, plan), in seconds: the issue that set the targets.
pub(crate) const TARGET_MEAN_S: f64 = 2e-3;
/// `palc`'s target for the 95th percentile of a whole learning iteration (s).
pub(crate) const TARGET_P95_S: f64 = 5e-3;

/// Writes the section: the timing experiment's table, then the grid's learning
/// iterations with the target's verdict.
pub fn section(out: &mut String, rows: &[RunRow], methods: &[Method]) {
    let _ = writeln!(out, "## Compute time per iteration (Fig. 13)\n");
    let _ = writeln!(
        out,
        "Measured with `std::time::Instant` around each part of each iteration, on this machine, \
         in a release build, several runs in parallel; the paper: 0.08 s mean and below 0.13 s up to \
         K = 120 at dt = 0.05 s (MATLAB). Times in ms. Each row of the timing experiment holds \
         every lane change of its runs, most of which learn nothing (no takeover) and cost next to \
         nothing; its p95 is then the largest of a few learning iterations. The table after it \
         times the learning iterations alone.\n"
    );
    header(out, "method | dt (s) | K");
    for &method in methods {
        let timed = views::timing(rows, method);
        let mut keys: Vec<(u64, usize)> = timed
            .iter()
            .filter_map(|r| r.dt.map(|dt| (dt.to_bits(), r.horizon)))
            .collect();
        keys.sort_by(|a, b| {
            f64::from_bits(b.0)
                .total_cmp(&f64::from_bits(a.0))
                .then(a.1.cmp(&b.1))
        });
        keys.dedup();
        for (dt_bits, k) in keys {
            let group = timed
                .iter()
                .copied()
                .filter(|r| r.dt.map(f64::to_bits) == Some(dt_bits) && r.horizon == k);
            if let Some(t) = stats::timing(group) {
                let label = format!("{} | {} | {k}", method.name(), f64::from_bits(dt_bits));
                line(out, &label, &t);
            }
        }
    }
    let _ = writeln!(out);
    learning_iterations(out, rows, methods);
}

/// The table of the grid's learning iterations, one row per method, and the
/// verdict on `palc`'s target.
fn learning_iterations(out: &mut String, rows: &[RunRow], methods: &[Method]) {
    let measured: Vec<(Method, Timing, usize, usize)> = methods
        .iter()
        .filter_map(|&method| {
            let grid: Vec<&RunRow> = (rows.iter())
                .filter(|r| r.spec.experiment == Experiment::Grid && r.spec.method == method)
                .collect();
            let learning: Vec<&Iteration> = (grid.iter())
                .flat_map(|r| r.iterations.iter().filter(|it| it.takeover))
                .collect();
            let t = stats::timing_of(&learning)?;
            let k = |pick: fn(usize, usize) -> usize| {
                (grid.iter())
                    .filter(|r| r.iterations.iter().any(|it| it.takeover))
                    .map(|r| r.horizon)
                    .reduce(pick)
            };
            Some((method, t, k(usize::min)?, k(usize::max)?))
        })
        .collect();
    if measured.is_empty() {
        return;
    }
    let _ = writeln!(
        out,
        "**Learning iterations of the grid**: every lane change of the grid runs with a takeover \
         (every user kind), the lesson learned after it, at the grid's step and horizons.\n"
    );
    header(out, "method | K");
    for (method, t, k_min, k_max) in &measured {
        line(out, &format!("{} | {k_min}-{k_max}", method.name()), t);
    }
    let _ = writeln!(out);
    if let Some((_, t, _, _)) = measured.iter().find(|m| m.0 == Method::Palc) {
        let _ = writeln!(out, "{}\n", verdict(t));
    }
}

/// The sentence that sets `palc`'s learning iterations against the target.
fn verdict(t: &Timing) -> String {
    let met = t.mean < TARGET_MEAN_S && t.p95 < TARGET_P95_S;
    format!(
        "Target for `palc`: a learning iteration below {:.0} ms in the mean and {:.0} ms at the \
         95th percentile: {} (mean {:.2} ms, p95 {:.2} ms over {} iterations).",
        TARGET_MEAN_S * 1e3,
        TARGET_P95_S * 1e3,
        if met { "met" } else { "**not met**" },
        t.mean * 1e3,
        t.p95 * 1e3,
        t.iterations
    )
}

/// A table header whose first columns are `first`, then the timing columns.
fn header(out: &mut String, first: &str) {
    let parts = Timings::PART_NAMES.map(|p| format!("{p} mean"));
    let columns = first.matches('|').count() + 1 + 5 + parts.len();
    let _ = writeln!(
        out,
        "| {first} | iterations | mean | p50 | p95 | max | {} |",
        parts.join(" | ")
    );
    let _ = writeln!(out, "|{}", " --- |".repeat(columns));
}

/// One table row: the label's columns, then `t` in milliseconds.
fn line(out: &mut String, label: &str, t: &Timing) {
    let ms = |v: f64| format!("{:.2}", v * 1e3);
    let _ = writeln!(
        out,
        "| {label} | {} | {} | {} | {} | {} | {} |",
        t.iterations,
        ms(t.mean),
        ms(t.p50),
        ms(t.p95),
        ms(t.max),
        t.part_means.parts().map(ms).join(" | ")
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    fn timing(mean_ms: f64, p95_ms: f64) -> Timing {
        Timing {
            iterations: 100,
            mean: mean_ms * 1e-3,
            p50: mean_ms * 1e-3,
            p95: p95_ms * 1e-3,
            max: p95_ms * 1e-3,
            part_means: Timings::default(),
            part_p95: Timings::default(),
        }
    }

    #[test]
    fn the_target_is_met_only_when_both_the_mean_and_the_p95_are_below_it() {
        assert!(verdict(&timing(0.25, 0.66)).contains(": met (mean 0.25 ms, p95 0.66 ms"));
        assert!(verdict(&timing(2.5, 4.0)).contains("**not met**"));
        assert!(verdict(&timing(1.0, 5.0)).contains("**not met**"));
    }

    #[test]
    fn a_table_has_as_many_separator_cells_as_header_cells() {
        let mut out = String::new();
        header(&mut out, "method | dt (s) | K");
        line(&mut out, "palc | 0.1 | 143", &timing(0.5, 1.0));
        let cells = |l: &str| l.matches('|').count();
        let lines: Vec<&str> = out.lines().collect();
        assert_eq!(cells(lines[0]), cells(lines[1]));
        assert_eq!(cells(lines[0]), cells(lines[2]));
    }
}
