//! REPORT.md's "Recorded drivers": for each recorded user kind, how many of its
//! file's lane changes became drivers, why the others did not (each one in
//! [`FILE`]), how far the recorded traces are from the shapes the drivers drive,
//! and why runs were refused. Success, takeovers, transfer and accumulation are
//! in the user-family and transfer tables, next to the simulated families.

use std::collections::BTreeMap;
use std::fmt::{self, Write as _};

use super::section::{Out, Results, Section, fill, header};

/// The CSV file of the lane changes refused as drivers.
pub const FILE: &str = "recorded-refused.csv";
const COLUMNS: &[&str] = &["user_kind", "lane_change", "kind", "detail"];

/// The recorded-drivers section.
pub struct Recorded;

impl Section for Recorded {
    fn title(&self) -> &'static str {
        "Recorded drivers"
    }

    fn applies(&self, results: &Results) -> bool {
        !results.input.recorded.is_empty()
    }

    fn render(&self, results: &Results, out: &mut Out) -> fmt::Result {
        let text = fill(
            include_str!("templates/recorded.md"),
            &[
                ("noise", format!("{:.2}", crate::recorded_drivers::NOISE_M)),
                ("file", FILE.to_owned()),
            ],
        );
        writeln!(out, "{text}\n")?;
        header(
            out,
            &[
                "kind",
                "file",
                "lane changes",
                "cut by the recording (not imported)",
                "drivers",
                "refused as drivers",
                "trace to shape, RMS (m): median / max",
                "runs refused, by kind",
            ],
        )?;
        for kind in results.input.recorded {
            let mut reasons: BTreeMap<&str, usize> = BTreeMap::new();
            for refused in &kind.refused {
                *reasons.entry(refused.kind).or_default() += 1;
            }
            let mut residuals: Vec<f64> = kind.accepted.iter().map(|d| d.rms_residual_m).collect();
            residuals.sort_by(f64::total_cmp);
            let residual = match (residuals.get(residuals.len() / 2), residuals.last()) {
                (Some(median), Some(max)) => format!("{median:.3} / {max:.3}"),
                _ => "-".to_owned(),
            };
            let mut run_refusals: BTreeMap<String, usize> = BTreeMap::new();
            for row in results
                .input
                .rows
                .iter()
                .filter(|r| r.spec.user.name == kind.kind)
            {
                if let Some(refusal) = row.status.refusal_kind() {
                    *run_refusals.entry(refusal).or_default() += 1;
                }
            }
            writeln!(
                out,
                "| {} | `{}` | {} | {} | {} | {} | {} | {} |",
                kind.kind,
                kind.file.display(),
                kind.lane_changes,
                kind.cut_by_recording,
                kind.accepted.len(),
                counts(reasons.iter().map(|(k, n)| (k.to_string(), *n))),
                residual,
                counts(run_refusals.into_iter()),
            )?;
            let table = out.table(FILE, COLUMNS);
            for refused in &kind.refused {
                table.rows.push(vec![
                    kind.kind.clone(),
                    refused.id.clone(),
                    refused.kind.to_owned(),
                    refused.detail.clone(),
                ]);
            }
        }
        writeln!(out)
    }
}

/// `kind n, kind n`, or `none`.
fn counts(counts: impl Iterator<Item = (String, usize)>) -> String {
    let parts: Vec<String> = counts.map(|(kind, n)| format!("{kind} {n}")).collect();
    if parts.is_empty() {
        "none".to_owned()
    } else {
        parts.join(", ")
    }
}
