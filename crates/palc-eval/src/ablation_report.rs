//! REPORT.md's ablation section: the ladder from `paper` to `palc`
//! ([`crate::ablation`]), one row per rung and user kind, with success rate and
//! mean takeovers from scratch and with the experience of another scene.

use std::fmt::Write as _;

use crate::ablation::Rung;
use crate::claims::num;
use crate::plan::Experiment;
use crate::results::RunRow;
use crate::stats::{self, Summary};

/// Writes the section; nothing without ablation runs.
pub fn section(out: &mut String, rows: &[RunRow], rungs: &[Rung], users: &[String]) {
    let ablation: Vec<&RunRow> = (rows.iter())
        .filter(|r| {
            matches!(
                r.spec.experiment,
                Experiment::Ablation | Experiment::AblationTransfer
            )
        })
        .collect();
    if ablation.is_empty() {
        return;
    }
    let _ = writeln!(out, "## From `paper` to `palc`, one change at a time\n");
    let _ = writeln!(
        out,
        "Each rung is the rung above it with one change (`[ablation]` in the evaluation config); \
         every rung runs every grid cell of the user kind from scratch, and again with the \
         experience the same rung learned in the cell's other scene (`[transfer] source`). Mean \
         takeovers count failures at the cap. *With experience* pairs each cell with its run from \
         scratch where both were counted; the change is `with / from scratch - 1`.\n"
    );
    for user in users {
        let _ = writeln!(out, "**{user} users**\n");
        let _ = writeln!(
            out,
            "| rung | change | labels | personalized | mean takeovers | max takeovers | \
             with experience: from scratch -> with | change with experience | \
             after learning, frozen (users with spread) |"
        );
        let _ = writeln!(
            out,
            "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"
        );
        for rung in rungs {
            let of_rung: Vec<&RunRow> = (ablation.iter().copied())
                .filter(|r| r.spec.user.name == *user && r.spec.rung.as_ref() == Some(&rung.name))
                .collect();
            let from_scratch: Vec<&RunRow> = (of_rung.iter().copied())
                .filter(|r| r.spec.experiment == Experiment::Ablation)
                .collect();
            let scratch = Summary::of(from_scratch.iter().copied());
            let frozen = stats::frozen(&from_scratch).map_or("-".to_owned(), |f| f.describe());
            let transfer = stats::transfer_between(
                &of_rung,
                Experiment::Ablation,
                Experiment::AblationTransfer,
            );
            let name = match [palc_harness::Method::Paper, palc_harness::Method::Palc]
                .into_iter()
                .find(|&m| rung.is_method(m))
            {
                Some(method) => format!("{} (= `{}`)", rung.name, method.name()),
                None => rung.name.clone(),
            };
            let _ = writeln!(
                out,
                "| {name} | {} | `{}` | {} | {} | {} | {} | {} | {frozen} |",
                rung.change,
                rung.labels.name(),
                match scratch.success_rate() {
                    Some(rate) => format!(
                        "{:.0} % ({}/{})",
                        100.0 * rate,
                        scratch.personalized,
                        scratch.runs
                    ),
                    None => "n/a".to_owned(),
                },
                num(scratch.mean, 2),
                scratch.max.map_or("n/a".to_owned(), |m| m.to_string()),
                if transfer.pairs == 0 {
                    "-".to_owned()
                } else {
                    format!(
                        "{} -> {} ({} cells)",
                        num(transfer.without, 2),
                        num(transfer.with, 2),
                        transfer.pairs
                    )
                },
                transfer
                    .reduction
                    .map_or("-".to_owned(), |r| format!("{:+.0} %", -100.0 * r)),
            );
        }
        let _ = writeln!(out);
    }
}
