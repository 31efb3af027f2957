//! Grid points whose class is already certain, so the zone's line scan need
//! not classify them (the scan of [`crate::bounds`], Eqs. 27-32).
//!
//! Along the line of one planning step only the ego's lateral position `l`
//! varies. Each feature then either does not depend on `l` (`ds`, a time gap),
//! is an offset `const - l` (slope exactly -1), or a distance
//! `hypot(ds, const - l)` (slope in `[-1, 1]`). The log-odds of the linear
//! discriminant, `a(x) = w . (x - m) + c`, therefore changes along the line by
//! at most `L = |Σ_offsets w_j| + Σ_distances |w_j|` per metre. A grid point at
//! distance `δ` from a point where the computed log-odds is `v` has the class
//! of `v` whenever `|v| - L δ` exceeds twice the rounding error of an
//! evaluation: the scan then skips it and its result is the one it would have
//! computed, crossing for crossing (a proptest compares both).
//!
//! The rounding error of one evaluation is below `10 ε S`, with `S` the sum of
//! the magnitudes that enter it (`|c| + Σ |w_j| (|x_j| + |m_j|)`, bounded over
//! the whole line); the margin [`ROUNDING_MARGIN`] allows `1e-10 S`, more than
//! four hundred thousand times that. The quadratic discriminant has no such
//! global slope and is scanned point by point.

use crate::features::FeatureSet;
use crate::gaussian::Fitted;

/// The allowance for the rounding of one log-odds evaluation, relative to the
/// magnitudes that enter it (see the module doc: the true error is below
/// `10 ε ≈ 2.2e-15` of them).
const ROUNDING_MARGIN: f64 = 1e-10;

/// Magnitudes beyond this skip nothing: a feature or a product near the
/// overflow could turn into an infinity or a NaN at a point the scan skips.
const LARGEST_SCALE: f64 = 1e300;

/// Which features of `set` vary with `l` along a line of constant `s`:
/// `(offsets, distances)` by index.
fn lateral_terms(set: FeatureSet) -> (&'static [usize], &'static [usize]) {
    match set {
        FeatureSet::Paper => (&[1, 4], &[2, 5]),
        FeatureSet::NoDistance | FeatureSet::TimeGap => (&[1, 3], &[]),
    }
}

/// How far along the line the class of an evaluated point is certain.
#[derive(Debug, Clone, Copy)]
pub(crate) struct CertainSign<'a> {
    weights: &'a [f64],
    midpoint: &'a [f64],
    log_prior_ratio: f64,
    /// `L`: the largest change of the log-odds per metre of `l`.
    slope: f64,
    /// `Σ |w_j|` over the features that vary with `l`: how much the
    /// magnitudes of an evaluation can grow per metre along the line.
    growth: f64,
    /// The length of the line (m).
    span: f64,
}

impl<'a> CertainSign<'a> {
    /// For a linear discriminant on `set` scanned over a line of `span` metres;
    /// `None` for the quadratic one.
    pub fn new(fitted: &'a Fitted, set: FeatureSet, span: f64) -> Option<CertainSign<'a>> {
        let Fitted::Linear {
            weights,
            midpoint,
            log_prior_ratio,
        } = fitted
        else {
            return None;
        };
        let (offsets, distances) = lateral_terms(set);
        let offset_slope: f64 = offsets.iter().map(|&j| weights[j]).sum();
        let distance_slope: f64 = distances.iter().map(|&j| weights[j].abs()).sum();
        let growth = (offsets.iter().chain(distances))
            .map(|&j| weights[j].abs())
            .sum();
        Some(CertainSign {
            weights,
            midpoint,
            log_prior_ratio: *log_prior_ratio,
            slope: offset_slope.abs() + distance_slope,
            growth,
            span,
        })
    }

    /// The distance (m) from the point with features `x` and computed
    /// log-odds `value` within which every point of the line has the class of
    /// `value`; 0 when nothing is certain.
    pub fn reach(&self, x: &[f64], value: f64) -> f64 {
        let here: f64 = (self.weights.iter().zip(self.midpoint).zip(x))
            .map(|((w, m), x)| w.abs() * (x.abs() + m.abs()))
            .sum();
        let scale = self.log_prior_ratio.abs() + here + self.growth * self.span;
        if !(scale.is_finite() && scale <= LARGEST_SCALE && value.is_finite()) {
            return 0.0;
        }
        let certain = value.abs() - 2.0 * ROUNDING_MARGIN * scale;
        if certain <= 0.0 {
            0.0
        } else if self.slope > 0.0 {
            certain / self.slope
        } else {
            f64::INFINITY
        }
    }
}
