//! REPORT.md's user-family section: every user kind of `[[users]]` on the grid,
//! both methods (docs/experiments/0036-user-families.md). The text states
//! palc's targets for the kinds; the table of every kind goes to [`FILE`].

use std::fmt::{self, Write as _};

use crate::claims::{num, pct};
use crate::config::UserKind;
use crate::results::RunRow;
use crate::stats::{self, Summary};
use crate::targets::TargetId;

use super::section::{Out, Results, Section, fill, state_targets};

/// The CSV file of the user-family table.
pub const FILE: &str = "families.csv";
const COLUMNS: &[&str] = &[
    "user_kind",
    "rules",
    "method",
    "runs",
    "refused",
    "personalized",
    "mean_takeovers",
    "max_takeovers",
    "final_max_deviation_m",
    "final_takeover_rate_vs_ceiling",
    "perceived_safety_takeovers",
    "takeovers",
    "transfer_scratch_to_with_experience",
];

/// The user-family section.
pub struct Families;

impl Section for Families {
    fn title(&self) -> &'static str {
        "User families"
    }

    fn applies(&self, results: &Results) -> bool {
        !results.input.user_kinds.is_empty()
    }

    fn render(&self, results: &Results, out: &mut Out) -> fmt::Result {
        let kinds = results.input.user_kinds;
        let text = fill(
            include_str!("templates/families.md"),
            &[("file", FILE.to_owned())],
        );
        writeln!(out, "{text}\n")?;
        let ids = [
            TargetId::KindsLearned,
            TargetId::KindTransfer,
            TargetId::SpreadAfterLearning,
        ];
        state_targets(out, results, &ids)?;
        writeln!(out)?;
        for kind in kinds {
            for &method in results.methods() {
                let line = row(results, kind, method);
                out.table(FILE, COLUMNS).rows.push(line);
            }
        }
        Ok(())
    }
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

/// The table's record of one kind and method.
fn row(results: &Results, kind: &UserKind, method: palc_harness::Method) -> Vec<String> {
    let rows = results.index.grid(method, &kind.name);
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
    let deviation =
        (!deviations.is_empty()).then(|| deviations.iter().sum::<f64>() / deviations.len() as f64);
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
    let iterations = || counted.iter().flat_map(|r| &r.iterations);
    let takeovers = iterations().filter(|i| i.takeover).count();
    let perceived = iterations().filter(|i| i.perceived_safety_takeover).count();
    let transfer = stats::transfer(&results.index.with_transfer(method, &kind.name));
    let transfer = if transfer.pairs == 0 {
        "-".to_owned()
    } else {
        format!(
            "{} -> {} ({}, {} cells)",
            num(transfer.without, 2),
            num(transfer.with, 2),
            (transfer.reduction)
                .map_or_else(|| "n/a".to_owned(), |r| format!("{:+.0} %", -100.0 * r)),
            transfer.pairs
        )
    };
    vec![
        kind.name.clone(),
        rules(kind),
        method.name().to_owned(),
        summary.runs.to_string(),
        summary.refused.to_string(),
        pct(summary.success_rate()),
        num(summary.mean, 1),
        summary
            .max
            .map_or_else(|| "n/a".to_owned(), |m| m.to_string()),
        num(deviation, 3),
        rates,
        perceived.to_string(),
        takeovers.to_string(),
        transfer,
    ]
}
