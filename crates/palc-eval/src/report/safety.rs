//! REPORT.md's safety section: collisions, RSS safe-distance violations, the
//! safety layer's refusals and the distributions of the smallest gaps and times to
//! collision, per experiment (every one with runs) and method, and palc's
//! target of none
//! (docs/experiments/0030-safety-measures-acc-and-gap-seeking.md,
//! docs/experiments/0031-the-safety-layer-and-the-papers-scenes.md and
//! docs/experiments/0032-the-safe-set-up-measured.md).

use std::fmt::{self, Write as _};

use palc_harness::safety::SafetyMetrics;

use crate::plan::Experiment;
use crate::results::Iteration;
use crate::stats::percentile;
use crate::targets::{TargetId, events_of, target};

use super::section::{Out, Results, Section, fill, header};

/// The safety section.
pub struct Safety;

impl Section for Safety {
    fn title(&self) -> &'static str {
        "Safety of every executed lane change"
    }

    fn render(&self, results: &Results, out: &mut Out) -> fmt::Result {
        writeln!(out, "{}\n", fill(include_str!("templates/safety.md"), &[]))?;
        header(
            out,
            &[
                "experiment",
                "method",
                "lane changes",
                "system: collisions",
                "system: RSS violations",
                "user: collisions",
                "user: RSS violations",
                "refusals",
                "min gap preceding, p5 / min (m)",
                "min gap target lead, p5 / min (m)",
                "min gap target lag, p5 / min (m)",
                "min TTC, p5 / min (s)",
            ],
        )?;
        // Every experiment with runs, a new one included, in the order of its variant.
        for experiment in results.index.experiments() {
            for &method in results.methods() {
                let rows = results.index.of_experiment(experiment, method);
                let iterations: Vec<&Iteration> = rows.iter().flat_map(|r| &r.iterations).collect();
                if iterations.is_empty() {
                    continue;
                }
                let distribution = |f: &dyn Fn(&SafetyMetrics) -> Option<f64>| {
                    low_tail(iterations.iter().filter_map(|i| f(&i.safety)).collect())
                };
                // An ablation run's method is its rung's label rule: every such rung.
                let who = match experiment {
                    Experiment::Ablation | Experiment::AblationTransfer => {
                        format!("rungs with `{}` labels", method.name())
                    }
                    _ => format!("`{}`", method.name()),
                };
                let events = events_of(rows);
                writeln!(
                    out,
                    "| {} | {who} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                    experiment.name(),
                    iterations.len(),
                    events.system_collisions,
                    events.system_violations,
                    events.user_collisions,
                    events.user_violations,
                    iterations
                        .iter()
                        .filter(|i| i.safety_refusal.is_some())
                        .count(),
                    distribution(&|s| s.min_gap_preceding_m),
                    distribution(&|s| s.min_gap_target_lead_m),
                    distribution(&|s| s.min_gap_target_lag_m),
                    distribution(&SafetyMetrics::min_ttc_s),
                )?;
            }
        }
        writeln!(out)?;
        let safety = target(TargetId::Safety);
        let method = results.methods().first().copied().unwrap_or_default();
        for case in safety.cases(&results.index, method, &[]) {
            writeln!(out, "{}\n", safety.state(&case))?;
        }
        let first_user_violation = (results.input.rows.iter())
            .flat_map(|r| r.iterations.iter().map(move |i| (r, i)))
            .find_map(|(r, i)| i.user_safety.first_violation.map(|v| (r, v)));
        if let Some((row, violation)) = first_user_violation {
            writeln!(
                out,
                "A user-driven violation, for example (`{}`): {violation}. The simulated user's own \
                 lane change is the user's choice; the system neither plans nor drives it.\n",
                row.spec.label()
            )?;
        }
        Ok(())
    }
}

/// `p5 / min` of `values` (nearest-rank percentile) with one decimal, `-` when
/// there are none.
fn low_tail(mut values: Vec<f64>) -> String {
    if values.is_empty() {
        return "-".to_owned();
    }
    values.sort_by(f64::total_cmp);
    format!("{:.1} / {:.1}", percentile(&values, 0.05), values[0])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_low_tail_is_the_fifth_percentile_and_the_minimum() {
        assert_eq!(low_tail(Vec::new()), "-");
        let values: Vec<f64> = (0..=100).map(f64::from).rev().collect();
        assert_eq!(low_tail(values), "5.0 / 0.0");
        assert_eq!(low_tail(vec![3.25]), "3.2 / 3.2");
    }
}
