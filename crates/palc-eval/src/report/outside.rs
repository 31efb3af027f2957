//! REPORT.md's "Drivers outside the model": for every user kind, what palc
//! achieved (from scratch, with experience from another scene, after
//! accumulation, over a drive) beside what the driver estimate believed when
//! the kind's experience was carried into a new scene: how often it found no
//! start model that explains every scene the driver was seen in (a misfit,
//! `palc_harness::driver::DriverEstimate::outside_model`) and the cue it most
//! often put the decision on. Recorded and out-of-class kinds
//! ([`UserKind::is_out_of_class`]) stand in the text beside the paper's
//! deterministic users; every kind is in [`FILE`].

use std::collections::BTreeMap;
use std::fmt::{self, Write as _};

use palc_harness::Method;

use super::section::{Results, Section, fill, header, state_targets};
use crate::claims::{num, pct};
use crate::config::UserKind;
use crate::drive_report::{self, KindDrives};
use crate::plan::Experiment;
use crate::results::RunRow;
use crate::stats::{self, Summary};
use crate::targets::TargetId;

/// The drive's band the table shows (lane changes, counted from 1).
const DRIVE_BAND: (usize, usize) = (11, 50);

/// The CSV file of the table, every user kind.
pub const FILE: &str = "outside-the-model.csv";
const COLUMNS: &[&str] = &[
    "method",
    "user_kind",
    "class",
    "from_scratch_personalized_mean_takeovers",
    "transfer_scratch_to_with_experience",
    "accumulation_scratch_to_with_experience",
    "drive_lane_changes_11_50_taken_over",
    "carries_judged",
    "outside_the_model",
    "cue_most_often_believed",
];
/// The text table's columns but the drive's band (inserted at 6).
const TEXT_COLUMNS: &[&str] = &[
    "method",
    "user",
    "class",
    "from scratch: personalized, mean takeovers",
    "experience from another scene: scratch -> with",
    "after accumulation: scratch -> with",
    "carries the estimate judged",
    "outside the model",
    "cue most often believed",
];

/// The drivers-outside-the-model section.
pub struct Outside;

impl Section for Outside {
    fn title(&self) -> &'static str {
        "Drivers outside the model"
    }

    fn applies(&self, results: &Results) -> bool {
        (results.input.rows.iter()).any(|r| r.driver_belief.is_some())
    }

    fn render(&self, results: &Results, out: &mut super::Out) -> fmt::Result {
        let text = fill(
            include_str!("templates/outside.md"),
            &[
                (
                    "misfit",
                    format!(
                        "{:.1}",
                        palc_harness::driver::prior::MISFIT_SDS
                            * palc_harness::driver::prior::OBSERVATION_SD_S
                    ),
                ),
                ("first", DRIVE_BAND.0.to_string()),
                ("last", DRIVE_BAND.1.to_string()),
                ("file", FILE.to_owned()),
            ],
        );
        writeln!(out, "{text}\n")?;
        let band = format!("drive, lane changes {}-{}", DRIVE_BAND.0, DRIVE_BAND.1);
        let mut columns = TEXT_COLUMNS.to_vec();
        columns.insert(6, &band);
        header(out, &columns)?;
        let drives = drive_report::drives(results.input.rows, results.methods(), Experiment::Drive);
        for &method in results.methods() {
            for kind in results.input.user_kinds {
                let beliefs = Beliefs::of(results, method, &kind.name);
                if beliefs.judged == 0 {
                    continue;
                }
                let drive = (drives.iter()).find(|d| d.method == method && d.user == kind.name);
                let line = vec![
                    method.name().to_owned(),
                    kind.name.clone(),
                    class(kind).to_owned(),
                    from_scratch(results, method, &kind.name),
                    transfer(results, method, &kind.name, Experiment::Transfer),
                    transfer(results, method, &kind.name, Experiment::Accumulation),
                    drive.map_or_else(|| "-".to_owned(), drive_rate),
                    beliefs.judged.to_string(),
                    format!(
                        "{} ({})",
                        beliefs.outside,
                        pct(Some(beliefs.outside as f64 / beliefs.judged as f64))
                    ),
                    beliefs.most_often(),
                ];
                // In the text: the kinds outside palc's families, and the paper's
                // deterministic users for reference; every kind in the CSV file.
                if kind.is_out_of_class() || kind.name == UserKind::deterministic().name {
                    writeln!(out, "| {} |", line.join(" | "))?;
                }
                out.table(FILE, COLUMNS).rows.push(line);
            }
        }
        writeln!(out)?;
        // The goals for these drivers beyond the drive's (stated in its section).
        let ids = [
            TargetId::RecordedTransfer,
            TargetId::OutOfClassTransfer,
            TargetId::OutOfClassAccumulation,
        ];
        state_targets(out, results, &ids)?;
        writeln!(out)
    }
}

/// What the estimate believed over the runs of one method and user kind.
#[derive(Debug, Default, PartialEq)]
struct Beliefs {
    /// Runs whose carried experience the estimate judged.
    judged: usize,
    /// Of those, the runs it called outside the model.
    outside: usize,
    /// How often each cue had the largest posterior mass.
    cues: BTreeMap<&'static str, usize>,
}

impl Beliefs {
    fn of(results: &Results, method: Method, user: &str) -> Beliefs {
        let rows = (results.index.of_method(method).iter()).filter(|r| r.spec.user.name == user);
        Beliefs::from_rows(rows.copied())
    }

    fn from_rows<'a>(rows: impl Iterator<Item = &'a RunRow>) -> Beliefs {
        let mut beliefs = Beliefs::default();
        for belief in rows.filter_map(|r| r.driver_belief) {
            beliefs.judged += 1;
            beliefs.outside += usize::from(belief.outside_model);
            *beliefs.cues.entry(belief.cue.name()).or_default() += 1;
        }
        beliefs
    }

    /// The cue most often believed, with its share; the first name among equals.
    fn most_often(&self) -> String {
        let best =
            (self.cues.iter()).fold(None, |best: Option<(&str, usize)>, (&cue, &n)| match best {
                Some((_, m)) if m >= n => best,
                _ => Some((cue, n)),
            });
        match best {
            Some((cue, n)) => format!("{cue} ({})", pct(Some(n as f64 / self.judged as f64))),
            None => "-".to_owned(),
        }
    }
}

/// Whose decision model the kind follows.
fn class(kind: &UserKind) -> &'static str {
    if kind.recorded.is_some() {
        "recorded"
    } else if kind.is_out_of_class() {
        "outside the one-cue rules"
    } else {
        "palc's families"
    }
}

fn from_scratch(results: &Results, method: Method, user: &str) -> String {
    let summary = Summary::of(results.index.grid(method, user).iter().copied());
    format!("{}, {}", pct(summary.success_rate()), num(summary.mean, 2))
}

/// Mean takeovers of `experiment`'s runs beside the same cells' grid runs.
fn transfer(results: &Results, method: Method, user: &str, experiment: Experiment) -> String {
    let rows: Vec<&RunRow> = (results.index.grid(method, user).iter())
        .chain(results.index.runs(experiment, method, user))
        .copied()
        .collect();
    let measured = stats::transfer_between(&rows, Experiment::Grid, experiment);
    if measured.pairs == 0 {
        return "-".to_owned();
    }
    format!(
        "{} -> {} ({} cells)",
        num(measured.without, 2),
        num(measured.with, 2),
        measured.pairs
    )
}

fn drive_rate(drive: &KindDrives) -> String {
    let (taken, driven) = drive.band(DRIVE_BAND);
    if driven == 0 {
        return "-".to_owned();
    }
    format!("{} of {driven}", pct(Some(taken as f64 / driven as f64)))
}

#[cfg(test)]
mod tests {
    use palc_harness::driver::CarriedBelief;
    use palc_harness::driver::prior::Cue;

    use super::*;
    use crate::runner::tests::synthetic_rows;

    fn belief(cue: Cue, outside_model: bool) -> Option<CarriedBelief> {
        Some(CarriedBelief {
            scenes: 2,
            cue,
            cue_mass: 0.9,
            outside_model,
        })
    }

    #[test]
    fn beliefs_count_the_judged_runs_their_misfits_and_the_cue_most_often_believed() {
        let mut rows = synthetic_rows();
        assert!(rows.len() >= 5);
        rows[0].driver_belief = belief(Cue::TimeHeadway, false);
        rows[1].driver_belief = belief(Cue::TimeToCollision, true);
        rows[2].driver_belief = belief(Cue::TimeToCollision, true);
        rows[3].driver_belief = belief(Cue::Incentive, false);
        let beliefs = Beliefs::from_rows(rows.iter());
        assert_eq!(beliefs.judged, 4);
        assert_eq!(beliefs.outside, 2);
        assert_eq!(beliefs.most_often(), "time-to-collision (50 %)");
        // Runs without a judged carry count for nothing.
        assert_eq!(Beliefs::from_rows(rows[4..].iter()), Beliefs::default());
        assert_eq!(Beliefs::default().most_often(), "-");
    }

    #[test]
    fn the_first_cue_in_name_order_wins_a_tie() {
        let mut rows = synthetic_rows();
        rows[0].driver_belief = belief(Cue::TimeToCollision, false);
        rows[1].driver_belief = belief(Cue::Incentive, false);
        let beliefs = Beliefs::from_rows(rows.iter());
        assert_eq!(beliefs.most_often(), "incentive (50 %)");
    }
}
