//! The paper's claims in the report: each claim measured on one user kind's
//! runs of each method ([`measure`]), and the section that says how each claim
//! and each of palc's targets is measured and judged.

use std::fmt::{self, Write as _};

use crate::claims::{CLAIMS, Claim, Measured, Runs};
use crate::targets::TARGETS;

use super::section::{Out, Results, Section, header};

/// Each claim shown for `user`, with its measurement for each method in report
/// order; the transfer claim only when some transfer run was paired.
pub fn measure(results: &Results, user: &str) -> Vec<(&'static Claim, Vec<Measured>)> {
    let index = &results.index;
    let methods = results.methods();
    let transfers: Vec<Vec<_>> = (methods.iter())
        .map(|&m| index.with_transfer(m, user))
        .collect();
    CLAIMS
        .iter()
        .map(|claim| {
            let measured: Vec<Measured> = (methods.iter().zip(&transfers))
                .map(|(&method, with_transfer)| {
                    claim.metric.measure(Runs {
                        grid: index.grid(method, user),
                        with_transfer,
                    })
                })
                .collect();
            (claim, measured)
        })
        .filter(|(claim, measured)| claim.shown(measured))
        .collect()
}

/// One table row per claim shown for `user`: name, the paper's value, each
/// method's measurement and the verdicts.
pub fn rows(results: &Results, user: &str, out: &mut Out) -> fmt::Result {
    let cap = results.cap().to_string();
    for (claim, measured) in measure(results, user) {
        let cells: Vec<String> = measured.iter().map(|m| claim.cell(m)).collect();
        writeln!(
            out,
            "| {} | {} | {} | {} |",
            claim.name.replace("{cap}", &cap),
            claim.claimed,
            cells.join(" | "),
            verdicts(results, claim, &measured)
        )?;
    }
    Ok(())
}

/// The verdicts of one claim, `method: verdict` for each method.
fn verdicts(results: &Results, claim: &Claim, measured: &[Measured]) -> String {
    let verdicts: Vec<String> = (results.methods().iter().zip(measured))
        .map(|(method, m)| format!("{}: {}", method.name(), claim.verdict(m)))
        .collect();
    verdicts.join("; ")
}

/// How each claim and each target is measured and judged.
pub struct HowMeasured;

impl Section for HowMeasured {
    fn title(&self) -> &'static str {
        "How each claim and target is measured"
    }

    fn render(&self, _results: &Results, out: &mut Out) -> fmt::Result {
        header(
            out,
            &["metric", "paper's claim", "how palc measures it", "rule"],
        )?;
        for claim in CLAIMS {
            writeln!(
                out,
                "| {} | {} | {} | {} |",
                claim.name.replace(" (failures at {cap})", ""),
                claim.claimed,
                claim.how,
                claim.rule.describe()
            )?;
        }
        writeln!(out)?;
        header(
            out,
            &[
                "palc's target",
                "rule",
                "how palc measures it",
                "set and measured in",
            ],
        )?;
        for target in TARGETS {
            writeln!(
                out,
                "| {} | {} | {} | {} |",
                target.name,
                target.rule.describe(),
                target.how,
                target.source
            )?;
        }
        writeln!(out)
    }
}
