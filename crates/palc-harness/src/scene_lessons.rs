//! Averaging the lessons of a scene (`[aggregator] average_lessons`,
//! docs/paper-mapping.md, "Users with spread").
//!
//! A user with spread drives each lane change a little differently; a learner
//! that follows each lesson's path chases the last draw and oscillates around the
//! user. With averaging, the expert of the n-th lesson of a scene follows the mean
//! of the n paths seen, taken in the time of each lane change: with `S_j`, `D_j`
//! the start and duration fitted to lesson `j` ([`UserLaneChange`]) and
//! `S̄`, `D̄` their means, the mean path is
//!
//! `l̄(t) = (1/n) Σ_j l_j(S_j + (t − S̄) / D̄ · D_j)`,
//!
//! each path sampled at the same fraction of its own lane change, over the
//! lessons that started within one lane-change duration of the median start: a
//! user with spread who takes another gap of the target lane made another
//! decision, and the mean of two gaps is a lane change into neither. A user who
//! repeats a lane change exactly (a deterministic user) gives the same path back,
//! so averaging costs them nothing; for a user with spread the start, duration
//! and shape each converge to their means (step `1/n`), whatever the profile's
//! shape.

use crate::onset::UserLaneChange;

/// The lessons of the current scene: the user's fitted lane change and the
/// lateral path (m, one value per step) each lesson's expert followed.
#[derive(Debug, Clone, Default)]
pub(crate) struct SceneLessons {
    seen: Vec<(UserLaneChange, Vec<f64>)>,
}

impl SceneLessons {
    /// Adds a lesson and returns the mean path of the lessons so far that started
    /// with the median start (within one lane-change duration of it), at steps
    /// `0..path.len()` of `dt`. A path of another length than the first (another
    /// horizon) starts the mean again.
    pub(crate) fn add(&mut self, user: UserLaneChange, path: Vec<f64>, dt: f64) -> Vec<f64> {
        if self
            .seen
            .first()
            .is_some_and(|(_, p)| p.len() != path.len())
        {
            self.seen.clear();
        }
        self.seen.push((user, path));
        let mode = self.mode();
        let n = mode.len() as f64;
        let start = mode.iter().map(|(u, _)| u.start_s).sum::<f64>() / n;
        let duration = mode.iter().map(|(u, _)| u.duration_s).sum::<f64>() / n;
        let steps = self.seen[0].1.len();
        (0..steps)
            .map(|i| {
                let fraction = (i as f64 * dt - start) / duration;
                let sum: f64 = (mode.iter())
                    .map(|(u, p)| sampled(p, (u.start_s + fraction * u.duration_s) / dt))
                    .sum();
                sum / n
            })
            .collect()
    }

    /// The lessons that started with the median start: within one lane-change
    /// duration of it. A start further away is another decision (the user took
    /// another gap of the target lane), and a mean across two gaps is a lane
    /// change into neither.
    fn mode(&self) -> Vec<&(UserLaneChange, Vec<f64>)> {
        let mut starts: Vec<f64> = self.seen.iter().map(|(u, _)| u.start_s).collect();
        starts.sort_by(f64::total_cmp);
        let median = starts[(starts.len() - 1) / 2];
        (self.seen.iter())
            .filter(|(u, _)| (u.start_s - median).abs() <= u.duration_s)
            .collect()
    }
}

/// `path` at the fractional step `position`, linear between steps and held
/// beyond its ends.
fn sampled(path: &[f64], position: f64) -> f64 {
    let last = path.len().saturating_sub(1);
    let position = position.clamp(0.0, last as f64);
    let below = position.floor() as usize;
    let above = (below + 1).min(last);
    let fraction = position - below as f64;
    path[below] + fraction * (path[above] - path[below])
}

#[cfg(test)]
mod tests {
    use super::*;

    const DT: f64 = 0.1;

    fn lane_change(start_s: f64, duration_s: f64) -> (UserLaneChange, Vec<f64>) {
        let user = UserLaneChange {
            start_s,
            duration_s,
            target_l: 3.5,
            shape: crate::onset::Shape::QUINTIC,
        };
        let path = (0..120).map(|i| user.lateral(i as f64 * DT)).collect();
        (user, path)
    }

    #[test]
    fn lessons_in_another_gap_stay_out_of_the_mean() {
        // Two lane changes into the gap at 4 s, one into the gap at 13 s: the mean
        // is the first gap's, not a lane change at 7 s.
        let mut lessons = SceneLessons::default();
        let mut mean = Vec::new();
        for start in [4.0, 13.0, 4.2] {
            let (user, path) = lane_change(start, 2.0);
            mean = lessons.add(user, path, DT);
        }
        let (_, expected) = lane_change(4.1, 2.0);
        for (a, b) in mean.iter().zip(&expected) {
            assert!((a - b).abs() < 1e-9, "{a} != {b}");
        }
    }

    #[test]
    fn a_repeated_lane_change_is_its_own_mean() {
        let (user, path) = lane_change(4.03, 2.1);
        let mut lessons = SceneLessons::default();
        for _ in 0..3 {
            let mean = lessons.add(user, path.clone(), DT);
            for (a, b) in mean.iter().zip(&path) {
                assert!((a - b).abs() < 1e-12, "{a} != {b}");
            }
        }
    }

    #[test]
    fn the_mean_of_draws_is_the_lane_change_at_the_mean_start_and_duration() {
        let mut lessons = SceneLessons::default();
        let mut mean = Vec::new();
        for (start, duration) in [(4.0, 2.0), (4.4, 2.2), (3.8, 1.9), (4.2, 2.3)] {
            let (user, path) = lane_change(start, duration);
            mean = lessons.add(user, path, DT);
        }
        let (_, expected) = lane_change(4.1, 2.1);
        for (i, (a, b)) in mean.iter().zip(&expected).enumerate() {
            assert!((a - b).abs() < 0.02, "step {i}: {a} against {b}");
        }
    }

    #[test]
    fn another_horizon_starts_the_mean_again() {
        let mut lessons = SceneLessons::default();
        let (user, path) = lane_change(4.0, 2.0);
        lessons.add(user, path, DT);
        let (user, path) = lane_change(5.0, 2.5);
        let short: Vec<f64> = path[..100].to_vec();
        let mean = lessons.add(user, short.clone(), DT);
        assert_eq!(mean.len(), short.len());
        for (a, b) in mean.iter().zip(&short) {
            assert!((a - b).abs() < 1e-12, "{a} != {b}");
        }
    }
}
