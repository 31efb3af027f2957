//! The lane-change models a user's start is fitted with ([`Shape`]): a
//! symmetric base, the paper's quintic or a half-sine lateral speed, whose
//! lateral speed may peak earlier or later than mid-move.

/// The symmetric lane-change models a user's start is fitted with: the paper's
/// quintic (minimum jerk, a cubic onset) and the half-sine lateral speed of many
/// driver models (a quadratic onset).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Base {
    /// `p(x) = 10x³ − 15x⁴ + 6x⁵`.
    Quintic,
    /// `p(x) = (1 − cos πx) / 2`.
    HalfSine,
}

impl Base {
    /// The bases tried, the paper's first (it wins a tie).
    pub(super) const ALL: [Base; 2] = [Base::Quintic, Base::HalfSine];

    /// The fraction `p(x)` of the lane change done at the fraction `x` of its
    /// duration, on `[0, 1]`; symmetric: `p(1 − x) = 1 − p(x)`.
    pub(super) fn fraction(self, x: f64) -> f64 {
        match self {
            Base::Quintic => x * x * x * (10.0 + x * (-15.0 + 6.0 * x)),
            Base::HalfSine => 0.5 * (1.0 - (std::f64::consts::PI * x).cos()),
        }
    }

    /// The inverse of [`Base::fraction`] on `[0, 1]`: closed form for the
    /// half-sine, bisection for the quintic (it is increasing).
    pub(super) fn inverse(self, p: f64) -> f64 {
        match self {
            Base::HalfSine => (1.0 - 2.0 * p.clamp(0.0, 1.0)).acos() / std::f64::consts::PI,
            Base::Quintic => {
                let (mut low, mut high) = (0.0, 1.0);
                for _ in 0..52 {
                    let mid = 0.5 * (low + high);
                    if self.fraction(mid) < p {
                        low = mid;
                    } else {
                        high = mid;
                    }
                }
                0.5 * (low + high)
            }
        }
    }
}

/// A lane-change model: a [`Base`] whose lateral speed peaks at the fraction
/// `peak` of the duration. The accelerating half of the base is stretched over
/// `[0, peak]` and its decelerating half over `[peak, 1]`, each covering its
/// share of the distance, so that position and lateral speed stay continuous
/// (the construction of the asymmetric driver profiles). A driver whose lateral
/// speed peaks early (or late) has the base's onset but reaches the middle of
/// the lane sooner (or later); a symmetric model fitted to such a profile
/// misplaces its start by several percent of the duration (for a quintic base
/// peaking at 0.4, the half-sine fits best and puts the start 5 % of the
/// duration late), and the start is what experience carries to another scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Shape {
    /// The symmetric model stretched.
    pub base: Base,
    /// Where the lateral speed peaks, as a fraction of the duration.
    pub peak: f64,
}

impl Shape {
    /// The paper's quintic, symmetric.
    #[cfg(test)]
    pub(crate) const QUINTIC: Shape = Shape {
        base: Base::Quintic,
        peak: 0.5,
    };

    /// The fraction `p(x)` of the lane change done at the fraction `x` of its
    /// duration, on `[0, 1]`.
    pub(super) fn fraction(self, x: f64) -> f64 {
        self.stretched(x, Base::fraction)
    }

    /// The inverse of [`Shape::fraction`] on `[0, 1]`, through the base's.
    pub(super) fn inverse(self, p: f64) -> f64 {
        self.stretched(p, Base::inverse)
    }

    /// `f` of the base stretched as the skew stretches the base's halves:
    /// `2 peak f(v / 2 peak)` up to the peak, mirrored after it. The same for the
    /// progress and its inverse, since both split at `peak` (the progress at the
    /// peak's time is `peak`) and the base is symmetric.
    fn stretched(self, v: f64, f: fn(Base, f64) -> f64) -> f64 {
        let (base, peak) = (self.base, self.peak);
        let v = v.clamp(0.0, 1.0);
        if v <= peak {
            2.0 * peak * f(base, v / (2.0 * peak))
        } else {
            1.0 - 2.0 * (1.0 - peak) * f(base, (1.0 - v) / (2.0 * (1.0 - peak)))
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::onset::test_scenes::shapes;

    #[test]
    fn each_shapes_inverse_inverts() {
        for shape in shapes() {
            for p in [0.0, 0.05, 0.1, 0.5, 0.9, 1.0] {
                let x = shape.inverse(p);
                assert!((shape.fraction(x) - p).abs() < 1e-12, "{shape:?}: {p}");
            }
        }
    }

    #[test]
    fn a_skewed_shape_peaks_where_it_says_and_keeps_its_speed_continuous() {
        let h = 1e-6;
        for shape in shapes() {
            let speed = |x: f64| (shape.fraction(x + h) - shape.fraction(x - h)) / (2.0 * h);
            let (at, before, after) = (
                speed(shape.peak),
                speed(shape.peak - 0.01),
                speed(shape.peak + 0.01),
            );
            assert!(at > before && at > after, "{shape:?}");
            assert!((shape.fraction(shape.peak) - shape.peak).abs() < 1e-12);
        }
    }
}
