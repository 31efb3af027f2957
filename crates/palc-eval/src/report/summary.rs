//! REPORT.md's summary: how many runs were counted, refused and failed, and per
//! user kind and method the grid's success, mean takeovers and the reduction
//! with experience from the next speed case.

use std::fmt::{self, Write as _};

use crate::claims::num;
use crate::results::Status;
use crate::stats::{self, Summary as Takeovers};

use super::section::{Out, Results, Section, header};

/// The summary section.
pub struct Summary;

impl Section for Summary {
    fn title(&self) -> &'static str {
        "Summary"
    }

    fn render(&self, results: &Results, out: &mut Out) -> fmt::Result {
        let rows = results.input.rows;
        let refused = rows.iter().filter(|r| !r.status.counted()).count();
        let failed = (rows.iter())
            .filter(|r| matches!(r.status, Status::Failed { .. }))
            .count();
        writeln!(
            out,
            "{} runs: {} counted, {refused} refused before running (their kinds in \"Refused scenarios \
             and failed runs\"), {failed} of the counted stopped on an error (counted at the cap). \
             The grid, per user kind and method (failures at the cap):\n",
            rows.len(),
            rows.len() - refused
        )?;
        header(
            out,
            &[
                "users",
                "method",
                "personalized",
                "mean takeovers",
                "with experience from the next speed case",
            ],
        )?;
        for user in results.input.users {
            for &method in results.methods() {
                let summary = Takeovers::of(results.index.grid(method, user).iter().copied());
                let transfer = stats::transfer(&results.index.with_transfer(method, user));
                writeln!(
                    out,
                    "| {user} | `{}` | {}/{} | {} | {} |",
                    method.name(),
                    summary.personalized,
                    summary.runs,
                    num(summary.mean, 1),
                    experience(&transfer)
                )?;
            }
        }
        writeln!(out)
    }
}

/// `without -> with (x % fewer, n cells)`, or `n/a`.
fn experience(transfer: &stats::Transfer) -> String {
    match (transfer.without, transfer.with, transfer.reduction) {
        (Some(without), Some(with), Some(reduction)) => {
            // `+ 0.0` turns a rounded -0 into 0.
            let percent = (reduction * 100.0).round() + 0.0;
            let change = if percent >= 0.0 {
                format!("{percent} % fewer")
            } else {
                format!("{} % more", -percent)
            };
            format!(
                "{} -> {} ({change}, {} cells)",
                num(Some(without), 1),
                num(Some(with), 1),
                transfer.pairs
            )
        }
        _ => "n/a".to_owned(),
    }
}
