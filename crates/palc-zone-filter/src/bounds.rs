//! The zone in the road plane: boundary and lateral bounds per planning step
//! (Eqs. 27-32 and a corrected projection).

use serde::{Deserialize, Serialize};

use crate::{
    certain_sign::CertainSign,
    error::{ZoneError, check_finite},
    features::{FeatureInput, FeatureSet, MAX_FEATURES, features_into, write_checked_features},
    gaussian::Fitted,
    model::ZoneModel,
};

/// What the zone filter needs to know about one planning step i.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StepScene {
    /// The ego's longitudinal position s_i at this step (m), e.g. from the
    /// previous plan or the reference path.
    pub ego_s: f64,
    /// The reference lateral position l_i (m) that Eqs. (27)-(28) compare with;
    /// the paper's l_i is a decision variable, so the caller passes the
    /// previous iterate or the reference path.
    pub reference_l: f64,
    /// The ego speed at this step (m/s); used only by time-based features.
    pub ego_speed: f64,
    /// The preceding vehicle's predicted `[s, l]` at this step (m).
    pub preceding: [f64; 2],
    /// The adjacent vehicle's predicted `[s, l]` at this step (m).
    pub adjacent: [f64; 2],
}

/// How the boundary is projected onto lateral bounds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Projection {
    /// Eqs. (27)-(32) as printed: the nearest boundary points below and above
    /// the reference l_i, whatever the class between them; a side without a
    /// boundary point falls back to the edge of the lateral range.
    Paper,
    /// The maximal interval classified safe that contains the reference l_i,
    /// or, if l_i is unsafe, the safe interval nearest to it (the lower one on a tie).
    #[default]
    SafeInterval,
}

/// How the zone is searched at each step. Maps one to one onto a TOML table.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BoundsConfig {
    /// Which projection to use.
    pub projection: Projection,
    /// The lateral search range `[l_lo, l_hi]` (m); by default the road edges
    /// `[-1.75, 5.25]` of the two-lane test bed.
    pub lateral_range: [f64; 2],
    /// Spacing of the classification grid along l (m). Safe or unsafe
    /// stretches narrower than this can be missed.
    pub grid_step: f64,
    /// Each boundary crossing is refined by bisection until it is known to
    /// within this width (m); a bound moves by at most half of it.
    pub tolerance: f64,
}

impl Default for BoundsConfig {
    fn default() -> Self {
        BoundsConfig {
            projection: Projection::SafeInterval,
            lateral_range: [-1.75, 5.25],
            grid_step: 0.05,
            tolerance: 1e-3,
        }
    }
}

impl BoundsConfig {
    /// Checks every field.
    ///
    /// # Errors
    /// [`ZoneError::InvalidConfig`] naming the first field out of range.
    pub fn validate(&self) -> Result<(), ZoneError> {
        let [lo, hi] = self.lateral_range;
        if !(lo.is_finite() && hi.is_finite()) || lo >= hi {
            return Err(ZoneError::InvalidConfig {
                field: "lateral_range",
                value: if lo.is_finite() { hi } else { lo },
                bound: "finite with lateral_range[0] < lateral_range[1]",
            });
        }
        if !(self.grid_step.is_finite() && self.grid_step > 0.0) || self.grid_step > hi - lo {
            return Err(ZoneError::InvalidConfig {
                field: "grid_step",
                value: self.grid_step,
                bound: "positive and at most the width of lateral_range",
            });
        }
        // At most a million grid cells: the scan allocates and evaluates each.
        if self.grid_step < (hi - lo) * 1e-6 {
            return Err(ZoneError::InvalidConfig {
                field: "grid_step",
                value: self.grid_step,
                bound: "at least 1e-6 of the width of lateral_range (a million cells)",
            });
        }
        if !(self.tolerance.is_finite() && self.tolerance > 0.0 && self.tolerance <= self.grid_step)
        {
            return Err(ZoneError::InvalidConfig {
                field: "tolerance",
                value: self.tolerance,
                bound: "positive and at most grid_step",
            });
        }
        // The bisection halves an interval until it is narrower than the tolerance;
        // below the spacing of doubles at the range's ends it would never get there.
        if self.tolerance < 1e-9 * lo.abs().max(hi.abs()).max(1.0) {
            return Err(ZoneError::InvalidConfig {
                field: "tolerance",
                value: self.tolerance,
                bound: "at least 1e-9 times the largest of 1 m and |lateral_range|",
            });
        }
        Ok(())
    }
}

/// The lateral bounds at one step, Eq. (22)'s `l_min,i <= l_i <= l_max,i`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StepBounds {
    /// The zone bounds l to `[min, max]` (m).
    Bounded {
        /// `l_min,i` (m).
        min: f64,
        /// `l_max,i` (m).
        max: f64,
    },
    /// The zone says nothing here: the model is not informative, or the whole
    /// lateral range is classified safe. Not the road edges: their centre is the
    /// lane marking, which must not be tracked.
    Unconstrained,
    /// No point of the lateral range is classified safe (the safe-interval
    /// projection also reports this when no safe stretch exists).
    NoSafeInterval,
}

/// A point of the boundary B at a step: where the class changes along l.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Crossing {
    /// Lateral position of the crossing (m), within the bisection tolerance.
    pub l: f64,
    /// Whether the zone is safe just below this l (and unsafe just above).
    pub safe_below: bool,
}

/// The boundary B of the perceived safe zone on the line `s = s_i` of one step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StepBoundary {
    /// The longitudinal coordinate `B_1` shared by all points (m).
    pub s: f64,
    /// The crossings `B_2` in increasing l.
    pub crossings: Vec<Crossing>,
    /// Whether the lower end of the lateral range is safe.
    pub safe_at_lower_edge: bool,
    /// The lateral range searched (m).
    pub lateral_range: [f64; 2],
}

impl StepBoundary {
    /// The maximal intervals `[start, end]` classified safe, in increasing l.
    pub fn safe_intervals(&self) -> Vec<[f64; 2]> {
        let [lo, hi] = self.lateral_range;
        let mut intervals = Vec::new();
        let mut start = self.safe_at_lower_edge.then_some(lo);
        for crossing in &self.crossings {
            match start {
                Some(begin) if crossing.safe_below => {
                    intervals.push([begin, crossing.l]);
                    start = None;
                }
                None if !crossing.safe_below => start = Some(crossing.l),
                _ => {}
            }
        }
        if let Some(begin) = start {
            intervals.push([begin, hi]);
        }
        intervals
    }
}

/// The boundary B of the zone at one step, on the ego's station `s = s_i`.
///
/// The log-odds is evaluated on a grid of spacing at most `grid_step` over the
/// lateral range, and each class change is refined by bisection to `tolerance`.
///
/// # Errors
/// [`ZoneError::NotInformative`] if the model has no boundary,
/// [`ZoneError::InvalidConfig`] for a bad config, [`ZoneError::NonFinite`] or
/// [`ZoneError::NonPositiveSpeed`] for a bad scene.
pub fn step_boundary(
    model: &ZoneModel,
    scene: &StepScene,
    config: &BoundsConfig,
) -> Result<StepBoundary, ZoneError> {
    config.validate()?;
    boundary_on_line(model, model.fitted()?, scene, config)
}

/// The lateral bounds `l_min,i`, `l_max,i` for every step (Eqs. 27-32 or the
/// corrected projection, see [`Projection`]).
///
/// Before the model is informative every step is [`StepBounds::Unconstrained`].
///
/// # Errors
/// [`ZoneError::InvalidConfig`] for a bad config, [`ZoneError::NonFinite`] or
/// [`ZoneError::NonPositiveSpeed`] for a bad scene (the message names the step).
pub fn lateral_bounds(
    model: &ZoneModel,
    scenes: &[StepScene],
    config: &BoundsConfig,
) -> Result<Vec<StepBounds>, ZoneError> {
    config.validate()?;
    let Ok(fitted) = model.fitted() else {
        return Ok(vec![StepBounds::Unconstrained; scenes.len()]);
    };
    scenes
        .iter()
        .enumerate()
        .map(|(i, scene)| {
            check_finite(scene.reference_l, || format!("step {i} reference_l"))?;
            let boundary = boundary_on_line(model, fitted, scene, config).map_err(|e| match e {
                ZoneError::NonFinite { field, value } => ZoneError::NonFinite {
                    field: format!("step {i} {field}"),
                    value,
                },
                ZoneError::NonPositiveSpeed { field, value } => ZoneError::NonPositiveSpeed {
                    field: format!("step {i} {field}"),
                    value,
                },
                other => other,
            })?;
            Ok(project(&boundary, scene.reference_l, config.projection))
        })
        .collect()
}

/// Projects one step's boundary onto bounds around `reference_l`.
pub fn project(boundary: &StepBoundary, reference_l: f64, projection: Projection) -> StepBounds {
    let [lo, hi] = boundary.lateral_range;
    if boundary.crossings.is_empty() {
        return if boundary.safe_at_lower_edge {
            StepBounds::Unconstrained
        } else {
            StepBounds::NoSafeInterval
        };
    }
    match projection {
        Projection::Paper => {
            // Eqs. (27)-(32): every B point lies at s = s_i, so the argmin over
            // |B_1 - s_i| ties; the tie is broken by the lateral distance, the
            // point "closest to the ego vehicle" of the paper's text.
            let below = boundary
                .crossings
                .iter()
                .filter(|c| c.l < reference_l)
                .map(|c| c.l)
                .next_back();
            let above = boundary
                .crossings
                .iter()
                .find(|c| c.l > reference_l)
                .map(|c| c.l);
            StepBounds::Bounded {
                min: below.unwrap_or(lo),
                max: above.unwrap_or(hi),
            }
        }
        Projection::SafeInterval => {
            let distance = |[a, b]: [f64; 2]| (a - reference_l).max(reference_l - b).max(0.0);
            boundary
                .safe_intervals()
                .into_iter()
                .fold(None::<[f64; 2]>, |best, interval| match best {
                    Some(kept) if distance(kept) <= distance(interval) => Some(kept),
                    _ => Some(interval),
                })
                .map_or(StepBounds::NoSafeInterval, |[min, max]| {
                    StepBounds::Bounded { min, max }
                })
        }
    }
}

/// The zone's boundary on the line of `scene`: the grid of `config` classified
/// from the lower edge up, each change of class refined by bisection, and the
/// grid points whose class is already certain ([`CertainSign`]) not classified.
fn boundary_on_line(
    model: &ZoneModel,
    fitted: &Fitted,
    scene: &StepScene,
    config: &BoundsConfig,
) -> Result<StepBoundary, ZoneError> {
    let set = model.config().feature_set;
    let [lo, hi] = config.lateral_range;
    let certain = CertainSign::new(fitted, set, hi - lo);
    scan_line(set, fitted, scene, config, certain)
}

/// [`boundary_on_line`] with the certainty it skips by (`None`: every grid
/// point classified).
fn scan_line(
    set: FeatureSet,
    fitted: &Fitted,
    scene: &StepScene,
    config: &BoundsConfig,
    certain: Option<CertainSign<'_>>,
) -> Result<StepBoundary, ZoneError> {
    let [lo, hi] = config.lateral_range;
    let mut buffer = [0.0; MAX_FEATURES];
    let at_l = |l: f64| FeatureInput {
        ego_s: scene.ego_s,
        ego_l: l,
        ego_speed: scene.ego_speed,
        preceding: scene.preceding,
        adjacent: scene.adjacent,
    };
    // The scene is checked once, at the lower edge; every other point of the
    // line differs only in its finite `ego_l`, so it passes the same checks.
    features_into(set, &at_l(lo), &mut buffer)?;
    let log_odds = |l: f64, buffer: &mut [f64; MAX_FEATURES]| -> Result<f64, ZoneError> {
        write_checked_features(set, &at_l(l), buffer);
        let a = fitted.log_odds(&buffer[..set.dimension()]);
        if a.is_nan() {
            return Err(ZoneError::Overflow {
                what: format!("the zone at s = {}, l = {l}", scene.ego_s),
            });
        }
        Ok(a)
    };
    let cells = ((hi - lo) / config.grid_step).ceil().max(1.0) as usize;
    let at = |k: usize| lo + (hi - lo) * k as f64 / cells as f64;
    let cell = (hi - lo) / cells as f64;
    // The grid points after the last one classified whose class is certain
    // (`certain_sign`): the scan takes their class without classifying them.
    let certain_cells = |value: f64, features: &[f64]| -> usize {
        let reach = certain.map_or(0.0, |c| c.reach(&features[..set.dimension()], value));
        (reach / cell).floor().min(cells as f64) as usize
    };
    let first = log_odds(lo, &mut buffer)?;
    let mut skip = certain_cells(first, &buffer);
    let mut previous_safe = first > 0.0;
    let safe_at_lower_edge = previous_safe;
    let mut crossings = Vec::new();
    for k in 1..=cells {
        if skip > 0 {
            skip -= 1;
            continue;
        }
        let value = log_odds(at(k), &mut buffer)?;
        skip = certain_cells(value, &buffer);
        let safe = value > 0.0;
        if safe != previous_safe {
            let (mut a, mut b) = (at(k - 1), at(k));
            while b - a > config.tolerance {
                let mid = 0.5 * (a + b);
                if (log_odds(mid, &mut buffer)? > 0.0) == previous_safe {
                    a = mid;
                } else {
                    b = mid;
                }
            }
            crossings.push(Crossing {
                l: 0.5 * (a + b),
                safe_below: previous_safe,
            });
        }
        previous_safe = safe;
    }
    Ok(StepBoundary {
        s: scene.ego_s,
        crossings,
        safe_at_lower_edge,
        lateral_range: config.lateral_range,
    })
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;
    use crate::{Discriminant, Label, Sample, ZoneConfig, features};

    fn feature_set() -> impl Strategy<Value = FeatureSet> {
        prop_oneof![
            Just(FeatureSet::Paper),
            Just(FeatureSet::NoDistance),
            Just(FeatureSet::TimeGap)
        ]
    }

    /// A scene: the ego at `s`, a preceding vehicle ahead in its lane and an
    /// adjacent one in the target lane.
    fn scene() -> impl Strategy<Value = StepScene> {
        (
            0.0..200.0f64,
            5.0..35.0f64,
            3.0..80.0f64,
            -0.3..0.3f64,
            -60.0..60.0f64,
            3.2..3.8f64,
        )
            .prop_map(|(s, v, ahead, pl, beside, al)| StepScene {
                ego_s: s,
                reference_l: 0.0,
                ego_speed: v,
                preceding: [s + ahead, pl],
                adjacent: [s + beside, al],
            })
    }

    /// Positions of `scenes` labelled safe below `split` (m) and unsafe above,
    /// a fraction of them flipped so that the classes overlap.
    fn samples(set: FeatureSet, scenes: &[StepScene], split: f64, flip: u32) -> Vec<Sample> {
        let mut out = Vec::new();
        for (i, scene) in scenes.iter().enumerate() {
            for j in 0..12 {
                let l = -1.5 + 0.55 * j as f64 + 0.01 * i as f64;
                let input = FeatureInput {
                    ego_s: scene.ego_s,
                    ego_l: l,
                    ego_speed: scene.ego_speed,
                    preceding: scene.preceding,
                    adjacent: scene.adjacent,
                };
                let mut safe = l < split;
                if (i as u32 * 12 + j) % 7 < flip {
                    safe = !safe;
                }
                let label = if safe { Label::Safe } else { Label::Unsafe };
                out.push(Sample::new(features(set, &input).unwrap(), label));
            }
        }
        out
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(96))]

        /// The scan that skips the grid points whose class is certain finds the
        /// boundary of the scan that classifies every point, crossing for
        /// crossing and bit for bit.
        #[test]
        fn skipping_certain_points_finds_the_boundary_of_the_full_scan(
            set in feature_set(),
            seen in prop::collection::vec(scene(), 3..8),
            split in 0.0..3.5f64,
            flip in 0u32..3,
            queries in prop::collection::vec(scene(), 1..6),
            grid_step in 0.01..0.3f64,
        ) {
            let config = ZoneConfig {
                feature_set: set,
                discriminant: Discriminant::Linear,
                ..ZoneConfig::default()
            };
            let Ok(model) = ZoneModel::fit(config, &samples(set, &seen, split, flip)) else {
                return Ok(());
            };
            let Ok(fitted) = model.fitted() else { return Ok(()) };
            let bounds = BoundsConfig {
                grid_step,
                tolerance: grid_step.min(1e-3),
                ..BoundsConfig::default()
            };
            let [lo, hi] = bounds.lateral_range;
            let certain = CertainSign::new(fitted, set, hi - lo);
            prop_assert!(certain.is_some());
            for query in &queries {
                let skipping = scan_line(set, fitted, query, &bounds, certain).unwrap();
                let full = scan_line(set, fitted, query, &bounds, None).unwrap();
                prop_assert_eq!(skipping, full);
            }
        }
    }
}
