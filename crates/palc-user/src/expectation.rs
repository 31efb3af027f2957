//! What a user expects of a lane change: its lateral move, the states it would
//! drive, and the rule by which it takes over a plan; and the sanity checks
//! every expectation passes before a user takes part in a run.

use palc_planner::State;
use serde::{Deserialize, Serialize};

use crate::family::{PerceivedSafety, SpeedRule};
use crate::profile::LateralProfile;
use crate::situation::Situation;

/// Largest lateral acceleration of an expected lane change (m/s²): about 1 g,
/// beyond any driver's lane change (the paper's aggressive quintic peaks at
/// 7.0 m/s²) yet short of a step in the profile.
pub const MAX_LATERAL_ACCELERATION_MPS2: f64 = 10.0;
/// Largest lateral jerk of an expected lane change (m/s³), measured over
/// [`SMOOTHNESS_STEP_S`]: the aggressive quintic peaks at 43 m/s³, and a cosine
/// profile's acceleration step at its ends reads as about 60-80 m/s³ at this step.
pub const MAX_LATERAL_JERK_MPS3: f64 = 150.0;
/// Step of the finite differences that measure lateral acceleration and jerk (s):
/// half the paper's planning step, so that a table's corner between two samples
/// still shows.
pub const SMOOTHNESS_STEP_S: f64 = 0.05;

/// The lateral move of a lane change a user expects.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExpectedLaneChange {
    /// Time of the start, from the start of the plan (s).
    pub start_s: f64,
    /// Duration of the lateral move (s).
    pub duration_s: f64,
    /// Lateral position before the move (m).
    pub from_l: f64,
    /// Lateral position after the move (m).
    pub to_l: f64,
    /// The shape of the move; quintic (the paper's users) unless given.
    #[serde(default)]
    pub profile: LateralProfile,
}

impl ExpectedLaneChange {
    /// A quintic (minimum-jerk) move, the paper's user's.
    pub fn quintic(start_s: f64, duration_s: f64, from_l: f64, to_l: f64) -> Self {
        Self {
            start_s,
            duration_s,
            from_l,
            to_l,
            profile: LateralProfile::Quintic,
        }
    }

    /// The expected lateral position at time `t` from the start of the plan.
    pub fn lateral(&self, t: f64) -> f64 {
        let offset = (self.to_l - self.from_l).abs();
        let direction = (self.to_l - self.from_l).signum();
        self.from_l
            + direction
                * self
                    .profile
                    .offset_at(t - self.start_s, self.duration_s, offset)
    }

    /// Time at which the move ends (s).
    pub fn end_s(&self) -> f64 {
        self.start_s + self.duration_s
    }

    /// The expected lateral position at steps `0..=k` of `dt`.
    pub fn sample(&self, k: usize, dt: f64) -> Vec<f64> {
        (0..=k).map(|i| self.lateral(i as f64 * dt)).collect()
    }

    /// Largest lateral acceleration (m/s²) and jerk (m/s³) of the move, by finite
    /// differences over [`SMOOTHNESS_STEP_S`].
    pub fn peak_acceleration_and_jerk(&self) -> (f64, f64) {
        let h = SMOOTHNESS_STEP_S;
        let first = self.start_s - 3.0 * h;
        let n = ((self.duration_s + 6.0 * h) / h).ceil() as usize;
        let y: Vec<f64> = (0..=n)
            .map(|j| self.lateral(first + j as f64 * h))
            .collect();
        let a: Vec<f64> = y
            .windows(3)
            .map(|w| (w[2] - 2.0 * w[1] + w[0]) / (h * h))
            .collect();
        let peak_a = a.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let peak_j = a
            .windows(3)
            .map(|w| ((w[2] - w[0]) / (2.0 * h)).abs())
            .fold(0.0, f64::max);
        (peak_a, peak_j)
    }
}

/// Why a user took over.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(tag = "rule", rename_all = "snake_case")]
pub enum TakeoverCause {
    /// The planned lateral position deviated beyond the threshold (paper, Section III.A).
    #[default]
    Deviation,
    /// A target-lane vehicle came nearer than the user's comfort bound.
    PerceivedSafety {
        /// Whether it was the target lane's leader (else its follower).
        lead: bool,
        /// Its net gap as a time gap (s); `None` when not finite.
        time_gap_s: Option<f64>,
        /// Its time to collision (s); `None` when not closing.
        ttc_s: Option<f64>,
    },
}

impl std::fmt::Display for TakeoverCause {
    /// In words, e.g. `the target lane's follower at a 0.58 s time gap`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            TakeoverCause::Deviation => write!(f, "the plan strayed past its deviation bound"),
            TakeoverCause::PerceivedSafety {
                lead,
                time_gap_s,
                ttc_s,
            } => {
                let who = if lead { "leader" } else { "follower" };
                write!(f, "the target lane's {who} came too near")?;
                if let Some(gap) = time_gap_s {
                    write!(f, ": a {gap:.2} s time gap")?;
                }
                if let Some(ttc) = ttc_s {
                    let sep = if time_gap_s.is_some() { "," } else { ":" };
                    write!(f, "{sep} {ttc:.2} s to collision")?;
                }
                Ok(())
            }
        }
    }
}

/// When a user takes over a plan.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TakeoverRule {
    /// Lateral deviation beyond which the user takes over (m); the paper's 0.3 m.
    pub deviation_m: f64,
    /// The perceived-safety bound, if the user has one.
    pub perceived_safety: Option<PerceivedSafety>,
}

impl TakeoverRule {
    /// Whether the user takes over at a step where the ego is at `ego_l`, the user
    /// expected `expected_l` and sees `seen`, in a lane change from `from_l` to
    /// `to_l`; the deviation rule first.
    pub fn judge(
        &self,
        ego_l: f64,
        expected_l: f64,
        (from_l, to_l): (f64, f64),
        seen: &Situation,
    ) -> Option<TakeoverCause> {
        if (ego_l - expected_l).abs() > self.deviation_m {
            return Some(TakeoverCause::Deviation);
        }
        let comfort = self.perceived_safety?;
        let direction = (to_l - from_l).signum();
        let (lead, gap, ttc) =
            comfort.breached((ego_l - from_l) * direction, (to_l - from_l).abs(), seen)?;
        Some(TakeoverCause::PerceivedSafety {
            lead,
            time_gap_s: gap.is_finite().then_some(gap),
            ttc_s: ttc.is_finite().then_some(ttc),
        })
    }
}

/// The lane change a user expects in one scenario, over the whole search window.
#[derive(Debug, Clone, PartialEq)]
pub struct Expectation {
    /// The lateral move.
    pub lane_change: ExpectedLaneChange,
    /// Step at which the user decided to change lanes.
    pub decision_step: usize,
    /// Step at which the move starts.
    pub start_step: usize,
    /// The states the user would drive, steps `0..` of the search window, in the
    /// plan frame (`s` from the trigger).
    pub states: Vec<State>,
    /// When the user takes over.
    pub takeover: TakeoverRule,
    /// The user's speed during its own lane change.
    pub speed: SpeedRule,
    /// The target lane's speed at the start (m/s): where an accelerating user heads.
    pub target_speed: f64,
}

impl Expectation {
    /// The expectation's own longitudinal acceleration at `step` after a takeover,
    /// driving at `speed`, when the ego ACC would command `acc`: the default of
    /// [`crate::User::acceleration_after_takeover`] (the ACC's, or, for an
    /// accelerating user from its start, the speed gap to the target lane times
    /// 1/s within its largest acceleration, never above the ACC's).
    pub fn acceleration_after_takeover(&self, step: usize, speed: f64, acc: f64) -> f64 {
        match self.speed {
            SpeedRule::Accelerating {
                max_acceleration_mps2,
            } if step >= self.start_step => (self.target_speed - speed)
                .clamp(-max_acceleration_mps2, max_acceleration_mps2)
                .min(acc),
            _ => acc,
        }
    }

    /// The expectation's own [`TakeoverRule`] at `step` of a drive, the ego at
    /// `ego` (plan frame) seeing `seen`: the default of [`crate::User::takes_over`].
    pub fn judge(&self, step: usize, ego: &State, seen: &Situation) -> Option<TakeoverCause> {
        let expected_l = self.states.get(step).map_or(ego.l, |x| x.l);
        let lane_change = &self.lane_change;
        self.takeover.judge(
            ego.l,
            expected_l,
            (lane_change.from_l, lane_change.to_l),
            seen,
        )
    }

    /// Expected lateral positions at steps `0..=k`.
    pub fn lateral(&self, k: usize) -> Vec<f64> {
        self.states.iter().take(k + 1).map(|x| x.l).collect()
    }
}
