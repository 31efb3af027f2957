//! An onset extrapolated from what was seen: the start of a lane change whose
//! shape is in no model, from the part of its onset seen after the takeover
//! (docs/experiments/0082-an-onset-extrapolated-from-what-was-seen.md).
//!
//! A lane change leaves its lane from rest, so near its start the fraction done
//! grows as a power of the time since the start, `p(t) = a (t − t₀)ⁿ`: `n = 2`
//! when the lateral acceleration is already non-zero at the start (the
//! half-sine's onset), `n = 3` when it rises from zero too (the quintic's, and
//! the recorded profiles' zero-acceleration ends), and `n` below 2 where the
//! part seen is past the peak of the lateral acceleration (recorded human
//! onsets: the acceleration rises within a few tenths of a second and then
//! falls while the lateral speed still grows). When no model explains what the
//! user drove, the samples from the takeover to [`ONSET_UP_TO_FRACTION`] of
//! the lane change are fitted by that law with `n` in [`EXPONENTS`], and `t₀`
//! is the start. The whole-move fit through the crossings of 10 % and 90 %
//! placed the start of recorded human lane changes (asymmetric ends, onsets of
//! neither base) by the shape of their ends; the onset's own law places it by
//! the onset (docs/experiments/0096-an-onset-past-its-acceleration-peak.md).

/// The samples fitted: up to this fraction of the lane change, the earliest at
/// which the fit lets a lane change's lateral speed peak (the start of its peak
/// range). Before it the lane change is still accelerating sideways, where the
/// onset's law holds; after the peak it bends over.
pub(crate) const ONSET_UP_TO_FRACTION: f64 = super::fit::PEAK_RANGE.0;
/// The exponents tried, and the step between them: up to the quintic's onset
/// (a lateral acceleration rising from zero), and down past the half-sine's
/// (one non-zero at the start) to 1.5, halfway to a lateral speed already
/// non-zero at the start (`n = 1`, which no lane change from rest has). Below
/// 2 the law's acceleration falls as the samples go on, as a recorded onset's
/// does past its peak. Measured on the recorded drivers' anchors (0096): from
/// 2, starts were placed 0.08 s early on average (184 of 582 more than
/// 0.15 s early); down to 1.5, 0.01 s early (108 early, 35 late); down to 1,
/// a creeping onset's samples fit a near-straight line and 190 starts came
/// more than 0.15 s late.
pub(crate) const EXPONENTS: (f64, f64, f64) = (1.5, 3.0, 0.05);
/// Fewest samples fitted: the law's three unknowns (`a`, `t₀`, `n`) and one
/// more, so that its residual says whether the law holds (three samples it
/// always fits; so fitted, a creeping onset was extrapolated 0.6 s early).
const MIN_SAMPLES: usize = 4;
/// The resolution of the start, as a fraction of the step: a tenth of a step
/// moves a plan by well under the takeover threshold.
const START_RESOLUTION_STEPS: f64 = 0.1;

/// `p(t) = scale (t − start_s)^exponent` (fraction of the lane change) from
/// `start_s` to `until_s`, the first time seen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PowerOnset {
    /// The start (s after the start of the plan).
    pub start_s: f64,
    /// The fraction of the lane change per second to the `exponent`.
    pub scale: f64,
    /// The power of the time since the start.
    pub exponent: f64,
    /// The first time (s) the user was seen, where the law hands over to what
    /// was driven.
    pub until_s: f64,
}

impl PowerOnset {
    /// The fraction of the lane change done at `t` (s): 0 before the start.
    pub(crate) fn fraction(&self, t: f64) -> f64 {
        if t <= self.start_s {
            0.0
        } else {
            self.scale * (t - self.start_s).powf(self.exponent)
        }
    }

    /// The samples of the onset seen: `(time, fraction)` of `profile`
    /// (fractions of the lane change at steps of `dt`) from `takeover_step` to
    /// [`ONSET_UP_TO_FRACTION`].
    pub(crate) fn samples(profile: &[f64], takeover_step: usize, dt: f64) -> Vec<(f64, f64)> {
        (profile.iter().enumerate().skip(takeover_step))
            .take_while(|&(_, &p)| p <= ONSET_UP_TO_FRACTION)
            .map(|(i, &p)| (i as f64 * dt, p))
            .collect()
    }

    /// The squared error of this law over `samples`.
    pub(crate) fn squared_error(&self, samples: &[(f64, f64)]) -> f64 {
        (samples.iter())
            .map(|&(t, p)| (self.fraction(t) - p).powi(2))
            .sum()
    }

    /// The law fitted (least squares) to the onset's `samples`
    /// ([`PowerOnset::samples`]), where the user had already moved, its start
    /// searched within `lookback_s` before the first sample (no earlier than
    /// 0): on steps of `dt`, then to a tenth of a step around the best. `None`
    /// with fewer than [`MIN_SAMPLES`] samples, or a user at rest at the first.
    pub(crate) fn fit(samples: &[(f64, f64)], dt: f64, lookback_s: f64) -> Option<PowerOnset> {
        let &(first_s, first_p) = samples.first()?;
        if samples.len() < MIN_SAMPLES || first_p <= 0.0 || !(lookback_s > 0.0 && dt > 0.0) {
            return None;
        }
        let earliest = (first_s - lookback_s).max(0.0);
        let squares: f64 = samples.iter().map(|&(_, p)| p * p).sum();
        // The best scale at a start and exponent, in closed form, and its error.
        let law = |start_s: f64, exponent: f64| {
            let (sxy, sxx) = samples.iter().fold((0.0, 0.0), |(xy, xx), &(t, p)| {
                let x = (t - start_s).powf(exponent);
                (xy + x * p, xx + x * x)
            });
            let onset = PowerOnset {
                start_s,
                scale: sxy / sxx,
                exponent,
                until_s: first_s,
            };
            (squares - sxy * sxy / sxx, onset)
        };
        let (low, high, step) = EXPONENTS;
        let exponents = ((high - low) / step).round() as usize;
        let better = |best: Option<(f64, PowerOnset)>, next: (f64, PowerOnset)| match best {
            Some(best) if best.0 <= next.0 => Some(best),
            _ => Some(next),
        };
        let mut best = None;
        for e in 0..=exponents {
            let exponent = low + e as f64 * step;
            let starts = |from: f64, by: f64, count: usize| {
                (1..=count)
                    .map(move |i| from - i as f64 * by)
                    .filter(|&start| start >= earliest && start < first_s)
            };
            let coarse = starts(first_s, dt, ((first_s - earliest) / dt).floor() as usize)
                .map(|start| law(start, exponent))
                .fold(None, better);
            let Some((_, around)) = coarse else { continue };
            let fine = START_RESOLUTION_STEPS * dt;
            let refined = starts(
                around.start_s + dt,
                fine,
                (2.0 / START_RESOLUTION_STEPS) as usize,
            )
            .map(|start| law(start, exponent))
            .fold(coarse, better);
            best = refined.into_iter().fold(best, better);
        }
        best.map(|(_, onset)| onset)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `0.04 (t − start)^exponent` at steps of `dt`.
    fn power_law(start: f64, exponent: f64, dt: f64) -> Vec<f64> {
        (0..120)
            .map(|i| 0.04 * (i as f64 * dt - start).max(0.0).powf(exponent))
            .collect()
    }

    #[test]
    fn a_power_law_onset_is_found_within_a_tenth_of_a_step() {
        let dt = 0.1;
        for (start, exponent) in [(4.23, 2.0), (2.37, 2.5), (6.01, 3.0), (3.12, 1.6)] {
            let profile = power_law(start, exponent, dt);
            let takeover = profile.iter().position(|&p| p > 0.08).unwrap();
            let samples = PowerOnset::samples(&profile, takeover, dt);
            let onset = PowerOnset::fit(&samples, dt, 3.0).unwrap();
            assert!(
                (onset.start_s - start).abs() <= 0.011,
                "{onset:?} vs {start}"
            );
            assert!((onset.exponent - exponent).abs() < 0.06, "{onset:?}");
        }
    }

    #[test]
    fn a_user_at_rest_or_seen_too_late_gives_no_onset() {
        let dt = 0.1;
        let profile = power_law(2.0, 2.0, dt);
        // At rest at the takeover.
        let fit = |step: usize| PowerOnset::fit(&PowerOnset::samples(&profile, step, dt), dt, 3.0);
        assert_eq!(fit(10), None);
        // Past a quarter of the lane change at the takeover.
        assert_eq!(fit(profile.iter().position(|&p| p > 0.3).unwrap()), None);
    }
}
