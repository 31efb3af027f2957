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
/// A start this many [`OBSERVATION_SD_S`] (0.6 s) from a model's is not
/// observation noise: the model needs it misread. A driver is outside the
/// model when every model of the grid needs more misread starts than
/// [`MISREAD_START_PROBABILITY`] makes plausible (0087).
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

/// Of the time-headway thresholds, every this-many-th is paired in the two-cue
/// decision ([`Cue::HeadwayOrTtc`]): 0.03 s apart, about three steps of a
/// typical approach (a tenth of a second moves the headway by about 0.01 s).
/// Pairing every one as well took a two-cue driver without spread from 14 %
/// to 10 % of its drive's lane changes 11-50 taken over, for three times the
/// pairs (docs/experiments/0094-the-time-to-collisions-pairs.md).
pub const PAIRED_HEADWAY_EVERY: usize = 3;
/// Of the time-to-collision thresholds, every this-many-th is paired: every
/// one, 1.7 % apart, 0.14 s at an 8 s threshold, where a tenth of a second of
/// approach takes 0.1 s off the time to collision, so that a two-cue driver
/// has a neighbour that starts within about a step of it. Every third (5.2 %,
/// four steps at 8 s) left the two-cue driver without spread 24 % of its
/// drive's lane changes 11-50 taken over, against 14 % (0094).
pub const PAIRED_TTC_EVERY: usize = 1;

/// The prior mass of a cue: half on the time headway, the paper's cue
/// (Section III.A: a user starts when the time headway falls to its own), the
/// rest shared by the other cues.
pub fn cue_mass(cue: Cue) -> f64 {
    match cue {
        Cue::TimeHeadway => 0.5,
        _ => 0.5 / (Cue::ALL.len() - 1) as f64,
    }
}

/// The threshold pairs of the two-cue decision ([`Cue::HeadwayOrTtc`]): every
/// [`PAIRED_HEADWAY_EVERY`]-th time-headway threshold with every
/// [`PAIRED_TTC_EVERY`]-th time-to-collision threshold, as indices into
/// [`Cue::thresholds`] of the two cues, the headway's outer.
pub fn paired_thresholds() -> Vec<(usize, usize)> {
    let every = |cue: Cue, step: usize| (0..cue.thresholds().len()).step_by(step);
    every(Cue::TimeHeadway, PAIRED_HEADWAY_EVERY)
        .flat_map(|h| every(Cue::TimeToCollision, PAIRED_TTC_EVERY).map(move |t| (h, t)))
        .collect()
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
    /// Two cues at once: the first of the time headway and the time to
    /// collision to fall to its own threshold (palc-user's
    /// [`StartRule::HeadwayOrTtc`]). Its thresholds are pairs
    /// ([`paired_thresholds`]); the single-threshold functions below
    /// ([`Cue::thresholds`], [`Cue::rule`], [`Cue::urgency`]) are the one-cue
    /// decisions', and the estimate combines the two cues' decisions itself.
    /// The driver is assumed to start without a reaction after deciding (the
    /// paper's users do), which keeps the pairs' share of the grid small.
    HeadwayOrTtc,
}

impl Cue {
    /// Every cue of the model.
    pub const ALL: [Cue; 5] = [
        Cue::TimeHeadway,
        Cue::TimeToCollision,
        Cue::DistanceGap,
        Cue::Incentive,
        Cue::HeadwayOrTtc,
    ];

    /// The cues decided on one threshold.
    pub const SINGLE: [Cue; 4] = [
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
            Cue::HeadwayOrTtc => "headway-or-ttc",
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
            // Pairs, not single thresholds: `paired_thresholds`.
            Cue::HeadwayOrTtc => Vec::new(),
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
            // A pair's rule needs both thresholds: `Cue::paired_rule`.
            Cue::HeadwayOrTtc => (StartRule::TimeHeadway, threshold),
        }
    }

    /// The two-cue rule at a headway of `time_headway_s` and a time to
    /// collision of `ttc_s`, with the time headway it reads.
    pub fn paired_rule(time_headway_s: f64, ttc_s: f64) -> (StartRule, f64) {
        (
            StartRule::HeadwayOrTtc { ttc_seconds: ttc_s },
            time_headway_s,
        )
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
            // Two cues have no single urgency: the estimate takes the earlier
            // of the two cues' decisions.
            Cue::HeadwayOrTtc => f64::NEG_INFINITY,
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
