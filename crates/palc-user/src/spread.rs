//! How a user's parameters vary between lane changes: every numeric parameter
//! may be drawn anew for each lane change, uniformly around its nominal value,
//! with a relative or an absolute half-width, from a seeded generator.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::UserError;
use crate::family::{
    ACCELERATION_BOUNDS_MPS2, COMFORT_TIME_GAP_BOUNDS_S, COMFORT_TTC_BOUNDS_S,
    DISTANCE_START_BOUNDS_M, Family, INCENTIVE_START_BOUNDS_MPS2, MAX_REACTION_S, SpeedRule,
    StartRule, TTC_START_BOUNDS_S,
};
use crate::profile::{LateralProfile, PEAK_FRACTION_BOUNDS};
use crate::style::{MAX_GAP_ACCEPTANCE_S, Style};

/// Largest relative half-width: a draw never halves or doubles a parameter.
pub const MAX_RELATIVE_SPREAD: f64 = 0.5;
/// Largest absolute half-width, in the parameter's own unit.
pub const MAX_ABSOLUTE_SPREAD: f64 = 100.0;

/// The half-width of the uniform draw of one parameter.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Draw {
    /// `nominal × (1 + e)`, `e` uniform in `[−w, w]`, `w < MAX_RELATIVE_SPREAD`.
    Relative(f64),
    /// `nominal + e`, `e` uniform in `[−w, w]`, in the parameter's unit.
    Absolute(f64),
}

impl Draw {
    fn validate(&self, field: &str) -> Result<(), UserError> {
        let (value, bound, ok) = match *self {
            Draw::Relative(w) => (
                w,
                format!("a value in [0, {MAX_RELATIVE_SPREAD})"),
                (0.0..MAX_RELATIVE_SPREAD).contains(&w),
            ),
            Draw::Absolute(w) => (
                w,
                format!("a value in [0, {MAX_ABSOLUTE_SPREAD}]"),
                (0.0..=MAX_ABSOLUTE_SPREAD).contains(&w),
            ),
        };
        if value.is_finite() && ok {
            Ok(())
        } else {
            Err(UserError::InvalidConfig {
                field: field.to_owned(),
                value,
                bound,
            })
        }
    }

    fn half_width(&self) -> f64 {
        match *self {
            Draw::Relative(w) | Draw::Absolute(w) => w,
        }
    }

    /// `nominal` moved by one draw of `rng`, clipped to `bounds`.
    fn apply(&self, nominal: f64, rng: &mut ChaCha8Rng, (low, high): (f64, f64)) -> f64 {
        let w = self.half_width();
        let e = rng.random_range(-w..=w);
        let drawn = match self {
            Draw::Relative(_) => nominal * (1.0 + e),
            Draw::Absolute(_) => nominal + e,
        };
        drawn.clamp(low, high)
    }
}

/// Half-widths of the parameters beyond the start threshold and the duration,
/// by name; a parameter left out is not drawn.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ParameterSpread {
    /// The start rule's threshold (headway, time to collision or distance);
    /// replaces `relative` for it.
    pub start_threshold: Option<Draw>,
    /// The lane-change duration (or a table profile's time scale); replaces
    /// `relative` for it.
    pub duration_s: Option<Draw>,
    /// The reaction time.
    pub reaction_s: Option<Draw>,
    /// The accepted lead gap.
    pub min_lead_gap_s: Option<Draw>,
    /// The accepted lag gap.
    pub min_lag_gap_s: Option<Draw>,
    /// The asymmetric profile's peak fraction.
    pub peak_fraction: Option<Draw>,
    /// The accelerating user's largest acceleration.
    pub max_acceleration_mps2: Option<Draw>,
    /// The perceived-safety time gap.
    pub comfort_time_gap_s: Option<Draw>,
    /// The perceived-safety time to collision.
    pub comfort_ttc_s: Option<Draw>,
}

impl ParameterSpread {
    /// Every parameter's half-width with its name in the TOML table.
    fn named(&self) -> [(&'static str, Option<Draw>); 9] {
        [
            ("start_threshold", self.start_threshold),
            ("duration_s", self.duration_s),
            ("reaction_s", self.reaction_s),
            ("min_lead_gap_s", self.min_lead_gap_s),
            ("min_lag_gap_s", self.min_lag_gap_s),
            ("peak_fraction", self.peak_fraction),
            ("max_acceleration_mps2", self.max_acceleration_mps2),
            ("comfort_time_gap_s", self.comfort_time_gap_s),
            ("comfort_ttc_s", self.comfort_ttc_s),
        ]
    }

    /// Checks every half-width, naming the field under `table`
    /// (`{table}.reaction_s.absolute`).
    pub fn validate(&self, table: &str) -> Result<(), UserError> {
        for (name, draw) in self.named() {
            if let Some(draw) = draw {
                let kind = match draw {
                    Draw::Relative(_) => "relative",
                    Draw::Absolute(_) => "absolute",
                };
                draw.validate(&format!("{table}.{name}.{kind}"))?;
            }
        }
        Ok(())
    }
}

/// How much a user's parameters vary between lane changes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Spread {
    /// Relative half-width of the uniform draw around the start threshold (the
    /// style's headway for the paper's users) and the duration: 0.05 draws each
    /// from `[0.95, 1.05]` times the nominal value.
    pub relative: f64,
    /// Seed of the draws.
    pub seed: u64,
    /// Half-widths of other parameters (or other half-widths for these two).
    #[serde(default)]
    pub parameters: ParameterSpread,
}

impl Spread {
    /// Checks every half-width, naming the field under `table`.
    pub fn validate(&self, table: &str) -> Result<(), UserError> {
        Draw::Relative(self.relative).validate(&format!("{table}.relative"))?;
        self.parameters.validate(&format!("{table}.parameters"))
    }

    /// Whether any parameter is drawn with a positive half-width.
    pub fn is_active(&self) -> bool {
        self.relative > 0.0
            || (self.parameters.named().iter())
                .filter_map(|(_, draw)| *draw)
                .any(|d| d.half_width() > 0.0)
    }

    /// One draw of the user's parameters for the next lane change. The draws are
    /// made in a fixed order (start threshold, duration, then the others in the
    /// order of [`ParameterSpread`]), each only when its half-width is positive,
    /// so that a user with only `relative` draws as it always has. A draw is
    /// clipped to its parameter's bounds.
    pub fn draw(&self, style: &Style, family: &Family, rng: &mut ChaCha8Rng) -> (Style, Family) {
        let (mut style, mut family) = (*style, family.clone());
        let p = &self.parameters;
        let relative = (self.relative > 0.0).then_some(Draw::Relative(self.relative));
        let active = |d: Option<Draw>| d.filter(|d| d.half_width() > 0.0);
        if let Some(d) = active(p.start_threshold.or(relative)) {
            match &mut family.start {
                StartRule::TimeHeadway => {
                    style.time_headway_s = d.apply(style.time_headway_s, rng, (1e-3, 1e3));
                }
                StartRule::TimeToCollision { seconds } => {
                    *seconds = d.apply(*seconds, rng, TTC_START_BOUNDS_S);
                }
                StartRule::DistanceGap { metres } => {
                    *metres = d.apply(*metres, rng, DISTANCE_START_BOUNDS_M);
                }
                StartRule::Incentive { threshold_mps2 } => {
                    *threshold_mps2 = d.apply(*threshold_mps2, rng, INCENTIVE_START_BOUNDS_MPS2);
                }
                StartRule::HeadwayOrTtc { ttc_seconds } => {
                    // Both cues, headway first.
                    style.time_headway_s = d.apply(style.time_headway_s, rng, (1e-3, 1e3));
                    *ttc_seconds = d.apply(*ttc_seconds, rng, TTC_START_BOUNDS_S);
                }
            }
        }
        if let Some(d) = active(p.duration_s.or(relative)) {
            let nominal = style.lane_change_duration_s;
            let drawn = d.apply(nominal, rng, (1e-3, 1e3));
            style.lane_change_duration_s = drawn;
            if let LateralProfile::Table { points } = &mut family.profile {
                // A table's duration is its last time: stretch its time axis.
                let scale = drawn / nominal;
                points.iter_mut().for_each(|point| point.time_s *= scale);
            }
        }
        if let Some(d) = active(p.reaction_s) {
            family.reaction_s = d.apply(family.reaction_s, rng, (0.0, MAX_REACTION_S));
        }
        let gaps = (0.0, MAX_GAP_ACCEPTANCE_S);
        if let Some(d) = active(p.min_lead_gap_s) {
            let nominal = family.min_lead_gap_s.unwrap_or(style.min_lead_gap_s);
            family.min_lead_gap_s = Some(d.apply(nominal, rng, (1e-3, MAX_GAP_ACCEPTANCE_S)));
        }
        if let Some(d) = active(p.min_lag_gap_s) {
            let nominal = family.min_lag_gap_s.unwrap_or(style.min_lag_gap_s);
            family.min_lag_gap_s = Some(d.apply(nominal, rng, gaps));
        }
        if let (Some(d), LateralProfile::Asymmetric { peak_fraction }) =
            (active(p.peak_fraction), &mut family.profile)
        {
            *peak_fraction = d.apply(*peak_fraction, rng, PEAK_FRACTION_BOUNDS);
        }
        if let (
            Some(d),
            SpeedRule::Accelerating {
                max_acceleration_mps2,
            },
        ) = (active(p.max_acceleration_mps2), &mut family.speed)
        {
            *max_acceleration_mps2 = d.apply(*max_acceleration_mps2, rng, ACCELERATION_BOUNDS_MPS2);
        }
        if let Some(comfort) = &mut family.perceived_safety {
            if let Some(d) = active(p.comfort_time_gap_s) {
                comfort.min_time_gap_s =
                    d.apply(comfort.min_time_gap_s, rng, COMFORT_TIME_GAP_BOUNDS_S);
            }
            if let (Some(d), Some(ttc)) = (active(p.comfort_ttc_s), comfort.min_ttc_s.as_mut()) {
                *ttc = d.apply(*ttc, rng, COMFORT_TTC_BOUNDS_S);
            }
        }
        (style, family)
    }

    /// The generator of this spread's draws.
    pub fn rng(&self) -> ChaCha8Rng {
        ChaCha8Rng::seed_from_u64(self.seed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::family::PerceivedSafety;

    #[test]
    fn relative_spread_draws_as_the_paper_user_always_has() {
        // Headway then duration, each uniform in [-r, r]: the sequence of the
        // original two-parameter user, so that its runs are unchanged.
        let spread = Spread {
            relative: 0.05,
            seed: 7,
            parameters: ParameterSpread::default(),
        };
        let mut rng = spread.rng();
        let mut reference = spread.rng();
        for _ in 0..50 {
            let (style, _) = spread.draw(&Style::CAUTIOUS, &Family::default(), &mut rng);
            let e_h: f64 = reference.random_range(-0.05..=0.05);
            let e_t: f64 = reference.random_range(-0.05..=0.05);
            assert_eq!(
                style.time_headway_s,
                Style::CAUTIOUS.time_headway_s * (1.0 + e_h)
            );
            assert_eq!(
                style.lane_change_duration_s,
                Style::CAUTIOUS.lane_change_duration_s * (1.0 + e_t)
            );
        }
    }

    #[test]
    fn every_parameter_can_be_drawn_and_stays_in_its_bounds() {
        let family = Family {
            start: StartRule::TimeToCollision { seconds: 6.0 },
            reaction_s: 0.2,
            profile: LateralProfile::Asymmetric { peak_fraction: 0.7 },
            speed: SpeedRule::Accelerating {
                max_acceleration_mps2: 1.0,
            },
            perceived_safety: Some(PerceivedSafety {
                min_ttc_s: Some(3.0),
                ..PerceivedSafety::default()
            }),
            ..Family::default()
        };
        let spread = Spread {
            relative: 0.0,
            seed: 3,
            parameters: ParameterSpread {
                start_threshold: Some(Draw::Relative(0.1)),
                duration_s: Some(Draw::Absolute(0.3)),
                reaction_s: Some(Draw::Absolute(0.5)),
                min_lead_gap_s: Some(Draw::Relative(0.2)),
                min_lag_gap_s: Some(Draw::Absolute(0.2)),
                peak_fraction: Some(Draw::Absolute(0.3)),
                max_acceleration_mps2: Some(Draw::Relative(0.3)),
                comfort_time_gap_s: Some(Draw::Relative(0.1)),
                comfort_ttc_s: Some(Draw::Absolute(1.0)),
            },
        };
        spread.validate("user.spread").unwrap();
        assert!(spread.is_active());
        let mut rng = spread.rng();
        let mut varied = 0;
        for _ in 0..200 {
            let (style, drawn) = spread.draw(&Style::NEUTRAL, &family, &mut rng);
            drawn.validate("drawn").unwrap();
            style.validate("drawn").unwrap();
            varied += usize::from(drawn != family);
        }
        assert_eq!(varied, 200);
    }

    #[test]
    fn bad_half_widths_name_their_field() {
        let spread = Spread {
            relative: 0.0,
            seed: 0,
            parameters: ParameterSpread {
                reaction_s: Some(Draw::Relative(0.9)),
                ..ParameterSpread::default()
            },
        };
        let err = spread.validate("user.spread").unwrap_err().to_string();
        assert!(
            err.contains("user.spread.parameters.reaction_s.relative"),
            "{err}"
        );
        let spread = Spread {
            relative: f64::NAN,
            ..spread
        };
        let err = spread.validate("user.spread").unwrap_err().to_string();
        assert!(err.contains("user.spread.relative"), "{err}");
    }
}
