//! The lateral profile of the lane change a user expects: how the lateral
//! position moves from the current lane's centre to the target lane's over the
//! user's duration.
//!
//! Every shape maps the normalized time `τ = (t − start) / T ∈ [0, 1]` to the
//! normalized progress `p(τ) ∈ [0, 1]`, with `p(0) = 0`, `p(1) = 1`, monotone:
//!
//! - **quintic**, `p = 10τ³ − 15τ⁴ + 6τ⁵`: the minimum-jerk profile (Flash and
//!   Hogan, 1985), zero lateral speed and acceleration at both ends; the paper's
//!   expected trajectory (palc's model of it, NOTES.md).
//! - **cosine**, `p = (1 − cos πτ) / 2`: a half-sine lateral speed, the
//!   lane-change model of Nelson (1989) and of many driver models; its lateral
//!   acceleration steps at both ends.
//! - **asymmetric**, the quintic's accelerating half over `[0, p]` and its
//!   decelerating half over `[p, 1]`, `p = peak_fraction`: the lateral speed
//!   peaks at `p` (early or late), position, speed and acceleration stay
//!   continuous; `p = 0.5` is the quintic exactly.
//! - **table**: `(time since start, lateral offset)` points, e.g. recorded from a
//!   driver or another simulator, interpolated by the monotone piecewise cubic
//!   of Fritsch and Carlson (1980): monotone data stays monotone, no overshoot.
//!   The table sets its own duration (its last time) and offset (its last point).
//! - **recorded**: noisy samples of a recorded lane change (10–25 Hz), smoothed
//!   into the smoothest monotone shape within the samples' stated noise
//!   ([`RecordedProfile`]); the user drives, and is checked on, the smoothed shape.

use serde::{Deserialize, Serialize};

use crate::UserError;
pub use crate::point::ProfilePoint;
use crate::recorded::RecordedProfile;

/// Smallest and largest `peak_fraction` of the asymmetric profile.
/// At the bounds the peak lateral acceleration is 1.67 times the quintic's.
pub const PEAK_FRACTION_BOUNDS: (f64, f64) = (0.3, 0.7);
/// Most points of a table profile: a minute of samples at 100 Hz.
pub const MAX_TABLE_POINTS: usize = 6_000;
/// Largest gap between the table's last offset and the lane change's offset (m):
/// a recorded profile ends on the target lane's centre to within a centimetre.
pub const TABLE_END_TOLERANCE_M: f64 = 0.01;

/// The shape of the lateral move; see the module documentation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(tag = "shape", rename_all = "kebab-case", deny_unknown_fields)]
pub enum LateralProfile {
    /// Minimum jerk, `10τ³ − 15τ⁴ + 6τ⁵` (the paper's users).
    #[default]
    Quintic,
    /// Half-sine lateral speed, `(1 − cos πτ) / 2`.
    Cosine,
    /// Two half-quintics, the lateral speed peaking at `peak_fraction` of the duration.
    Asymmetric {
        /// Where the lateral speed peaks, as a fraction of the duration, in
        /// [`PEAK_FRACTION_BOUNDS`]; 0.5 is the quintic.
        peak_fraction: f64,
    },
    /// Noisy samples of a recorded lane change, smoothed into a monotone shape
    /// (see [`RecordedProfile`]); the user stretches it over its duration and
    /// the scene's lane width, as the analytic shapes.
    Recorded(RecordedProfile),
    /// Points `(time since start, lateral offset)`, interpolated monotonically.
    Table {
        /// At least two points, times strictly increasing from 0, offsets from 0.
        points: Vec<ProfilePoint>,
    },
}

impl LateralProfile {
    /// The shape's name in reports: `quintic`, `cosine`, `asymmetric`, `table`.
    pub fn name(&self) -> &'static str {
        match self {
            LateralProfile::Quintic => "quintic",
            LateralProfile::Cosine => "cosine",
            LateralProfile::Asymmetric { .. } => "asymmetric",
            LateralProfile::Table { .. } => "table",
            LateralProfile::Recorded(_) => "recorded",
        }
    }

    /// Checks the shape's parameters, naming the field under `table` that is out of bound.
    pub fn validate(&self, table: &str) -> Result<(), UserError> {
        let invalid = |field: String, value: f64, bound: &str| UserError::InvalidConfig {
            field,
            value,
            bound: bound.to_owned(),
        };
        match self {
            LateralProfile::Quintic | LateralProfile::Cosine => Ok(()),
            LateralProfile::Recorded(recorded) => recorded.fit(table).map(|_| ()),
            LateralProfile::Asymmetric { peak_fraction } => {
                let (low, high) = PEAK_FRACTION_BOUNDS;
                if peak_fraction.is_finite() && (low..=high).contains(peak_fraction) {
                    Ok(())
                } else {
                    Err(invalid(
                        format!("{table}.peak_fraction"),
                        *peak_fraction,
                        &format!("a value in [{low}, {high}]"),
                    ))
                }
            }
            LateralProfile::Table { points } => {
                if !(2..=MAX_TABLE_POINTS).contains(&points.len()) {
                    return Err(invalid(
                        format!("{table}.points"),
                        points.len() as f64,
                        &format!("between 2 and {MAX_TABLE_POINTS} points"),
                    ));
                }
                for (i, point) in points.iter().enumerate() {
                    if !point.offset_m.is_finite() {
                        return Err(invalid(
                            format!("{table}.points[{i}].offset_m"),
                            point.offset_m,
                            "finite",
                        ));
                    }
                    let time_ok = match i {
                        0 => point.time_s == 0.0,
                        _ => point.time_s.is_finite() && point.time_s > points[i - 1].time_s,
                    };
                    if !time_ok {
                        let bound = match i {
                            0 => "0 (the table starts at the start of the lane change)".to_owned(),
                            _ => format!(
                                "finite and greater than the previous point's {} s",
                                points[i - 1].time_s
                            ),
                        };
                        return Err(invalid(
                            format!("{table}.points[{i}].time_s"),
                            point.time_s,
                            &bound,
                        ));
                    }
                }
                if points[0].offset_m != 0.0 {
                    return Err(invalid(
                        format!("{table}.points[0].offset_m"),
                        points[0].offset_m,
                        "0 (the lane change starts on the current lane's centre)",
                    ));
                }
                Ok(())
            }
        }
    }

    /// The duration the shape sets itself (a table's last time), if any.
    pub fn own_duration_s(&self) -> Option<f64> {
        match self {
            LateralProfile::Table { points } => points.last().map(|p| p.time_s),
            _ => None,
        }
    }

    /// The lateral offset the shape sets itself (a table's last offset), if any.
    pub fn own_offset_m(&self) -> Option<f64> {
        match self {
            LateralProfile::Table { points } => points.last().map(|p| p.offset_m),
            _ => None,
        }
    }

    /// Lateral offset (m) at `t` seconds after the start of a move of `offset_m`
    /// over `duration_s`; 0 before the start, the whole offset after the end.
    pub fn offset_at(&self, t: f64, duration_s: f64, offset_m: f64) -> f64 {
        match self {
            LateralProfile::Table { points } => table_offset(points, t),
            _ => {
                let tau = (t / duration_s).clamp(0.0, 1.0);
                offset_m * self.progress(tau)
            }
        }
    }

    /// Normalized progress `p(τ)` of the analytic shapes (a table is in time and metres).
    fn progress(&self, tau: f64) -> f64 {
        match self {
            LateralProfile::Quintic | LateralProfile::Table { .. } => quintic(tau),
            LateralProfile::Cosine => 0.5 * (1.0 - (std::f64::consts::PI * tau).cos()),
            LateralProfile::Asymmetric { peak_fraction } => asymmetric(tau, *peak_fraction),
            LateralProfile::Recorded(recorded) => recorded.progress(tau),
        }
    }
}

/// The minimum-jerk blend `10 τ³ − 15 τ⁴ + 6 τ⁵` on `[0, 1]`: zero speed and
/// acceleration at both ends.
pub fn quintic(tau: f64) -> f64 {
    let t = tau.clamp(0.0, 1.0);
    t * t * t * (10.0 + t * (-15.0 + 6.0 * t))
}

/// Progress of the asymmetric profile: the accelerating half of a quintic
/// stretched over `[0, p]` and its decelerating half over `[p, 1]`, each covering
/// its share of the distance, so that position, lateral speed (peaking at `p`)
/// and lateral acceleration (zero at `p`) are continuous; only the jerk steps at
/// `p`. The peak acceleration is the quintic's times `1 / (2 min(p, 1 − p))`.
fn asymmetric(tau: f64, peak: f64) -> f64 {
    let tau = tau.clamp(0.0, 1.0);
    if tau <= peak {
        2.0 * peak * quintic(tau / (2.0 * peak))
    } else {
        1.0 - 2.0 * (1.0 - peak) * quintic((1.0 - tau) / (2.0 * (1.0 - peak)))
    }
}

/// The monotone piecewise cubic Hermite interpolant of `points` at `t` (Fritsch
/// and Carlson, 1980, with the three-point end slopes of Moler's `pchip`):
/// constant before the first point and after the last.
fn table_offset(points: &[ProfilePoint], t: f64) -> f64 {
    let (Some(first), Some(last)) = (points.first(), points.last()) else {
        return 0.0;
    };
    if t <= first.time_s || points.len() < 2 {
        return first.offset_m;
    }
    if t >= last.time_s {
        return last.offset_m;
    }
    // The segment [i, i + 1] holding t.
    let i = points.partition_point(|p| p.time_s <= t).saturating_sub(1);
    let i = i.min(points.len() - 2);
    let (p0, p1) = (points[i], points[i + 1]);
    let h = p1.time_s - p0.time_s;
    let (m0, m1) = (pchip_slope(points, i), pchip_slope(points, i + 1));
    let s = (t - p0.time_s) / h;
    let (s2, s3) = (s * s, s * s * s);
    let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
    let h10 = s3 - 2.0 * s2 + s;
    let h01 = -2.0 * s3 + 3.0 * s2;
    let h11 = s3 - s2;
    h00 * p0.offset_m + h10 * h * m0 + h01 * p1.offset_m + h11 * h * m1
}

/// Secant slope of segment `i`.
fn secant(points: &[ProfilePoint], i: usize) -> f64 {
    (points[i + 1].offset_m - points[i].offset_m) / (points[i + 1].time_s - points[i].time_s)
}

/// The Fritsch–Carlson slope at point `i`: the weighted harmonic mean of the
/// neighbouring secants where they agree in sign, zero at a local extremum; at
/// the ends, the three-point estimate limited so as to keep monotonicity.
fn pchip_slope(points: &[ProfilePoint], i: usize) -> f64 {
    let n = points.len();
    if n == 2 {
        return secant(points, 0);
    }
    let h = |j: usize| points[j + 1].time_s - points[j].time_s;
    if i == 0 || i == n - 1 {
        let (j0, j1) = if i == 0 { (0, 1) } else { (n - 2, n - 3) };
        let (h0, h1) = (h(j0), h(j1));
        let (d0, d1) = (secant(points, j0), secant(points, j1));
        let m = ((2.0 * h0 + h1) * d0 - h0 * d1) / (h0 + h1);
        return if m.signum() != d0.signum() || d0 == 0.0 {
            0.0
        } else if d0.signum() != d1.signum() && m.abs() > 3.0 * d0.abs() {
            3.0 * d0
        } else {
            m
        };
    }
    let (d0, d1) = (secant(points, i - 1), secant(points, i));
    if d0 == 0.0 || d1 == 0.0 || d0.signum() != d1.signum() {
        return 0.0;
    }
    let (h0, h1) = (h(i - 1), h(i));
    let (w1, w2) = (2.0 * h1 + h0, h1 + 2.0 * h0);
    (w1 + w2) / (w1 / d0 + w2 / d1)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sampled(profile: &LateralProfile, duration: f64, offset: f64) -> Vec<f64> {
        (0..=1000)
            .map(|i| profile.offset_at(i as f64 * duration / 1000.0, duration, offset))
            .collect()
    }

    #[test]
    fn quintic_has_flat_ends_and_is_monotone() {
        assert!(quintic(0.0).abs() < 1e-15);
        assert!((quintic(1.0) - 1.0).abs() < 1e-15);
        assert!((quintic(0.5) - 0.5).abs() < 1e-15);
        let mut previous = 0.0;
        for i in 1..=100 {
            let value = quintic(i as f64 / 100.0);
            assert!(value >= previous);
            previous = value;
        }
    }

    #[test]
    fn every_shape_goes_from_zero_to_the_offset_monotonically() {
        let shapes = [
            LateralProfile::Quintic,
            LateralProfile::Cosine,
            LateralProfile::Asymmetric { peak_fraction: 0.3 },
            LateralProfile::Asymmetric {
                peak_fraction: 0.75,
            },
        ];
        for shape in shapes {
            let path = sampled(&shape, 2.0, 3.5);
            assert!(path[0].abs() < 1e-12, "{shape:?}");
            assert!((path[1000] - 3.5).abs() < 1e-9, "{shape:?}");
            assert!(path.windows(2).all(|w| w[1] >= w[0] - 1e-12), "{shape:?}");
        }
    }

    #[test]
    fn the_symmetric_asymmetric_profile_is_the_quintic() {
        let symmetric = LateralProfile::Asymmetric { peak_fraction: 0.5 };
        for i in 0..=100 {
            let tau = i as f64 / 100.0;
            let difference = symmetric.offset_at(tau, 1.0, 1.0) - quintic(tau);
            assert!(difference.abs() < 1e-12, "τ = {tau}: {difference:e}");
        }
    }

    #[test]
    fn the_asymmetric_speed_peaks_where_asked() {
        for peak in [0.3, 0.4, 0.6, 0.7] {
            let shape = LateralProfile::Asymmetric {
                peak_fraction: peak,
            };
            let path = sampled(&shape, 1.0, 1.0);
            let (argmax, _) = path.windows(2).map(|w| w[1] - w[0]).enumerate().fold(
                (0, f64::MIN),
                |best, (i, v)| if v > best.1 { (i, v) } else { best },
            );
            let at = (argmax as f64 + 0.5) / 1000.0;
            assert!((at - peak).abs() < 2e-3, "peak {peak}: speed peaks at {at}");
        }
    }

    #[test]
    fn a_table_of_quintic_points_reproduces_the_quintic() {
        let (duration, offset) = (2.1, 3.5);
        let points: Vec<ProfilePoint> = (0..=210)
            .map(|i| {
                let t = i as f64 * 0.01;
                ProfilePoint {
                    time_s: t,
                    offset_m: offset * quintic(t / duration),
                }
            })
            .collect();
        let table = LateralProfile::Table { points };
        table.validate("user.profile").unwrap();
        assert_eq!(table.own_duration_s(), Some(2.1));
        for i in 0..=2100 {
            let t = i as f64 * 0.001;
            let difference = table.offset_at(t, duration, offset) - offset * quintic(t / duration);
            assert!(difference.abs() < 1e-6, "t = {t}: {difference:e}");
        }
    }

    #[test]
    fn a_table_keeps_monotone_data_monotone() {
        let points = [(0.0, 0.0), (0.5, 0.1), (1.0, 2.9), (1.2, 3.4), (3.0, 3.5)]
            .map(|(time_s, offset_m)| ProfilePoint { time_s, offset_m })
            .to_vec();
        let table = LateralProfile::Table { points };
        let path = sampled(&table, 3.0, 3.5);
        assert!(path.windows(2).all(|w| w[1] >= w[0] - 1e-12));
        assert!(path.iter().all(|&l| (0.0..=3.5 + 1e-12).contains(&l)));
        assert_eq!(table.offset_at(-1.0, 3.0, 3.5), 0.0);
        assert_eq!(table.offset_at(10.0, 3.0, 3.5), 3.5);
    }

    #[test]
    fn bad_tables_and_peaks_name_the_field() {
        let point = |time_s, offset_m| ProfilePoint { time_s, offset_m };
        let cases = [
            (vec![point(0.0, 0.0)], "user.profile.points"),
            (
                vec![point(0.1, 0.0), point(1.0, 3.5)],
                "user.profile.points[0].time_s",
            ),
            (
                vec![point(0.0, 0.0), point(1.0, 1.0), point(1.0, 3.5)],
                "user.profile.points[2].time_s",
            ),
            (
                vec![point(0.0, 0.0), point(1.0, f64::NAN)],
                "user.profile.points[1].offset_m",
            ),
            (
                vec![point(0.0, 0.5), point(1.0, 3.5)],
                "user.profile.points[0].offset_m",
            ),
        ];
        for (points, field) in cases {
            let err = LateralProfile::Table { points }
                .validate("user.profile")
                .unwrap_err()
                .to_string();
            assert!(err.contains(field), "{err}");
        }
        let err = LateralProfile::Asymmetric {
            peak_fraction: 0.95,
        }
        .validate("user.profile")
        .unwrap_err()
        .to_string();
        assert!(
            err.contains("user.profile.peak_fraction") && err.contains("0.95"),
            "{err}"
        );
    }
}

#[cfg(test)]
mod recorded_tests {
    use super::*;

    #[test]
    fn a_recorded_profile_reads_from_toml_and_drives_its_fit() {
        let mut text = String::from("shape = \"recorded\"\nnoise_m = 0.05\nsamples = [\n");
        for i in 0..=30 {
            let t = i as f64 * 0.1;
            let wobble = 0.03 * (i as f64 * 2.1).sin();
            let offset = 3.6 * quintic(t / 3.0) + wobble;
            text.push_str(&format!("{{ time_s = {t}, offset_m = {offset} }},\n"));
        }
        text.push(']');
        let profile: LateralProfile = toml::from_str(&text).unwrap();
        assert_eq!(profile.name(), "recorded");
        profile.validate("user.family.profile").unwrap();
        assert_eq!(profile.own_duration_s(), None);
        // Stretched over the user's duration and the scene's offset.
        assert!(profile.offset_at(0.0, 2.0, 3.5).abs() < 1e-9);
        assert!((profile.offset_at(2.0, 2.0, 3.5) - 3.5).abs() < 1e-9);
        assert!((profile.offset_at(1.0, 2.0, 3.5) - 1.75).abs() < 0.15);
        let unknown = toml::from_str::<LateralProfile>(&text.replace("noise_m", "noise"));
        assert!(unknown.is_err());
    }
}
