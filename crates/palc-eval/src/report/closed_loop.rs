//! REPORT.md's closed-loop section: the grid cells run again with
//! `[planning.closed_loop]` on, against the same cells in open loop, and palc's
//! target that closed loop personalizes like open loop
//! (docs/experiments/0039-closed-loop-execution.md).

use std::fmt::{self, Write as _};

use palc_harness::{Method, safety::SafetyMetrics};

use crate::results::{Iteration, RunRow};
use crate::stats::{Summary, percentile};
use crate::targets::{self, Case, TargetId, target};

use super::section::{Out, Results, Section, fill, header};

/// The grid row and the closed-loop row of one cell.
type Pair<'a> = (&'a RunRow, &'a RunRow);

/// The closed-loop section.
pub struct ClosedLoop;

impl ClosedLoop {
    /// Per method and paper user kind, the cells run in both loops.
    fn tables<'a>(results: &Results<'a>) -> Vec<(Method, &'a String, Vec<Pair<'a>>)> {
        (results.methods().iter())
            .flat_map(|&m| results.input.users.iter().map(move |u| (m, u)))
            .map(|(m, u)| (m, u, results.index.closed_loop_pairs(m, u)))
            .filter(|(_, _, pairs)| !pairs.is_empty())
            .collect()
    }
}

impl Section for ClosedLoop {
    fn title(&self) -> &'static str {
        "Closed-loop execution"
    }

    fn applies(&self, results: &Results) -> bool {
        !ClosedLoop::tables(results).is_empty()
    }

    fn render(&self, results: &Results, out: &mut Out) -> fmt::Result {
        writeln!(
            out,
            "{}\n",
            fill(include_str!("templates/closed-loop.md"), &[])
        )?;
        header(
            out,
            &[
                "method",
                "user",
                "cells",
                "success, open / closed",
                "mean takeovers, open / closed",
                "collisions, open / closed",
                "RSS violations, open / closed",
                "min gap p5 / p50, open (m)",
                "min gap p5 / p50, closed (m)",
                "re-plans per lane change",
                "refusals, closed",
                "verdict",
            ],
        )?;
        let like_open_loop = target(TargetId::ClosedLoop);
        let mut statements = Vec::new();
        for (method, user, pairs) in ClosedLoop::tables(results) {
            let open = Summary::of(pairs.iter().map(|p| p.0));
            let closed = Summary::of(pairs.iter().map(|p| p.1));
            let open_lc: Vec<&Iteration> = pairs.iter().flat_map(|p| &p.0.iterations).collect();
            let closed_lc: Vec<&Iteration> = pairs.iter().flat_map(|p| &p.1.iterations).collect();
            let count = |lc: &[&Iteration], f: fn(&SafetyMetrics) -> bool| {
                lc.iter().filter(|i| f(&i.safety)).count()
            };
            let replans: usize = (closed_lc.iter())
                .filter_map(|i| i.closed_loop.map(|c| c.replans))
                .sum();
            let refusals = (closed_lc.iter())
                .filter(|i| {
                    i.closed_loop.is_some_and(|c| c.refusals > 0) || i.safety_refusal.is_some()
                })
                .count();
            let verdict = match targets::closed_loop(&results.index, method, user) {
                Some(measured) => {
                    let case = Case {
                        who: format!("`{}`, {user}", method.name()),
                        measured,
                    };
                    let verdict = like_open_loop.verdict(&case.measured).to_string();
                    statements.push(like_open_loop.state(&case));
                    verdict
                }
                None => "-".to_owned(),
            };
            let rate =
                |s: &Summary| (s.runs > 0).then(|| 100.0 * s.personalized as f64 / s.runs as f64);
            let pct = |r: Option<f64>| r.map_or_else(|| "-".to_owned(), |r| format!("{r:.1} %"));
            let num = |m: Option<f64>| m.map_or_else(|| "-".to_owned(), |m| format!("{m:.2}"));
            let refused = if open.refused + closed.refused > 0 {
                format!(" ({} / {} refused)", open.refused, closed.refused)
            } else {
                String::new()
            };
            writeln!(
                out,
                "| `{}` | {user} | {}{refused} | {} / {} | {} / {} | {} / {} | {} / {} | {} | {} | {} | {} | {verdict} |",
                method.name(),
                pairs.len(),
                pct(rate(&open)),
                pct(rate(&closed)),
                num(open.mean),
                num(closed.mean),
                count(&open_lc, |s| s.collision),
                count(&closed_lc, |s| s.collision),
                count(&open_lc, |s| s.rss_violations > 0),
                count(&closed_lc, |s| s.rss_violations > 0),
                gaps(&open_lc),
                gaps(&closed_lc),
                if closed_lc.is_empty() {
                    "-".to_owned()
                } else {
                    format!("{:.1}", replans as f64 / closed_lc.len() as f64)
                },
                refusals,
            )?;
        }
        writeln!(out)?;
        for statement in statements {
            writeln!(out, "- {statement}")?;
        }
        writeln!(out)
    }
}

/// `p5 / p50` of the smallest gaps of `lc`, `-` without any.
fn gaps(lc: &[&Iteration]) -> String {
    let mut values: Vec<f64> = lc.iter().filter_map(|i| i.safety.min_gap_m()).collect();
    if values.is_empty() {
        return "-".to_owned();
    }
    values.sort_by(f64::total_cmp);
    format!(
        "{:.1} / {:.1}",
        percentile(&values, 0.05),
        percentile(&values, 0.5)
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::{Experiment, expand};
    use crate::report::ReportInput;
    use crate::results::Status;

    /// Grid and closed-loop rows of the test selection's deterministic users,
    /// the closed-loop ones personalized after `closed_takeovers` takeovers.
    fn rows(closed_takeovers: usize) -> Vec<RunRow> {
        let mut selection = crate::plan::tests::selection();
        selection.closed_loop.users = vec!["deterministic".into()];
        let plan = expand(&selection, &crate::plan::tests::testbed()).unwrap();
        plan.all()
            .map(|spec| {
                let mut row = RunRow::without_result(spec.clone(), Status::Personalized, 30, 0.0);
                row.takeovers = match spec.experiment {
                    Experiment::ClosedLoop => closed_takeovers,
                    _ => 2,
                };
                row
            })
            .collect()
    }

    fn section(rows: &[RunRow]) -> String {
        let users = ["deterministic".to_owned(), "spread".to_owned()];
        let methods = [Method::Paper, Method::Palc];
        let manifest = crate::manifest::Manifest {
            palc_version: String::new(),
            git_commit: None,
            git_dirty: None,
            config_sha256: String::new(),
            config_path: String::new(),
            base_path: String::new(),
            quick: false,
            seeds: Vec::new(),
            threads: 1,
            cores: 1,
            machine: String::new(),
            runs: 0,
            wall_s: 0.0,
        };
        let input = ReportInput {
            rows,
            methods: &methods,
            users: &users,
            user_kinds: &[],
            example: Err(String::new()),
            figures: &[],
            manifest: &manifest,
            ablation: (&[], &[]),
            recorded: &[],
            idle: &[],
        };
        let results = crate::report::Results::new(&input);
        let mut out = crate::report::Out::default();
        if ClosedLoop.applies(&results) {
            ClosedLoop.render(&results, &mut out).unwrap();
        }
        out.text
    }

    #[test]
    fn closed_loop_runs_are_compared_with_the_same_cells_in_open_loop() {
        let out = section(&rows(2));
        // One line per method, for the deterministic users only.
        assert_eq!(out.matches("| deterministic |").count(), 2, "{out}");
        assert!(!out.contains("| spread |"), "{out}");
        assert_eq!(out.matches("| met |").count(), 2, "{out}");
        assert!(out.contains("100.0 % / 100.0 %"), "{out}");
        assert!(
            out.contains(
                "- Target, closed loop personalizes like open loop (`palc`, deterministic)"
            )
        );

        let out = section(&rows(3));
        assert!(out.contains("2.00 / 3.00"), "{out}");
        assert_eq!(out.matches("| **not met** |").count(), 2, "{out}");

        // Without closed-loop runs there is no section.
        let open: Vec<RunRow> = (rows(2).into_iter())
            .filter(|r| r.spec.experiment != Experiment::ClosedLoop)
            .collect();
        assert!(section(&open).is_empty());
    }
}
