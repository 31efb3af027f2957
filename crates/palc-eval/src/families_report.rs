//! REPORT.md's user-family section: every user kind of `[[users]]` on the grid,
//! both methods, one row each (docs/paper-mapping.md, "User families").

use std::fmt::Write as _;

use palc_harness::Method;

use crate::claims::{num, pct};
use crate::config::UserKind;
use crate::results::RunRow;
use crate::stats::{self, Summary};
use crate::views::{grid, with_transfer};

/// Share of counted runs that must personalize for a family to count as learned.
pub const FAMILY_SUCCESS_TARGET: f64 = 0.95;

/// How a kind's users are built, for the table: its family's rules and its spread.
fn rules(kind: &UserKind) -> String {
    let mut parts = vec![kind.family.clone().unwrap_or_default().describe()];
    if let Some(relative) = kind.spread_relative {
        parts.push(format!("±{:.0} % headway and duration", relative * 100.0));
    }
    if kind.spread_parameters.is_some() {
        parts.push("spread on further parameters".to_owned());
    }
    parts.join("; ")
}

/// Writes the section; nothing when `kinds` is empty.
pub fn section(out: &mut String, all: &[RunRow], methods: &[Method], kinds: &[UserKind]) {
    if kinds.is_empty() {
        return;
    }
    let _ = writeln!(out, "## User families\n");
    let _ = writeln!(
        out,
        "Every user kind of the config's `[[users]]`, each run on every grid cell and style. A family \
         refines each of the paper's styles (start rule, reaction, lateral profile, speed, \
         perceived-safety takeover; docs/paper-mapping.md, \"User families\"). Both methods run with \
         one set of settings for every kind: nothing in `palc` is tuned per family. A kind counts as \
         learned when at least {:.0} % of its counted runs personalize; refused runs (a user without \
         a sane lane change in the scene, named in the refusals section) are not counted. For users \
         with spread, the takeover rate is shown against the ceiling (the rate of the user's own \
         nominal lane change on the same draws): in the evaluation phase after learning (`frozen`: \
         `loop.frozen_lane_changes` further lane changes, learning frozen), with the number of runs \
         whose rate is within 3 points of the ceiling, or else over the last window. The transfer column pairs each \
         `[transfer]` run of the kind with the same cell learned from scratch: mean takeovers without \
         and with the experience of the other scene, and the reduction.\n",
        FAMILY_SUCCESS_TARGET * 100.0
    );
    let _ = writeln!(
        out,
        "| user kind | rules | method | runs | refused | personalized | mean takeovers | max takeovers | final max deviation (m) | final takeover rate vs ceiling | perceived-safety takeovers | transfer: scratch -> with experience | verdict |"
    );
    let _ = writeln!(
        out,
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
    );
    for kind in kinds {
        for &method in methods {
            let rows = grid(all, method, &kind.name);
            let summary = Summary::of(rows.iter().copied());
            let counted: Vec<&RunRow> = rows
                .iter()
                .copied()
                .filter(|r| r.status.counted())
                .collect();
            let deviations: Vec<f64> = counted
                .iter()
                .filter_map(|r| r.final_max_deviation_m)
                .collect();
            let deviation = (!deviations.is_empty())
                .then(|| deviations.iter().sum::<f64>() / deviations.len() as f64);
            let rates = if kind.has_spread() {
                match stats::frozen(&counted) {
                    Some(frozen) => format!("frozen: {}", frozen.describe()),
                    None => {
                        let (rate, ceiling) = stats::final_rates(&counted);
                        format!("{} vs {}", pct(rate), pct(ceiling))
                    }
                }
            } else {
                "-".to_owned()
            };
            let takeovers: usize = counted
                .iter()
                .flat_map(|r| &r.iterations)
                .filter(|i| i.takeover)
                .count();
            let perceived: usize = counted
                .iter()
                .flat_map(|r| &r.iterations)
                .filter(|i| i.perceived_safety_takeover)
                .count();
            let transfer = stats::transfer(&with_transfer(all, method, &kind.name));
            let transfer = if transfer.pairs == 0 {
                "-".to_owned()
            } else {
                format!(
                    "{} -> {} ({}, {} cells)",
                    num(transfer.without, 2),
                    num(transfer.with, 2),
                    transfer
                        .reduction
                        .map_or_else(|| "n/a".to_owned(), |r| format!("{:+.0} %", -100.0 * r)),
                    transfer.pairs
                )
            };
            let verdict = match summary.success_rate() {
                None => "no run counted".to_owned(),
                Some(rate) if rate >= FAMILY_SUCCESS_TARGET => "learned".to_owned(),
                Some(_) => format!(
                    "**not learned**: {} of {} runs fail",
                    summary.runs - summary.personalized,
                    summary.runs
                ),
            };
            let _ = writeln!(
                out,
                "| {} | {} | `{}` | {} | {} | {} | {} | {} | {} | {} | {perceived} of {takeovers} | {transfer} | {verdict} |",
                kind.name,
                rules(kind),
                method.name(),
                summary.runs,
                summary.refused,
                pct(summary.success_rate()),
                num(summary.mean, 1),
                summary
                    .max
                    .map_or_else(|| "n/a".to_owned(), |m| m.to_string()),
                num(deviation, 3),
                rates,
            );
        }
    }
    let _ = writeln!(out);
}
