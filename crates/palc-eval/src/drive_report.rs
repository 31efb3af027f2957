//! The takeover rate over a drive's lane changes ([`crate::drive`]), per method
//! and user kind: the table of REPORT.md's "A drive of varied scenes" (written by
//! the report's drive section) and Fig. 16.
//!
//! A drive's lane changes are counted in driving order among the ones driven: a
//! scene refused for the user (its standard ALC never starts, its start rule is
//! met before the plan) is skipped, not counted. A lane change whose run failed
//! (its experience planned off the road, a solver error) counts as taken over:
//! the user would not have driven it.

use std::collections::BTreeMap;

use palc_harness::Method;

#[cfg(feature = "plot")]
use crate::figures::Lines;
use crate::plan::Experiment;
use crate::results::{RunRow, Status};

/// The bands of lane changes the report gives a takeover rate for (first and
/// last lane change, counted from 1 among the driven ones).
pub const BANDS: [(usize, usize); 3] = [(1, 10), (11, 50), (51, 100)];

/// The window of the figure's moving takeover rate (lane changes).
pub const WINDOW: usize = 10;

/// One drive: its lane changes in driving order, `true` where taken over (or failed).
type Drive = Vec<bool>;

/// The drives of one method and user kind.
#[derive(Debug, Clone, PartialEq)]
pub struct KindDrives {
    /// The method.
    pub method: Method,
    /// The user kind.
    pub user: String,
    /// One drive per style (a recorded kind: per driver), in plan order.
    pub drives: Vec<Drive>,
    /// Scenes of all these drives.
    pub scenes: usize,
    /// Scenes refused (skipped).
    pub refused: usize,
    /// Lane changes whose run failed (counted as taken over).
    pub failed: usize,
}

impl KindDrives {
    /// Lane changes driven.
    pub fn driven(&self) -> usize {
        self.drives.iter().map(Vec::len).sum()
    }

    /// Takeovers and lane changes driven in the band `(first, last)`, over every drive.
    pub fn band(&self, (first, last): (usize, usize)) -> (usize, usize) {
        (self.drives.iter()).fold((0, 0), |(taken, driven), drive| {
            let band = &drive[(first - 1).min(drive.len())..last.min(drive.len())];
            (
                taken + band.iter().filter(|&&t| t).count(),
                driven + band.len(),
            )
        })
    }

    /// The takeover rate over the last [`WINDOW`] lane changes at each lane change
    /// from the window's end on, over every drive that drove that far.
    pub fn moving_rate(&self) -> Vec<(f64, f64)> {
        let longest = self.drives.iter().map(Vec::len).max().unwrap_or(0);
        (WINDOW..=longest)
            .filter_map(|end| {
                let windows = (self.drives.iter()).filter(|d| d.len() >= end);
                let (taken, n) = windows.fold((0, 0), |(taken, n), d| {
                    let window = &d[end - WINDOW..end];
                    (taken + window.iter().filter(|&&t| t).count(), n + WINDOW)
                });
                (n > 0).then(|| (end as f64, taken as f64 / n as f64))
            })
            .collect()
    }
}

/// The drives of `rows` (`experiment`: the drives, or their scenes from scratch),
/// per method (in `methods` order) and user kind (in plan order).
pub fn drives(rows: &[RunRow], methods: &[Method], experiment: Experiment) -> Vec<KindDrives> {
    let mut out = Vec::new();
    for &method in methods {
        let of_method = rows
            .iter()
            .filter(|r| r.spec.experiment == experiment && r.spec.method == method);
        let mut users: Vec<&str> = Vec::new();
        let mut by_drive: BTreeMap<(&str, &str), Vec<&RunRow>> = BTreeMap::new();
        for row in of_method {
            let user = row.spec.user.name.as_str();
            if !users.contains(&user) {
                users.push(user);
            }
            let drive = by_drive.entry((user, row.spec.style_name())).or_default();
            drive.push(row);
        }
        for user in users {
            let mut kind = KindDrives {
                method,
                user: user.to_owned(),
                drives: Vec::new(),
                scenes: 0,
                refused: 0,
                failed: 0,
            };
            for ((_, _), rows) in by_drive
                .range((user, "")..)
                .take_while(|((u, _), _)| *u == user)
            {
                let mut drive = Drive::new();
                for row in rows {
                    kind.scenes += 1;
                    match &row.status {
                        Status::Refused { .. } => kind.refused += 1,
                        Status::Failed { .. } => {
                            kind.failed += 1;
                            drive.push(true);
                        }
                        Status::Personalized | Status::CapReached => {
                            drive.push(row.counted_takeovers() > 0);
                        }
                    }
                }
                kind.drives.push(drive);
            }
            out.push(kind);
        }
    }
    out
}

/// The table's lines, one per method and user kind of the drives in `rows`: the
/// drives, scenes, driven, refused and failed lane changes and the takeover rate
/// in each of [`BANDS`], beside the rate of the same lane changes from scratch.
pub fn table_lines(rows: &[RunRow], methods: &[Method]) -> Vec<String> {
    let kinds = drives(rows, methods, Experiment::Drive);
    let scratch = drives(rows, methods, Experiment::DriveFromScratch);
    let rate = |(taken, n): (usize, usize)| 100.0 * taken as f64 / n as f64;
    (kinds.iter())
        .map(|kind| {
            let baseline =
                (scratch.iter()).find(|s| s.method == kind.method && s.user == kind.user);
            let bands: Vec<String> = (BANDS.iter())
                .map(
                    |&band| match (kind.band(band), baseline.map(|b| b.band(band))) {
                        ((_, 0), _) => "-".to_owned(),
                        ((taken, n), Some(scratch)) if scratch.1 > 0 => format!(
                            "{:.0} % ({taken}/{n}); from scratch {:.0} %",
                            rate((taken, n)),
                            rate(scratch)
                        ),
                        ((taken, n), _) => format!("{:.0} % ({taken}/{n})", rate((taken, n))),
                    },
                )
                .collect();
            format!(
                "| {} | {} | {} | {} | {} | {} | {} | {} |",
                kind.method.name(),
                kind.user,
                kind.drives.len(),
                kind.scenes,
                kind.driven(),
                kind.refused,
                kind.failed,
                bands.join(" | ")
            )
        })
        .collect()
}

#[cfg(feature = "plot")]
/// The figure of `method`'s drives: the moving takeover rate of each user kind,
/// in groups of at most `per_figure` kinds (one figure each); none without drives.
pub fn figures(rows: &[RunRow], method: Method, per_figure: usize) -> Vec<Lines> {
    let kinds = drives(rows, &[method], Experiment::Drive);
    let groups: Vec<&[KindDrives]> = kinds.chunks(per_figure.max(1)).collect();
    let count = groups.len();
    (groups.into_iter().enumerate())
        .map(|(i, group)| Lines {
            title: match count {
                1 => format!(
                    "Takeover rate over a drive of varied scenes ({})",
                    method.name()
                ),
                _ => format!(
                    "Takeover rate over a drive of varied scenes ({}, {} of {count})",
                    method.name(),
                    i + 1
                ),
            },
            x_desc: "lane change of the drive (driven ones)".into(),
            y_desc: format!("takeover rate over the last {WINDOW} (-)"),
            series: (group.iter())
                .map(|kind| (kind.user.clone(), kind.moving_rate()))
                .filter(|(_, points)| !points.is_empty())
                .collect(),
            y_range: Some((0.0, 1.05)),
            log_y: false,
        })
        .filter(|lines| !lines.series.is_empty())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::UserKind;
    use crate::plan::RunSpec;
    use palc_harness::StylePreset;
    use palc_traffic::SpeedCaseConfig;

    /// A drive run of `user` (`style`), taken over or not, or refused or failed.
    fn run(id: usize, user: &str, style: StylePreset, outcome: &str) -> RunRow {
        let spec = RunSpec {
            id,
            experiment: Experiment::Drive,
            method: Method::Palc,
            user: UserKind {
                name: user.into(),
                ..UserKind::deterministic()
            },
            style,
            speed_case: SpeedCaseConfig {
                name: "collector-high".into(),
                ego_mph: 45.0,
                others_mph: 40.0,
            },
            headway_m: 40.0,
            seed: 1,
            dt: None,
            horizon_margin_s: None,
            experience_from: id.checked_sub(1),
            rung: None,
        };
        let status = match outcome {
            "T" => Status::CapReached,
            "-" => Status::Personalized,
            "F" => Status::Failed {
                error: "off the road".into(),
            },
            _ => Status::Refused {
                reason: "standard never starts".into(),
                refusal: None,
            },
        };
        let mut row = RunRow::without_result(spec, status, 1, 0.0);
        row.takeovers = usize::from(outcome == "T");
        row
    }

    fn drive(user: &str, style: StylePreset, outcomes: &str, first_id: usize) -> Vec<RunRow> {
        (outcomes.chars().enumerate())
            .map(|(i, c)| run(first_id + i, user, style, &c.to_string()))
            .collect()
    }

    #[test]
    fn refused_scenes_are_skipped_and_failed_lane_changes_count_as_taken_over() {
        // 12 scenes: one refused, one failed; driven: T T - - F - - - - - - (11).
        let mut rows = drive("deterministic", StylePreset::Neutral, "TTR--F------", 0);
        rows.extend(drive(
            "deterministic",
            StylePreset::Cautious,
            "-----------T",
            12,
        ));
        let kinds = drives(&rows, &[Method::Palc], Experiment::Drive);
        assert_eq!(kinds.len(), 1);
        let kind = &kinds[0];
        assert_eq!(
            (kind.scenes, kind.refused, kind.failed, kind.driven()),
            (24, 1, 1, 23)
        );
        // Lane changes 1-10: neutral T T - - F - - - - - (3), cautious 10 clean.
        assert_eq!(kind.band((1, 10)), (3, 20));
        // 11-50: neutral's 11th (clean), cautious's 11th and 12th (one taken over).
        assert_eq!(kind.band((11, 50)), (1, 3));
        assert_eq!(kind.band((51, 100)), (0, 0));
        let rate = kind.moving_rate();
        // Windows ending at 10 (both drives) and 11 (both) and 12 (cautious only).
        assert_eq!(rate.len(), 3);
        assert!((rate[0].1 - 3.0 / 20.0).abs() < 1e-12, "{rate:?}");
        assert!((rate[2].1 - 1.0 / 10.0).abs() < 1e-12, "{rate:?}");
    }

    #[test]
    fn the_table_states_each_band_beside_the_rate_from_scratch() {
        assert!(table_lines(&[], &[Method::Palc]).is_empty());
        let mut rows = drive("incentive", StylePreset::Aggressive, "T---------T", 0);
        let mut scratch = drive("incentive", StylePreset::Aggressive, "TTTTT-----T", 11);
        for row in &mut scratch {
            row.spec.experiment = Experiment::DriveFromScratch;
        }
        rows.extend(scratch);
        let lines = table_lines(&rows, &[Method::Paper, Method::Palc]);
        let line = "| palc | incentive | 1 | 11 | 11 | 0 | 0 | 10 % (1/10); from scratch 50 % | \
                    100 % (1/1); from scratch 100 % | - |";
        assert_eq!(lines, [line]);
    }

    #[cfg(feature = "plot")]
    #[test]
    fn a_figure_per_method_that_drove() {
        let rows = drive("incentive", StylePreset::Aggressive, "T---------T", 0);
        assert_eq!(figures(&rows, Method::Palc, 6).len(), 1);
        assert!(figures(&rows, Method::Paper, 6).is_empty());
    }
}
