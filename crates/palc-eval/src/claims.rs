//! The paper's claims as data: one table of what the paper claims, how palc
//! measures it on the runs and the rule that turns the measurement into a
//! verdict. REPORT.md prints one line per claim and per method.
//!
//! The numbers are the paper's (Section III; `shared/paper/NOTES.md`, "Headline
//! results"). A claim is never tuned: the rule compares, the report prints both.

use serde::Serialize;

use crate::results::RunRow;
use crate::stats::{self, Summary, Transfer, Trend};

/// One of the paper's claims.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Claim {
    /// What is measured.
    pub metric: Metric,
    /// The line's name in the report; `{cap}` stands for the takeover cap.
    pub name: &'static str,
    /// The claim as the paper states it.
    pub claimed: &'static str,
    /// How palc measures it.
    pub how: &'static str,
    /// How the measurement is compared with the claim.
    pub rule: Rule,
}

/// A measurement over the runs of one method and user kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Metric {
    /// Mean takeovers to personalization over the grid, failures at the cap.
    MeanTakeovers,
    /// Share of counted grid runs that personalized.
    SuccessRate,
    /// Fewest, median and most takeovers over the grid.
    TakeoverRange,
    /// Aggressive users against cautious users.
    TrendStyle,
    /// Slower traffic against faster traffic, per ego speed.
    TrendTrafficSpeed,
    /// The widest adjacent headway against the narrowest.
    TrendCongestion,
    /// Relative takeover reduction with experience from another scenario.
    ExperienceReduction,
    /// Personalized runs whose takeover-free lane changes all have ratio 1.
    SafetyAtOne,
    /// Most takeovers of a personalized run before the ratio stays at 1.
    MaxTakeoversToOne,
    /// Mean compute time per iteration over the grid.
    MeanCompute,
    /// Largest compute time per iteration over the grid.
    MaxCompute,
}

/// How a measurement is compared with the paper's value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Rule {
    /// Relative difference to the value: `x % lower`, `x % higher`, or `equal`
    /// within [`EQUAL_WITHIN`].
    Relative(f64),
    /// Every counted run personalizes: `holds`, else the shortfall in points.
    AllPersonalize,
    /// Fewest and most takeovers inside `[min, max]`.
    Range {
        /// The paper's fewest takeovers.
        min: usize,
        /// The paper's most takeovers.
        max: usize,
    },
    /// The first end needs fewer takeovers than the second: `holds`,
    /// `reversed`, or `no difference` when the means are within
    /// [`TREND_RESOLUTION`].
    Direction,
    /// Difference to the value in percentage points.
    Points(f64),
    /// Strictly below the value: `holds`, else by how much it is over.
    Below(f64),
    /// Every personalized run ends at ratio 1.
    AllAtOne,
}

impl Rule {
    /// The rule in words, for the report.
    pub fn describe(&self) -> String {
        match *self {
            Rule::Relative(v) => format!(
                "relative difference to {v} (equal within {:.1} %)",
                EQUAL_WITHIN * 100.0
            ),
            Rule::AllPersonalize => "holds when every counted run personalizes".to_owned(),
            Rule::Range { min, max } => format!("holds when fewest and most lie in [{min}, {max}]"),
            Rule::Direction => format!(
                "holds when the first needs fewer takeovers; means within {TREND_RESOLUTION} are no difference"
            ),
            Rule::Points(v) => format!("difference to {:.0} % in percentage points", v * 100.0),
            Rule::Below(v) => format!("holds when below {v} s"),
            Rule::AllAtOne => "holds when every personalized run ends at ratio 1".to_owned(),
        }
    }
}

/// Relative differences below this are reported as `equal`.
pub const EQUAL_WITHIN: f64 = 0.005;

/// Means closer than this (takeovers) are reported as no difference: it is
/// below the report's resolution of 0.1 takeover.
pub const TREND_RESOLUTION: f64 = 0.05;

/// The paper's mean takeovers to personalization.
pub const PAPER_MEAN_TAKEOVERS: f64 = 13.8;
/// The paper's fewest and most takeovers.
pub const PAPER_TAKEOVER_RANGE: (usize, usize) = (6, 26);

/// Every claim of Section III that the evaluation measures, in report order.
pub const CLAIMS: &[Claim] = &[
    Claim {
        metric: Metric::MeanTakeovers,
        name: "mean takeovers to personalization (failures at {cap})",
        claimed: "13.8",
        how: "mean over the counted grid runs; a run that does not personalize counts at the cap",
        rule: Rule::Relative(PAPER_MEAN_TAKEOVERS),
    },
    Claim {
        metric: Metric::SuccessRate,
        name: "success rate",
        claimed: "100 % (\"consistent and reliable in all cases\")",
        how: "personalized grid runs over the counted grid runs",
        rule: Rule::AllPersonalize,
    },
    Claim {
        metric: Metric::TakeoverRange,
        name: "min / median / max takeovers",
        claimed: "6 / - / 26",
        how: "over the counted grid runs, failures at the cap",
        rule: Rule::Range {
            min: PAPER_TAKEOVER_RANGE.0,
            max: PAPER_TAKEOVER_RANGE.1,
        },
    },
    Claim {
        metric: Metric::TrendStyle,
        name: "fewer takeovers for aggressive users",
        claimed: "aggressive < cautious",
        how: "mean takeovers of the aggressive against the cautious grid runs",
        rule: Rule::Direction,
    },
    Claim {
        metric: Metric::TrendTrafficSpeed,
        name: "fewer takeovers in slower traffic",
        claimed: "slower < faster others",
        how: "mean takeovers of the speed cases with the slower others against the faster, at the same ego speed",
        rule: Rule::Direction,
    },
    Claim {
        metric: Metric::TrendCongestion,
        name: "fewer takeovers with less congestion",
        claimed: "50 m < 30 m headway",
        how: "mean takeovers at the widest against the narrowest adjacent headway",
        rule: Rule::Direction,
    },
    Claim {
        metric: Metric::ExperienceReduction,
        name: "takeover reduction with experience",
        claimed: "24 %",
        how: "1 - with / without, means over the cells where both the transfer run and the grid run were counted",
        rule: Rule::Points(0.24),
    },
    Claim {
        metric: Metric::SafetyAtOne,
        name: "perceived-safety ratio 1 after personalization",
        claimed: "yes, no further takeover",
        how: "personalized grid runs whose final takeover-free lane changes all have ratio 1",
        rule: Rule::AllAtOne,
    },
    Claim {
        metric: Metric::MaxTakeoversToOne,
        name: "most takeovers before ratio 1",
        claimed: "26",
        how: "largest takeover count of a personalized grid run",
        rule: Rule::Relative(26.0),
    },
    Claim {
        metric: Metric::MeanCompute,
        name: "compute per iteration, mean (grid)",
        claimed: "0.08 s (MATLAB)",
        how: "mean over every lane change of the grid runs of zone fit, bounds, expert, correction and plan",
        rule: Rule::Relative(0.08),
    },
    Claim {
        metric: Metric::MaxCompute,
        name: "compute per iteration, max (grid)",
        claimed: "< 0.13 s",
        how: "largest such time over every lane change of the grid runs",
        rule: Rule::Below(0.13),
    },
];

/// What a metric measured on the runs of one method and user kind.
#[derive(Debug, Clone, PartialEq)]
pub enum Measured {
    /// A number, or nothing to measure.
    Number(Option<f64>),
    /// A count of runs, or nothing to measure.
    Count(Option<usize>),
    /// Takeover statistics.
    Summary(Summary),
    /// A trend.
    Trend(Trend),
    /// The transfer experiment.
    Transfer(Transfer),
    /// Perceived safety.
    Safety(stats::Safety),
}

/// The runs a claim is measured on: the grid runs of one method and user kind,
/// and those with the transfer runs of the same cells.
#[derive(Debug, Clone, Copy)]
pub struct Runs<'a> {
    /// Grid runs.
    pub grid: &'a [&'a RunRow],
    /// Grid and transfer runs.
    pub with_transfer: &'a [&'a RunRow],
}

impl Metric {
    /// Measures this metric on `runs`.
    pub fn measure(self, runs: Runs) -> Measured {
        let grid = runs.grid;
        match self {
            Metric::MeanTakeovers | Metric::SuccessRate | Metric::TakeoverRange => {
                Measured::Summary(Summary::of(grid.iter().copied()))
            }
            Metric::TrendStyle => Measured::Trend(stats::style_trend(grid)),
            Metric::TrendTrafficSpeed => Measured::Trend(stats::traffic_speed_trend(grid)),
            Metric::TrendCongestion => Measured::Trend(stats::congestion_trend(grid)),
            Metric::ExperienceReduction => Measured::Transfer(stats::transfer(runs.with_transfer)),
            Metric::SafetyAtOne => Measured::Safety(stats::safety(grid)),
            Metric::MaxTakeoversToOne => Measured::Count(stats::safety(grid).max_takeovers_to_one),
            Metric::MeanCompute => {
                Measured::Number(stats::timing(grid.iter().copied()).map(|t| t.mean))
            }
            Metric::MaxCompute => {
                Measured::Number(stats::timing(grid.iter().copied()).map(|t| t.max))
            }
        }
    }
}

impl Claim {
    /// The report's cell for a measurement of this claim.
    pub fn cell(&self, measured: &Measured) -> String {
        match (self.metric, measured) {
            (Metric::MeanTakeovers, Measured::Summary(s)) => num(s.mean, 1),
            (Metric::SuccessRate, Measured::Summary(s)) => {
                format!("{} ({}/{})", pct(s.success_rate()), s.personalized, s.runs)
            }
            (Metric::TakeoverRange, Measured::Summary(s)) => {
                let opt = |v: Option<usize>| v.map_or("n/a".to_owned(), |v| v.to_string());
                format!("{} / {} / {}", opt(s.min), num(s.median, 1), opt(s.max))
            }
            (_, Measured::Trend(t)) => format!(
                "{} {} vs {} {}",
                t.first.0,
                num(t.first.1, 1),
                t.second.0,
                num(t.second.1, 1)
            ),
            (_, Measured::Transfer(t)) => format!(
                "{} ({} -> {}, {} cells)",
                pct(t.reduction),
                num(t.without, 1),
                num(t.with, 1),
                t.pairs
            ),
            (_, Measured::Safety(s)) => format!(
                "{}/{} personalized runs",
                s.personalized_at_one, s.personalized
            ),
            (_, Measured::Count(c)) => c.map_or("n/a".to_owned(), |v| v.to_string()),
            (Metric::MeanCompute | Metric::MaxCompute, Measured::Number(v)) => {
                format!("{} s", num(*v, 4))
            }
            (_, Measured::Number(v)) => num(*v, 2),
            (_, Measured::Summary(s)) => num(s.mean, 1),
        }
    }

    /// The verdict of this claim's rule on a measurement.
    pub fn verdict(&self, measured: &Measured) -> String {
        match (self.rule, measured) {
            (Rule::Relative(paper), Measured::Summary(s)) => against(s.mean, paper),
            (Rule::Relative(paper), Measured::Number(v)) => against(*v, paper),
            (Rule::Relative(paper), Measured::Count(c)) => against(c.map(|v| v as f64), paper),
            (Rule::AllPersonalize, Measured::Summary(s)) => match s.success_rate() {
                Some(r) if r >= 1.0 => "holds".to_owned(),
                Some(r) => format!("{:.0} points lower", (1.0 - r) * 100.0),
                None => "not measured".to_owned(),
            },
            (Rule::Range { min, max }, Measured::Summary(s)) => match (s.min, s.max) {
                (Some(a), Some(b)) if a >= min && b <= max => "within the paper's range".to_owned(),
                (Some(a), Some(b)) => format!("outside {min}-{max} ({a}-{b})"),
                _ => "not measured".to_owned(),
            },
            (Rule::Direction, Measured::Trend(t)) => trend_verdict(t).to_owned(),
            (Rule::Points(paper), Measured::Transfer(t)) => match t.reduction {
                Some(r) => format!("{:+.0} points", (r - paper) * 100.0),
                None => "not measured".to_owned(),
            },
            (Rule::Below(bound), Measured::Number(v)) => match v {
                Some(v) if *v < bound => "holds".to_owned(),
                Some(v) => format!("{:.3} s over", v - bound),
                None => "not measured".to_owned(),
            },
            (Rule::AllAtOne, Measured::Safety(s)) => {
                if s.personalized == 0 {
                    "no personalized run".to_owned()
                } else if s.personalized_at_one == s.personalized {
                    "holds".to_owned()
                } else {
                    "does not hold".to_owned()
                }
            }
            _ => "not measured".to_owned(),
        }
    }

    /// Whether the report shows this claim: the transfer claim only when some
    /// transfer run was paired with its grid run.
    pub fn shown(&self, measured: &[Measured]) -> bool {
        match self.metric {
            Metric::ExperienceReduction => measured
                .iter()
                .any(|m| matches!(m, Measured::Transfer(t) if t.pairs > 0)),
            _ => true,
        }
    }
}

/// `value` with `digits` decimals, or `n/a`.
pub fn num(value: Option<f64>, digits: usize) -> String {
    value.map_or_else(|| "n/a".to_owned(), |v| format!("{v:.digits$}"))
}

/// `value` as a whole percentage, or `n/a`.
pub fn pct(value: Option<f64>) -> String {
    value.map_or_else(|| "n/a".to_owned(), |v| format!("{:.0} %", v * 100.0))
}

/// "42 % lower" / "10 % higher" / "equal" relative to the paper's value.
pub fn against(ours: Option<f64>, paper: f64) -> String {
    match ours {
        None => "not measured".to_owned(),
        Some(v) => {
            let rel = (v - paper) / paper;
            if rel.abs() < EQUAL_WITHIN {
                "equal".to_owned()
            } else if rel < 0.0 {
                format!("{:.0} % lower", -rel * 100.0)
            } else {
                format!("{:.0} % higher", rel * 100.0)
            }
        }
    }
}

/// `holds`, `reversed`, `no difference` (within [`TREND_RESOLUTION`]) or `not measured`.
pub fn trend_verdict(trend: &Trend) -> &'static str {
    match (trend.agrees(), trend.first.1, trend.second.1) {
        (None, ..) => "not measured",
        (_, Some(a), Some(b)) if (a - b).abs() < TREND_RESOLUTION => "no difference",
        (Some(true), ..) => "holds",
        (Some(false), ..) => "reversed",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn trend(a: f64, b: f64) -> Trend {
        Trend {
            first: ("a".into(), Some(a)),
            second: ("b".into(), Some(b)),
        }
    }

    #[test]
    fn a_trend_within_the_resolution_is_no_difference() {
        assert_eq!(trend_verdict(&trend(2.10, 2.12)), "no difference");
        assert_eq!(trend_verdict(&trend(2.0, 2.3)), "holds");
        assert_eq!(trend_verdict(&trend(2.3, 2.0)), "reversed");
        let missing = Trend {
            first: ("a".into(), None),
            second: ("b".into(), Some(1.0)),
        };
        assert_eq!(trend_verdict(&missing), "not measured");
    }

    #[test]
    fn verdicts_say_by_how_much() {
        assert_eq!(against(Some(6.9), 13.8), "50 % lower");
        assert_eq!(against(Some(27.6), 13.8), "100 % higher");
        assert_eq!(against(Some(13.8), 13.8), "equal");
        assert_eq!(against(Some(13.85), 13.8), "equal");
        assert_eq!(against(None, 13.8), "not measured");
    }

    #[test]
    fn every_metric_has_one_claim_and_every_claim_a_rule_that_applies() {
        for (i, claim) in CLAIMS.iter().enumerate() {
            assert!(
                !CLAIMS[..i].iter().any(|c| c.metric == claim.metric),
                "{:?} twice",
                claim.metric
            );
            let empty = Runs {
                grid: &[],
                with_transfer: &[],
            };
            let measured = claim.metric.measure(empty);
            // Nothing measured is "not measured" or a statement about no runs, never a number.
            let verdict = claim.verdict(&measured);
            assert!(
                verdict.contains("not measured") || verdict.contains("no personalized run"),
                "{}: {verdict}",
                claim.name
            );
        }
    }

    #[test]
    fn the_transfer_claim_reads_the_reduction_in_points() {
        let claim = CLAIMS
            .iter()
            .find(|c| c.metric == Metric::ExperienceReduction)
            .unwrap();
        let transfer = Transfer {
            pairs: 4,
            without: Some(4.0),
            with: Some(3.0),
            personalized: (4, 4),
            reduction: Some(0.25),
            refused: 0,
            worse: 0,
        };
        let measured = Measured::Transfer(transfer);
        assert_eq!(claim.cell(&measured), "25 % (4.0 -> 3.0, 4 cells)");
        assert_eq!(claim.verdict(&measured), "+1 points");
        assert!(claim.shown(&[measured]));
        let none = Measured::Transfer(Transfer {
            pairs: 0,
            without: None,
            with: None,
            personalized: (0, 0),
            reduction: None,
            refused: 2,
            worse: 0,
        });
        assert!(!claim.shown(&[none]));
    }
}
