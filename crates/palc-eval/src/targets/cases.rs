//! How each of palc's targets is measured on the indexed runs: its cases
//! ([`Target::cases`]), one per method, user kind, axis or user.

use palc_harness::Method;

use crate::config::UserKind;
use crate::plan::Experiment;
use crate::results::{Iteration, RunRow};
use crate::scenes::{self, Axis};
use crate::stats::{self, Summary};
use crate::views::Indexed;

use super::{Case, Events, Measured, Pairs, Target, TargetId};

impl Target {
    /// This target's cases for `method` over the indexed runs: the method as a
    /// whole, or each of `kinds` (user kinds) that has runs of the target's
    /// experiment. The safety target counts every method at once.
    pub fn cases(&self, index: &Indexed, method: Method, kinds: &[UserKind]) -> Vec<Case> {
        let whole = |measured: Measured| {
            vec![Case {
                who: format!("`{}`", method.name()),
                measured,
            }]
        };
        match self.id {
            TargetId::TransferSpeedCase => {
                transfer(index, method, Axis::SpeedCase).map_or_else(Vec::new, whole)
            }
            TargetId::TransferHeadway => {
                transfer(index, method, Axis::Headway).map_or_else(Vec::new, whole)
            }
            TargetId::Accumulation => accumulation(index, method, 1, |_| true),
            TargetId::KindsLearned => (kinds.iter())
                .filter_map(|kind| {
                    let s = Summary::of(index.grid(method, &kind.name).iter().copied());
                    (s.runs > 0).then(|| {
                        case(
                            kind,
                            Measured::Share {
                                hits: s.personalized,
                                runs: s.runs,
                            },
                        )
                    })
                })
                .collect(),
            TargetId::KindTransfer => (kinds.iter())
                .filter_map(|kind| {
                    let t = stats::transfer(&index.with_transfer(method, &kind.name));
                    (t.pairs > 0).then(|| case(kind, Measured::Reduction(t.reduction)))
                })
                .collect(),
            TargetId::SpreadAfterLearning => (kinds.iter())
                .filter(|kind| kind.has_spread())
                .filter_map(|kind| {
                    let f = stats::frozen(index.grid(method, &kind.name))?;
                    Some(case(
                        kind,
                        Measured::Share {
                            hits: f.within_margin,
                            runs: f.runs,
                        },
                    ))
                })
                .collect(),
            TargetId::ClosedLoop => (kinds.iter())
                .filter_map(|kind| closed_loop(index, method, &kind.name).map(|m| case(kind, m)))
                .collect(),
            TargetId::Safety => {
                let iterations = index.rows().iter().flat_map(|r| &r.iterations);
                let events = Events::of(iterations);
                let any = index.rows().iter().any(|r| !r.iterations.is_empty());
                if any {
                    vec![Case {
                        who: "every method".to_owned(),
                        measured: Measured::Events(events),
                    }]
                } else {
                    Vec::new()
                }
            }
            TargetId::LearningTime => {
                let grid = index.of_experiment(Experiment::Grid, method);
                let learning: Vec<&Iteration> = (grid.iter())
                    .flat_map(|r| r.iterations.iter().filter(|it| it.takeover))
                    .collect();
                stats::timing_of(&learning).map_or_else(Vec::new, |t| whole(Measured::Timing(t)))
            }
            TargetId::DriveOwnFamilies => drive(index, method, kinds, |k| {
                !k.has_spread() && !k.is_out_of_class()
            }),
            TargetId::DriveOutOfClass => drive(index, method, kinds, UserKind::is_out_of_class),
            TargetId::RecordedTransfer => (kinds.iter())
                .filter(|kind| kind.recorded.is_some())
                .filter_map(|kind| {
                    let t = stats::transfer(&index.with_transfer(method, &kind.name));
                    (t.pairs > 0).then(|| case(kind, Measured::Reduction(t.reduction)))
                })
                .collect(),
            TargetId::OutOfClassTransfer => (kinds.iter())
                .filter(|kind| out_of_class_family(kind))
                .filter_map(|kind| {
                    let t = stats::transfer(&index.with_transfer(method, &kind.name));
                    (t.pairs > 0).then(|| {
                        let pairs = Pairs {
                            pairs: t.pairs,
                            without: t.without,
                            with: t.with,
                            worse: t.worse,
                            capped: t.pairs - t.personalized.1,
                        };
                        case(kind, Measured::Transfer(pairs))
                    })
                })
                .collect(),
            TargetId::OutOfClassAccumulation => {
                let family =
                    |name: &str| (kinds.iter()).any(|k| k.name == name && out_of_class_family(k));
                accumulation(index, method, 2, family)
            }
        }
    }
}

/// The drive's lane changes 11-50 of `method`, per user kind of `kinds` that
/// `includes` and that drove any of them.
fn drive(
    index: &Indexed,
    method: Method,
    kinds: &[UserKind],
    includes: impl Fn(&UserKind) -> bool,
) -> Vec<Case> {
    let drives = crate::drive_report::drives(index.rows(), &[method], Experiment::Drive);
    (kinds.iter())
        .filter(|kind| includes(kind))
        .filter_map(|kind| {
            let drive = drives.iter().find(|d| d.user == kind.name)?;
            let (taken, driven) = drive.band(crate::drive_report::BANDS[1]);
            (driven > 0).then(|| case(kind, Measured::TakenOver { taken, driven }))
        })
        .collect()
}

/// A simulated family outside the one-cue rules (MOBIL's incentive, two cues):
/// the out-of-class families, whose goals differ from recorded drivers'.
fn out_of_class_family(kind: &UserKind) -> bool {
    kind.is_out_of_class() && kind.recorded.is_none()
}

/// A case of one user kind.
fn case(kind: &UserKind, measured: Measured) -> Case {
    Case {
        who: kind.name.clone(),
        measured,
    }
}

/// The transfer matrix's pairs of `method` along `axis`; `None` without pairs.
pub fn transfer(index: &Indexed, method: Method, axis: Axis) -> Option<Measured> {
    let pairs = scenes::matrix_pairs(index.rows(), method, axis);
    if pairs.is_empty() {
        return None;
    }
    let without: Vec<f64> = pairs.iter().map(|p| p.without).collect();
    let with: Vec<f64> = pairs.iter().map(|p| p.with).collect();
    Some(Measured::Transfer(Pairs {
        pairs: pairs.len(),
        without: scenes::mean(&without),
        with: scenes::mean(&with),
        worse: pairs.iter().filter(|p| p.with > p.without + 1.0).count(),
        capped: pairs.iter().filter(|p| !p.personalized).count(),
    }))
}

/// The accumulation chains of `method`: one case per axis and user kind that
/// `includes` (by name), the mean takeovers per scene after the first
/// `after_scenes` of each chain (`None` when no chain is that long).
fn accumulation(
    index: &Indexed,
    method: Method,
    after_scenes: usize,
    includes: impl Fn(&str) -> bool,
) -> Vec<Case> {
    let mut cases = Vec::new();
    for axis in Axis::BOTH {
        let kinds = scenes::accumulation_places(index.rows(), method, axis);
        if kinds.iter().map(|(_, p)| p.len()).max().unwrap_or(0) < 2 {
            continue;
        }
        for (name, places) in kinds.into_iter().filter(|(name, _)| includes(name)) {
            let following: Vec<f64> = (places.iter().skip(after_scenes))
                .flatten()
                .copied()
                .collect();
            cases.push(Case {
                who: format!("{name}, {}s", axis.name()),
                measured: Measured::Takeovers(scenes::mean(&following)),
            });
        }
    }
    cases
}

/// Closed loop against open loop on the same cells of `method` and `user`;
/// `None` without closed-loop runs.
pub fn closed_loop(index: &Indexed, method: Method, user: &str) -> Option<Measured> {
    let pairs = index.closed_loop_pairs(method, user);
    let open = Summary::of(pairs.iter().map(|p| p.0));
    let closed = Summary::of(pairs.iter().map(|p| p.1));
    let rate = |s: &Summary| (s.runs > 0).then(|| 100.0 * s.personalized as f64 / s.runs as f64);
    Some(Measured::Gaps {
        success: (rate(&open)?, rate(&closed)?),
        takeovers: (open.mean?, closed.mean?),
    })
}

/// The events of every lane change of `rows`.
pub fn events_of(rows: &[&RunRow]) -> Events {
    Events::of(rows.iter().flat_map(|r| &r.iterations))
}
