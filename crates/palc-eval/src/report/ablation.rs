//! REPORT.md's ablation section: the ladder from `paper` to `palc`
//! ([`crate::ablation`]), one row per rung and user kind, with success rate and
//! mean takeovers from scratch and with the experience of another scene. The
//! first user kind's ladder is in the text, every kind's in [`FILE`].

use std::fmt::{self, Write as _};

use palc_harness::Method;

use crate::ablation::Rung;
use crate::claims::num;
use crate::plan::Experiment;
use crate::results::RunRow;
use crate::stats::{self, Summary};

use super::section::{Out, Results, Section, fill, header};

/// The CSV file of every user kind's ladder.
pub const FILE: &str = "ablation.csv";
const COLUMNS: &[&str] = &[
    "user_kind",
    "rung",
    "change",
    "labels",
    "personalized",
    "mean_takeovers",
    "max_takeovers",
    "with_experience_scratch_to_with",
    "change_with_experience",
    "after_learning_frozen",
];

/// The text's columns: [`COLUMNS`] after the user kind.
const HEADER: &[&str] = &[
    "rung",
    "change",
    "labels",
    "personalized",
    "mean takeovers",
    "max takeovers",
    "with experience: from scratch -> with",
    "change with experience",
    "after learning, frozen (users with spread)",
];

/// The ablation section.
pub struct Ablation;

impl Section for Ablation {
    fn title(&self) -> &'static str {
        "From `paper` to `palc`, one change at a time"
    }

    fn applies(&self, results: &Results) -> bool {
        results.index.has(Experiment::Ablation) || results.index.has(Experiment::AblationTransfer)
    }

    fn render(&self, results: &Results, out: &mut Out) -> fmt::Result {
        let (rungs, users) = results.input.ablation;
        let Some(first) = users.first() else {
            return Ok(());
        };
        let text = fill(
            include_str!("templates/ablation.md"),
            &[("first", first.clone()), ("file", FILE.to_owned())],
        );
        writeln!(out, "{text}\n")?;
        for user in users {
            let lines: Vec<Vec<String>> =
                rungs.iter().map(|r| ladder_row(results, user, r)).collect();
            if user == first {
                header(out, HEADER)?;
                for line in &lines {
                    writeln!(out, "| {} |", line.join(" | "))?;
                }
                writeln!(out)?;
            }
            let table = out.table(FILE, COLUMNS);
            for line in lines {
                let mut record = vec![user.clone()];
                record.extend(line);
                table.rows.push(record);
            }
        }
        Ok(())
    }
}

/// One rung's cells for `user`: every column of [`COLUMNS`] after the user kind.
fn ladder_row(results: &Results, user: &str, rung: &Rung) -> Vec<String> {
    let of_rung: Vec<&RunRow> = [Experiment::Ablation, Experiment::AblationTransfer]
        .into_iter()
        .flat_map(|e| {
            [Method::Paper, Method::Palc]
                .into_iter()
                .flat_map(move |m| results.index.runs(e, m, user).iter().copied())
        })
        .filter(|r| r.spec.rung.as_ref() == Some(&rung.name))
        .collect();
    let mut of_rung = of_rung;
    of_rung.sort_by_key(|r| r.spec.id);
    let from_scratch: Vec<&RunRow> = (of_rung.iter().copied())
        .filter(|r| r.spec.experiment == Experiment::Ablation)
        .collect();
    let scratch = Summary::of(from_scratch.iter().copied());
    let frozen = stats::frozen(&from_scratch).map_or("-".to_owned(), |f| f.describe());
    let transfer =
        stats::transfer_between(&of_rung, Experiment::Ablation, Experiment::AblationTransfer);
    let name = match [Method::Paper, Method::Palc]
        .into_iter()
        .find(|&m| rung.is_method(m))
    {
        Some(method) => format!("{} (= `{}`)", rung.name, method.name()),
        None => rung.name.clone(),
    };
    vec![
        name,
        rung.change.clone(),
        format!("`{}`", rung.labels.name()),
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
        (transfer.reduction).map_or("-".to_owned(), |r| format!("{:+.0} %", -100.0 * r)),
        frozen,
    ]
}
