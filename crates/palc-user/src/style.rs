//! The paper's driving styles (Section III.A): a time headway at which the user
//! starts, a lane-change duration, and the gaps on the target lane the user accepts.

use serde::{Deserialize, Serialize};

use crate::UserError;
use crate::situation::Situation;

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
    /// paper's congestion levels matter (see docs/experiments/0002-the-papers-user-model.md).
    #[serde(default = "Style::default_min_lead_gap_s")]
    pub min_lead_gap_s: f64,
    /// Smallest net gap to the follower on the target lane that the user accepts,
    /// as a time gap at the follower's speed (s); 0 (the default, and the paper's
    /// styles) accepts any positive gap.
    #[serde(default)]
    pub min_lag_gap_s: f64,
}

/// Largest `min_lag_gap_s` and `min_lead_gap_s` (s).
pub const MAX_GAP_ACCEPTANCE_S: f64 = 10.0;

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
    pub fn validate(&self, field: &str) -> Result<(), UserError> {
        let fields = [
            ("time_headway_s", self.time_headway_s),
            ("lane_change_duration_s", self.lane_change_duration_s),
            ("min_lead_gap_s", self.min_lead_gap_s),
        ];
        for (name, value) in fields {
            if !(value.is_finite() && value > 0.0) {
                return Err(UserError::InvalidConfig {
                    field: format!("{field}.{name}"),
                    value,
                    bound: "a finite value > 0".to_owned(),
                });
            }
        }
        if !(self.min_lag_gap_s.is_finite()
            && (0.0..=MAX_GAP_ACCEPTANCE_S).contains(&self.min_lag_gap_s))
        {
            return Err(UserError::InvalidConfig {
                field: format!("{field}.min_lag_gap_s"),
                value: self.min_lag_gap_s,
                bound: format!("a value in [0, {MAX_GAP_ACCEPTANCE_S:?}]"),
            });
        }
        Ok(())
    }

    /// Whether the user, having decided to change lanes, finds the gaps in this
    /// situation acceptable: the lead gap at least `min_lead_gap_s` at the ego's
    /// speed, the lag gap positive and at least `min_lag_gap_s` at the follower's
    /// speed, and the ego still behind the preceding vehicle (nobody starts behind
    /// a vehicle it has already reached).
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
    pub fn quoted_names() -> String {
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
    type Err = UserError;

    /// The preset with this name; [`UserError::UnknownStyle`] lists the valid names.
    fn from_str(name: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|preset| preset.name() == name)
            .ok_or_else(|| UserError::UnknownStyle {
                name: name.to_owned(),
                expected: Self::quoted_names(),
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(headway: f64, lead: Option<f64>, lag: f64) -> Situation {
        Situation {
            time_headway_s: headway,
            preceding_gap_m: headway * 20.0,
            preceding_speed: Some(15.0),
            target_lead_gap_m: lead,
            target_lag_gap_m: Some(lag),
            ego_speed: 20.0,
            target_lead_speed: Some(20.0),
            target_lag_speed: Some(20.0),
        }
    }

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
    fn the_user_starts_only_when_headway_and_gap_are_acceptable() {
        let style = Style::NEUTRAL;
        let situations = [
            at(2.0, Some(50.0), 3.0),
            at(1.2, Some(5.0), 3.0),
            at(1.1, Some(11.0), 3.0),
            at(1.0, Some(13.0), 3.0),
        ];
        assert_eq!(style.start_step(&situations), Some(3));
        assert_eq!(style.start_step(&situations[..3]), None);
        assert_eq!(style.start_step(&[at(1.0, None, 3.0)]), Some(0));
    }

    #[test]
    fn a_user_decides_on_the_headway_then_waits_for_the_gap() {
        let style = Style {
            min_lag_gap_s: 0.5,
            ..Style::NEUTRAL
        };
        // Decides at step 1 (1.2 s <= 1.23 s); the lag gap (10 m needed) opens at
        // step 3, when an ego dropping back has opened the headway again.
        let situations = [
            at(1.5, Some(50.0), 20.0),
            at(1.2, Some(50.0), 5.0),
            at(1.3, Some(50.0), 8.0),
            at(1.6, Some(50.0), 12.0),
        ];
        assert_eq!(style.start_step(&situations), Some(3));
        // A gap before the decision does not count.
        assert_eq!(style.start_step(&situations[..1]), None);
        // Nobody starts behind a vehicle it has reached.
        assert_eq!(style.start_step(&[at(-0.5, Some(50.0), 20.0)]), None);
        let bad = Style {
            min_lag_gap_s: f64::NAN,
            ..Style::NEUTRAL
        };
        let err = bad.validate("user.custom").unwrap_err().to_string();
        assert!(err.contains("user.custom.min_lag_gap_s"), "{err}");
    }
}
