//! REPORT.md's closed-loop section: the grid cells run again with
//! `[planning.closed_loop]` on, against the same cells in open loop (issue 14's
//! goal: success within 2 points and mean takeovers within 0.5 of open loop).

use std::fmt::Write as _;

use palc_harness::{Method, safety::SafetyMetrics};

use crate::results::{Iteration, RunRow};
use crate::stats::{Summary, percentile};
use crate::views::closed_loop_pairs;

/// Largest gap in success rate (points) for closed loop to count as personalizing
/// like open loop.
pub const SUCCESS_POINTS: f64 = 2.0;
/// Largest gap in mean takeovers for closed loop to count as personalizing like
/// open loop.
pub const MEAN_TAKEOVERS: f64 = 0.5;

/// The grid row and the closed-loop row of one cell.
type Pair<'a> = (&'a RunRow, &'a RunRow);

/// Writes the section when there are closed-loop runs.
pub fn section(out: &mut String, rows: &[RunRow], methods: &[Method], users: &[String]) {
    let tables: Vec<(Method, &String, Vec<Pair>)> = (methods.iter())
        .flat_map(|&m| users.iter().map(move |u| (m, u)))
        .map(|(m, u)| (m, u, closed_loop_pairs(rows, m, u)))
        .filter(|(_, _, pairs)| !pairs.is_empty())
        .collect();
    if tables.is_empty() {
        return;
    }
    let _ = writeln!(out, "## Closed-loop execution\n");
    let _ = writeln!(
        out,
        "Each grid cell below is run twice: in open loop (one plan per lane change, the paper's \
         set-up and every other table) and in closed loop (`[planning.closed_loop]`: the lane \
         change is re-planned every period from the state driven, with fresh predictions of the \
         other vehicles and the same learned weights and zone, over the remaining horizon; the user \
         judges what is driven). Goal: closed loop within {SUCCESS_POINTS} points of open loop's \
         success rate and within {MEAN_TAKEOVERS} of its mean takeovers (failures at the cap). \
         Collisions and RSS violations count system-driven lane changes; min gap is the smallest \
         net gap of each system-driven lane change to any surrounding vehicle.\n"
    );
    let _ = writeln!(
        out,
        "| method | user | cells | success, open / closed | mean takeovers, open / closed | collisions, open / closed | RSS violations, open / closed | min gap p5 / p50, open (m) | min gap p5 / p50, closed (m) | re-plans per lane change | refusals, closed | verdict |"
    );
    let _ = writeln!(
        out,
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
    );
    for (method, user, pairs) in tables {
        let open = Summary::of(pairs.iter().map(|p| p.0));
        let closed = Summary::of(pairs.iter().map(|p| p.1));
        let rate =
            |s: &Summary| (s.runs > 0).then(|| 100.0 * s.personalized as f64 / s.runs as f64);
        let (open_rate, closed_rate) = (rate(&open), rate(&closed));
        let open_lc: Vec<&Iteration> = pairs.iter().flat_map(|p| &p.0.iterations).collect();
        let closed_lc: Vec<&Iteration> = pairs.iter().flat_map(|p| &p.1.iterations).collect();
        let count = |lc: &[&Iteration], f: fn(&SafetyMetrics) -> bool| {
            lc.iter().filter(|i| f(&i.safety)).count()
        };
        let gaps = |lc: &[&Iteration]| {
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
        };
        let replans: usize = (closed_lc.iter())
            .filter_map(|i| i.closed_loop.map(|c| c.replans))
            .sum();
        let refusals = closed_lc
            .iter()
            .filter(|i| i.closed_loop.is_some_and(|c| c.refusals > 0) || i.safety_refusal.is_some())
            .count();
        let verdict = match (open_rate, closed_rate, open.mean, closed.mean) {
            (Some(a), Some(b), Some(x), Some(y)) => {
                if (a - b).abs() <= SUCCESS_POINTS && (x - y).abs() <= MEAN_TAKEOVERS {
                    "like open loop"
                } else {
                    "differs"
                }
            }
            _ => "-",
        };
        let pct = |r: Option<f64>| r.map_or_else(|| "-".to_owned(), |r| format!("{r:.1} %"));
        let num = |m: Option<f64>| m.map_or_else(|| "-".to_owned(), |m| format!("{m:.2}"));
        let refused = if open.refused + closed.refused > 0 {
            format!(" ({} / {} refused)", open.refused, closed.refused)
        } else {
            String::new()
        };
        let _ = writeln!(
            out,
            "| `{}` | {user} | {}{refused} | {} / {} | {} / {} | {} / {} | {} / {} | {} | {} | {} | {} | {verdict} |",
            method.name(),
            pairs.len(),
            pct(open_rate),
            pct(closed_rate),
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
        );
    }
    let _ = writeln!(out);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::{Experiment, expand};
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

    #[test]
    fn closed_loop_runs_are_compared_with_the_same_cells_in_open_loop() {
        let users = ["deterministic".to_owned(), "spread".to_owned()];
        let methods = [Method::Paper, Method::Palc];
        let mut out = String::new();
        section(&mut out, &rows(2), &methods, &users);
        assert!(out.contains("## Closed-loop execution"), "{out}");
        // One line per method, for the deterministic users only.
        assert_eq!(out.matches("| deterministic |").count(), 2, "{out}");
        assert!(!out.contains("| spread |"), "{out}");
        assert_eq!(out.matches("like open loop").count(), 2, "{out}");
        assert!(out.contains("100.0 % / 100.0 %"), "{out}");

        let mut out = String::new();
        section(&mut out, &rows(3), &methods, &users);
        assert!(out.contains("2.00 / 3.00"), "{out}");
        assert_eq!(out.matches("| differs |").count(), 2, "{out}");

        // Without closed-loop runs there is no section.
        let open: Vec<RunRow> = (rows(2).into_iter())
            .filter(|r| r.spec.experiment != Experiment::ClosedLoop)
            .collect();
        let mut out = String::new();
        section(&mut out, &open, &methods, &users);
        assert!(out.is_empty());
    }
}
