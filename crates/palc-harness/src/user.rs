//! Simulated users: the paper's three driving styles (Section III.A), the
//! lane change each user expects, and how a user's parameters spread from one
//! lane change to the next.
//!
//! The paper gives only a time headway and a lane-change duration per style.
//! The expected trajectory built from them is palc's model (NOTES.md, "The user
//! model"): the user starts the lane change at the first step where the time
//! headway to the preceding vehicle has fallen to the user's value *and* the gap
//! on the target lane is acceptable to the user, then moves laterally along a
//! quintic (minimum-jerk) profile over the user's duration; its speed is the
//! ego ACC's (docs/paper-mapping.md, "Ego longitudinal behaviour").

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::HarnessError;

/// A driving style: what one user expects of a lane change.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Style {
    /// Time headway to the preceding vehicle at which the user starts (s).
    pub time_headway_s: f64,
    /// Duration of the lateral move from lane centre to lane centre (s).
    pub lane_change_duration_s: f64,
    /// Smallest net gap to the leader on the target lane that the user accepts,
    /// as a time gap at the ego's speed (s). Not in the paper: it makes the
    /// paper's congestion levels matter (see docs/paper-mapping.md).
    #[serde(default = "Style::default_min_lead_gap_s")]
    pub min_lead_gap_s: f64,
    /// Smallest net gap to the follower on the target lane that the user accepts,
    /// as a time gap at the follower's speed (s); 0 (the default, and the paper's
    /// styles) accepts any positive gap.
    #[serde(default)]
    pub min_lag_gap_s: f64,
}

impl Style {
    /// Aggressive: 1.15 s headway, 1.7 s lane change (paper, Section III.A).
    pub const AGGRESSIVE: Style = Style {
        time_headway_s: 1.15,
        lane_change_duration_s: 1.7,
        min_lead_gap_s: 0.5,
        min_lag_gap_s: 0.0,
    };
    /// Neutral: 1.23 s headway, 2.1 s lane change (paper, Section III.A).
    pub const NEUTRAL: Style = Style {
        time_headway_s: 1.23,
        lane_change_duration_s: 2.1,
        min_lead_gap_s: 0.6,
        min_lag_gap_s: 0.0,
    };
    /// Cautious: 1.76 s headway, 2.5 s lane change (paper, Section III.A).
    pub const CAUTIOUS: Style = Style {
        time_headway_s: 1.76,
        lane_change_duration_s: 2.5,
        min_lead_gap_s: 0.8,
        min_lag_gap_s: 0.0,
    };

    fn default_min_lead_gap_s() -> f64 {
        0.6
    }

    /// Checks every field is finite and positive, naming the first that is not.
    pub fn validate(&self, field: &str) -> Result<(), HarnessError> {
        let fields = [
            ("time_headway_s", self.time_headway_s),
            ("lane_change_duration_s", self.lane_change_duration_s),
            ("min_lead_gap_s", self.min_lead_gap_s),
        ];
        for (name, value) in fields {
            if !(value.is_finite() && value > 0.0) {
                return Err(HarnessError::InvalidConfig {
                    field: format!("{field}.{name}"),
                    value,
                    bound: "a finite value > 0".to_owned(),
                });
            }
        }
        if !(self.min_lag_gap_s.is_finite() && (0.0..=10.0).contains(&self.min_lag_gap_s)) {
            return Err(HarnessError::InvalidConfig {
                field: format!("{field}.min_lag_gap_s"),
                value: self.min_lag_gap_s,
                bound: "a value in [0, 10.0]".to_owned(),
            });
        }
        Ok(())
    }

    /// This style with headway and duration scaled by `1 + e_h` and `1 + e_t`.
    fn perturbed(self, e_h: f64, e_t: f64) -> Style {
        Style {
            time_headway_s: self.time_headway_s * (1.0 + e_h),
            lane_change_duration_s: self.lane_change_duration_s * (1.0 + e_t),
            ..self
        }
    }
}

/// The paper's three driving styles (Section III.A), by name.
///
/// Serializes as its [`name`](StylePreset::name): `aggressive`, `neutral` or
/// `cautious`; parsing any other name is refused with the list of valid ones.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StylePreset {
    /// [`Style::AGGRESSIVE`].
    Aggressive,
    /// [`Style::NEUTRAL`].
    Neutral,
    /// [`Style::CAUTIOUS`].
    Cautious,
}

impl StylePreset {
    /// The three presets, from the shortest headway to the longest.
    pub const ALL: [StylePreset; 3] = [
        StylePreset::Aggressive,
        StylePreset::Neutral,
        StylePreset::Cautious,
    ];

    /// The preset's name in configs and reports.
    pub const fn name(self) -> &'static str {
        match self {
            StylePreset::Aggressive => "aggressive",
            StylePreset::Neutral => "neutral",
            StylePreset::Cautious => "cautious",
        }
    }

    /// The style of this preset.
    pub const fn style(self) -> Style {
        match self {
            StylePreset::Aggressive => Style::AGGRESSIVE,
            StylePreset::Neutral => Style::NEUTRAL,
            StylePreset::Cautious => Style::CAUTIOUS,
        }
    }

    /// The valid names, quoted, for messages: `` `aggressive`, `neutral`, `cautious` ``.
    pub(crate) fn quoted_names() -> String {
        Self::ALL
            .map(|preset| format!("`{}`", preset.name()))
            .join(", ")
    }
}

impl std::fmt::Display for StylePreset {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for StylePreset {
    type Err = HarnessError;

    /// The preset with this name; [`HarnessError::UnknownStyle`] lists the valid names.
    fn from_str(name: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|preset| preset.name() == name)
            .ok_or_else(|| HarnessError::UnknownStyle {
                name: name.to_owned(),
                expected: Self::quoted_names(),
            })
    }
}

/// What the user sees at one step of the predicted approach, the ego keeping its lane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Situation {
    /// Time headway to the preceding vehicle: net gap / ego speed (s).
    pub time_headway_s: f64,
    /// Net gap to the leader on the target lane (m); `None` when there is none.
    pub target_lead_gap_m: Option<f64>,
    /// Net gap to the follower on the target lane (m); `None` when there is none.
    /// Negative while that vehicle is alongside the ego.
    pub target_lag_gap_m: Option<f64>,
    /// Ego speed (m/s).
    pub ego_speed: f64,
    /// Speed of the leader on the target lane (m/s); `None` when there is none.
    pub target_lead_speed: Option<f64>,
    /// Speed of the follower on the target lane (m/s); `None` when there is none.
    pub target_lag_speed: Option<f64>,
}

impl Situation {
    /// Whether the time headway to the preceding vehicle is positive and at most
    /// `time_headway_s`.
    pub fn decides_at(&self, time_headway_s: f64) -> bool {
        self.time_headway_s > 0.0 && self.time_headway_s <= time_headway_s
    }
}

impl Style {
    /// Whether the user, having decided to change lanes, finds the gaps in this
    /// situation acceptable: the lead gap at least `min_lead_gap_s` at the ego's
    /// speed, the lag gap positive and at least `min_lag_gap_s` at the follower's
    /// speed, and the ego
    /// still behind the preceding vehicle (nobody starts behind a vehicle it has
    /// already reached).
    pub fn accepts(&self, situation: &Situation) -> bool {
        let lead_ok = situation
            .target_lead_gap_m
            .is_none_or(|gap| gap >= self.min_lead_gap_s * situation.ego_speed);
        let lag_ok = situation.target_lag_gap_m.is_none_or(|gap| {
            gap > 0.0 && gap >= self.min_lag_gap_s * situation.target_lag_speed.unwrap_or(0.0)
        });
        situation.time_headway_s > 0.0 && lead_ok && lag_ok
    }

    /// Whether the time headway to the preceding vehicle has fallen to the user's.
    pub fn decides(&self, situation: &Situation) -> bool {
        situation.decides_at(self.time_headway_s)
    }

    /// The step at which the user starts, given the situation per step: the user
    /// decides to change lanes at the first step where the headway has fallen to
    /// theirs, then starts at the first step from there where the gaps are
    /// acceptable. (An ego that drops back to seek a gap opens the headway again;
    /// the decision stands.)
    pub fn start_step(&self, situations: &[Situation]) -> Option<usize> {
        let decided = situations.iter().position(|s| self.decides(s))?;
        situations[decided..]
            .iter()
            .position(|s| self.accepts(s))
            .map(|offset| decided + offset)
    }
}

/// The lateral profile of a lane change the user expects.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ExpectedLaneChange {
    /// Time of the start, from the start of the plan (s).
    pub start_s: f64,
    /// Duration of the lateral move (s).
    pub duration_s: f64,
    /// Lateral position before the move (m).
    pub from_l: f64,
    /// Lateral position after the move (m).
    pub to_l: f64,
}

impl ExpectedLaneChange {
    /// The expected lateral position at time `t` from the start of the plan.
    pub fn lateral(&self, t: f64) -> f64 {
        let tau = ((t - self.start_s) / self.duration_s).clamp(0.0, 1.0);
        self.from_l + (self.to_l - self.from_l) * quintic(tau)
    }

    /// Time at which the move ends (s).
    pub fn end_s(&self) -> f64 {
        self.start_s + self.duration_s
    }

    /// The expected lateral position at steps `0..=k` of `dt`.
    pub fn sample(&self, k: usize, dt: f64) -> Vec<f64> {
        (0..=k).map(|i| self.lateral(i as f64 * dt)).collect()
    }
}

/// The minimum-jerk blend `10 τ³ − 15 τ⁴ + 6 τ⁵` on `[0, 1]`: zero speed and
/// acceleration at both ends.
pub fn quintic(tau: f64) -> f64 {
    let t = tau.clamp(0.0, 1.0);
    t * t * t * (10.0 + t * (-15.0 + 6.0 * t))
}

/// How much a user's parameters vary between lane changes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Spread {
    /// Relative half-width of the uniform draw around the style's headway and
    /// duration: 0.05 draws each from `[0.95, 1.05]` times the nominal value.
    pub relative: f64,
    /// Seed of the draws.
    pub seed: u64,
}

/// A simulated user: a nominal style and, optionally, a spread around it.
#[derive(Debug, Clone)]
pub struct User {
    nominal: Style,
    spread: Option<Spread>,
    rng: Option<ChaCha8Rng>,
}

impl User {
    /// A user who expects exactly `nominal` in every lane change.
    pub fn deterministic(nominal: Style) -> Result<Self, HarnessError> {
        nominal.validate("user.style")?;
        Ok(Self {
            nominal,
            spread: None,
            rng: None,
        })
    }

    /// A user whose headway and duration are drawn anew for every lane change.
    pub fn with_spread(nominal: Style, spread: Spread) -> Result<Self, HarnessError> {
        nominal.validate("user.style")?;
        if !(spread.relative.is_finite() && (0.0..0.5).contains(&spread.relative)) {
            return Err(HarnessError::InvalidConfig {
                field: "user.spread.relative".to_owned(),
                value: spread.relative,
                bound: "a value in [0, 0.5)".to_owned(),
            });
        }
        Ok(Self {
            nominal,
            spread: Some(spread),
            rng: Some(ChaCha8Rng::seed_from_u64(spread.seed)),
        })
    }

    /// The nominal style.
    pub fn nominal(&self) -> Style {
        self.nominal
    }

    /// Whether the user's parameters vary between lane changes.
    pub fn has_spread(&self) -> bool {
        self.spread.is_some_and(|s| s.relative > 0.0)
    }

    /// The style this user expects in the next lane change (one draw per call).
    pub fn next_style(&mut self) -> Style {
        match (self.spread, self.rng.as_mut()) {
            (Some(spread), Some(rng)) if spread.relative > 0.0 => {
                let r = spread.relative;
                let e_h = rng.random_range(-r..=r);
                let e_t = rng.random_range(-r..=r);
                self.nominal.perturbed(e_h, e_t)
            }
            _ => self.nominal,
        }
    }
}

/// The takeover rule (paper, Section III.A): the user takes over at the first
/// step where the planned lateral position deviates from the expected one by
/// more than `threshold` (0.3 m in the paper).
pub fn first_takeover(planned_l: &[f64], expected_l: &[f64], threshold: f64) -> Option<usize> {
    planned_l
        .iter()
        .zip(expected_l)
        .position(|(p, e)| (p - e).abs() > threshold)
}

/// Largest `|planned − expected|` over the steps.
pub fn max_deviation(planned_l: &[f64], expected_l: &[f64]) -> f64 {
    planned_l
        .iter()
        .zip(expected_l)
        .map(|(p, e)| (p - e).abs())
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_round_trip_through_their_names() {
        for preset in StylePreset::ALL {
            assert_eq!(preset.name().parse::<StylePreset>().unwrap(), preset);
            assert_eq!(preset.to_string(), preset.name());
        }
        assert_eq!(StylePreset::Neutral.style(), Style::NEUTRAL);
        let err = "reckless".parse::<StylePreset>().unwrap_err().to_string();
        for name in ["reckless", "`aggressive`", "`neutral`", "`cautious`"] {
            assert!(err.contains(name), "{err}");
        }
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
    fn the_user_starts_only_when_headway_and_gap_are_acceptable() {
        let style = Style::NEUTRAL;
        let at = |headway: f64, gap: Option<f64>| Situation {
            time_headway_s: headway,
            target_lead_gap_m: gap,
            target_lag_gap_m: Some(3.0),
            ego_speed: 20.0,
            target_lead_speed: Some(20.0),
            target_lag_speed: Some(20.0),
        };
        let situations = [
            at(2.0, Some(50.0)),
            at(1.2, Some(5.0)),
            at(1.1, Some(11.0)),
            at(1.0, Some(13.0)),
        ];
        assert_eq!(style.start_step(&situations), Some(3));
        assert_eq!(style.start_step(&situations[..3]), None);
        assert_eq!(style.start_step(&[at(1.0, None)]), Some(0));
    }

    #[test]
    fn a_user_decides_on_the_headway_then_waits_for_the_gap() {
        let style = Style {
            min_lag_gap_s: 0.5,
            ..Style::NEUTRAL
        };
        let at = |headway: f64, lag: f64| Situation {
            time_headway_s: headway,
            target_lead_gap_m: Some(50.0),
            target_lag_gap_m: Some(lag),
            ego_speed: 20.0,
            target_lead_speed: Some(20.0),
            target_lag_speed: Some(20.0),
        };
        // Decides at step 1 (1.2 s <= 1.23 s); the lag gap (10 m needed) opens at
        // step 3, when an ego dropping back has opened the headway again.
        let situations = [at(1.5, 20.0), at(1.2, 5.0), at(1.3, 8.0), at(1.6, 12.0)];
        assert_eq!(style.start_step(&situations), Some(3));
        // A gap before the decision does not count.
        assert_eq!(style.start_step(&situations[..1]), None);
        // Nobody starts behind a vehicle it has reached.
        assert_eq!(style.start_step(&[at(-0.5, 20.0)]), None);
        let bad = Style {
            min_lag_gap_s: f64::NAN,
            ..Style::NEUTRAL
        };
        let err = bad.validate("user.custom").unwrap_err().to_string();
        assert!(err.contains("user.custom.min_lag_gap_s"), "{err}");
    }

    #[test]
    fn takeover_is_the_first_step_beyond_the_threshold() {
        let planned = [0.0, 0.1, 0.5, 0.9];
        let expected = [0.0, 0.2, 0.9, 0.0];
        assert_eq!(first_takeover(&planned, &expected, 0.3), Some(2));
        assert_eq!(first_takeover(&planned[..2], &expected[..2], 0.3), None);
        assert!((max_deviation(&planned, &expected) - 0.9).abs() < 1e-12);
    }

    #[test]
    fn spread_draws_are_reproducible_and_bounded() {
        let spread = Spread {
            relative: 0.05,
            seed: 7,
        };
        let mut a = User::with_spread(Style::CAUTIOUS, spread).unwrap();
        let mut b = User::with_spread(Style::CAUTIOUS, spread).unwrap();
        for _ in 0..100 {
            let (x, y) = (a.next_style(), b.next_style());
            assert_eq!(x, y);
            let ratio = x.time_headway_s / Style::CAUTIOUS.time_headway_s;
            assert!((0.95 - 1e-12..=1.05 + 1e-12).contains(&ratio));
        }
    }

    #[test]
    fn invalid_users_are_refused_naming_the_field() {
        let bad = Style {
            time_headway_s: -1.0,
            ..Style::NEUTRAL
        };
        let err = User::deterministic(bad).unwrap_err().to_string();
        assert!(err.contains("user.style.time_headway_s"), "{err}");
        let spread = Spread {
            relative: 0.7,
            seed: 0,
        };
        let err = User::with_spread(Style::NEUTRAL, spread)
            .unwrap_err()
            .to_string();
        assert!(err.contains("user.spread.relative"), "{err}");
    }
}
