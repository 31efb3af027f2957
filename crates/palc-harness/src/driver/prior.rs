//! The estimate's prior: which start models are considered, each with its
//! stated support, and how closely a start is observed.
//!
//! Every start model of the grid has the same prior mass within its cue, and
//! each cue a quarter of the whole. The supports are the bounds a simulated
//! user's parameters are validated against (palc-user), so that every valid
//! user of a cue has a neighbour in the grid; the grids are fine enough that the
//! neighbour starts within a step or two of it.

use palc_user::{
    DISTANCE_START_BOUNDS_M, INCENTIVE_SAFE_DECELERATION_MPS2, INCENTIVE_START_BOUNDS_MPS2,
    Situation, StartRule, TTC_START_BOUNDS_S, incentive_mps2,
};
use serde::{Deserialize, Serialize};

/// Standard deviation (s) of an observed start around the start a model
/// predicts: the fitted start is within 0.15 s of a lane change's true start
/// for the profiles outside the fit's own models (onset/fit.rs), and a grid
/// neighbour of the driver's model starts up to a step (0.1 s) away.
pub const OBSERVATION_SD_S: f64 = 0.2;
/// The prior probability that an observed start is not where the driver's
/// model starts but misread, equally likely anywhere in its scene: a lesson's
/// fit placed it off (a shape in no model, up to 1.3 s; 0075, 0079) or a wait was
/// read as a decision. One start in twenty, stated, not fitted. Without it one
/// misread start outweighs every other scene: a ttc-start user's estimate moved
/// to a 0.7 s reaction and predicted 0.4 s late (0081).
pub const MISREAD_START_PROBABILITY: f64 = 0.05;
/// A driver is outside the model when no model of the grid predicts every
/// observed start within this many [`OBSERVATION_SD_S`] (0.6 s): a start that far
/// from every model's is not observation noise.
pub const MISFIT_SDS: f64 = 3.0;
/// Time-headway thresholds (s): from 0.3 s, closer than drivers keep while
/// still deciding, to 4 s, beyond the 2.2 s at which the scenes' plans start;
/// in steps of 0.01 s, the headway's fall in a tenth of a second of approach.
const TIME_HEADWAY_RANGE_S: (f64, f64, f64) = (0.3, 4.0, 0.01);
/// Geometric grids of the time-to-collision and distance thresholds: this many
/// values over palc-user's bounds ([`TTC_START_BOUNDS_S`],
/// [`DISTANCE_START_BOUNDS_M`]), 1.7 % and 2.3 % apart.
const GEOMETRIC_STEPS: usize = 200;
/// Incentive thresholds (m/s²) over [`INCENTIVE_START_BOUNDS_MPS2`], 0.01 apart.
const INCENTIVE_STEP_MPS2: f64 = 0.01;
/// Reaction times (s), a step apart: alerted drivers react within 1.5 s
/// (Green, 2000).
pub const REACTIONS_S: [f64; 16] = [
    0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2, 1.3, 1.4, 1.5,
];
/// Accepted lead gaps (s): critical lead gaps of gap-acceptance studies lie
/// within 0-2 s (Toledo, Koutsopoulos and Ben-Akiva, 2003).
pub const LEAD_GAPS_S: [f64; 11] = [0.0, 0.2, 0.4, 0.6, 0.8, 1.0, 1.2, 1.4, 1.6, 1.8, 2.0];
/// Accepted lag gaps (s), as [`LEAD_GAPS_S`] but for the follower, which
/// drivers accept closer.
pub const LAG_GAPS_S: [f64; 6] = [0.0, 0.25, 0.5, 0.75, 1.0, 1.5];

/// The prior's scale of demand (s): a driver is assumed to need no more than
/// it has been seen to need; each further `DEMAND_SCALE_S` of reaction or of an
/// accepted gap makes a model `e` times less likely a priori.
pub const DEMAND_SCALE_S: f64 = 0.5;

/// The prior mass of a cue: half on the time headway, the paper's cue
/// (Section III.A: a user starts when the time headway falls to its own), the
/// rest shared by the other cues.
pub fn cue_mass(cue: Cue) -> f64 {
    match cue {
        Cue::TimeHeadway => 0.5,
        _ => 0.5 / (Cue::ALL.len() - 1) as f64,
    }
}

/// The cue a decision is taken on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Cue {
    /// Time headway to the vehicle ahead.
    TimeHeadway,
    /// Time to collision with the vehicle ahead.
    TimeToCollision,
    /// Net distance to the vehicle ahead.
    DistanceGap,
    /// MOBIL's speed-gain incentive.
    Incentive,
}

impl Cue {
    /// Every cue of the model.
    pub const ALL: [Cue; 4] = [
        Cue::TimeHeadway,
        Cue::TimeToCollision,
        Cue::DistanceGap,
        Cue::Incentive,
    ];

    /// The cue's name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Cue::TimeHeadway => "time-headway",
            Cue::TimeToCollision => "time-to-collision",
            Cue::DistanceGap => "distance-gap",
            Cue::Incentive => "incentive",
        }
    }

    /// The thresholds of the grid, in the cue's unit, from the one that decides
    /// latest to the one that decides first.
    pub fn thresholds(self) -> Vec<f64> {
        let geometric = |(low, high): (f64, f64)| {
            let ratio = (high / low).powf(1.0 / (GEOMETRIC_STEPS - 1) as f64);
            (0..GEOMETRIC_STEPS)
                .map(|i| low * ratio.powi(i as i32))
                .collect()
        };
        let linear = |(low, high): (f64, f64), step: f64| {
            let n = ((high - low) / step).round() as usize;
            (0..=n).map(|i| low + step * i as f64).collect()
        };
        match self {
            Cue::TimeHeadway => {
                let (low, high, step) = TIME_HEADWAY_RANGE_S;
                linear((low, high), step)
            }
            Cue::TimeToCollision => geometric(TTC_START_BOUNDS_S),
            Cue::DistanceGap => geometric(DISTANCE_START_BOUNDS_M),
            // Descending, as the other cues' thresholds: from the latest decision.
            Cue::Incentive => {
                let mut thresholds: Vec<f64> =
                    linear(INCENTIVE_START_BOUNDS_MPS2, INCENTIVE_STEP_MPS2);
                thresholds.reverse();
                thresholds
            }
        }
    }

    /// The start rule of this cue at `threshold`, with the time headway it reads
    /// (the rule's own headway for [`StartRule::TimeHeadway`]).
    pub fn rule(self, threshold: f64) -> (StartRule, f64) {
        match self {
            Cue::TimeHeadway => (StartRule::TimeHeadway, threshold),
            Cue::TimeToCollision => (StartRule::TimeToCollision { seconds: threshold }, 0.0),
            Cue::DistanceGap => (StartRule::DistanceGap { metres: threshold }, 0.0),
            Cue::Incentive => (
                StartRule::Incentive {
                    threshold_mps2: threshold,
                },
                0.0,
            ),
        }
    }

    /// The cue's urgency in `situation`: the rule at `threshold` decides exactly
    /// when the urgency is at least [`Cue::key`]`(threshold)`, so that the first
    /// deciding step is monotone in the threshold. `-∞` where no threshold decides.
    pub fn urgency(self, situation: &Situation, set_speed_mps: f64) -> f64 {
        if situation.time_headway_s <= 0.0 {
            return f64::NEG_INFINITY;
        }
        let urgency = match self {
            Cue::TimeHeadway => -situation.time_headway_s,
            Cue::TimeToCollision => -situation.preceding_ttc_s(),
            Cue::DistanceGap => -situation.preceding_gap_m,
            Cue::Incentive => {
                let (gain, follower) = incentive_mps2(situation, set_speed_mps);
                if follower >= -INCENTIVE_SAFE_DECELERATION_MPS2 {
                    gain
                } else {
                    f64::NEG_INFINITY
                }
            }
        };
        if urgency.is_nan() {
            f64::NEG_INFINITY
        } else {
            urgency
        }
    }

    /// The urgency at or above which the rule at `threshold` decides. The
    /// incentive's rule decides strictly above its threshold (never negative):
    /// the next float.
    pub fn key(self, threshold: f64) -> f64 {
        match self {
            Cue::Incentive => f64::from_bits(threshold.max(0.0).to_bits() + 1),
            _ => -threshold,
        }
    }
}
