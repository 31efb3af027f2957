//! REPORT.md's user-family section: every user kind of `[[users]]` on the grid,
//! both methods, one row each (docs/experiments/0036-user-families.md).

use std::fmt::Write as _;

use palc_harness::Method;

use crate::claims::{num, pct};
use crate::config::UserKind;
use crate::results::RunRow;
use crate::stats::{self, Summary};
use crate::views::{grid, with_transfer};

/// Share of counted runs that must personalize for a family to count as learned.
pub const FAMILY_SUCCESS_TARGET: f64 = 0.95;
/// palc's target for every family's transfer: at least this reduction of the mean
/// takeovers with the experience of another scene.
pub const FAMILY_TRANSFER_TARGET: f64 = 0.3;
/// palc's target for users with spread: the share of counted runs whose frozen
/// takeover rate is within the margin of the ceiling.
pub const SPREAD_WITHIN_MARGIN_TARGET: f64 = 0.95;

/// The parts of a kind's verdict after learned / not learned: palc's transfer
/// target, and for users with spread the target of the evaluation phase; empty
/// when both are met or not measured.
fn target_shortfalls(reduction: Option<f64>, frozen: Option<&stats::Frozen>) -> Vec<String> {
    let mut parts = Vec::new();
    if reduction.is_some_and(|r| r < FAMILY_TRANSFER_TARGET) {
        parts.push(format!(
            "transfer below the {:.0} % target",
            100.0 * FAMILY_TRANSFER_TARGET
        ));
    }
    if let Some(f) = frozen
        .filter(|f| (f.within_margin as f64) < SPREAD_WITHIN_MARGIN_TARGET * f.runs as f64 - 1e-9)
    {
        parts.push(format!(
            "{}/{} within {:.0} points after learning, below the {:.0} % target",
            f.within_margin,
            f.runs,
            100.0 * stats::FROZEN_MARGIN,
            100.0 * SPREAD_WITHIN_MARGIN_TARGET
        ));
    }
    parts
}

/// How a kind's users are built, for the table: its family's rules and its spread.
fn rules(kind: &UserKind) -> String {
    if let Some(file) = &kind.recorded {
        return format!(
            "recorded drivers of `{}`, each with its own shape, duration and start headway",
            file.display()
        );
    }
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
         perceived-safety takeover; docs/experiments/0036-user-families.md). Both methods run with \
         one set of settings for every kind: nothing in `palc` is tuned per family. A kind counts as \
         learned when at least {:.0} % of its counted runs personalize; refused runs (a user without \
         a sane lane change in the scene, named in the refusals section) are not counted. For users \
         with spread, the takeover rate is shown against the ceiling (the rate of the user's own \
         nominal lane change on the same draws): in the evaluation phase after learning (`frozen`: \
         `loop.frozen_lane_changes` further lane changes, learning frozen), with the number of runs \
         whose rate is within 3 points of the ceiling, or else over the last window. The transfer column pairs each \
         `[transfer]` run of the kind with the same cell learned from scratch: mean takeovers without \
         and with the experience of the other scene, and the reduction. The verdict also names \
         palc's targets a kind misses: a transfer of at least {:.0} % fewer takeovers, and for users \
         with spread at least {:.0} % of the runs within 3 points of the ceiling after learning.\n",
        FAMILY_SUCCESS_TARGET * 100.0,
        FAMILY_TRANSFER_TARGET * 100.0,
        SPREAD_WITHIN_MARGIN_TARGET * 100.0
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
            let frozen = kind.has_spread().then(|| stats::frozen(&counted)).flatten();
            let rates = if kind.has_spread() {
                match &frozen {
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
            let shortfalls = target_shortfalls(
                (transfer.pairs > 0).then_some(transfer.reduction).flatten(),
                frozen.as_ref(),
            );
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
            let mut verdict = match summary.success_rate() {
                None => "no run counted".to_owned(),
                Some(rate) if rate >= FAMILY_SUCCESS_TARGET => "learned".to_owned(),
                Some(_) => format!(
                    "**not learned**: {} of {} runs fail",
                    summary.runs - summary.personalized,
                    summary.runs
                ),
            };
            if !shortfalls.is_empty() {
                let _ = write!(verdict, "; **{}**", shortfalls.join("; "));
            }
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

#[cfg(test)]
mod tests {
    use super::*;

    fn frozen(within_margin: usize, runs: usize) -> stats::Frozen {
        stats::Frozen {
            runs,
            takeover_rate: 0.2,
            ceiling_rate: 0.2,
            within_margin,
        }
    }

    #[test]
    fn a_kind_names_each_target_it_misses() {
        assert!(target_shortfalls(Some(0.3), Some(&frozen(95, 100))).is_empty());
        assert!(target_shortfalls(None, None).is_empty());
        let short = target_shortfalls(Some(0.29), Some(&frozen(87, 93)));
        assert_eq!(
            short,
            [
                "transfer below the 30 % target",
                "87/93 within 3 points after learning, below the 95 % target"
            ]
        );
        // 89 of 93 is 95.7 %: met.
        assert_eq!(
            target_shortfalls(Some(0.5), Some(&frozen(89, 93))),
            Vec::<String>::new()
        );
    }
}
