//! Statistics over runs: takeovers to personalization (failures counted at the
//! cap), success rates, trends, the experience reduction, perceived safety and
//! compute-time percentiles.

use std::collections::HashMap;

use palc_harness::{StylePreset, record::Timings};
use serde::Serialize;

use crate::plan::{CellKey, Experiment};
use crate::results::{Iteration, RunRow};

/// Takeover statistics of a set of runs; refused runs are counted apart.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    /// Runs counted (every run but the refused ones).
    pub runs: usize,
    /// Runs refused before they started.
    pub refused: usize,
    /// Runs that personalized within the cap.
    pub personalized: usize,
    /// Mean takeovers, failures at the cap; `None` without runs.
    pub mean: Option<f64>,
    /// Fewest takeovers.
    pub min: Option<usize>,
    /// Most takeovers (the cap when a run failed).
    pub max: Option<usize>,
    /// Median takeovers.
    pub median: Option<f64>,
}

impl Summary {
    /// Summarizes `rows`.
    pub fn of<'a>(rows: impl IntoIterator<Item = &'a RunRow>) -> Summary {
        let mut counted = Vec::new();
        let mut refused = 0;
        let mut personalized = 0;
        for row in rows {
            if !row.status.counted() {
                refused += 1;
                continue;
            }
            personalized += usize::from(row.personalized());
            counted.push(row.counted_takeovers());
        }
        counted.sort_unstable();
        let n = counted.len();
        let values: Vec<f64> = counted.iter().map(|&v| v as f64).collect();
        Summary {
            runs: n,
            refused,
            personalized,
            mean: (n > 0).then(|| values.iter().sum::<f64>() / n as f64),
            min: counted.first().copied(),
            max: counted.last().copied(),
            median: (n > 0).then(|| {
                if n % 2 == 1 {
                    values[n / 2]
                } else {
                    (values[n / 2 - 1] + values[n / 2]) / 2.0
                }
            }),
        }
    }

    /// Share of counted runs that personalized.
    pub fn success_rate(&self) -> Option<f64> {
        (self.runs > 0).then(|| self.personalized as f64 / self.runs as f64)
    }
}

/// Groups `rows` by `key`, in the order keys first appear, and summarizes each.
pub fn by<K: PartialEq + Clone>(rows: &[&RunRow], key: impl Fn(&RunRow) -> K) -> Vec<(K, Summary)> {
    let mut keys: Vec<K> = Vec::new();
    for row in rows {
        let k = key(row);
        if !keys.contains(&k) {
            keys.push(k);
        }
    }
    keys.into_iter()
        .map(|k| {
            let group = rows.iter().copied().filter(|r| key(r) == k);
            let summary = Summary::of(group);
            (k, summary)
        })
        .collect()
}

/// Experience accumulation: runs with experience against the same cells without.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Transfer {
    /// Cells where both runs were counted.
    pub pairs: usize,
    /// Mean takeovers without experience over those cells.
    pub without: Option<f64>,
    /// Mean takeovers with experience over those cells.
    pub with: Option<f64>,
    /// Personalized without / with experience.
    pub personalized: (usize, usize),
    /// Relative reduction `1 − with / without` (the paper: 0.24).
    pub reduction: Option<f64>,
    /// Transfer runs not counted (refused, or their source had no experience).
    pub refused: usize,
    /// Pairs more than one takeover worse with experience than from scratch.
    pub worse: usize,
}

/// Pairs each transfer run of `rows` with the grid run of its cell.
pub fn transfer(rows: &[&RunRow]) -> Transfer {
    transfer_between(rows, Experiment::Grid, Experiment::Transfer)
}

/// Pairs each run of experiment `with` in `rows` with the run of experiment
/// `without` of its cell (the ablation's transfer runs with the rung's runs from
/// scratch: `rows` then holds one rung).
pub fn transfer_between(rows: &[&RunRow], without: Experiment, with: Experiment) -> Transfer {
    let (from_scratch, with_experience) = (without, with);
    let grid: HashMap<CellKey, &RunRow> = rows
        .iter()
        .filter(|r| r.spec.experiment == from_scratch)
        .map(|r| (r.spec.experiment_cell(), *r))
        .collect();
    let (mut without, mut with) = (Vec::new(), Vec::new());
    let mut personalized = (0, 0);
    let mut refused = 0;
    for row in rows.iter().filter(|r| r.spec.experiment == with_experience) {
        let Some(base) = grid.get(&row.spec.experiment_cell()) else {
            continue;
        };
        if !row.status.counted() || !base.status.counted() {
            refused += usize::from(!row.status.counted());
            continue;
        }
        without.push(base.counted_takeovers() as f64);
        with.push(row.counted_takeovers() as f64);
        personalized.0 += usize::from(base.personalized());
        personalized.1 += usize::from(row.personalized());
    }
    let mean = |v: &[f64]| (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64);
    let (without_mean, with_mean) = (mean(&without), mean(&with));
    let worse = (without.iter().zip(&with))
        .filter(|&(a, b)| *b > a + 1.0)
        .count();
    Transfer {
        pairs: without.len(),
        without: without_mean,
        with: with_mean,
        personalized,
        reduction: match (without_mean, with_mean) {
            (Some(a), Some(b)) if a > 0.0 => Some(1.0 - b / a),
            _ => None,
        },
        refused,
        worse,
    }
}

/// Perceived safety distance ratio against the lane-change index.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Safety {
    /// Per lane-change index: mean ratio over the runs that drove that lane
    /// change, and how many did.
    pub mean_by_iteration: Vec<(f64, usize)>,
    /// Personalized runs whose final takeover-free lane changes all have ratio 1.
    pub personalized_at_one: usize,
    /// Personalized runs.
    pub personalized: usize,
    /// Largest index of the last takeover of a personalized run (1-based), the
    /// paper's "maximum number of required iterations" of Fig. 12(b).
    pub max_takeovers_to_one: Option<usize>,
}

/// Perceived safety over `rows`.
pub fn safety(rows: &[&RunRow]) -> Safety {
    let longest = rows.iter().map(|r| r.iterations.len()).max().unwrap_or(0);
    let mean_by_iteration = (0..longest)
        .map(|i| {
            let values: Vec<f64> = rows
                .iter()
                .filter_map(|r| r.iterations.get(i).map(|it| it.perceived_safety_ratio))
                .collect();
            (
                values.iter().sum::<f64>() / values.len() as f64,
                values.len(),
            )
        })
        .collect();
    let personalized: Vec<&&RunRow> = rows.iter().filter(|r| r.personalized()).collect();
    let personalized_at_one = personalized
        .iter()
        .filter(|r| {
            let clean = r.iterations.iter().rev().take_while(|it| !it.takeover);
            let mut any = false;
            let all_one = clean
                .inspect(|_| any = true)
                .all(|it| it.perceived_safety_ratio == 1.0);
            any && all_one
        })
        .count();
    Safety {
        mean_by_iteration,
        personalized_at_one,
        personalized: personalized.len(),
        max_takeovers_to_one: personalized.iter().map(|r| r.counted_takeovers()).max(),
    }
}

/// Compute-time percentiles of a set of iterations (s).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Timing {
    /// Iterations measured.
    pub iterations: usize,
    /// Mean total time.
    pub mean: f64,
    /// Median total time.
    pub p50: f64,
    /// 95th percentile of the total time.
    pub p95: f64,
    /// Largest total time.
    pub max: f64,
    /// Mean time of each part.
    pub part_means: Timings,
    /// 95th percentile of each part.
    pub part_p95: Timings,
}

/// Nearest-rank percentile `q ∈ [0, 1]` of sorted values.
pub fn percentile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let rank = (q * sorted.len() as f64).ceil() as usize;
    sorted[rank.clamp(1, sorted.len()) - 1]
}

/// Timing of every iteration of `rows`; `None` without iterations.
pub fn timing<'a>(rows: impl IntoIterator<Item = &'a RunRow>) -> Option<Timing> {
    let iterations: Vec<&Iteration> = rows.into_iter().flat_map(|r| &r.iterations).collect();
    timing_of(&iterations)
}

/// Timing of `iterations`; `None` without any.
pub fn timing_of(iterations: &[&Iteration]) -> Option<Timing> {
    if iterations.is_empty() {
        return None;
    }
    let sorted = |f: &dyn Fn(&Iteration) -> f64| {
        let mut v: Vec<f64> = iterations.iter().map(|it| f(it)).collect();
        v.sort_by(f64::total_cmp);
        v
    };
    let totals = sorted(&Iteration::total_s);
    let n = iterations.len() as f64;
    let mut part_means = [0.0; Timings::PART_NAMES.len()];
    let mut part_p95 = [0.0; Timings::PART_NAMES.len()];
    for p in 0..Timings::PART_NAMES.len() {
        let values = sorted(&|it: &Iteration| it.times_s.parts()[p]);
        part_means[p] = values.iter().sum::<f64>() / n;
        part_p95[p] = percentile(&values, 0.95);
    }
    Some(Timing {
        iterations: iterations.len(),
        mean: totals.iter().sum::<f64>() / n,
        p50: percentile(&totals, 0.5),
        p95: percentile(&totals, 0.95),
        max: totals[totals.len() - 1],
        part_means: Timings::from_parts(part_means),
        part_p95: Timings::from_parts(part_p95),
    })
}

/// A trend: mean takeovers of two ends of a factor, and whether the paper's
/// direction holds (`first` needs fewer takeovers than `second`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Trend {
    /// The end the paper says needs fewer takeovers, and its mean.
    pub first: (String, Option<f64>),
    /// The other end, and its mean.
    pub second: (String, Option<f64>),
}

impl Trend {
    /// Whether `first` needs strictly fewer takeovers; `None` when a mean is missing.
    pub fn agrees(&self) -> Option<bool> {
        Some(self.first.1? < self.second.1?)
    }
}

/// Mean takeovers of the rows for which `keep` holds.
fn mean_where(rows: &[&RunRow], keep: impl Fn(&RunRow) -> bool) -> Option<f64> {
    Summary::of(rows.iter().copied().filter(|r| keep(r))).mean
}

/// The paper's style trend: aggressive users need fewer takeovers than cautious ones.
pub fn style_trend(rows: &[&RunRow]) -> Trend {
    Trend {
        first: (
            StylePreset::Aggressive.name().into(),
            mean_where(rows, |r| r.spec.style == StylePreset::Aggressive),
        ),
        second: (
            StylePreset::Cautious.name().into(),
            mean_where(rows, |r| r.spec.style == StylePreset::Cautious),
        ),
    }
}

/// The paper's traffic-speed trend: for each ego speed, the case with the
/// slower surrounding traffic needs fewer takeovers than the one with faster.
/// A row is "slower" when another row has the same ego speed and faster others.
pub fn traffic_speed_trend(rows: &[&RunRow]) -> Trend {
    let has_other = |r: &RunRow, faster: bool| {
        rows.iter().any(|o| {
            let (mine, theirs) = (&r.spec.speed_case, &o.spec.speed_case);
            mine.ego_mph == theirs.ego_mph
                && if faster {
                    theirs.others_mph > mine.others_mph
                } else {
                    theirs.others_mph < mine.others_mph
                }
        })
    };
    Trend {
        first: ("slower".into(), mean_where(rows, |r| has_other(r, true))),
        second: ("faster".into(), mean_where(rows, |r| has_other(r, false))),
    }
}

/// The paper's congestion trend: the widest adjacent headway needs fewer
/// takeovers than the narrowest.
pub fn congestion_trend(rows: &[&RunRow]) -> Trend {
    let headways = rows.iter().map(|r| r.spec.headway_m);
    let widest = headways.clone().fold(f64::NEG_INFINITY, f64::max);
    let narrowest = headways.fold(f64::INFINITY, f64::min);
    Trend {
        first: (
            format!("{widest} m"),
            mean_where(rows, |r| r.spec.headway_m == widest),
        ),
        second: (
            format!("{narrowest} m"),
            mean_where(rows, |r| r.spec.headway_m == narrowest),
        ),
    }
}

/// Users with spread: the mean final takeover rate of the counted runs and the
/// mean ceiling (the rate of the user's own nominal plan on the same draws).
pub fn final_rates(rows: &[&RunRow]) -> (Option<f64>, Option<f64>) {
    let counted: Vec<&RunRow> = rows
        .iter()
        .copied()
        .filter(|r| r.status.counted())
        .collect();
    let mean = |f: fn(&RunRow) -> Option<f64>| {
        let v: Vec<f64> = counted.iter().filter_map(|r| f(r)).collect();
        (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
    };
    (
        mean(|r| r.final_takeover_rate),
        mean(|r| r.ceiling_takeover_rate),
    )
}

/// Margin over the ceiling within which a user with spread counts as served in
/// the evaluation phase: 3 percentage points.
pub const FROZEN_MARGIN: f64 = 0.03;

/// Users with spread: the evaluation phase after learning (learning frozen).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Frozen {
    /// Counted runs with an evaluation phase.
    pub runs: usize,
    /// Mean takeover rate of the frozen plan.
    pub takeover_rate: f64,
    /// Mean rate of the nominal plan on the same draws (the ceiling).
    pub ceiling_rate: f64,
    /// Runs whose frozen rate is at most the ceiling plus [`FROZEN_MARGIN`].
    pub within_margin: usize,
}

/// The evaluation phase over the counted runs of `rows` that have one; `None`
/// when none has.
pub fn frozen(rows: &[&RunRow]) -> Option<Frozen> {
    let phases: Vec<_> = (rows.iter())
        .filter(|r| r.status.counted())
        .filter_map(|r| r.frozen)
        .collect();
    let n = phases.len();
    (n > 0).then(|| Frozen {
        runs: n,
        takeover_rate: phases.iter().map(|f| f.takeover_rate()).sum::<f64>() / n as f64,
        ceiling_rate: phases.iter().map(|f| f.ceiling_rate()).sum::<f64>() / n as f64,
        within_margin: (phases.iter())
            .filter(|f| f.takeover_rate() <= f.ceiling_rate() + FROZEN_MARGIN + 1e-12)
            .count(),
    })
}

impl Frozen {
    /// "34 % vs ceiling 27 %, 22/117 within 3 points".
    pub fn describe(&self) -> String {
        format!(
            "{:.0} % vs ceiling {:.0} %, {}/{} within {:.0} points",
            100.0 * self.takeover_rate,
            100.0 * self.ceiling_rate,
            self.within_margin,
            self.runs,
            100.0 * FROZEN_MARGIN
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::UserKind;
    use crate::plan::RunSpec;
    use crate::results::Status;
    use crate::runner::tests::synthetic_rows;
    use palc_harness::Method;
    use palc_traffic::SpeedCaseConfig;

    /// A grid row built by hand: personalized after `takeovers`, or capped at 30
    /// when `takeovers` is `None`.
    fn row(
        style: StylePreset,
        case: (&str, f64, f64),
        headway_m: f64,
        takeovers: Option<usize>,
    ) -> RunRow {
        let spec = RunSpec {
            id: 0,
            experiment: Experiment::Grid,
            method: Method::Palc,
            user: UserKind::deterministic(),
            style,
            speed_case: SpeedCaseConfig {
                name: case.0.to_owned(),
                ego_mph: case.1,
                others_mph: case.2,
            },
            headway_m,
            seed: 1,
            dt: None,
            horizon_margin_s: None,
            experience_from: None,
            rung: None,
        };
        let status = match takeovers {
            Some(_) => Status::Personalized,
            None => Status::CapReached,
        };
        let mut row = RunRow::without_result(spec, status, 30, 0.0);
        row.takeovers = takeovers.unwrap_or(30);
        row
    }

    const HIGH: (&str, f64, f64) = ("high", 45.0, 40.0);
    const SLOW: (&str, f64, f64) = ("slow", 45.0, 35.0);

    #[test]
    fn trends_compare_hand_computed_means() {
        let rows = [
            row(StylePreset::Aggressive, SLOW, 50.0, Some(2)),
            row(StylePreset::Aggressive, HIGH, 30.0, Some(4)),
            row(StylePreset::Cautious, SLOW, 50.0, Some(3)),
            row(StylePreset::Cautious, HIGH, 30.0, None),
        ];
        let refs: Vec<&RunRow> = rows.iter().collect();
        // Aggressive (2 + 4) / 2 = 3, cautious (3 + 30) / 2 = 16.5.
        let style = style_trend(&refs);
        assert_eq!(style.first, ("aggressive".to_owned(), Some(3.0)));
        assert_eq!(style.second, ("cautious".to_owned(), Some(16.5)));
        assert_eq!(style.agrees(), Some(true));
        // Slower others (35 mph): (2 + 3) / 2 = 2.5; faster (40 mph): (4 + 30) / 2 = 17.
        let speed = traffic_speed_trend(&refs);
        assert_eq!((speed.first.1, speed.second.1), (Some(2.5), Some(17.0)));
        // Widest headway 50 m: 2.5; narrowest 30 m: 17.
        let congestion = congestion_trend(&refs);
        assert_eq!(congestion.first, ("50 m".to_owned(), Some(2.5)));
        assert_eq!(congestion.second, ("30 m".to_owned(), Some(17.0)));
        // Reversed when the narrow headway needs fewer.
        let reversed = [
            row(StylePreset::Neutral, HIGH, 50.0, Some(5)),
            row(StylePreset::Neutral, HIGH, 30.0, Some(3)),
        ];
        let refs: Vec<&RunRow> = reversed.iter().collect();
        assert_eq!(congestion_trend(&refs).agrees(), Some(false));
        // One speed per ego speed: no slower or faster case to compare.
        assert_eq!(traffic_speed_trend(&refs).agrees(), None);
    }

    #[test]
    fn the_transfer_reduction_is_one_minus_the_ratio_of_paired_means() {
        let mut grid = [
            row(StylePreset::Neutral, HIGH, 40.0, Some(4)),
            row(StylePreset::Neutral, SLOW, 40.0, None),
            row(StylePreset::Cautious, HIGH, 40.0, Some(6)),
        ];
        let mut transfer = [
            row(StylePreset::Neutral, HIGH, 40.0, Some(2)),
            row(StylePreset::Neutral, SLOW, 40.0, Some(5)),
            row(StylePreset::Cautious, HIGH, 40.0, Some(6)),
        ];
        for (i, r) in transfer.iter_mut().enumerate() {
            r.spec.experiment = Experiment::Transfer;
            r.spec.id = 10 + i;
        }
        // The third transfer run is refused: it and its grid run leave the pairs.
        transfer[2].status = Status::Refused {
            reason: "no experience".into(),
            refusal: None,
        };
        grid[2].spec.id = 2;
        let rows: Vec<&RunRow> = grid.iter().chain(&transfer).collect();
        let t = super::transfer(&rows);
        // Without: (4 + 30) / 2 = 17; with: (2 + 5) / 2 = 3.5; 1 - 3.5 / 17.
        assert_eq!(t.pairs, 2);
        assert_eq!((t.without, t.with), (Some(17.0), Some(3.5)));
        assert!((t.reduction.unwrap() - (1.0 - 3.5 / 17.0)).abs() < 1e-12);
        assert_eq!(t.personalized, (1, 2));
        assert_eq!(t.refused, 1);
    }

    #[test]
    fn the_final_rate_is_compared_with_the_ceiling_over_counted_runs() {
        let mut rows = [
            row(StylePreset::Neutral, HIGH, 40.0, Some(3)),
            row(StylePreset::Neutral, SLOW, 40.0, None),
            row(StylePreset::Neutral, SLOW, 30.0, None),
        ];
        rows[0].final_takeover_rate = Some(0.2);
        rows[0].ceiling_takeover_rate = Some(0.1);
        rows[1].final_takeover_rate = Some(0.4);
        rows[1].ceiling_takeover_rate = Some(0.3);
        // A refused run's rates, were there any, would not count.
        rows[2].status = Status::Refused {
            reason: "x".into(),
            refusal: None,
        };
        rows[2].final_takeover_rate = Some(1.0);
        rows[2].ceiling_takeover_rate = Some(1.0);
        let refs: Vec<&RunRow> = rows.iter().collect();
        let (rate, ceiling) = final_rates(&refs);
        assert!((rate.unwrap() - 0.3).abs() < 1e-12);
        assert!((ceiling.unwrap() - 0.2).abs() < 1e-12);
        assert_eq!(final_rates(&[]), (None, None));
    }

    #[test]
    fn the_mean_of_a_mixed_set_counts_failures_at_the_cap() {
        let rows = [
            row(StylePreset::Neutral, HIGH, 40.0, Some(2)),
            row(StylePreset::Neutral, HIGH, 35.0, Some(3)),
            row(StylePreset::Neutral, HIGH, 30.0, None),
        ];
        let summary = Summary::of(&rows);
        // (2 + 3 + 30) / 3, median 3.
        assert!((summary.mean.unwrap() - 35.0 / 3.0).abs() < 1e-12);
        assert_eq!(summary.median, Some(3.0));
        assert_eq!(summary.personalized, 2);
    }

    #[test]
    fn failures_count_at_the_cap_and_refusals_apart() {
        let rows = synthetic_rows();
        let mut picked: Vec<RunRow> = rows[..3].to_vec();
        picked[0].status = Status::Personalized;
        picked[0].takeovers = 4;
        picked[1].status = Status::CapReached;
        picked[1].takeovers = 30;
        picked[1].cap = 30;
        picked[2].status = Status::Refused {
            reason: "x".into(),
            refusal: None,
        };
        let summary = Summary::of(&picked);
        assert_eq!(
            (summary.runs, summary.refused, summary.personalized),
            (2, 1, 1)
        );
        assert_eq!(summary.mean, Some(17.0));
        assert_eq!((summary.min, summary.max), (Some(4), Some(30)));
        assert_eq!(summary.median, Some(17.0));
        assert_eq!(summary.success_rate(), Some(0.5));
    }

    #[test]
    fn percentiles_use_the_nearest_rank() {
        let values: Vec<f64> = (1..=100).map(f64::from).collect();
        assert_eq!(percentile(&values, 0.5), 50.0);
        assert_eq!(percentile(&values, 0.95), 95.0);
        assert_eq!(percentile(&values, 1.0), 100.0);
        assert_eq!(percentile(&[3.0], 0.95), 3.0);
    }

    #[test]
    fn the_transfer_reduction_compares_the_same_cells() {
        let rows = synthetic_rows();
        let refs: Vec<&RunRow> = rows
            .iter()
            .filter(|r| r.spec.method == Method::Palc)
            .collect();
        let transfer = transfer(&refs);
        assert!(transfer.pairs > 0);
        // The synthetic executor needs three quarters of the takeovers (rounded down).
        let reduction = transfer.reduction.unwrap();
        assert!((0.2..0.4).contains(&reduction), "{reduction}");
        assert!(
            transfer.refused > 0,
            "cells refused in the synthetic grid are counted"
        );
    }

    #[test]
    fn safety_reaches_one_after_the_last_takeover() {
        let rows = synthetic_rows();
        let refs: Vec<&RunRow> = rows
            .iter()
            .filter(|r| r.spec.method == Method::Palc)
            .collect();
        let safety = safety(&refs);
        assert_eq!(safety.personalized_at_one, safety.personalized);
        assert!(safety.mean_by_iteration[0].0 < 1.0);
        let groups = by(&refs, |r| r.spec.style);
        assert_eq!(groups.len(), 3);
        assert!(groups[0].1.mean < groups[2].1.mean);
    }
}
