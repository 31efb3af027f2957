//! REPORT.md's "Recorded drivers": for each recorded user kind, how many of its
//! file's lane changes became drivers, why the others did not, how far the
//! recorded traces are from the shapes the drivers drive, and why runs were refused.
//! Success, takeovers, transfer and accumulation are in the user-family and
//! transfer tables, next to the simulated families.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use crate::recorded_drivers::RecordedDrivers;
use crate::results::RunRow;

/// Writes the section; nothing without recorded kinds.
pub fn section(out: &mut String, recorded: &[RecordedDrivers], rows: &[RunRow]) {
    if recorded.is_empty() {
        return;
    }
    let _ = writeln!(out, "## Recorded drivers\n");
    let _ = writeln!(
        out,
        "Each lane change of an imported file (`palc import commonroad`) is a driver with its own \
         lateral shape (the trace smoothed within {:.2} m of noise by palc-user's recorded profile), \
         duration and start headway (`recorded_drivers` states the assumptions). A lane change is \
         refused as a driver when its lane ended (a merge), when no vehicle was ahead or its headway \
         was not positive (nothing to start on), or when its trace is not a monotone lane change \
         within the noise. The drivers' runs are in the user-family and transfer tables under the \
         kind's name.\n",
        crate::recorded_drivers::NOISE_M,
    );
    let _ = writeln!(
        out,
        "| kind | file | lane changes | cut by the recording (not imported) | drivers | refused as drivers | trace to shape, RMS (m): median / max | runs refused, by kind |"
    );
    let _ = writeln!(out, "| --- | --- | --- | --- | --- | --- | --- | --- |");
    for kind in recorded {
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
        for row in rows.iter().filter(|r| r.spec.user.name == kind.kind) {
            if let Some(refusal) = row.status.refusal_kind() {
                *run_refusals.entry(refusal).or_default() += 1;
            }
        }
        let _ = writeln!(
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
        );
    }
    let refused: Vec<_> = recorded.iter().flat_map(|k| &k.refused).collect();
    if !refused.is_empty() {
        let _ = writeln!(out, "\nLane changes refused as drivers:\n");
        for refused in refused {
            let _ = writeln!(
                out,
                "- `{}` ({}): {}",
                refused.id, refused.kind, refused.detail
            );
        }
    }
    let _ = writeln!(out);
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
