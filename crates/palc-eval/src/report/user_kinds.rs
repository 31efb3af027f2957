//! REPORT.md's section per paper user kind: each claim of the paper measured on
//! the kind's grid runs of each method, with a verdict; for users with spread,
//! the takeover rate against the ceiling and palc's target after learning. The
//! tables by style, speed case and headway go to [`FILE`].

use std::fmt::{self, Write as _};

use crate::claims::{num, pct};
use crate::results::RunRow;
use crate::stats::{self, Summary};
use crate::targets::{Measured, TargetId, Verdict, target};
use crate::views::speed_label;

use super::section::{Out, Results, Section, fill};

/// The CSV file of the sensitivity tables.
pub const FILE: &str = "sensitivity.csv";
const COLUMNS: &[&str] = &[
    "user",
    "method",
    "by",
    "value",
    "mean_takeovers",
    "personalized",
    "runs",
];

/// The paper's user kinds, one subsection each.
pub struct UserKinds;

impl Section for UserKinds {
    fn title(&self) -> &'static str {
        "The paper's user kinds"
    }

    fn applies(&self, results: &Results) -> bool {
        !results.input.users.is_empty()
    }

    fn render(&self, results: &Results, out: &mut Out) -> fmt::Result {
        writeln!(
            out,
            "The tables by style, speed case and adjacent headway (mean takeovers, personalized of \
             counted runs) are in `{FILE}`.\n"
        )?;
        for user in results.input.users {
            user_kind(results, user, out)?;
        }
        Ok(())
    }
}

fn user_kind(results: &Results, user: &str, out: &mut Out) -> fmt::Result {
    let methods = results.methods();
    let grids: Vec<&[&RunRow]> = (methods.iter())
        .map(|&m| results.index.grid(m, user))
        .collect();
    let cells = grids.first().map_or(0, |g| {
        let summary = Summary::of(g.iter().copied());
        summary.runs + summary.refused
    });
    let spread = (grids.iter().flat_map(|g| g.iter())).find_map(|r| r.spec.user.spread_relative);
    writeln!(out, "### {user} users\n")?;
    let who = match spread {
        Some(spread) => fill(
            include_str!("templates/spread-user.md"),
            &[("spread", format!("{:.0}", spread * 100.0))],
        ),
        None => "Deterministic users are the paper's set-up.".to_owned(),
    };
    writeln!(out, "{cells} grid runs per method. {who}\n")?;
    let first = results.input.users.first().is_some_and(|u| u == user);
    if first && spread.is_none() {
        writeln!(
            out,
            "The paper's claims on these users are the report's first table.\n"
        )?;
    } else {
        claims_table(results, user, &grids, spread.is_some(), out)?;
    }
    sensitivity(results, user, &grids, out);
    let rarely: Vec<String> = (methods.iter().zip(&grids))
        .map(|(m, g)| (m, Summary::of(g.iter().copied())))
        .filter(|(_, s)| s.success_rate().is_some_and(|r| r < 0.5))
        .map(|(m, s)| {
            format!(
                "`{}` personalized {}/{} runs",
                m.name(),
                s.personalized,
                s.runs
            )
        })
        .collect();
    if !rarely.is_empty() {
        let text = fill(
            include_str!("templates/rarely.md"),
            &[("which", rarely.join(", "))],
        );
        writeln!(out, "{text}\n")?;
    }
    Ok(())
}

/// The claims measured on `user`'s runs of each method, with a verdict each;
/// for users with spread (`spread`), the ceiling lines after them.
fn claims_table(
    results: &Results,
    user: &str,
    grids: &[&[&RunRow]],
    spread: bool,
    out: &mut Out,
) -> fmt::Result {
    let methods = results.methods();
    let header: Vec<String> = (methods.iter())
        .map(|m| format!("`{}` method", m.name()))
        .collect();
    writeln!(
        out,
        "| metric | paper's claim | {} | verdict |",
        header.join(" | ")
    )?;
    writeln!(out, "| --- | --- |{} --- |", " --- |".repeat(methods.len()))?;
    super::claims::rows(results, user, out)?;
    if spread {
        ceiling_lines(results, grids, out)?;
    }
    writeln!(out)
}

/// Users with spread: the final takeover rate against the ceiling (the rate of
/// the user's own nominal plan on the same draws), and palc's target after
/// learning.
fn ceiling_lines(results: &Results, grids: &[&[&RunRow]], out: &mut Out) -> fmt::Result {
    let methods = results.methods();
    let cells: Vec<String> = (grids.iter())
        .map(|grid| {
            let (rate, ceiling) = stats::final_rates(grid);
            format!("{} vs ceiling {}", pct(rate), pct(ceiling))
        })
        .collect();
    let measured: Vec<String> = methods
        .iter()
        .map(|m| format!("{}: measured", m.name()))
        .collect();
    writeln!(
        out,
        "| final takeover rate vs the nominal plan's | (not in the paper) | {} | {} |",
        cells.join(" | "),
        measured.join("; ")
    )?;
    let phases: Vec<Option<stats::Frozen>> = grids.iter().map(|g| stats::frozen(g)).collect();
    if phases.iter().all(Option::is_none) {
        return Ok(());
    }
    let spread = target(TargetId::SpreadAfterLearning);
    let cells: Vec<String> = (phases.iter())
        .map(|f| f.map_or("n/a".to_owned(), |f| f.describe()))
        .collect();
    let verdicts: Vec<String> = (methods.iter().zip(&phases))
        .map(|(m, f)| {
            let verdict = f.map_or(Verdict::NotMeasured, |f| {
                spread.verdict(&Measured::Share {
                    hits: f.within_margin,
                    runs: f.runs,
                })
            });
            format!("{}: {verdict}", m.name())
        })
        .collect();
    writeln!(
        out,
        "| after learning, frozen: takeover rate vs the nominal plan's, users within {:.0} points | \
         (palc's target: {}) | {} | {} |",
        100.0 * stats::FROZEN_MARGIN,
        spread.rule.describe(),
        cells.join(" | "),
        verdicts.join("; ")
    )?;
    Ok(())
}

/// What a sensitivity table groups the runs by.
type Key<'a> = &'a dyn Fn(&RunRow) -> String;

/// The tables by style, speed case and headway, into [`FILE`].
fn sensitivity(results: &Results, user: &str, grids: &[&[&RunRow]], out: &mut Out) {
    let style = |r: &RunRow| r.spec.style_name().to_owned();
    let headway = |r: &RunRow| format!("{}", r.spec.headway_m);
    let keys: [(&str, Key); 3] = [
        ("style", &style),
        ("speed case", &speed_label),
        ("headway (m)", &headway),
    ];
    let table = out.table(FILE, COLUMNS);
    for (by, key) in keys {
        for (method, grid) in results.methods().iter().zip(grids) {
            for (value, s) in stats::by(grid, key) {
                table.rows.push(vec![
                    user.to_owned(),
                    method.name().to_owned(),
                    by.to_owned(),
                    value,
                    num(s.mean, 2),
                    s.personalized.to_string(),
                    s.runs.to_string(),
                ]);
            }
        }
    }
}
