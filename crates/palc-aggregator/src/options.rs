//! The options of one learning step.

use palc_zone_filter::{BoundsConfig, ZoneConfig};
use serde::{Deserialize, Serialize};

use crate::{
    AggregatorError, ApprenticeshipRule, ConvexSet, CorrectionRule, ExpertKind, FeatureScale,
    LearnableRows, ZoneCentreExpert,
};

/// How the aggregator learns from a lesson. Maps one to one onto a TOML table.
///
/// The defaults are `palc`'s method: the lesson expert, the target rule
/// ([`crate::TargetRule`]) on rows `w1`, `w2`, no zone (a zone on top personalized
/// only 35 / 60 grid cases in an independent prototype; it has to earn its place by
/// measurement), experience anchored at the user's start
/// ([`Representation::RelativeOnset`]). [`AggregatorOptions::paper`] gives the
/// paper's method.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AggregatorOptions {
    /// Expert trajectory generator.
    pub expert: ExpertKind,
    /// Reward correction rule.
    pub correction: CorrectionRule,
    /// Rows the correction may change.
    pub learnable_rows: LearnableRows,
    /// Per-row feature scale of the correction.
    pub feature_scale: FeatureScale,
    /// The convex set the weights are kept in.
    pub convex_set: ConvexSet,
    /// Learn the perceived safe zone and bound the plans by it (Eqs. 1-8, 22, 27-32).
    /// Default `false`.
    pub use_zone: bool,
    /// Configuration of a new zone model, when the experience has none yet.
    pub zone: ZoneConfig,
    /// How the zone is projected onto lateral bounds.
    pub bounds: BoundsConfig,
    /// How the learned weights carry into another scene.
    pub representation: Representation,
    /// Average the lessons of a scene (applied by the loop, `palc_harness`): the
    /// expert of the n-th lesson follows the mean of the n paths the user drove in
    /// this scene, each taken at the same fraction of its own lane change, instead
    /// of the last one alone, so that a user who varies from lane change to lane
    /// change is learned at the mean of what they do rather than chased draw after
    /// draw. A first lesson is learned as it is, and a new scene starts a new mean.
    /// Default `true`; the paper's method learns from the last lesson alone.
    pub average_lessons: bool,
    /// Follow the user's speed (applied by the loop, `palc_harness`): after a
    /// lesson in which the user, having taken over, drove at a speed of its own
    /// (another acceleration than the ego's ACC would have commanded), the plan's
    /// reference and terminal speeds from the takeover on are the speeds the user
    /// drove, so that the next plan moves along the road as the user did (a user
    /// who slows to the target lane's speed no longer sees the plan close on the
    /// target lane's leader). The learned weights change the lateral rows only.
    /// Within a scene: a new scene starts from its own speeds; and not under the
    /// safety layer, whose ACC keeps the safe distance. Default `true`; the
    /// paper's method plans at the scenario's speeds.
    pub follow_user_speed: bool,
}

/// How learned weights carry into another scene
/// (docs/experiments/0042-observing-the-users-start.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Representation {
    /// Indexed by time since the start of the plan, as learned: the lane change
    /// starts as long after the plan's start as it did where it was learned.
    TimeIndexed,
    /// Anchored at the user's start, found in relative space: the weights are
    /// shifted so that the learned start falls where the new scene predicts the
    /// relative state the user started in (the time headway, time to collision
    /// or gap to the vehicle ahead, and the target lane's gaps, [`crate::Onset`]).
    #[default]
    RelativeOnset,
}

impl Default for AggregatorOptions {
    fn default() -> Self {
        AggregatorOptions {
            expert: ExpertKind::default(),
            correction: CorrectionRule::default(),
            learnable_rows: LearnableRows::default(),
            feature_scale: FeatureScale::default(),
            convex_set: ConvexSet::default(),
            use_zone: false,
            zone: ZoneConfig::default(),
            bounds: BoundsConfig::default(),
            representation: Representation::default(),
            average_lessons: true,
            follow_user_speed: true,
        }
    }
}

impl AggregatorOptions {
    /// The paper's method: zone-centre expert (Eqs. 24-26), apprenticeship learning
    /// (Eqs. 33-36) on all ten rows, zone on (scaled features and the convex set stay,
    /// since the printed method is unbounded and non-convex without them).
    pub fn paper() -> Self {
        AggregatorOptions {
            expert: ExpertKind::ZoneCentre(ZoneCentreExpert::default()),
            correction: CorrectionRule::Apprenticeship(ApprenticeshipRule::default()),
            learnable_rows: LearnableRows::ALL,
            use_zone: true,
            representation: Representation::TimeIndexed,
            average_lessons: false,
            follow_user_speed: false,
            ..AggregatorOptions::default()
        }
    }

    /// Checks every option and their combination.
    pub fn validate(&self) -> Result<(), AggregatorError> {
        self.feature_scale.validate()?;
        self.convex_set.validate()?;
        match &self.correction {
            CorrectionRule::Incremental(rule) => rule.validate()?,
            CorrectionRule::Target(rule) => {
                rule.validate()?;
                if !self.learnable_rows.contains(palc_planner::feature::L) {
                    return Err(AggregatorError::ConflictingOptions {
                        reason: "the target rule moves w2: learnable_rows must include row 1 (l)",
                    });
                }
            }
            CorrectionRule::Apprenticeship(_) => {}
        }
        if matches!(self.expert, ExpertKind::ZoneCentre(_)) && !self.use_zone {
            return Err(AggregatorError::ConflictingOptions {
                reason: "the zone_centre expert needs the zone: set use_zone = true or use the lesson expert",
            });
        }
        // Checked also when the zone is off: a value that cannot be right is
        // refused wherever it is written.
        self.zone.validate()?;
        self.bounds.validate()?;
        Ok(())
    }
}
