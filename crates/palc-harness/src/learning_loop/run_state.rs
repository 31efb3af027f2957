//! The run's state: the lane changes driven, the takeovers, the streak since
//! the last one and whether the last lesson failed; the stopping rules
//! ([`termination`]) read nothing else, and the summary is made from it.

use crate::config::StoppingConfig;
use crate::record::{LaneChangeRecord, Outcome, RunSummary};

/// What a run has done so far.
#[derive(Debug, Clone, Default)]
pub(super) struct RunState {
    /// One record per lane change.
    pub(super) records: Vec<LaneChangeRecord>,
    /// Takeovers so far.
    pub(super) takeovers: usize,
    /// Takeover-free lane changes since the last takeover.
    pub(super) streak: usize,
    /// Lessons the method could not learn from.
    pub(super) learning_failures: usize,
    /// Whether the last lane change's lesson failed.
    pub(super) last_lesson_failed: bool,
}

impl RunState {
    /// Counts a driven lane change, taken over or not; its lesson is yet to come.
    pub(super) fn count(&mut self, record: LaneChangeRecord) {
        self.last_lesson_failed = false;
        if record.takeover.is_some() {
            self.takeovers += 1;
            self.streak = 0;
        } else {
            self.streak += 1;
        }
        self.records.push(record);
    }

    /// The summary of a run that ended with `outcome`.
    pub(super) fn summary(&self, outcome: Outcome, stopping: &StoppingConfig) -> RunSummary {
        let records = &self.records;
        let window = &records[records.len().saturating_sub(stopping.spread_window)..];
        let rate = |f: fn(&LaneChangeRecord) -> bool| {
            window.iter().filter(|r| f(r)).count() as f64 / window.len().max(1) as f64
        };
        RunSummary {
            outcome,
            takeovers: self.takeovers,
            cap: stopping.max_takeovers,
            lane_changes: records.len(),
            learning_failures: self.learning_failures,
            final_max_deviation_m: records.last().map_or(0.0, |r| r.max_deviation_m),
            final_takeover_rate: rate(|r| r.takeover.is_some()),
            ceiling_takeover_rate: rate(|r| r.nominal_plan_taken_over),
            frozen: None,
        }
    }
}

/// The rule of [`crate::LearningLoop::termination`], a pure function of the
/// run's state.
pub(super) fn termination(stopping: &StoppingConfig, run: &RunState) -> Option<Outcome> {
    let records = &run.records;
    if run.takeovers >= stopping.max_takeovers {
        return Some(Outcome::CapReached);
    }
    if run.last_lesson_failed {
        return None;
    }
    if success(records, run.streak, stopping) {
        return Some(Outcome::Personalized);
    }
    let lane_change_cap = stopping
        .max_lane_changes
        .max(stopping.max_takeovers + stopping.success_streak);
    (records.len() >= lane_change_cap).then_some(Outcome::CapReached)
}

/// Whether the run has succeeded: `success_streak` takeover-free lane changes in a
/// row for a deterministic user; for a user with spread, the takeover rate over the
/// last window within the margin of the nominal plan's rate on the same draws.
fn success(records: &[LaneChangeRecord], streak: usize, stopping: &StoppingConfig) -> bool {
    let with_spread = records.last().is_some_and(|r| r.with_spread);
    if !with_spread {
        return streak >= stopping.success_streak;
    }
    if records.len() < stopping.spread_window {
        return false;
    }
    let window = &records[records.len() - stopping.spread_window..];
    let n = window.len() as f64;
    let taken = window.iter().filter(|r| r.takeover.is_some()).count() as f64 / n;
    let ceiling = window.iter().filter(|r| r.nominal_plan_taken_over).count() as f64 / n;
    taken <= ceiling + stopping.spread_margin
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::record::Takeover;
    use palc_aggregator::Timings;

    fn stopping() -> StoppingConfig {
        StoppingConfig {
            max_takeovers: 4,
            success_streak: 3,
            spread_window: 5,
            spread_margin: 0.1,
            max_lane_changes: 12,
            frozen_lane_changes: 0,
        }
    }

    /// A lane change, taken over or not, of a user with or without spread whose
    /// nominal plan would (not) have been taken over.
    fn record(
        index: usize,
        taken: bool,
        with_spread: bool,
        nominal_taken: bool,
    ) -> LaneChangeRecord {
        LaneChangeRecord {
            index,
            takeovers_before: 0,
            takeover: taken.then_some(Takeover {
                step: 10,
                time_s: 1.0,
                distance_m: 20.0,
                deviation_m: 0.4,
                cause: Default::default(),
            }),
            max_deviation_m: if taken { 0.4 } else { 0.1 },
            perceived_safety_ratio: if taken { 0.5 } else { 1.0 },
            times: Timings::default(),
            dt: 0.1,
            planned_l: Vec::new(),
            expected_l: Vec::new(),
            driven_l: Vec::new(),
            with_spread,
            nominal_plan_taken_over: nominal_taken,
            safety: Default::default(),
            user_safety: Default::default(),
            planned_safety: Default::default(),
            safety_refusal: None,
            closed_loop: None,
            learning_error: None,
        }
    }

    /// Records of a deterministic user from a pattern: `T` a takeover, `-` none.
    fn deterministic(pattern: &str) -> Vec<LaneChangeRecord> {
        pattern
            .chars()
            .enumerate()
            .map(|(i, c)| record(i, c == 'T', false, false))
            .collect()
    }

    /// The counters the run keeps besides its records.
    #[derive(Debug, Clone, Copy, Default)]
    struct Progress {
        takeovers: usize,
        streak: usize,
        last_lesson_failed: bool,
    }

    /// The rule on `records` with the counters of `progress`.
    fn termination(
        stopping: &StoppingConfig,
        records: &[LaneChangeRecord],
        progress: Progress,
    ) -> Option<Outcome> {
        let run = RunState {
            records: records.to_vec(),
            takeovers: progress.takeovers,
            streak: progress.streak,
            learning_failures: 0,
            last_lesson_failed: progress.last_lesson_failed,
        };
        super::termination(stopping, &run)
    }

    /// Replays `pattern` through the counters the loop keeps.
    fn progress(pattern: &str) -> Progress {
        pattern.chars().fold(Progress::default(), |p, c| match c {
            'T' => Progress {
                takeovers: p.takeovers + 1,
                streak: 0,
                ..p
            },
            _ => Progress {
                streak: p.streak + 1,
                ..p
            },
        })
    }

    fn judge(pattern: &str) -> Option<Outcome> {
        termination(&stopping(), &deterministic(pattern), progress(pattern))
    }

    #[test]
    fn a_deterministic_user_personalizes_after_the_success_streak() {
        assert_eq!(judge(""), None);
        assert_eq!(judge("T-"), None);
        assert_eq!(judge("T--"), None);
        assert_eq!(judge("T---"), Some(Outcome::Personalized));
        assert_eq!(judge("---"), Some(Outcome::Personalized));
    }

    #[test]
    fn the_takeover_cap_ends_the_run_before_anything_else() {
        assert_eq!(judge("TTT"), None);
        assert_eq!(judge("TTTT"), Some(Outcome::CapReached));
        assert_eq!(judge("T-T-T--T"), Some(Outcome::CapReached));
        let failed = Progress {
            last_lesson_failed: true,
            ..progress("TTTT")
        };
        let records = deterministic("TTTT");
        assert_eq!(
            termination(&stopping(), &records, failed),
            Some(Outcome::CapReached)
        );
    }

    #[test]
    fn after_a_failed_lesson_only_the_takeover_cap_is_checked() {
        // With spread, a window within the margin would be success, and 12 lane
        // changes reach the lane-change cap; a failed lesson defers both.
        let records: Vec<_> = (0..12).map(|i| record(i, i == 11, true, i == 11)).collect();
        let p = Progress {
            takeovers: 1,
            streak: 0,
            last_lesson_failed: true,
        };
        assert_eq!(termination(&stopping(), &records, p), None);
        let p = Progress {
            last_lesson_failed: false,
            ..p
        };
        assert_eq!(
            termination(&stopping(), &records, p),
            Some(Outcome::Personalized)
        );
    }

    #[test]
    fn a_user_with_spread_is_judged_on_the_window_against_the_ceiling() {
        let s = stopping();
        // Five lane changes, two taken over, the nominal plan would have had one:
        // 0.4 > 0.2 + 0.1, not yet personalized.
        let pattern = [true, false, true, false, false];
        let records: Vec<_> = (pattern.iter().enumerate())
            .map(|(i, &t)| record(i, t, true, i == 0))
            .collect();
        let p = Progress {
            takeovers: 2,
            streak: 2,
            last_lesson_failed: false,
        };
        assert_eq!(termination(&s, &records, p), None);
        // Too short a window is never success, whatever the streak.
        assert_eq!(
            termination(&s, &records[..4], Progress { streak: 9, ..p }),
            None
        );
        // The ceiling at two of five: 0.4 <= 0.4 + 0.1.
        let records: Vec<_> = (pattern.iter().enumerate())
            .map(|(i, &t)| record(i, t, true, i < 2))
            .collect();
        assert_eq!(termination(&s, &records, p), Some(Outcome::Personalized));
    }

    #[test]
    fn a_user_with_spread_stops_at_the_lane_change_cap() {
        let s = stopping();
        let records: Vec<_> = (0..12)
            .map(|i| record(i, i % 2 == 0, true, false))
            .collect();
        let p = Progress {
            takeovers: 3,
            streak: 1,
            last_lesson_failed: false,
        };
        assert_eq!(termination(&s, &records[..11], p), None);
        assert_eq!(termination(&s, &records, p), Some(Outcome::CapReached));
        // The cap is at least max_takeovers + success_streak lane changes.
        let s = StoppingConfig {
            max_lane_changes: 1,
            ..s
        };
        assert_eq!(termination(&s, &records[..6], p), None);
        assert_eq!(termination(&s, &records[..7], p), Some(Outcome::CapReached));
    }

    #[test]
    fn counting_lane_changes_keeps_the_takeovers_and_the_streak() {
        let mut run = RunState {
            last_lesson_failed: true,
            ..RunState::default()
        };
        for record in deterministic("T--T-") {
            run.count(record);
        }
        assert_eq!((run.takeovers, run.streak, run.records.len()), (2, 1, 5));
        // A new lane change clears the last lesson's failure until its own lesson.
        assert!(!run.last_lesson_failed);
        assert_eq!(
            termination(&stopping(), &run.records, progress("T--T-")),
            super::termination(&stopping(), &run)
        );
    }
}
