//! The user's own lane-change shape, seen whole in one lesson and used to place
//! the start in later ones (the driver-model issue's "any lane-change shape").
//!
//! A lesson in which the user took over before its own start shows its whole
//! lane change: at rest in its lane, then moving to the end
//! ([`super::UserLaneChange::fit_lesson`] holds the start within what was seen).
//! That path, stretched over its duration, is the user's shape
//! ([`OwnShape::seen`]), which the experience keeps
//! ([`palc_aggregator::OwnLaneChange`]). A later lesson that sees only the end of
//! a lane change (the user had already started at the takeover) is fitted with
//! it beside the models ([`super::fit`]): through the same two crossings, the
//! one with the smaller squared error wins. A recorded driver's gradual,
//! asymmetric onset is in no model; fitted with the models, its start came out
//! 0.25-1.3 s early (docs/experiments/0075-what-palc-believes-and-recorded-drivers.md).
//!
//! Until a lesson shows it whole, a lesson that pins a model down stands for it
//! ([`super::UserLaneChange::own_shape_fitted`]: taken over early enough for the
//! peak to be fitted, and explained within a centimetre): a late-peak user's
//! later lessons, seen only from a third of the way on, then keep their start.
//!
//! The shape assumes what the models assume: the user changes lanes with the
//! same shape in every scene, stretched over its duration and the lane's width.

use std::sync::Arc;

use palc_aggregator::{MAX_OWN_LANE_CHANGE_SAMPLES, OwnLaneChange};

/// Samples per lane change of the stored shape: a step of 1 % of the duration
/// (0.02-0.06 s for the paper's 2-6 s), finer than the plans' 0.1 s steps
/// that the shape is read from, so the resampling adds no visible error.
const SAMPLES: usize = 101;

/// The user's shape: the fraction of the lane change done at equally spaced
/// fractions of its duration, from 0 to 1, never decreasing.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct OwnShape {
    progress: Arc<[f64]>,
}

impl OwnShape {
    /// The shape of a lane change the user drove as `driven_l` (m, steps of
    /// `dt`) towards `target_l`, from `start_s` to `end_s`: sampled between the
    /// steps, held between 0 and 1 and never decreasing (what the checks of
    /// [`OwnLaneChange`] require; a user's own path does not turn back by more
    /// than the solver's rounding). `None` when the path ends before `end_s` or
    /// the lane change is empty.
    pub(crate) fn seen(
        driven_l: &[f64],
        dt: f64,
        target_l: f64,
        start_s: f64,
        end_s: f64,
    ) -> Option<OwnShape> {
        let last_s = driven_l.len().checked_sub(1)? as f64 * dt;
        if target_l == 0.0 || !(start_s >= 0.0 && start_s < end_s && end_s <= last_s) {
            return None;
        }
        let at = |t: f64| {
            let i = ((t / dt).floor() as usize).min(driven_l.len() - 2);
            let w = (t / dt - i as f64).clamp(0.0, 1.0);
            (driven_l[i] + w * (driven_l[i + 1] - driven_l[i])) / target_l
        };
        Some(OwnShape::held(
            (0..SAMPLES)
                .map(|k| at(start_s + (end_s - start_s) * k as f64 / (SAMPLES - 1) as f64))
                .collect(),
        ))
    }

    /// The shape of a lane-change model: `fraction(x)`, the fraction of the lane
    /// change done at the fraction `x` of its duration, sampled and held as
    /// [`OwnShape::seen`] holds a driven path.
    pub(crate) fn of_model(fraction: impl Fn(f64) -> f64) -> OwnShape {
        OwnShape::held(
            (0..SAMPLES)
                .map(|k| fraction(k as f64 / (SAMPLES - 1) as f64))
                .collect(),
        )
    }

    /// Samples of the fraction done, held in [0, 1] and never decreasing, from 0
    /// at the first to 1 at the last: what [`OwnLaneChange::validate`] requires.
    fn held(mut progress: Vec<f64>) -> OwnShape {
        let mut highest = 0.0f64;
        for p in &mut progress {
            highest = highest.max(p.clamp(0.0, 1.0));
            *p = highest;
        }
        if let Some(first) = progress.first_mut() {
            *first = 0.0;
        }
        if let Some(last) = progress.last_mut() {
            *last = 1.0;
        }
        OwnShape {
            progress: progress.into(),
        }
    }

    /// The shape an experience keeps, `None` when it fails the checks of
    /// [`OwnLaneChange::validate`] (a loaded file is checked on load).
    pub(crate) fn stored(own: &OwnLaneChange) -> Option<OwnShape> {
        own.validate().ok()?;
        debug_assert!(own.progress.len() <= MAX_OWN_LANE_CHANGE_SAMPLES);
        Some(OwnShape {
            progress: own.progress.as_slice().into(),
        })
    }

    /// The shape as the experience keeps it.
    pub(crate) fn to_stored(&self) -> OwnLaneChange {
        OwnLaneChange {
            progress: self.progress.to_vec(),
        }
    }

    /// The fraction of the lane change done at the fraction `x` of its duration,
    /// interpolated between the samples.
    pub(crate) fn fraction(&self, x: f64) -> f64 {
        let n = self.progress.len() - 1;
        let u = x.clamp(0.0, 1.0) * n as f64;
        let i = (u.floor() as usize).min(n - 1);
        let w = u - i as f64;
        self.progress[i] + w * (self.progress[i + 1] - self.progress[i])
    }

    /// The first fraction of the duration at which the fraction `p` of the lane
    /// change is done: the inverse of [`OwnShape::fraction`] where it rises.
    pub(crate) fn inverse(&self, p: f64) -> f64 {
        let n = self.progress.len() - 1;
        let p = p.clamp(0.0, 1.0);
        let i = self.progress.partition_point(|&q| q < p);
        if i == 0 {
            return 0.0;
        }
        let (a, b) = (self.progress[i - 1], self.progress[i.min(n)]);
        let w = if b > a { (p - a) / (b - a) } else { 0.0 };
        ((i - 1) as f64 + w) / n as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A lane change whose lateral speed jumps at the start and falls off as a
    /// cubic, as `fit.rs`'s tests' abrupt profile.
    fn abrupt(x: f64) -> f64 {
        1.0 - (1.0 - x.clamp(0.0, 1.0)).powi(3)
    }

    #[test]
    fn a_shape_seen_whole_is_the_users_own() {
        let (start, duration, dt) = (3.0, 2.5, 0.1);
        let driven: Vec<f64> = (0..100)
            .map(|i| 3.5 * abrupt((i as f64 * dt - start) / duration))
            .collect();
        let own = OwnShape::seen(&driven, dt, 3.5, start, start + duration).unwrap();
        for x in [0.0, 0.1, 0.25, 0.5, 0.9, 1.0] {
            // Linear between steps of 4 % of the duration: within 0.4 % of the move.
            assert!((own.fraction(x) - abrupt(x)).abs() < 4e-3, "{x}");
        }
        assert!(own.to_stored().validate().is_ok());
        assert_eq!(OwnShape::stored(&own.to_stored()), Some(own));
    }

    #[test]
    fn the_inverse_inverts_where_the_shape_rises() {
        let progress: Vec<f64> = (0..SAMPLES)
            .map(|k| abrupt(k as f64 / (SAMPLES - 1) as f64))
            .collect();
        let own = OwnShape {
            progress: progress.into(),
        };
        for p in [0.0, 0.05, 0.1, 0.5, 0.9, 1.0] {
            assert!((own.fraction(own.inverse(p)) - p).abs() < 1e-12, "{p}");
        }
    }

    #[test]
    fn a_path_that_ends_too_soon_or_an_empty_lane_change_gives_no_shape() {
        let driven = vec![0.0, 0.5, 1.0, 2.0, 3.5];
        assert!(OwnShape::seen(&driven, 0.1, 3.5, 0.0, 0.5).is_none());
        assert!(OwnShape::seen(&driven, 0.1, 3.5, 0.2, 0.2).is_none());
        assert!(OwnShape::seen(&driven, 0.1, 0.0, 0.0, 0.4).is_none());
        assert!(OwnShape::seen(&driven, 0.1, 3.5, 0.0, 0.4).is_some());
    }
}
