//! Where a lane change started, from the part of it seen after a takeover: a
//! lane-change model ([`Shape`]) fitted through two crossings of the profile.
//! When the user took over before its own start and was seen keeping its lane,
//! the start is held between the last step it was seen at rest and the first it
//! had moved ([`UserLaneChange::fit_lesson`]): what was seen outranks the
//! model, whose onset a real driver's need not share
//! (docs/experiments/0075-what-palc-believes-and-recorded-drivers.md).

use super::own_shape::OwnShape;
use super::power::PowerOnset;
use super::shape::{Base, Shape};

/// The root mean square distance (m) within which a lane-change model explains
/// what the user drove: the fit through two crossings interpolated between 0.1 s
/// steps leaves 1-5 mm on lane changes of the models' own shapes; lessons the
/// models miss lie at 1-23 cm (median 3.5 cm in the quick reproduction). Within it
/// the model is kept and the user's own shape ([`OwnShape`], sampled from another
/// lesson) is not tried (docs/experiments/0077-the-users-own-shape.md).
const MODEL_EXPLAINS_RMS_M: f64 = 0.01;

/// The lower fraction of the lane change whose crossing anchors the fit: low
/// enough to lie early in the move, high enough to lie clear of the takeover's
/// 0.3 m (8.6 % of a 3.5 m lane) in the usual first lesson.
const LOWER_FRACTION: f64 = 0.1;
/// The upper fraction: late enough that the profile up to it shows where the
/// lateral speed peaks (the skew of [`Shape`]), early enough to lie clear of the
/// settling at the end.
const UPPER_FRACTION: f64 = 0.9;
/// The smallest span accepted when the user is past the lower fraction at the
/// takeover.
const MIN_FRACTION_SPAN: f64 = 0.2;
/// The peak fractions the fit tries: where a lane change's lateral speed peaks,
/// in the middle half of the move (0.5 is a symmetric profile), on a coarse grid
/// refined once around the best of each base shape.
pub(super) const PEAK_RANGE: (f64, f64) = (0.25, 0.75);
/// The latest takeover (as the fraction of the lane change the user had done)
/// after which the peak is still fitted. The two bases differ most in the
/// onset; seen only from later on, a skewed model of the wrong base fits as
/// well and misplaces the start (a half-sine peaking at 0.74 seen from 24 % on
/// fits a quintic peaking at 0.72 best, 0.2 s early). Up to 20 % the start of
/// every model is found within 0.03 s (the property test below runs to this
/// bound; 3,000 cases to 20 % passed too), which leaves a margin; a takeover at
/// the paper's 0.3 m, the usual first lesson of a scene, comes at 8.6 % of a
/// 3.5 m lane. A later takeover is fitted with the symmetric models only.
const SKEW_MAX_TAKEOVER_FRACTION: f64 = 0.15;
/// The coarse grid of peak fractions: 11 fits per base over [`PEAK_RANGE`].
const COARSE_PEAK_STEP: f64 = 0.05;
/// The fine grid around the coarse best: a peak off by 0.01 moves the start by
/// well under a step of the grid's planning (0.1 s) for the paper's durations.
const FINE_PEAK_STEP: f64 = 0.01;
/// The lateral offset (m) within which a driven path counts as at rest in its
/// lane: when the user took over before its own start, the steps it then kept
/// its lane bound its start whatever the shape of its onset (a recorded
/// driver's onset is in neither base; fitted, its start came out up to 1.3 s
/// early). A micrometre, because the paths palc's users drive are free of
/// sensor noise, and the smoothest onset of the bases (the quintic's cubic) stays
/// below it for 0.3 % of its duration (0.012 s of a 4 s lane change), well
/// under a step. A noisy path is never at rest by this measure, and is fitted
/// as before.
const REST_M: f64 = 1e-6;

/// The time (s) at which the fraction `profile` first reaches `level` at or
/// after `from`, interpolated between the two steps around it.
fn crossing_s(profile: &[f64], from: usize, level: f64, dt: f64) -> Option<f64> {
    (from + 1..profile.len()).find_map(|i| {
        let (a, b) = (profile[i - 1], profile[i]);
        (a < level && b >= level).then(|| (i - 1) as f64 * dt + dt * (level - a) / (b - a))
    })
}

/// The user's own lane change seen in a lesson: the lane-change model ([`Shape`])
/// or the user's own shape ([`OwnShape`]) fitted to the lateral positions
/// `driven_l` the user drove from `takeover_step` on, towards `target_l` from 0.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct UserLaneChange {
    /// The user's start (s after the start of the plan).
    pub start_s: f64,
    /// Its duration (s).
    pub duration_s: f64,
    /// The lateral offset it ends at (m).
    pub target_l: f64,
    /// The model that fitted best.
    pub shape: Shape,
    /// The user's own shape, when it fitted better than every model; the lane
    /// change then follows it, not `shape`.
    pub own: Option<OwnShape>,
    /// The onset extrapolated from what was seen, when neither the models nor
    /// the user's own shape explained it ([`PowerOnset`]): the start is its, and
    /// before the first step seen the lane change follows it.
    pub onset: Option<PowerOnset>,
}

impl UserLaneChange {
    /// The fit described in the module documentation: for each [`Base`] and
    /// peak fraction, the start and duration through the crossings of
    /// [`LOWER_FRACTION`] (or just above the takeover) and [`UPPER_FRACTION`];
    /// the model with the smallest squared error over the positions driven from
    /// the takeover to the upper crossing is kept. The peak fraction is searched
    /// on a coarse grid over [`PEAK_RANGE`], then on a fine one around each
    /// base's best. `None` when the profile after the takeover is too short to
    /// fit (the user was past 70 % of the lane change at the takeover).
    pub(crate) fn fit(
        driven_l: &[f64],
        takeover_step: usize,
        dt: f64,
        target_l: f64,
    ) -> Option<UserLaneChange> {
        UserLaneChange::fit_with(driven_l, takeover_step, dt, target_l, None)
    }

    /// [`UserLaneChange::fit`], with the user's own shape `own` fitted beside the
    /// models through the same crossings: it is kept when its squared error is
    /// smaller than the best model's.
    pub(crate) fn fit_with(
        driven_l: &[f64],
        takeover_step: usize,
        dt: f64,
        target_l: f64,
        own: Option<&OwnShape>,
    ) -> Option<UserLaneChange> {
        if target_l == 0.0 || takeover_step >= driven_l.len() {
            return None;
        }
        let profile: Vec<f64> = driven_l.iter().map(|l| l / target_l).collect();
        let at_takeover = profile[takeover_step];
        let lower = LOWER_FRACTION.max(at_takeover + 0.01);
        let upper = UPPER_FRACTION;
        if upper - lower < MIN_FRACTION_SPAN {
            return None;
        }
        let t_a = crossing_s(&profile, takeover_step, lower, dt)?;
        let t_b = crossing_s(&profile, takeover_step, upper, dt)?;
        let fit_form = |shape: Shape, own: Option<OwnShape>| {
            let (x_a, x_b) = match &own {
                Some(own) => (own.inverse(lower), own.inverse(upper)),
                None => (shape.inverse(lower), shape.inverse(upper)),
            };
            let duration = (t_b - t_a) / (x_b - x_a);
            let user = UserLaneChange {
                start_s: (t_a - x_a * duration).max(0.0),
                duration_s: duration,
                target_l,
                shape,
                own,
                onset: None,
            };
            let error: f64 = (profile.iter().enumerate().skip(takeover_step))
                .take_while(|&(i, _)| i as f64 * dt <= t_b)
                .map(|(i, p)| (p - user.lateral(i as f64 * dt) / target_l).powi(2))
                .sum();
            (user, error)
        };
        let fit = |shape: Shape| fit_form(shape, None);
        // The samples each squared error sums over, for its root mean square.
        let samples = (takeover_step..profile.len())
            .take_while(|&i| i as f64 * dt <= t_b)
            .count()
            .max(1);
        let model_explains =
            |error: f64| (error / samples as f64).sqrt() * target_l.abs() <= MODEL_EXPLAINS_RMS_M;
        // The smaller squared error; the earlier model wins a tie.
        let better = |best: (UserLaneChange, f64), next: (UserLaneChange, f64)| {
            if next.1 < best.1 { next } else { best }
        };
        let best_of = |base: Base, peaks: &mut dyn Iterator<Item = f64>| {
            peaks.map(|peak| fit(Shape { base, peak })).reduce(better)
        };
        let grid = |from: f64, to: f64, step: f64| {
            let n = ((to - from) / step).round() as usize;
            (0..=n).map(move |i| from + i as f64 * step)
        };
        let (low, high) = PEAK_RANGE;
        let skewed = at_takeover <= SKEW_MAX_TAKEOVER_FRACTION;
        let best_of_base = |base: Base| {
            // The symmetric model first: it wins a tie.
            let mut symmetric = std::iter::once(0.5);
            if !skewed {
                return best_of(base, &mut symmetric);
            }
            let (coarse, _) = best_of(
                base,
                &mut symmetric.chain(grid(low, high, COARSE_PEAK_STEP)),
            )?;
            let peak = coarse.shape.peak;
            let around = grid(
                (peak - COARSE_PEAK_STEP).max(low),
                (peak + COARSE_PEAK_STEP).min(high),
                FINE_PEAK_STEP,
            );
            best_of(base, &mut std::iter::once(peak).chain(around))
        };
        let best = (Base::ALL.into_iter())
            .filter_map(best_of_base)
            .reduce(better)?;
        // The models first: they win a tie.
        let best = match own {
            Some(own) if !model_explains(best.1) => {
                better(best.clone(), fit_form(best.0.shape, Some(own.clone())))
            }
            _ => best,
        };
        if model_explains(best.1) {
            return Some(best.0);
        }
        // Neither explains what the user drove: the onset's own law, when it
        // explains the onset seen better than the lane change fitted as a whole.
        let samples = PowerOnset::samples(&profile, takeover_step, dt);
        let onset = PowerOnset::fit(&samples, dt, best.0.duration_s).filter(|onset| {
            let fitted: f64 = (samples.iter())
                .map(|&(t, p)| (best.0.lateral(t) / target_l - p).powi(2))
                .sum();
            let error = onset.squared_error(&samples);
            error < fitted
                && (error / samples.len() as f64).sqrt() * target_l.abs() <= MODEL_EXPLAINS_RMS_M
        });
        Some(match onset {
            Some(onset) => best.0.with_onset(onset),
            None => best.0,
        })
    }

    /// This lane change started by `onset`, its end kept.
    fn with_onset(self, onset: PowerOnset) -> UserLaneChange {
        let end_s = self.start_s + self.duration_s;
        if end_s <= onset.start_s {
            return self;
        }
        UserLaneChange {
            start_s: onset.start_s,
            duration_s: end_s - onset.start_s,
            onset: Some(onset),
            ..self
        }
    }

    /// [`UserLaneChange::fit`] to a lesson, where the user drove `driven_l`
    /// itself from `takeover_step` on: when it was then seen at rest in its lane
    /// before moving, its start is held within what was seen ([`REST_M`]). Not for
    /// paths the system drove (their numerical drift is no rest).
    pub(crate) fn fit_lesson(
        driven_l: &[f64],
        takeover_step: usize,
        dt: f64,
        target_l: f64,
        own: Option<&OwnShape>,
    ) -> Option<UserLaneChange> {
        let fitted = UserLaneChange::fit_with(driven_l, takeover_step, dt, target_l, own)?;
        Some(match rest_bounds_s(driven_l, takeover_step, dt) {
            Some(bounds) => fitted.started_within(bounds),
            None => fitted,
        })
    }

    /// The user's whole lane change as its own shape, when the lesson it was
    /// fitted to (`driven_l`, taken over at `takeover_step`) showed it from rest
    /// in its lane ([`REST_M`]) to this fit's end; `None` otherwise.
    pub(crate) fn own_shape_seen(
        &self,
        driven_l: &[f64],
        takeover_step: usize,
        dt: f64,
    ) -> Option<OwnShape> {
        rest_bounds_s(driven_l, takeover_step, dt)?;
        let end_s = self.start_s + self.duration_s;
        OwnShape::seen(driven_l, dt, self.target_l, self.start_s, end_s)
    }

    /// The user's shape as this fit's model, when the lesson pins it down: the
    /// takeover came early enough for the peak to be fitted
    /// ([`SKEW_MAX_TAKEOVER_FRACTION`]) and the model explains what the user
    /// drove from the takeover to the lane change's end within
    /// [`MODEL_EXPLAINS_RMS_M`]. A later lesson that sees the lane change only
    /// from further on fits the symmetric models alone; with this shape beside
    /// them its start is placed as the early lesson placed it. `None` otherwise,
    /// and for a fit that already follows the user's own shape.
    pub(crate) fn own_shape_fitted(
        &self,
        driven_l: &[f64],
        takeover_step: usize,
        dt: f64,
    ) -> Option<OwnShape> {
        if self.own.is_some() || self.target_l == 0.0 {
            return None;
        }
        let at_takeover = driven_l.get(takeover_step)? / self.target_l;
        if at_takeover > SKEW_MAX_TAKEOVER_FRACTION {
            return None;
        }
        let end_s = self.start_s + self.duration_s;
        let (squared, samples) = (driven_l.iter().enumerate().skip(takeover_step))
            .take_while(|&(i, _)| i as f64 * dt <= end_s)
            .fold((0.0, 0usize), |(sum, n), (i, &l)| {
                (sum + (l - self.lateral(i as f64 * dt)).powi(2), n + 1)
            });
        let rms = (squared / samples.max(1) as f64).sqrt();
        (samples > 0 && rms <= MODEL_EXPLAINS_RMS_M)
            .then(|| OwnShape::of_model(|x| self.shape.fraction(x)))
    }

    /// This lane change with its start moved into `(earliest, latest)` (s), its
    /// end kept: what was seen of the user outranks the model's extrapolation.
    fn started_within(self, (earliest, latest): (f64, f64)) -> UserLaneChange {
        let start_s = self.start_s.clamp(earliest, latest);
        let end_s = self.start_s + self.duration_s;
        if start_s == self.start_s || end_s <= start_s {
            return self;
        }
        UserLaneChange {
            start_s,
            duration_s: end_s - start_s,
            ..self
        }
    }

    /// The fitted lateral position (m) at time `t` (s): 0 before the start.
    pub(crate) fn lateral(&self, t: f64) -> f64 {
        if let Some(onset) = self.onset.filter(|onset| t < onset.until_s) {
            return self.target_l * onset.fraction(t);
        }
        let x = ((t - self.start_s) / self.duration_s).clamp(0.0, 1.0);
        let done = match &self.own {
            Some(own) => own.fraction(x),
            None => self.shape.fraction(x),
        };
        self.target_l * done
    }

    /// The user's lateral path in the lesson it was fitted to: what the user drove
    /// (`driven_l`) from `takeover_step` on, and before it, where the system drove,
    /// the fitted model.
    pub(crate) fn path(&self, driven_l: &[f64], takeover_step: usize, dt: f64) -> Vec<f64> {
        (driven_l.iter().enumerate())
            .map(|(i, &l)| {
                if i < takeover_step {
                    self.lateral(i as f64 * dt)
                } else {
                    l
                }
            })
            .collect()
    }
}

/// The interval (s) the user's start lies in when it was seen at rest in its lane
/// from the takeover on ([`REST_M`]): after the last step at rest, no later than
/// the first step it had moved. `None` when it had already left its lane at the
/// takeover, or never moved in what was seen.
fn rest_bounds_s(driven_l: &[f64], takeover_step: usize, dt: f64) -> Option<(f64, f64)> {
    let after = driven_l.get(takeover_step..)?;
    let moved = after.iter().position(|l| l.abs() > REST_M)?;
    let last_rest = takeover_step + moved.checked_sub(1)?;
    Some((last_rest as f64 * dt, (last_rest + 1) as f64 * dt))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::onset::test_scenes::shapes;

    /// A lane change of `shape` starting at `start` (s), sampled at `dt`.
    fn profile(shape: Shape, start: f64, duration: f64, dt: f64, n: usize) -> Vec<f64> {
        (0..n)
            .map(|i| {
                let x = ((i as f64 * dt - start) / duration).clamp(0.0, 1.0);
                3.5 * shape.fraction(x)
            })
            .collect()
    }

    fn quintic_profile(start: f64, duration: f64, dt: f64, n: usize) -> Vec<f64> {
        profile(Shape::QUINTIC, start, duration, dt, n)
    }

    #[test]
    fn the_start_of_each_model_is_found_between_steps() {
        for shape in shapes() {
            for (start, duration, takeover) in [(4.23, 2.1, 46), (4.23, 2.1, 30), (1.07, 1.7, 13)] {
                let driven = profile(shape, start, duration, 0.1, 120);
                let fit = UserLaneChange::fit(&driven, takeover, 0.1, 3.5).unwrap();
                assert_eq!(fit.shape.base, shape.base, "{shape:?}");
                assert!(
                    (fit.shape.peak - shape.peak).abs() < 0.02,
                    "{shape:?}: {fit:?}"
                );
                assert!(
                    (fit.start_s - start).abs() < 0.02,
                    "{shape:?}: {} vs {start}",
                    fit.start_s
                );
            }
        }
    }

    proptest::proptest! {
        /// Whatever the base, the peak in the fitted range, the duration and the
        /// takeover (while the peak is fitted), the start is found within a
        /// third of a step: what a new scene's prediction is anchored at.
        #[test]
        fn the_start_of_any_fitted_model_is_found(
            half_sine in proptest::bool::ANY,
            peak in PEAK_RANGE.0..PEAK_RANGE.1,
            start in 0.5f64..8.0,
            duration in 1.5f64..4.0,
            takeover_fraction in 0.0f64..SKEW_MAX_TAKEOVER_FRACTION,
        ) {
            let base = if half_sine { Base::HalfSine } else { Base::Quintic };
            let shape = Shape { base, peak };
            let dt = 0.1;
            let driven = profile(shape, start, duration, dt, 150);
            let takeover = ((start + shape.inverse(takeover_fraction) * duration) / dt) as usize;
            let fit = UserLaneChange::fit(&driven, takeover, dt, 3.5).unwrap();
            proptest::prop_assert!(
                (fit.start_s - start).abs() < 0.03,
                "{:?}: {} vs {}", fit, fit.start_s, start
            );
        }
    }

    #[test]
    fn a_late_takeover_is_fitted_with_the_symmetric_models() {
        for base in Base::ALL {
            let shape = Shape { base, peak: 0.5 };
            let driven = profile(shape, 4.23, 2.1, 0.1, 120);
            // The user is past 30 % of the move at the takeover.
            let takeover = driven.iter().position(|&l| l > 0.3 * 3.5).unwrap();
            let fit = UserLaneChange::fit(&driven, takeover, 0.1, 3.5).unwrap();
            assert_eq!(fit.shape, shape);
            assert!((fit.start_s - 4.23).abs() < 0.02, "{fit:?}");
        }
    }

    /// The start of a lane change of `user` (4.23 s, 2.1 s, seen from step 46)
    /// that `model` puts through its crossings of [`LOWER_FRACTION`] and `upper`.
    fn start_by(user: Shape, model: Shape, upper: f64) -> f64 {
        let fraction: Vec<f64> = (profile(user, 4.23, 2.1, 0.1, 120).iter())
            .map(|l| l / 3.5)
            .collect();
        let t_a = crossing_s(&fraction, 46, LOWER_FRACTION, 0.1).unwrap();
        let t_b = crossing_s(&fraction, 46, upper, 0.1).unwrap();
        let (x_a, x_b) = (model.inverse(LOWER_FRACTION), model.inverse(upper));
        t_a - x_a * (t_b - t_a) / (x_b - x_a)
    }

    const HALF_SINE: Shape = Shape {
        base: Base::HalfSine,
        peak: 0.5,
    };

    #[test]
    fn the_quintic_alone_misplaces_a_half_sine_start() {
        // Why both bases are fitted: the quintic through the crossings of 10 %
        // and 90 % puts a half-sine lane change of 2.1 s more than 0.1 s early.
        let quintic_start = start_by(HALF_SINE, Shape::QUINTIC, UPPER_FRACTION);
        assert!(4.23 - quintic_start > 0.1, "{quintic_start}");
    }

    #[test]
    fn a_symmetric_model_misplaces_an_early_peak_start() {
        // Why the peak is fitted: through the crossings of 10 % and 50 % (the
        // part a symmetric model was judged on), the half-sine puts a quintic
        // lane change of 2.1 s whose lateral speed peaks at 40 % more than 0.05 s
        // late; the fit with the peak finds it.
        let early = Shape {
            base: Base::Quintic,
            peak: 0.4,
        };
        let start = start_by(early, HALF_SINE, 0.5);
        assert!(start - 4.23 > 0.05, "{start}");
        let driven = profile(early, 4.23, 2.1, 0.1, 120);
        let fit = UserLaneChange::fit(&driven, 46, 0.1, 3.5).unwrap();
        assert!((fit.start_s - 4.23).abs() < 0.02, "{fit:?}");
    }

    #[test]
    fn the_users_path_before_the_takeover_is_the_fitted_quintic() {
        let user = quintic_profile(4.23, 2.1, 0.1, 90);
        // The system drove its own (late) plan until the takeover at step 47.
        let driven: Vec<f64> = (0..90)
            .map(|i| if i < 47 { 0.0 } else { user[i] })
            .collect();
        let path = UserLaneChange::fit(&driven, 47, 0.1, 3.5)
            .unwrap()
            .path(&driven, 47, 0.1);
        for (i, (got, want)) in path.iter().zip(&user).enumerate() {
            assert!((got - want).abs() < 0.01, "step {i}: {got} vs {want}");
        }
        assert_eq!(&path[47..], &user[47..]);
    }

    #[test]
    fn a_profile_seen_too_late_gives_no_start() {
        let profile = quintic_profile(1.0, 2.0, 0.1, 60);
        // At step 25 the user is past 80 % of the lane change.
        assert_eq!(UserLaneChange::fit(&profile, 25, 0.1, 3.5), None);
        assert_eq!(UserLaneChange::fit(&profile, 5, 0.1, 0.0), None);
    }

    /// A lane change whose onset is in neither base: its lateral speed jumps at
    /// the start and falls off as a cubic (`p(x) = 1 − (1 − x)³`).
    fn abrupt_profile(start: f64, duration: f64, dt: f64, n: usize) -> Vec<f64> {
        (0..n)
            .map(|i| {
                let x = ((i as f64 * dt - start) / duration).clamp(0.0, 1.0);
                3.5 * (1.0 - (1.0 - x).powi(3))
            })
            .collect()
    }

    /// A lane change in neither base: its lateral speed rises linearly over the
    /// first half (a quadratic onset, `2.4 x²`) and falls off as a square over
    /// the second (`1 − 3.2 (1 − x)³`), position and speed continuous.
    fn quadratic_onset(x: f64) -> f64 {
        let x = x.clamp(0.0, 1.0);
        if x <= 0.5 {
            2.4 * x * x
        } else {
            1.0 - 3.2 * (1.0 - x).powi(3)
        }
    }

    /// A lane change in neither base whose lateral acceleration falls from its
    /// start on while its lateral speed still grows, as a recorded human onset's
    /// does past its peak: `1.6 x^1.7` over the first half, then
    /// `1 − q (1 − x)^r` with position and speed continuous at the middle.
    fn onset_past_its_peak(x: f64) -> f64 {
        let x = x.clamp(0.0, 1.0);
        let (c, n) = (1.6, 1.7);
        let (at, speed) = (c * 0.5_f64.powf(n), c * n * 0.5_f64.powf(n - 1.0));
        let r = 0.5 * speed / (1.0 - at);
        let q = (1.0 - at) / 0.5_f64.powf(r);
        if x <= 0.5 {
            c * x.powf(n)
        } else {
            1.0 - q * (1.0 - x).powf(r)
        }
    }

    /// A lane change of `shape` (fraction of the lane at each fraction of its
    /// duration) from `start` over `duration` at steps of 0.1 s, taken over at
    /// the paper's 0.3 m, already moving: what was driven, the takeover's step
    /// and the lesson's fit.
    fn fitted_after_takeover(
        shape: fn(f64) -> f64,
        start: f64,
        duration: f64,
    ) -> (Vec<f64>, usize, UserLaneChange) {
        let dt = 0.1;
        let driven: Vec<f64> = (0..120)
            .map(|i| 3.5 * shape((i as f64 * dt - start) / duration))
            .collect();
        let takeover = driven.iter().position(|&l| l > 0.3).unwrap();
        let fitted = UserLaneChange::fit_lesson(&driven, takeover, dt, 3.5, None).unwrap();
        (driven, takeover, fitted)
    }

    #[test]
    fn an_onset_seen_past_its_acceleration_peak_is_not_placed_early() {
        let start = 3.17;
        let (_, _, fitted) = fitted_after_takeover(onset_past_its_peak, start, 4.0);
        assert!(fitted.onset.is_some(), "{fitted:?}");
        assert!((fitted.start_s - start).abs() < 0.05, "{fitted:?}");
    }

    #[test]
    fn the_start_of_a_shape_in_no_model_is_its_onsets() {
        let (dt, start) = (0.1, 4.23);
        let (driven, takeover, fitted) = fitted_after_takeover(quadratic_onset, start, 3.0);
        assert!(fitted.onset.is_some(), "{fitted:?}");
        assert!((fitted.start_s - start).abs() < 0.03, "{fitted:?}");
        // Before the takeover the path follows the onset, and meets what was
        // driven within a centimetre.
        let path = fitted.path(&driven, takeover, dt);
        for (i, (got, want)) in path.iter().zip(&driven).enumerate().take(takeover + 1) {
            assert!((got - want).abs() < 0.01, "step {i}: {got} vs {want}");
        }
    }

    #[test]
    fn a_start_seen_from_rest_is_held_within_what_was_seen_whatever_the_onset() {
        let (start, dt) = (5.03, 0.1);
        let driven = abrupt_profile(start, 3.0, dt, 120);
        // The takeover at 4.0 s came before the start: the user kept its lane
        // until step 50 and had moved at step 51.
        let fitted = UserLaneChange::fit(&driven, 40, dt, 3.5).unwrap();
        assert!((fitted.start_s - start).abs() > dt, "{fitted:?}");
        let seen = UserLaneChange::fit_lesson(&driven, 40, dt, 3.5, None).unwrap();
        assert!((seen.start_s - start).abs() <= dt, "{seen:?}");
        // The end of the lane change is the model's.
        let end = |u: &UserLaneChange| u.start_s + u.duration_s;
        assert!((end(&seen) - end(&fitted)).abs() < 1e-9);
    }

    #[test]
    fn a_start_seen_only_after_it_is_placed_by_the_users_own_shape() {
        let dt = 0.1;
        // A first lesson shows the whole lane change from rest (takeover at 4 s,
        // start at 5.03 s): its shape is the user's own.
        let first = abrupt_profile(5.03, 3.0, dt, 120);
        let seen = UserLaneChange::fit_lesson(&first, 40, dt, 3.5, None).unwrap();
        let own = seen.own_shape_seen(&first, 40, dt).unwrap();
        // A later lesson in another scene: the user started at 2.37 s and was
        // taken over 0.4 s later, already moving.
        let (start, later) = (2.37, abrupt_profile(2.37, 3.0, dt, 120));
        assert_eq!(seen.own_shape_seen(&later, 27, dt), None, "no rest is seen");
        let by_models = UserLaneChange::fit_lesson(&later, 27, dt, 3.5, None).unwrap();
        let by_own = UserLaneChange::fit_lesson(&later, 27, dt, 3.5, Some(&own)).unwrap();
        assert!((by_models.start_s - start).abs() > dt, "{by_models:?}");
        assert!((by_own.start_s - start).abs() <= dt, "{by_own:?}");
        assert!(by_own.own.is_some());
        // Its path before the takeover follows the user's shape.
        for (i, (got, want)) in (by_own.path(&later, 27, dt).iter().zip(&later)).enumerate() {
            assert!((got - want).abs() < 0.05, "step {i}: {got} vs {want}");
        }
    }

    #[test]
    fn a_late_peak_pinned_down_early_places_a_start_seen_late() {
        let (dt, duration) = (0.1, 2.0);
        let late_peak = Shape {
            base: Base::Quintic,
            peak: 0.65,
        };
        let lane_change = |start: f64| -> Vec<f64> {
            (0..120)
                .map(|i| {
                    3.5 * late_peak.fraction(((i as f64 * dt - start) / duration).clamp(0.0, 1.0))
                })
                .collect()
        };
        // Taken over at 5 % of the lane change: the peak is fitted and explains
        // the path, so the lesson pins the shape down.
        let first = lane_change(4.0);
        let early = (0..first.len()).find(|&i| first[i] >= 0.05 * 3.5).unwrap();
        let seen = UserLaneChange::fit_lesson(&first, early, dt, 3.5, None).unwrap();
        assert!((seen.start_s - 4.0).abs() < 0.03, "{seen:?}");
        let pinned = seen
            .own_shape_fitted(&first, early, dt)
            .expect("pinned down");
        // Taken over at a third of it, only the symmetric models are fitted.
        let (start, later) = (3.33, lane_change(3.33));
        let late = (0..later.len()).find(|&i| later[i] >= 0.3 * 3.5).unwrap();
        assert_eq!(
            seen.own_shape_fitted(&later, late, dt),
            None,
            "seen too late"
        );
        let by_models = UserLaneChange::fit_lesson(&later, late, dt, 3.5, None).unwrap();
        let by_pinned = UserLaneChange::fit_lesson(&later, late, dt, 3.5, Some(&pinned)).unwrap();
        assert!((by_models.start_s - start).abs() > dt, "{by_models:?}");
        assert!((by_pinned.start_s - start).abs() < 0.03, "{by_pinned:?}");
    }

    #[test]
    fn a_path_the_model_misses_pins_no_shape_down() {
        let dt = 0.1;
        // The abrupt onset is in neither base: the best model misses it by more
        // than the centimetre within which a model explains a path.
        let driven = abrupt_profile(4.0, 3.0, dt, 120);
        let fitted = UserLaneChange::fit_lesson(&driven, 41, dt, 3.5, None).unwrap();
        assert_eq!(fitted.own_shape_fitted(&driven, 41, dt), None);
    }

    #[test]
    fn a_models_lane_change_keeps_its_model_beside_an_own_shape() {
        // A quintic user: the model fits exactly and wins over the sampled shape.
        let dt = 0.1;
        let first = quintic_profile(5.03, 3.0, dt, 120);
        let seen = UserLaneChange::fit_lesson(&first, 40, dt, 3.5, None).unwrap();
        let own = seen.own_shape_seen(&first, 40, dt).unwrap();
        let later = quintic_profile(2.37, 3.0, dt, 120);
        let with = UserLaneChange::fit_lesson(&later, 27, dt, 3.5, Some(&own)).unwrap();
        let without = UserLaneChange::fit_lesson(&later, 27, dt, 3.5, None).unwrap();
        assert_eq!(with, without);
    }

    #[test]
    fn a_start_the_model_places_within_what_was_seen_is_kept() {
        let driven = quintic_profile(5.03, 3.0, 0.1, 120);
        for takeover in [30, 45, 50] {
            let fitted = UserLaneChange::fit(&driven, takeover, 0.1, 3.5).unwrap();
            let seen = UserLaneChange::fit_lesson(&driven, takeover, 0.1, 3.5, None).unwrap();
            assert_eq!(seen, fitted, "takeover at step {takeover}");
        }
    }

    #[test]
    fn a_user_moving_at_the_takeover_or_a_noisy_path_shows_no_rest() {
        let driven = abrupt_profile(5.03, 3.0, 0.1, 120);
        assert_eq!(rest_bounds_s(&driven, 52, 0.1), None);
        let noisy: Vec<f64> = (driven.iter().enumerate())
            .map(|(i, l)| l + if i % 2 == 0 { 1e-3 } else { -1e-3 })
            .collect();
        assert_eq!(rest_bounds_s(&noisy, 40, 0.1), None);
        let (earliest, latest) = rest_bounds_s(&driven, 40, 0.1).unwrap();
        assert!((earliest - 5.0).abs() < 1e-9 && (latest - 5.1).abs() < 1e-9);
    }
}
