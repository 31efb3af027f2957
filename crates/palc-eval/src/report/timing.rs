//! REPORT.md's compute-time section (Fig. 13): the timing experiment's rows, one
//! per step and horizon, and every learning iteration of the grid against
//! palc's target ([`crate::targets`]).
//!
//! A lane change without a takeover learns nothing and costs next to nothing, so
//! the timing experiment's rows (12 lane changes each, about one in four
//! learning) give a p95 that is the largest of three learning iterations. The
//! grid's learning iterations (every lane change with a takeover, thousands of
//! them at the grid's horizons) are the stable measure of what one learning
//! iteration costs.

use std::fmt::{self, Write as _};

use palc_harness::{Method, record::Timings};

use crate::plan::Experiment;
use crate::results::{Iteration, RunRow};
use crate::stats::{self, Timing as Times};
use crate::targets::{TargetId, target};

use super::section::{Out, Results, Section, fill};

/// The compute-time section.
pub struct Timing;

impl Section for Timing {
    fn title(&self) -> &'static str {
        "Compute time per iteration (Fig. 13)"
    }

    fn render(&self, results: &Results, out: &mut Out) -> fmt::Result {
        writeln!(out, "{}\n", fill(include_str!("templates/timing.md"), &[]))?;
        header(out, "method | dt (s) | K")?;
        for &method in results.methods() {
            let timed = results.index.of_experiment(Experiment::Timing, method);
            let mut keys: Vec<(u64, usize)> = (timed.iter())
                .filter_map(|r| r.dt.map(|dt| (dt.to_bits(), r.horizon)))
                .collect();
            keys.sort_by(|a, b| {
                f64::from_bits(b.0)
                    .total_cmp(&f64::from_bits(a.0))
                    .then(a.1.cmp(&b.1))
            });
            keys.dedup();
            for (dt_bits, k) in keys {
                let group = (timed.iter().copied())
                    .filter(|r| r.dt.map(f64::to_bits) == Some(dt_bits) && r.horizon == k);
                if let Some(t) = stats::timing(group) {
                    let label = format!("{} | {} | {k}", method.name(), f64::from_bits(dt_bits));
                    line(out, &label, &t)?;
                }
            }
        }
        writeln!(out)?;
        learning_iterations(results, out)
    }
}

/// The table of the grid's learning iterations, one row per method, and
/// palc's target for each.
fn learning_iterations(results: &Results, out: &mut Out) -> fmt::Result {
    let measured: Vec<(Method, Times, usize, usize)> = (results.methods().iter())
        .filter_map(|&method| {
            let grid = results.index.of_experiment(Experiment::Grid, method);
            let learning: Vec<&Iteration> = (grid.iter())
                .flat_map(|r| r.iterations.iter().filter(|it| it.takeover))
                .collect();
            let t = stats::timing_of(&learning)?;
            let k = |pick: fn(usize, usize) -> usize| {
                (grid.iter())
                    .filter(|r: &&&RunRow| r.iterations.iter().any(|it| it.takeover))
                    .map(|r| r.horizon)
                    .reduce(pick)
            };
            Some((method, t, k(usize::min)?, k(usize::max)?))
        })
        .collect();
    if measured.is_empty() {
        return Ok(());
    }
    writeln!(
        out,
        "**Learning iterations of the grid**: every lane change of the grid runs with a takeover \
         (every user kind), the lesson learned after it, at the grid's step and horizons.\n"
    )?;
    header(out, "method | K")?;
    for (method, t, k_min, k_max) in &measured {
        line(out, &format!("{} | {k_min}-{k_max}", method.name()), t)?;
    }
    writeln!(out)?;
    let time = target(TargetId::LearningTime);
    if let Some(&(method, ..)) = measured.iter().find(|m| m.0 == Method::Palc) {
        for case in time.cases(&results.index, method, &[]) {
            writeln!(out, "{}\n", time.state(&case))?;
        }
    }
    Ok(())
}

/// A table header whose first columns are `first`, then the timing columns.
fn header(out: &mut Out, first: &str) -> fmt::Result {
    let parts = Timings::PART_NAMES.map(|p| format!("{p} mean"));
    let columns = first.matches('|').count() + 1 + 5 + parts.len();
    writeln!(
        out,
        "| {first} | iterations | mean | p50 | p95 | max | {} |",
        parts.join(" | ")
    )?;
    writeln!(out, "|{}", " --- |".repeat(columns))
}

/// One table row: the label's columns, then `t` in milliseconds.
fn line(out: &mut Out, label: &str, t: &Times) -> fmt::Result {
    let ms = |v: f64| format!("{:.2}", v * 1e3);
    writeln!(
        out,
        "| {label} | {} | {} | {} | {} | {} | {} |",
        t.iterations,
        ms(t.mean),
        ms(t.p50),
        ms(t.p95),
        ms(t.max),
        t.part_means.parts().map(ms).join(" | ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_table_has_as_many_separator_cells_as_header_cells() {
        let t = Times {
            iterations: 100,
            mean: 5e-4,
            p50: 5e-4,
            p95: 1e-3,
            max: 1e-3,
            part_means: Timings::default(),
            part_p95: Timings::default(),
        };
        let mut out = Out::default();
        header(&mut out, "method | dt (s) | K").unwrap();
        line(&mut out, "palc | 0.1 | 143", &t).unwrap();
        let cells = |l: &str| l.matches('|').count();
        let lines: Vec<&str> = out.text.lines().collect();
        assert_eq!(cells(lines[0]), cells(lines[1]));
        assert_eq!(cells(lines[0]), cells(lines[2]));
    }
}
