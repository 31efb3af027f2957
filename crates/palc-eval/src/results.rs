//! What is kept of each run: one row of numbers, plus a few numbers per lane
//! change (perceived safety, compute time), written to `runs.json` and `runs.csv`.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::EvalError;
use crate::plan::RunSpec;
use crate::run_id::run_ids;
use palc_harness::driver::CarriedBelief;

/// How a run ended, as the report counts it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case", tag = "kind")]
pub enum Status {
    /// The success criterion was met.
    Personalized,
    /// The takeover cap (or the lane-change cap of a user with spread) was reached.
    CapReached,
    /// The scenario was refused before running, e.g. because the standard ALC is
    /// not conservative there; named in the report, not counted in statistics.
    Refused {
        /// Why, as the report prints it.
        reason: String,
        /// The harness's refusal with its fields; `None` for the evaluation's own
        /// refusal of a run whose source of experience did not end
        /// ([`NO_EXPERIENCE_SOURCE`]).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        refusal: Option<Refusal>,
    },
    /// The run stopped on an error; counted as a failure at the cap.
    Failed {
        /// The error.
        error: String,
    },
}

/// The kind of the evaluation's own refusal: a transfer or accumulation run whose
/// source of experience was refused or failed.
pub const NO_EXPERIENCE_SOURCE: &str = "no-experience-source";

impl Status {
    /// A refusal by the harness, as `scenario: reason`.
    pub fn refused(scenario: &str, refusal: Refusal) -> Status {
        Status::Refused {
            reason: format!("{scenario}: {refusal}"),
            refusal: Some(refusal),
        }
    }

    /// The refusal's kind ([`Refusal::kind`] or [`NO_EXPERIENCE_SOURCE`]); `None`
    /// for a run that was not refused.
    pub fn refusal_kind(&self) -> Option<String> {
        match self {
            Status::Refused {
                refusal: Some(refusal),
                ..
            } => Some(refusal.kind()),
            Status::Refused { refusal: None, .. } => Some(NO_EXPERIENCE_SOURCE.to_owned()),
            _ => None,
        }
    }

    /// Name in CSV.
    pub fn name(&self) -> &'static str {
        match self {
            Status::Personalized => "personalized",
            Status::CapReached => "cap-reached",
            Status::Refused { .. } => "refused",
            Status::Failed { .. } => "failed",
        }
    }

    /// Whether the run counts in the takeover statistics (everything but a refusal).
    pub fn counted(&self) -> bool {
        !matches!(self, Status::Refused { .. })
    }
}

/// One lane change, reduced to what the figures need.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Iteration {
    /// Whether the user took over.
    pub takeover: bool,
    /// Whether it took over on its perceived-safety bound (not the lateral deviation).
    #[serde(default)]
    pub perceived_safety_takeover: bool,
    /// Perceived safety distance ratio (1 without takeover).
    pub perceived_safety_ratio: f64,
    /// Largest `|planned − expected|` (m).
    pub max_deviation_m: f64,
    /// Compute time by part (s); `runs.json` files that hold it as an array in the
    /// order of [`Timings::PART_NAMES`] read too.
    #[serde(deserialize_with = "timings_or_parts")]
    pub times_s: Timings,
    /// Why the lesson of this lane change could not be learned, if it could not.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub learning_error: Option<String>,
    /// Safety of the steps the system drove.
    #[serde(default)]
    pub safety: SafetyMetrics,
    /// Safety of the steps the user drove after a takeover.
    #[serde(default)]
    pub user_safety: SafetyMetrics,
    /// Why the safety layer refused the learned plan, if it did.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub safety_refusal: Option<Violation>,
    /// What the closed loop did (closed-loop runs only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub closed_loop: Option<ClosedLoopStats>,
}

use palc_harness::{
    Refusal,
    record::{ClosedLoopStats, FrozenEvaluation, Timings},
    safety::{SafetyMetrics, Violation},
};

/// Reads [`Iteration::times_s`] as written (the named parts of [`Timings`]) or as
/// older `runs.json` files hold it (an array in the order of [`Timings::PART_NAMES`]).
fn timings_or_parts<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Timings, D::Error> {
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Stored {
        Named(Timings),
        Parts([f64; 5]),
    }
    Ok(match Stored::deserialize(d)? {
        Stored::Named(timings) => timings,
        Stored::Parts(parts) => Timings::from_parts(parts),
    })
}

impl Iteration {
    /// Total compute time of the iteration (s).
    pub fn total_s(&self) -> f64 {
        self.times_s.total_s()
    }
}

/// One run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunRow {
    /// What was run.
    pub spec: RunSpec,
    /// How it ended.
    pub status: Status,
    /// Takeovers to success; the cap for a run that did not personalize.
    pub takeovers: usize,
    /// The takeover cap of the run.
    pub cap: usize,
    /// Lane changes driven.
    pub lane_changes: usize,
    /// Largest `|planned − expected|` of the last lane change (m).
    pub final_max_deviation_m: Option<f64>,
    /// Takeover rate over the last window (users with spread).
    pub final_takeover_rate: Option<f64>,
    /// Takeover rate of the user's nominal plan on the same draws.
    pub ceiling_takeover_rate: Option<f64>,
    /// Users with spread: the lane changes driven after the run, learning frozen.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frozen: Option<FrozenEvaluation>,
    /// Planning horizon K.
    pub horizon: usize,
    /// Step (s).
    pub dt: Option<f64>,
    /// Wall time of the whole run (s).
    pub wall_s: f64,
    /// Every lane change.
    pub iterations: Vec<Iteration>,
    /// What the driver estimate believed when this run's experience was carried
    /// in (two recorded scenes or more, `palc`'s relative space).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub driver_belief: Option<CarriedBelief>,
}

impl RunRow {
    /// A row for a run that did not produce a result.
    pub fn without_result(spec: RunSpec, status: Status, cap: usize, wall_s: f64) -> RunRow {
        let takeovers = if status.counted() { cap } else { 0 };
        RunRow {
            spec,
            status,
            takeovers,
            cap,
            lane_changes: 0,
            final_max_deviation_m: None,
            final_takeover_rate: None,
            ceiling_takeover_rate: None,
            frozen: None,
            horizon: 0,
            dt: None,
            wall_s,
            iterations: Vec::new(),
            driver_belief: None,
        }
    }

    /// Takeovers as every statistic counts them: a failure counts at the cap.
    pub fn counted_takeovers(&self) -> usize {
        let outcome = match self.status {
            Status::Personalized => palc_harness::Outcome::Personalized,
            _ => palc_harness::Outcome::CapReached,
        };
        outcome.counted_takeovers(self.takeovers, self.cap)
    }

    /// Lane changes of the run for which `predicate` holds.
    pub fn lane_changes_where(&self, predicate: impl Fn(&Iteration) -> bool) -> usize {
        self.iterations.iter().filter(|i| predicate(i)).count()
    }

    /// The smallest `measure` of the system-driven steps over the run's lane changes.
    pub fn min_of(&self, measure: impl Fn(&SafetyMetrics) -> Option<f64>) -> Option<f64> {
        self.iterations
            .iter()
            .filter_map(|i| measure(&i.safety))
            .min_by(f64::total_cmp)
    }

    /// Whether the run personalized.
    pub fn personalized(&self) -> bool {
        self.status == Status::Personalized
    }

    /// Mean compute time per lane change (s); `None` without lane changes.
    pub fn mean_compute_s(&self) -> Option<f64> {
        if self.iterations.is_empty() {
            return None;
        }
        let total: f64 = self.iterations.iter().map(Iteration::total_s).sum();
        Some(total / self.iterations.len() as f64)
    }

    /// This row with every measured time set to zero: what must not depend on
    /// the machine or the number of threads.
    pub fn without_timing(&self) -> RunRow {
        let mut row = self.clone();
        row.wall_s = 0.0;
        for iteration in &mut row.iterations {
            iteration.times_s = Timings::default();
        }
        row
    }
}

/// The columns of `refusals.csv`, in the order of [`RefusalCsvRow`]'s fields.
const REFUSAL_COLUMNS: [&str; 11] = [
    "id",
    "run_id",
    "experiment",
    "method",
    "user",
    "style",
    "speed_case",
    "headway_m",
    "seed",
    "kind",
    "reason",
];

/// One line of `refusals.csv`.
#[derive(Debug, Serialize)]
struct RefusalCsvRow<'a> {
    id: usize,
    run_id: &'a str,
    experiment: &'a str,
    method: &'a str,
    user: &'a str,
    style: &'a str,
    speed_case: &'a str,
    headway_m: f64,
    seed: u64,
    kind: String,
    reason: &'a str,
}

/// Writes `refusals.csv`: one line per refused run, with its kind and message
/// (REPORT.md counts them by kind and experiment); the header also without any.
pub fn write_refusals(rows: &[RunRow], path: &Path) -> Result<(), EvalError> {
    let ids = run_ids(rows.iter().map(|r| &r.spec));
    let lines = rows.iter().zip(&ids).filter_map(|(row, run_id)| {
        let Status::Refused { reason, .. } = &row.status else {
            return None;
        };
        Some(RefusalCsvRow {
            id: row.spec.id,
            run_id,
            experiment: row.spec.experiment.name(),
            method: row.spec.method.name(),
            user: &row.spec.user.name,
            style: row.spec.style_name(),
            speed_case: &row.spec.speed_case.name,
            headway_m: row.spec.headway_m,
            seed: row.spec.seed,
            kind: row.status.refusal_kind()?,
            reason,
        })
    });
    write_csv(path, Some(&REFUSAL_COLUMNS), lines)
}

/// Writes `lines` as CSV to `path` through the atomic writer, under `header`
/// when given (kept when there are no lines), else under the header serde
/// derives from the first line.
pub(crate) fn write_csv<T: Serialize>(
    path: &Path,
    header: Option<&[&str]>,
    lines: impl IntoIterator<Item = T>,
) -> Result<(), EvalError> {
    let mut bytes = Vec::new();
    let mut writer = csv::WriterBuilder::new()
        .has_headers(header.is_none())
        .from_writer(&mut bytes);
    if let Some(header) = header {
        writer.write_record(header)?;
    }
    for line in lines {
        writer.serialize(line)?;
    }
    writer.flush().map_err(csv::Error::from)?;
    drop(writer);
    palc_aggregator::output::write(path, &bytes)?;
    Ok(())
}

/// One line of `runs.csv`.
#[derive(Debug, Serialize)]
struct CsvRow<'a> {
    id: usize,
    run_id: &'a str,
    experiment: &'a str,
    method: &'a str,
    user: &'a str,
    style: &'a str,
    speed_case: &'a str,
    ego_mph: f64,
    others_mph: f64,
    headway_m: f64,
    seed: u64,
    dt_s: Option<f64>,
    horizon: usize,
    outcome: &'a str,
    refusal_kind: Option<String>,
    takeovers: usize,
    lane_changes: usize,
    final_max_deviation_m: Option<f64>,
    final_takeover_rate: Option<f64>,
    ceiling_takeover_rate: Option<f64>,
    frozen_lane_changes: Option<usize>,
    frozen_takeover_rate: Option<f64>,
    frozen_ceiling_rate: Option<f64>,
    mean_compute_per_iteration_s: Option<f64>,
    experience_from: Option<usize>,
    collisions: usize,
    rss_violations: usize,
    user_rss_violations: usize,
    safety_refusals: usize,
    min_gap_preceding_m: Option<f64>,
    min_gap_target_lead_m: Option<f64>,
    min_gap_target_lag_m: Option<f64>,
    min_ttc_s: Option<f64>,
    estimate_cue: Option<&'static str>,
    estimate_outside_model: Option<bool>,
    note: String,
}

/// One run of `runs.json`: its id ([`crate::run_id`]) and every field of the row.
#[derive(Debug, Serialize)]
struct JsonRow<'a> {
    run_id: &'a str,
    #[serde(flatten)]
    row: &'a RunRow,
}

/// Writes `runs.json` (every field) and `runs.csv` (one line per run), each
/// run with its id ([`crate::run_id`]).
pub fn write(rows: &[RunRow], json: &Path, csv_path: &Path) -> Result<(), EvalError> {
    let ids = run_ids(rows.iter().map(|r| &r.spec));
    let json_rows: Vec<JsonRow> = (rows.iter().zip(&ids))
        .map(|(row, run_id)| JsonRow { run_id, row })
        .collect();
    let text = serde_json::to_string_pretty(&json_rows)?;
    palc_aggregator::output::write(json, text.as_bytes())?;
    let lines = rows.iter().zip(&ids).map(|(row, run_id)| {
        let note = match &row.status {
            Status::Refused { reason, .. } => reason.clone(),
            Status::Failed { error } => error.clone(),
            _ => String::new(),
        };
        CsvRow {
            id: row.spec.id,
            run_id,
            experiment: row.spec.experiment.name(),
            method: row.spec.method.name(),
            user: &row.spec.user.name,
            style: row.spec.style_name(),
            speed_case: &row.spec.speed_case.name,
            ego_mph: row.spec.speed_case.ego_mph,
            others_mph: row.spec.speed_case.others_mph,
            headway_m: row.spec.headway_m,
            seed: row.spec.seed,
            dt_s: row.dt,
            horizon: row.horizon,
            outcome: row.status.name(),
            refusal_kind: row.status.refusal_kind(),
            takeovers: row.counted_takeovers(),
            lane_changes: row.lane_changes,
            final_max_deviation_m: row.final_max_deviation_m,
            final_takeover_rate: row.final_takeover_rate,
            ceiling_takeover_rate: row.ceiling_takeover_rate,
            frozen_lane_changes: row.frozen.map(|f| f.lane_changes),
            frozen_takeover_rate: row.frozen.map(|f| f.takeover_rate()),
            frozen_ceiling_rate: row.frozen.map(|f| f.ceiling_rate()),
            mean_compute_per_iteration_s: row.mean_compute_s(),
            experience_from: row.spec.experience_from,
            collisions: row.lane_changes_where(|i| i.safety.collision),
            rss_violations: row.lane_changes_where(|i| i.safety.rss_violations > 0),
            user_rss_violations: row.lane_changes_where(|i| !i.user_safety.is_safe()),
            safety_refusals: row.lane_changes_where(|i| i.safety_refusal.is_some()),
            min_gap_preceding_m: row.min_of(|s| s.min_gap_preceding_m),
            min_gap_target_lead_m: row.min_of(|s| s.min_gap_target_lead_m),
            min_gap_target_lag_m: row.min_of(|s| s.min_gap_target_lag_m),
            min_ttc_s: row.min_of(SafetyMetrics::min_ttc_s),
            estimate_cue: row.driver_belief.map(|b| b.cue.name()),
            estimate_outside_model: row.driver_belief.map(|b| b.outside_model),
            note,
        }
    });
    write_csv(csv_path, None, lines)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::runner::tests::synthetic_rows;

    #[test]
    fn csv_has_one_line_per_run_and_json_reads_back() {
        let rows = synthetic_rows();
        let dir = std::env::temp_dir().join(format!("palc-eval-results-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (json, csv_path) = (dir.join("runs.json"), dir.join("runs.csv"));
        write(&rows, &json, &csv_path).unwrap();
        let text = std::fs::read_to_string(&csv_path).unwrap();
        assert_eq!(text.lines().count(), rows.len() + 1);
        let header = text.lines().next().unwrap();
        for column in [
            "run_id",
            "method",
            "user",
            "style",
            "speed_case",
            "headway_m",
            "seed",
            "outcome",
        ] {
            assert!(header.split(',').any(|c| c == column), "{header}");
        }
        let back: Vec<RunRow> =
            serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        assert_eq!(back.len(), rows.len());
        assert_eq!(back[0].spec, rows[0].spec);
        let ids: Vec<serde_json::Value> =
            serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        assert_eq!(ids[0]["run_id"], run_ids(rows.iter().map(|r| &r.spec))[0]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn refusals_csv_lists_every_refused_run_with_its_kind_and_json_keeps_the_fields() {
        let rows = synthetic_rows();
        let refused: Vec<&RunRow> = rows.iter().filter(|r| !r.status.counted()).collect();
        assert!(!refused.is_empty());
        let dir = std::env::temp_dir().join(format!("palc-eval-refusals-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("refusals.csv");
        write_refusals(&rows, &path).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let mut lines = text.lines();
        assert_eq!(
            lines.next(),
            Some("id,run_id,experiment,method,user,style,speed_case,headway_m,seed,kind,reason")
        );
        assert_eq!(lines.count(), refused.len());
        for row in &refused {
            let kind = row.status.refusal_kind().unwrap();
            assert!(text.contains(&format!(",{kind},")), "{kind} in {text}");
        }
        // The harness's refusal keeps its fields in runs.json and reads back typed.
        let typed = (refused.iter())
            .find(|r| {
                matches!(
                    r.status,
                    Status::Refused {
                        refusal: Some(_),
                        ..
                    }
                )
            })
            .expect("a refusal of the harness");
        let json = serde_json::to_value(&typed.status).unwrap();
        assert_eq!(json["kind"], "refused");
        assert!(json["refusal"]["kind"].is_string(), "{json}");
        let back: Status = serde_json::from_value(json).unwrap();
        assert_eq!(&back, &typed.status);
        // Without refusals the file still names its columns.
        write_refusals(&[], &path).unwrap();
        let empty = std::fs::read_to_string(&path).unwrap();
        assert_eq!(empty.lines().count(), 1, "{empty}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn times_read_back_as_named_parts_and_as_an_old_array() {
        let iteration = synthetic_rows().remove(0).iterations.remove(0);
        let json = serde_json::to_value(&iteration).unwrap();
        let back: Iteration = serde_json::from_value(json.clone()).unwrap();
        assert_eq!(back, iteration);
        let mut old = json;
        old["times_s"] = serde_json::json!(iteration.times_s.parts());
        let back: Iteration = serde_json::from_value(old).unwrap();
        assert_eq!(back, iteration);
    }

    #[test]
    fn a_failure_counts_at_the_cap() {
        let mut row = synthetic_rows().remove(0);
        row.status = Status::CapReached;
        row.takeovers = 12;
        row.cap = 30;
        assert_eq!(row.counted_takeovers(), 30);
        row.status = Status::Failed {
            error: "solver".into(),
        };
        assert_eq!(row.counted_takeovers(), 30);
        row.status = Status::Personalized;
        assert_eq!(row.counted_takeovers(), 12);
    }
}
