//! Averaging the lessons of a scene (`[aggregator] average_lessons`;
//! docs/experiments/0050-users-with-spread-averaging-and-window.md,
//! docs/experiments/0051-one-gap-at-a-time.md and
//! docs/experiments/0063-the-gap-the-lane-changes-point-to.md).
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
//!
//! Which gap the user takes is decided by every lane change of the scene, not by
//! the lessons alone: a lane change the user accepted started within the
//! takeover threshold of the user's, so in the user's gap, and it counts there as
//! one start. Lessons exist only where a draw strayed from the plan, so while the
//! plan follows the gap most draws take, the lessons come from the others; counted
//! alone, a minority gap's lessons outnumbered the majority's and the plan moved
//! to the gap most draws do not take. A lesson in a gap the scene's lane changes
//! do not point to leaves the plan as it is.

use crate::onset::UserLaneChange;

/// The lessons of the current scene: the user's fitted lane change and the
/// lateral path (m, one value per step) each lesson's expert followed.
#[derive(Debug, Clone, Default)]
pub(crate) struct SceneLessons {
    seen: Vec<(UserLaneChange, Vec<f64>)>,
    /// The starts (s) of the lane changes of the scene the user accepted.
    accepted_starts_s: Vec<f64>,
}

/// What a lesson's expert follows, from [`SceneLessons::add`].
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SceneMean {
    /// The mean path (m, one value per step) of the lessons in the gap the scene's
    /// lane changes point to; `None` when no lesson took that gap (the plan stays).
    pub(crate) path: Option<Vec<f64>>,
    /// Whether the lesson just added is one of them: a lesson into another gap
    /// tells nothing of where the user starts in this one.
    pub(crate) includes_lesson: bool,
}

impl SceneLessons {
    /// Counts a lane change the user accepted, which started at `start_s`.
    pub(crate) fn accept(&mut self, start_s: f64) {
        self.accepted_starts_s.push(start_s);
    }

    /// Adds a lesson and returns the mean path of the lessons so far that started
    /// with the median start of the scene's lane changes (within one lane-change
    /// duration of it), at steps `0..path.len()` of `dt`. A path of another length
    /// than the first (another horizon) starts the scene again.
    pub(crate) fn add(&mut self, user: UserLaneChange, path: Vec<f64>, dt: f64) -> SceneMean {
        if self
            .seen
            .first()
            .is_some_and(|(_, p)| p.len() != path.len())
        {
            self.seen.clear();
            self.accepted_starts_s.clear();
        }
        self.seen.push((user, path));
        let mode = self.mode();
        let includes_lesson = mode.last() == Some(&(self.seen.len() - 1));
        if mode.is_empty() {
            return SceneMean {
                path: None,
                includes_lesson,
            };
        }
        let n = mode.len() as f64;
        let lessons = || mode.iter().map(|&i| &self.seen[i]);
        let start = lessons().map(|(u, _)| u.start_s).sum::<f64>() / n;
        let duration = lessons().map(|(u, _)| u.duration_s).sum::<f64>() / n;
        let steps = self.seen[0].1.len();
        let mean = (0..steps)
            .map(|i| {
                let fraction = (i as f64 * dt - start) / duration;
                let sum: f64 = lessons()
                    .map(|(u, p)| sampled(p, (u.start_s + fraction * u.duration_s) / dt))
                    .sum();
                sum / n
            })
            .collect();
        SceneMean {
            path: Some(mean),
            includes_lesson,
        }
    }

    /// The indices of the lessons that started with the median start of the
    /// scene's lane changes (lessons and accepted ones): within one lane-change
    /// duration of it. A start further away is another decision (the user took
    /// another gap of the target lane), and a mean across two gaps is a lane
    /// change into neither.
    fn mode(&self) -> Vec<usize> {
        let mut starts: Vec<f64> = (self.seen.iter().map(|(u, _)| u.start_s))
            .chain(self.accepted_starts_s.iter().copied())
            .collect();
        starts.sort_by(f64::total_cmp);
        let Some(&median) = starts.get(starts.len().saturating_sub(1) / 2) else {
            return Vec::new();
        };
        (self.seen.iter().enumerate())
            .filter(|(_, (u, _))| (u.start_s - median).abs() <= u.duration_s)
            .map(|(i, _)| i)
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
            own: None,
            onset: None,
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
            mean = lessons.add(user, path, DT).path.unwrap();
        }
        let (_, expected) = lane_change(4.1, 2.0);
        for (a, b) in mean.iter().zip(&expected) {
            assert!((a - b).abs() < 1e-9, "{a} != {b}");
        }
    }

    #[test]
    fn the_lane_changes_the_user_accepted_choose_the_gap() {
        // One lesson into the gap at 13 s, then three lane changes there the user
        // accepted: a lesson into the gap at 4 s (a draw that decided early) does
        // not move the plan, however many such lessons come while the plan is
        // right.
        let mut lessons = SceneLessons::default();
        let (late, late_path) = lane_change(13.0, 2.0);
        lessons.add(late.clone(), late_path.clone(), DT);
        for start in [12.9, 13.0, 13.1] {
            lessons.accept(start);
        }
        for start in [4.0, 4.1] {
            let (early, path) = lane_change(start, 2.0);
            let mean = lessons.add(early, path, DT);
            assert!(!mean.includes_lesson);
            for (a, b) in mean.path.unwrap().iter().zip(&late_path) {
                assert!((a - b).abs() < 1e-9, "{a} != {b}");
            }
        }
        // Counted alone, the two early lessons would have outvoted the late one.
        let mut alone = SceneLessons::default();
        alone.add(late, late_path, DT);
        for start in [4.0, 4.1] {
            let (early, path) = lane_change(start, 2.0);
            alone.add(early, path, DT);
        }
        assert_eq!(alone.mode().len(), 2);
    }

    #[test]
    fn a_lesson_in_a_gap_no_lane_change_points_to_leaves_the_plan() {
        let mut lessons = SceneLessons::default();
        for start in [12.9, 13.0, 13.1] {
            lessons.accept(start);
        }
        let (early, path) = lane_change(4.0, 2.0);
        let mean = lessons.add(early, path, DT);
        assert_eq!(mean.path, None);
        assert!(!mean.includes_lesson);
    }

    #[test]
    fn a_repeated_lane_change_is_its_own_mean() {
        let (user, path) = lane_change(4.03, 2.1);
        let mut lessons = SceneLessons::default();
        for _ in 0..3 {
            let mean = lessons.add(user.clone(), path.clone(), DT).path.unwrap();
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
            mean = lessons.add(user, path, DT).path.unwrap();
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
        let mean = lessons.add(user, short.clone(), DT).path.unwrap();
        assert_eq!(mean.len(), short.len());
        for (a, b) in mean.iter().zip(&short) {
            assert!((a - b).abs() < 1e-12, "{a} != {b}");
        }
    }
}
