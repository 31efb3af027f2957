//! palc's own targets as data, beside the paper's claims ([`crate::claims`]):
//! one table of what palc aims for beyond the paper, the rule that judges a
//! measurement, how it is measured on the runs, and one verdict function.
//! REPORT.md states every target the same way ([`Target::state`]).
//!
//! A target is measured per case ([`Target::cases`]): the method as a whole, or
//! each user kind, axis or user of its experiment; it is met when every
//! measured case is. The figures behind each value are in the log entry it cites.

use std::fmt;

use crate::results::Iteration;
use crate::stats::Timing;

mod cases;

pub use cases::{closed_loop, events_of, transfer};

/// One of palc's targets.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Target {
    /// What is measured.
    pub id: TargetId,
    /// The target's name in the report.
    pub name: &'static str,
    /// How palc measures it.
    pub how: &'static str,
    /// The rule that turns a measurement into a verdict.
    pub rule: Rule,
    /// The log entry that set the target and measured it.
    pub source: &'static str,
}

/// Which target.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TargetId {
    /// Experience from another speed case of the transfer matrix.
    TransferSpeedCase,
    /// Experience from another headway of the transfer matrix.
    TransferHeadway,
    /// One user through the scenes in sequence: takeovers after the first scene.
    Accumulation,
    /// Every user kind learns.
    KindsLearned,
    /// Every user kind's transfer from the next speed case.
    KindTransfer,
    /// Users with spread after learning, learning frozen.
    SpreadAfterLearning,
    /// Closed loop personalizes like open loop.
    ClosedLoop,
    /// No collision and no RSS violation.
    Safety,
    /// A learning iteration's compute time.
    LearningTime,
    /// A drive of varied scenes, palc's deterministic families.
    DriveOwnFamilies,
    /// A drive of varied scenes, drivers outside the one-cue rules.
    DriveOutOfClass,
    /// Recorded drivers' transfer from the transfer experiment's other scene.
    RecordedTransfer,
    /// Families outside the one-cue rules: experience from one other scene
    /// never much worse than none.
    OutOfClassTransfer,
    /// Families outside the one-cue rules through the scenes in sequence, once
    /// two scenes are behind.
    OutOfClassAccumulation,
}

/// How a measurement is judged.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Rule {
    /// Experience: the mean takeovers at least this much lower (relative), no
    /// pair more than one takeover worse, every run with experience personalized.
    Transfer(f64),
    /// A mean of at most `takeovers` per scene over the scenes that follow the
    /// first `after_scenes` of a chain.
    AtMostTakeovers {
        /// Bound of the mean takeovers per scene.
        takeovers: f64,
        /// Scenes of each chain not counted: the experience they built is
        /// what is judged.
        after_scenes: usize,
    },
    /// No pair of a transfer more than one takeover worse with experience than
    /// from scratch.
    NoPairWorse,
    /// At least this share of the counted runs.
    Share(f64),
    /// A relative reduction of the mean takeovers of at least this.
    Reduction(f64),
    /// Success rate within `points` and mean takeovers within `takeovers` of
    /// open loop.
    LikeOpenLoop {
        /// Largest gap in success rate (percentage points).
        points: f64,
        /// Largest gap in mean takeovers.
        takeovers: f64,
    },
    /// At most this share of a drive's lane changes 11-50 taken over.
    AtMostTakenOver(f64),
    /// Not one event.
    NoEvent,
    /// Mean and 95th percentile below these (s).
    Faster {
        /// Bound of the mean (s).
        mean_s: f64,
        /// Bound of the 95th percentile (s).
        p95_s: f64,
    },
}

/// palc's targets, in report order.
pub const TARGETS: &[Target] = &[
    Target {
        id: TargetId::TransferSpeedCase,
        name: "experience from another speed case",
        how: "transfer matrix: each cell from scratch against the same cell with the experience of another speed case",
        rule: Rule::Transfer(0.5),
        source: "docs/experiments/0017-how-the-reproduction-counts.md",
    },
    Target {
        id: TargetId::TransferHeadway,
        name: "experience from another headway",
        how: "transfer matrix: each cell from scratch against the same cell with the experience of another headway",
        rule: Rule::Transfer(0.8),
        source: "docs/experiments/0017-how-the-reproduction-counts.md",
    },
    Target {
        id: TargetId::Accumulation,
        name: "one user through the scenes in sequence",
        how: "mean takeovers after the first scene of each chain, per user kind and axis",
        rule: Rule::AtMostTakeovers {
            takeovers: 0.5,
            after_scenes: 1,
        },
        source: "docs/experiments/0047-relative-onset-measured.md",
    },
    Target {
        id: TargetId::KindsLearned,
        name: "every user kind learned",
        how: "personalized grid runs over the counted grid runs, per user kind",
        rule: Rule::Share(0.95),
        source: "docs/experiments/0036-user-families.md",
    },
    Target {
        id: TargetId::KindTransfer,
        name: "every user kind gains from experience",
        how: "1 - with / without over the cells where the transfer run and the grid run were counted, per user kind",
        rule: Rule::Reduction(0.3),
        source: "docs/experiments/0036-user-families.md",
    },
    Target {
        id: TargetId::SpreadAfterLearning,
        name: "users with spread after learning",
        how: "runs whose takeover rate with learning frozen is within 3 points of the ceiling, per user kind with spread",
        rule: Rule::Share(0.95),
        source: "docs/experiments/0050-users-with-spread-averaging-and-window.md",
    },
    Target {
        id: TargetId::ClosedLoop,
        name: "closed loop personalizes like open loop",
        how: "the same grid cells in open and closed loop: success rate and mean takeovers",
        rule: Rule::LikeOpenLoop {
            points: 2.0,
            takeovers: 0.5,
        },
        source: "docs/experiments/0039-closed-loop-execution.md",
    },
    Target {
        id: TargetId::Safety,
        name: "no collision, no RSS violation",
        how: "every executed lane change of every experiment and method, system- and user-driven steps",
        rule: Rule::NoEvent,
        source: "docs/experiments/0032-the-safe-set-up-measured.md",
    },
    Target {
        id: TargetId::LearningTime,
        name: "compute time of a learning iteration",
        how: "every grid lane change with a takeover: zone fit, bounds, expert, correction and plan",
        rule: Rule::Faster {
            mean_s: 2e-3,
            p95_s: 5e-3,
        },
        source: "docs/experiments/0018-compute-time.md",
    },
    Target {
        id: TargetId::DriveOwnFamilies,
        name: "a drive of varied scenes, palc's deterministic families",
        how: "taken-over lane changes over those driven, lane changes 11-50 of every drive, per user kind without spread \
              whose decision is a threshold on one cue",
        rule: Rule::AtMostTakenOver(0.10),
        source: "docs/experiments/0073-a-drive-of-varied-scenes.md",
    },
    Target {
        id: TargetId::DriveOutOfClass,
        name: "a drive of varied scenes, drivers outside the one-cue rules",
        how: "taken-over lane changes over those driven, lane changes 11-50 of every drive, per recorded user kind and per kind \
              that starts on MOBIL's incentive or on two cues",
        rule: Rule::AtMostTakenOver(0.20),
        source: "docs/experiments/0073-a-drive-of-varied-scenes.md",
    },
    Target {
        id: TargetId::RecordedTransfer,
        name: "recorded drivers gain from experience",
        how: "1 - with / without over the cells where the transfer run (experience of `[transfer] source`) and the grid run \
              were counted, per recorded user kind",
        rule: Rule::Reduction(0.5),
        source: "docs/experiments/0084-the-goals-for-drivers-outside-the-model-as-targets.md",
    },
    Target {
        id: TargetId::OutOfClassTransfer,
        name: "families outside the one-cue rules, experience from one other scene",
        how: "the transfer runs against the grid runs of their cells, both counted, per simulated user kind that starts on \
              MOBIL's incentive or on two cues",
        rule: Rule::NoPairWorse,
        source: "docs/experiments/0084-the-goals-for-drivers-outside-the-model-as-targets.md",
    },
    Target {
        id: TargetId::OutOfClassAccumulation,
        name: "families outside the one-cue rules through the scenes in sequence",
        how: "mean takeovers per scene after the first two of each chain, per simulated user kind that starts on MOBIL's \
              incentive or on two cues, and axis",
        rule: Rule::AtMostTakeovers {
            takeovers: 0.5,
            after_scenes: 2,
        },
        source: "docs/experiments/0084-the-goals-for-drivers-outside-the-model-as-targets.md",
    },
];

/// The target with `id`.
pub fn target(id: TargetId) -> &'static Target {
    // Every id has one entry; a test keeps it so.
    TARGETS.iter().find(|t| t.id == id).unwrap_or(&TARGETS[0])
}

/// What a target measured in one case.
#[derive(Debug, Clone, PartialEq)]
pub enum Measured {
    /// Pairs of a cell from scratch and with experience.
    Transfer(Pairs),
    /// A mean of takeovers, or nothing to measure.
    Takeovers(Option<f64>),
    /// Runs that meet the rule's condition, of the runs counted.
    Share {
        /// Runs that meet it.
        hits: usize,
        /// Runs counted.
        runs: usize,
    },
    /// A relative reduction, or nothing to measure.
    Reduction(Option<f64>),
    /// Closed loop against open loop.
    Gaps {
        /// Success rates, open and closed (%).
        success: (f64, f64),
        /// Mean takeovers, open and closed.
        takeovers: (f64, f64),
    },
    /// Lane changes with an event.
    Events(Events),
    /// Compute times.
    Timing(Timing),
    /// Lane changes taken over, of the lane changes driven.
    TakenOver {
        /// Taken over (or failed).
        taken: usize,
        /// Driven.
        driven: usize,
    },
}

/// Pairs of a transfer: a cell from scratch and with experience, both counted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pairs {
    /// Number of pairs.
    pub pairs: usize,
    /// Mean takeovers from scratch.
    pub without: Option<f64>,
    /// Mean takeovers with experience.
    pub with: Option<f64>,
    /// Pairs more than one takeover worse with experience.
    pub worse: usize,
    /// Runs with experience that did not personalize.
    pub capped: usize,
}

impl Pairs {
    /// `1 - with / without`, when both are measured and `without` is positive.
    pub fn reduction(&self) -> Option<f64> {
        match (self.without, self.with) {
            (Some(a), Some(b)) if a > 0.0 => Some(1.0 - b / a),
            _ => None,
        }
    }
}

/// Lane changes with a collision or an RSS violation, in the steps the system
/// drove and in those the user drove.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct Events {
    /// System-driven lane changes with a collision.
    pub system_collisions: usize,
    /// System-driven lane changes with an RSS violation.
    pub system_violations: usize,
    /// User-driven lane changes with a collision.
    pub user_collisions: usize,
    /// User-driven lane changes with an RSS violation.
    pub user_violations: usize,
}

impl Events {
    /// The events of `iterations`.
    pub fn of<'a>(iterations: impl IntoIterator<Item = &'a Iteration>) -> Events {
        let mut events = Events::default();
        for i in iterations {
            events.system_collisions += usize::from(i.safety.collision);
            events.system_violations += usize::from(i.safety.rss_violations > 0);
            events.user_collisions += usize::from(i.user_safety.collision);
            events.user_violations += usize::from(i.user_safety.rss_violations > 0);
        }
        events
    }
}

/// A target's verdict.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// The rule holds.
    Met,
    /// The rule does not hold.
    NotMet,
    /// Nothing to measure.
    NotMeasured,
}

impl fmt::Display for Verdict {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Verdict::Met => "met",
            Verdict::NotMet => "**not met**",
            Verdict::NotMeasured => "not measured",
        })
    }
}

/// One case of a target: who was measured, and what.
#[derive(Debug, Clone, PartialEq)]
pub struct Case {
    /// The method, user kind, axis or user measured.
    pub who: String,
    /// The measurement.
    pub measured: Measured,
}

/// Shares within this of the rule's bound count as meeting it.
const SHARE_TOLERANCE: f64 = 1e-9;

impl Rule {
    /// The rule in words.
    pub fn describe(&self) -> String {
        match *self {
            Rule::Transfer(r) => format!(
                "at least {:.0} % fewer takeovers, no pair worse by more than one, every run personalized",
                100.0 * r
            ),
            Rule::AtMostTakeovers {
                takeovers,
                after_scenes,
            } => {
                let first = match after_scenes {
                    1 => "the first scene".to_owned(),
                    2 => "the first two scenes".to_owned(),
                    n => format!("the first {n} scenes"),
                };
                format!("at most {takeovers} takeovers after {first}")
            }
            Rule::NoPairWorse => {
                "no pair worse than from scratch by more than one takeover".to_owned()
            }
            Rule::Share(s) => format!("at least {:.0} % of the counted runs", 100.0 * s),
            Rule::Reduction(r) => format!("at least {:.0} % fewer takeovers", 100.0 * r),
            Rule::LikeOpenLoop { points, takeovers } => format!(
                "success within {points} points and mean takeovers within {takeovers} of open loop"
            ),
            Rule::AtMostTakenOver(share) => format!(
                "at most {:.0} % of lane changes 11-50 taken over",
                100.0 * share
            ),
            Rule::NoEvent => "none in any executed lane change".to_owned(),
            Rule::Faster { mean_s, p95_s } => format!(
                "below {:.0} ms in the mean and {:.0} ms at the 95th percentile",
                mean_s * 1e3,
                p95_s * 1e3
            ),
        }
    }
}

impl Target {
    /// The verdict of this target's rule on one measurement.
    pub fn verdict(&self, measured: &Measured) -> Verdict {
        let met = match (self.rule, measured) {
            (Rule::Transfer(r), Measured::Transfer(p)) => match p.reduction() {
                None if p.pairs == 0 => return Verdict::NotMeasured,
                reduction => reduction.is_some_and(|x| x >= r) && p.worse == 0 && p.capped == 0,
            },
            (Rule::AtMostTakeovers { takeovers, .. }, Measured::Takeovers(Some(v))) => {
                *v <= takeovers
            }
            (Rule::NoPairWorse, Measured::Transfer(p)) if p.pairs > 0 => p.worse == 0,
            (Rule::Share(share), Measured::Share { hits, runs }) if *runs > 0 => {
                *hits as f64 >= share * *runs as f64 - SHARE_TOLERANCE
            }
            (Rule::Reduction(r), Measured::Reduction(Some(v))) => *v >= r,
            (
                Rule::LikeOpenLoop { points, takeovers },
                Measured::Gaps {
                    success,
                    takeovers: t,
                },
            ) => (success.0 - success.1).abs() <= points && (t.0 - t.1).abs() <= takeovers,
            (Rule::AtMostTakenOver(share), Measured::TakenOver { taken, driven })
                if *driven > 0 =>
            {
                *taken as f64 <= share * *driven as f64 + SHARE_TOLERANCE
            }
            (Rule::NoEvent, Measured::Events(e)) => *e == Events::default(),
            (Rule::Faster { mean_s, p95_s }, Measured::Timing(t)) => {
                t.mean < mean_s && t.p95 < p95_s
            }
            _ => return Verdict::NotMeasured,
        };
        if met { Verdict::Met } else { Verdict::NotMet }
    }

    /// A measurement in words.
    pub fn cell(&self, measured: &Measured) -> String {
        let num = crate::claims::num;
        match measured {
            Measured::Transfer(p) => format!(
                "{} -> {} takeovers ({}), {} pairs worse, {} not personalized, {} pairs",
                num(p.without, 2),
                num(p.with, 2),
                signed_percent(p.reduction()),
                p.worse,
                p.capped,
                p.pairs
            ),
            Measured::Takeovers(v) => format!("{} takeovers", num(*v, 2)),
            Measured::Share { hits, runs } => {
                let share = (*runs > 0).then(|| *hits as f64 / *runs as f64);
                format!("{hits}/{runs} ({})", crate::claims::pct(share))
            }
            Measured::Reduction(r) => signed_percent(*r),
            Measured::Gaps { success, takeovers } => format!(
                "success {:.1} % / {:.1} %, mean takeovers {:.2} / {:.2} (open / closed)",
                success.0, success.1, takeovers.0, takeovers.1
            ),
            Measured::Events(e) => format!(
                "collisions {} system / {} user, RSS violations {} system / {} user",
                e.system_collisions, e.user_collisions, e.system_violations, e.user_violations
            ),
            Measured::Timing(t) => format!(
                "mean {:.2} ms, p95 {:.2} ms over {} iterations",
                t.mean * 1e3,
                t.p95 * 1e3,
                t.iterations
            ),
            Measured::TakenOver { taken, driven } => {
                let share = (*driven > 0).then(|| *taken as f64 / *driven as f64);
                format!("{taken}/{driven} ({})", crate::claims::pct(share))
            }
        }
    }

    /// The one sentence REPORT.md states a target's case with:
    /// `Target, name (who): rule: verdict (measurement).`
    pub fn state(&self, case: &Case) -> String {
        format!(
            "Target, {} ({}): {}: {} ({}).",
            self.name,
            case.who,
            self.rule.describe(),
            self.verdict(&case.measured),
            self.cell(&case.measured)
        )
    }

    /// The sentence for several cases, as [`Target::state`] for one:
    /// `Target, name (who): rule: verdict (summary).`
    pub fn state_cases(&self, who: &str, cases: &[Case]) -> String {
        format!(
            "Target, {} ({who}): {}: {} ({}).",
            self.name,
            self.rule.describe(),
            self.judge(cases),
            self.summary(cases)
        )
    }

    /// The verdict over every case: met when every measured case is, not
    /// measured without a measured case.
    pub fn judge(&self, cases: &[Case]) -> Verdict {
        let verdicts: Vec<Verdict> = (cases.iter())
            .map(|c| self.verdict(&c.measured))
            .filter(|v| *v != Verdict::NotMeasured)
            .collect();
        if verdicts.is_empty() {
            Verdict::NotMeasured
        } else if verdicts.contains(&Verdict::NotMet) {
            Verdict::NotMet
        } else {
            Verdict::Met
        }
    }

    /// The cases in one cell: the measurement of a single case, else how many
    /// are met and the first few that are not.
    pub fn summary(&self, cases: &[Case]) -> String {
        if let [case] = cases {
            return self.cell(&case.measured);
        }
        let measured: Vec<&Case> = (cases.iter())
            .filter(|c| self.verdict(&c.measured) != Verdict::NotMeasured)
            .collect();
        if measured.is_empty() {
            return "-".to_owned();
        }
        let missed: Vec<&&Case> = (measured.iter())
            .filter(|c| self.verdict(&c.measured) == Verdict::NotMet)
            .collect();
        let mut text = format!(
            "met by {} of {}",
            measured.len() - missed.len(),
            measured.len()
        );
        if !missed.is_empty() {
            const SHOWN: usize = 3;
            let names: Vec<String> = (missed.iter().take(SHOWN))
                .map(|c| format!("{} ({})", c.who, self.cell(&c.measured)))
                .collect();
            text.push_str(&format!("; not met: {}", names.join(", ")));
            if missed.len() > SHOWN {
                text.push_str(&format!(" and {} more", missed.len() - SHOWN));
            }
        }
        text
    }
}

/// `-35 %` for a reduction of 0.35 (the change of the mean), `n/a` without one.
fn signed_percent(reduction: Option<f64>) -> String {
    reduction.map_or_else(|| "n/a".to_owned(), |r| format!("{:+.0} %", -100.0 * r))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pairs(without: f64, with: f64, worse: usize, capped: usize) -> Measured {
        Measured::Transfer(Pairs {
            pairs: 6,
            without: Some(without),
            with: Some(with),
            worse,
            capped,
        })
    }

    /// A transfer with no pair to measure.
    fn no_pairs() -> Measured {
        Measured::Transfer(Pairs {
            pairs: 0,
            without: None,
            with: None,
            worse: 0,
            capped: 0,
        })
    }

    #[test]
    fn every_target_has_one_entry_and_nothing_measured_is_not_measured() {
        for (i, t) in TARGETS.iter().enumerate() {
            assert!(
                !TARGETS[..i].iter().any(|o| o.id == t.id),
                "{:?} twice",
                t.id
            );
            assert_eq!(target(t.id), t);
            assert_eq!(t.judge(&[]), Verdict::NotMeasured);
            assert!(t.source.starts_with("docs/experiments/"));
        }
    }

    #[test]
    fn a_transfer_meets_its_target_only_with_no_pair_worse_and_none_capped() {
        let t = target(TargetId::TransferSpeedCase);
        assert_eq!(t.verdict(&pairs(2.0, 1.0, 0, 0)), Verdict::Met);
        assert_eq!(t.verdict(&pairs(2.0, 1.02, 0, 0)), Verdict::NotMet);
        assert_eq!(t.verdict(&pairs(2.0, 0.5, 1, 0)), Verdict::NotMet);
        assert_eq!(t.verdict(&pairs(2.0, 0.5, 0, 1)), Verdict::NotMet);
        let headway = target(TargetId::TransferHeadway);
        assert_eq!(headway.verdict(&pairs(3.0, 1.0, 0, 0)), Verdict::NotMet);
        assert!(headway.rule.describe().starts_with("at least 80 % fewer"));
        assert_eq!(t.verdict(&no_pairs()), Verdict::NotMeasured);
    }

    #[test]
    fn an_out_of_class_transfer_is_judged_on_its_worst_pair_alone() {
        let t = target(TargetId::OutOfClassTransfer);
        // No gain, even a loss, is met while no pair is worse by more than one.
        assert_eq!(t.verdict(&pairs(1.0, 1.4, 0, 2)), Verdict::Met);
        assert_eq!(t.verdict(&pairs(1.0, 0.2, 1, 0)), Verdict::NotMet);
        assert_eq!(t.verdict(&no_pairs()), Verdict::NotMeasured);
    }

    #[test]
    fn accumulation_after_two_scenes_says_so() {
        let t = target(TargetId::OutOfClassAccumulation);
        assert_eq!(
            t.rule.describe(),
            "at most 0.5 takeovers after the first two scenes"
        );
        assert_eq!(t.verdict(&Measured::Takeovers(Some(0.5))), Verdict::Met);
        assert_eq!(t.verdict(&Measured::Takeovers(Some(0.51))), Verdict::NotMet);
        assert_eq!(t.verdict(&Measured::Takeovers(None)), Verdict::NotMeasured);
    }

    #[test]
    fn a_share_meets_its_target_at_the_bound() {
        let t = target(TargetId::SpreadAfterLearning);
        let share = |hits, runs| Measured::Share { hits, runs };
        assert_eq!(t.verdict(&share(89, 93)), Verdict::Met);
        assert_eq!(t.verdict(&share(19, 20)), Verdict::Met);
        assert_eq!(t.verdict(&share(87, 93)), Verdict::NotMet);
        assert_eq!(t.verdict(&share(0, 0)), Verdict::NotMeasured);
    }

    #[test]
    fn the_timing_target_needs_both_the_mean_and_the_p95_below() {
        let t = target(TargetId::LearningTime);
        let timing = |mean_ms: f64, p95_ms: f64| {
            Measured::Timing(Timing {
                iterations: 100,
                mean: mean_ms * 1e-3,
                p50: mean_ms * 1e-3,
                p95: p95_ms * 1e-3,
                max: p95_ms * 1e-3,
                part_means: Default::default(),
                part_p95: Default::default(),
            })
        };
        assert_eq!(t.verdict(&timing(0.25, 0.66)), Verdict::Met);
        assert_eq!(t.verdict(&timing(2.5, 4.0)), Verdict::NotMet);
        assert_eq!(t.verdict(&timing(1.0, 5.0)), Verdict::NotMet);
    }

    #[test]
    fn a_target_is_stated_in_one_sentence_and_summarized_over_its_cases() {
        let t = target(TargetId::Accumulation);
        let cases = [
            Case {
                who: "deterministic, speed cases".into(),
                measured: Measured::Takeovers(Some(0.27)),
            },
            Case {
                who: "spread-2%, speed cases".into(),
                measured: Measured::Takeovers(Some(5.47)),
            },
            Case {
                who: "empty".into(),
                measured: Measured::Takeovers(None),
            },
        ];
        assert_eq!(
            t.state(&cases[0]),
            "Target, one user through the scenes in sequence (deterministic, speed cases): \
             at most 0.5 takeovers after the first scene: met (0.27 takeovers)."
        );
        assert_eq!(t.judge(&cases), Verdict::NotMet);
        assert_eq!(
            t.summary(&cases),
            "met by 1 of 2; not met: spread-2%, speed cases (5.47 takeovers)"
        );
        assert_eq!(
            t.state_cases("`palc`", &cases),
            "Target, one user through the scenes in sequence (`palc`): at most 0.5 takeovers \
             after the first scene: **not met** (met by 1 of 2; not met: spread-2%, speed cases \
             (5.47 takeovers))."
        );
        let safety = target(TargetId::Safety);
        let one = Events {
            user_violations: 1,
            ..Events::default()
        };
        assert_eq!(safety.verdict(&Measured::Events(one)), Verdict::NotMet);
        assert_eq!(
            safety.verdict(&Measured::Events(Events::default())),
            Verdict::Met
        );
    }
}
