//! The experience store: what was learned, versioned, saved without ever losing data.

use std::path::Path;

use palc_planner::Weights;
use palc_zone_filter::ZoneModel;
use serde::{Deserialize, Serialize};

use crate::{AggregatorError, ApprenticeshipState, Onset, OwnLaneChange, resample_weights};

/// The experience format version this build writes and the newest it reads.
/// Version 2 adds the scene each onset was observed in ([`crate::SceneSteps`]);
/// version-1 files load with none.
pub const EXPERIENCE_FORMAT_VERSION: u32 = 2;
/// Bounds of an experience's step `metadata.dt` (s): the harness plans at most at
/// 0.5 s (`planning.dt`), and a millisecond step resamples a 60 s plan into
/// 60,000 columns, beyond the planner's horizon.
pub const EXPERIENCE_DT_BOUNDS_S: (f64, f64) = (1e-3, 0.5);
/// Largest lateral offset (m) a stored demonstration may hold: four lanes of
/// 3.75 m either side of the ego's. The scene's own road is checked when the
/// experience is carried into it (palc-harness).
pub const MAX_DEMONSTRATION_OFFSET_M: f64 = 15.0;

/// Who and what an experience belongs to.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExperienceMetadata {
    /// The user the experience personalizes to.
    pub user_id: String,
    /// The scenario it was learned in (free text, e.g. `45-40mph-40m`).
    pub scenario: String,
    /// The method that learned it (free text, e.g. `palc` or `paper`).
    pub method: String,
    /// Lessons (takeovers) learned from so far.
    pub lessons: u64,
    /// Step `Δt` (s) of the weight matrix's columns.
    pub dt: f64,
}

/// What has been learned: the zone model with its statistics, the 10 x K weight
/// matrix, the apprenticeship state, the user's observed starts and metadata.
///
/// Saved as JSON `{format_version, metadata, weights, zone, apprenticeship,
/// anchor_s, onsets, demonstration, own_lane_change}` (the last four may be
/// absent in older files); the
/// zone is the zone filter's own versioned serialization. Numbers round-trip
/// bit-exactly (shortest representation on write, correctly rounded parse).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Experience {
    /// Who and what.
    pub metadata: ExperienceMetadata,
    /// The learned weights; column `c` weighs the stage at time `c · dt` after the
    /// start of the plan.
    pub weights: Weights,
    /// The zone model, once the zone is used.
    pub zone: Option<ZoneModel>,
    /// The apprenticeship rule's projection point, once that rule has run.
    pub apprenticeship: Option<ApprenticeshipState>,
    /// The user's start in the weights' time base (s after the start of the plan):
    /// observed in this scene, or predicted when the experience was carried into it.
    /// `None` until a start has been observed.
    pub anchor_s: Option<f64>,
    /// The user's observed starts, one per scene learned in, oldest first.
    pub onsets: Vec<Onset>,
    /// The lateral path (m) of the last lesson's expert, at steps `0..=K` of the
    /// weights' time base (step `metadata.dt`): what the user was seen to drive,
    /// which a new scene can rehearse. `None` before the first lesson.
    pub demonstration: Option<Vec<f64>>,
    /// The user's own lane change as last seen whole, from rest in its lane to
    /// its end, when a lesson showed it; `None` otherwise and in older files.
    pub own_lane_change: Option<OwnLaneChange>,
}

/// The file layout: the version first, so that a reader sees it before anything else.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Stored {
    format_version: u32,
    metadata: ExperienceMetadata,
    weights: Weights,
    zone: Option<ZoneModel>,
    apprenticeship: Option<ApprenticeshipState>,
    #[serde(default)]
    anchor_s: Option<f64>,
    #[serde(default)]
    onsets: Vec<Onset>,
    #[serde(default)]
    demonstration: Option<Vec<f64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    own_lane_change: Option<OwnLaneChange>,
}

#[derive(Deserialize)]
struct VersionProbe {
    format_version: u32,
}

impl Experience {
    /// A fresh experience: no lesson yet, the given (standard) weights, no zone.
    ///
    /// # Errors
    /// [`AggregatorError::Resample`] for `dt` not finite and positive or an empty
    /// weight matrix, [`AggregatorError::NonFinite`] for a non-finite weight,
    /// [`AggregatorError::OutOfRange`] for a step outside [`EXPERIENCE_DT_BOUNDS_S`]
    /// or more columns than [`palc_planner::MAX_HORIZON`].
    pub fn new(
        user_id: impl Into<String>,
        scenario: impl Into<String>,
        method: impl Into<String>,
        weights: Weights,
        dt: f64,
    ) -> Result<Self, AggregatorError> {
        let experience = Experience {
            metadata: ExperienceMetadata {
                user_id: user_id.into(),
                scenario: scenario.into(),
                method: method.into(),
                lessons: 0,
                dt,
            },
            weights,
            zone: None,
            apprenticeship: None,
            anchor_s: None,
            onsets: Vec::new(),
            demonstration: None,
            own_lane_change: None,
        };
        experience.validate()?;
        Ok(experience)
    }

    /// The weights for a plan of `horizon` steps of `dt`, resampled by the rule of
    /// [`resample_weights`] (time since the start of the plan, linear interpolation,
    /// last column held).
    pub fn weights_for(&self, horizon: usize, dt: f64) -> Result<Weights, AggregatorError> {
        resample_weights(&self.weights, self.metadata.dt, horizon, dt)
    }

    /// Checks the invariants a stored experience must satisfy: the step in
    /// [`EXPERIENCE_DT_BOUNDS_S`], at most [`palc_planner::MAX_HORIZON`] weight
    /// columns, finite numbers, the anchor inside the weights' time base, the
    /// demonstration no longer than the weights and within
    /// [`MAX_DEMONSTRATION_OFFSET_M`], the onsets in their ranges, the user's own
    /// lane change from 0 to 1 ([`OwnLaneChange::validate`]).
    pub fn validate(&self) -> Result<(), AggregatorError> {
        let out_of_range = |field: String, value: f64, bound: String| AggregatorError::OutOfRange {
            field,
            value,
            bound,
        };
        let dt = self.metadata.dt;
        if !(dt.is_finite() && dt > 0.0) {
            return Err(AggregatorError::Resample {
                reason: format!("metadata.dt = {dt} s must be finite and > 0"),
            });
        }
        let (dt_low, dt_high) = EXPERIENCE_DT_BOUNDS_S;
        if !(dt_low..=dt_high).contains(&dt) {
            return Err(out_of_range(
                "metadata.dt".into(),
                dt,
                format!("a step in [{dt_low}, {dt_high}] s"),
            ));
        }
        let horizon = self.weights.horizon();
        if horizon == 0 {
            return Err(AggregatorError::Resample {
                reason: "the weight matrix has no column".into(),
            });
        }
        if horizon > palc_planner::MAX_HORIZON {
            return Err(out_of_range(
                "weights".into(),
                horizon as f64,
                format!(
                    "at most {} columns (the planner's horizon)",
                    palc_planner::MAX_HORIZON
                ),
            ));
        }
        if let Some(anchor) = self.anchor_s {
            if !anchor.is_finite() {
                return Err(AggregatorError::NonFinite {
                    field: "anchor_s".into(),
                    value: anchor,
                });
            }
            let end = horizon as f64 * dt;
            if !(0.0..=end).contains(&anchor) {
                return Err(out_of_range(
                    "anchor_s".into(),
                    anchor,
                    format!("a time in the weights' time base, [0, {end}] s"),
                ));
            }
        }
        if let Some(path) = &self.demonstration {
            if path.len() > horizon + 1 {
                return Err(out_of_range(
                    "demonstration".into(),
                    path.len() as f64,
                    format!(
                        "at most {} steps (the weights' horizon plus one)",
                        horizon + 1
                    ),
                ));
            }
            for (i, &l) in path.iter().enumerate() {
                if l.is_finite() && l.abs() > MAX_DEMONSTRATION_OFFSET_M {
                    return Err(out_of_range(
                        format!("demonstration[{i}]"),
                        l,
                        format!("a lateral offset within ±{MAX_DEMONSTRATION_OFFSET_M} m"),
                    ));
                }
            }
        }
        for (i, onset) in self.onsets.iter().enumerate() {
            onset.validate(i)?;
        }
        if let Some(own) = &self.own_lane_change {
            own.validate()?;
        }
        for (i, &l) in self.demonstration.iter().flatten().enumerate() {
            if !l.is_finite() {
                return Err(AggregatorError::NonFinite {
                    field: format!("demonstration[{i}]"),
                    value: l,
                });
            }
        }
        let matrices = std::iter::once(("weights", self.weights.columns())).chain(
            self.apprenticeship
                .as_ref()
                .map(|a| ("apprenticeship.mu_bar", a.mu_bar.columns())),
        );
        for (name, columns) in matrices {
            for (c, column) in columns.iter().enumerate() {
                for (j, &x) in column.iter().enumerate() {
                    if !x.is_finite() {
                        return Err(AggregatorError::NonFinite {
                            field: format!("{name}[{c}][{j}]"),
                            value: x,
                        });
                    }
                }
            }
        }
        Ok(())
    }

    /// Writes the experience to `path` without ever losing data, through
    /// [`crate::output::write`]: a temporary file in the same directory, flushed and
    /// synced, renamed over `path`, the directory synced; an existing file keeps its
    /// permissions and a symbolic link keeps pointing to the file it names. On any
    /// error the previous file at `path` is left as it was.
    ///
    /// # Errors
    /// [`AggregatorError::NonFinite`] (JSON has no NaN), [`AggregatorError::Io`].
    pub fn save(&self, path: impl AsRef<Path>) -> Result<(), AggregatorError> {
        let path = path.as_ref();
        self.validate()?;
        let stored = Stored {
            format_version: EXPERIENCE_FORMAT_VERSION,
            metadata: self.metadata.clone(),
            weights: self.weights.clone(),
            zone: self.zone.clone(),
            apprenticeship: self.apprenticeship.clone(),
            anchor_s: self.anchor_s,
            onsets: self.onsets.clone(),
            demonstration: self.demonstration.clone(),
            own_lane_change: self.own_lane_change.clone(),
        };
        let mut bytes =
            serde_json::to_vec_pretty(&stored).map_err(|e| AggregatorError::Serialize {
                reason: e.to_string(),
            })?;
        bytes.push(b'\n');
        crate::output::write(path, &bytes).map_err(|e| AggregatorError::Io {
            path: e.path,
            source: e.error,
        })
    }

    /// Reads an experience written by [`Experience::save`]. Nothing is modified.
    ///
    /// # Errors
    /// [`AggregatorError::Io`] if the file cannot be read,
    /// [`AggregatorError::UnsupportedVersion`] for a file from a newer format version,
    /// [`AggregatorError::Corrupt`] for anything that does not parse or validate
    /// (truncated, edited, a zone model the zone filter refuses).
    pub fn load(path: impl AsRef<Path>) -> Result<Self, AggregatorError> {
        let path = path.as_ref();
        let bytes = crate::input::read(path).map_err(|e| AggregatorError::Io {
            path: path.to_path_buf(),
            source: e.into_io(),
        })?;
        Self::from_json(&bytes, path)
    }

    /// Parses and checks the bytes of an experience file as [`Experience::load`]
    /// does; `path` only names it in errors.
    ///
    /// # Errors
    /// As [`Experience::load`], without its I/O errors.
    pub fn from_json(bytes: &[u8], path: &Path) -> Result<Self, AggregatorError> {
        // A UTF-8 byte-order mark (some editors write one) is not part of the JSON.
        let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
        let corrupt = |reason: String| AggregatorError::Corrupt {
            path: path.to_path_buf(),
            reason,
        };
        let probe: VersionProbe =
            serde_json::from_slice(bytes).map_err(|e| corrupt(e.to_string()))?;
        if probe.format_version > EXPERIENCE_FORMAT_VERSION {
            return Err(AggregatorError::UnsupportedVersion {
                path: path.to_path_buf(),
                found: probe.format_version,
                supported: EXPERIENCE_FORMAT_VERSION,
            });
        }
        if probe.format_version == 0 {
            return Err(corrupt("format_version 0 does not exist".into()));
        }
        let stored: Stored = serde_json::from_slice(bytes).map_err(|e| corrupt(e.to_string()))?;
        let experience = Experience {
            metadata: stored.metadata,
            weights: stored.weights,
            zone: stored.zone,
            apprenticeship: stored.apprenticeship,
            anchor_s: stored.anchor_s,
            onsets: stored.onsets,
            demonstration: stored.demonstration,
            own_lane_change: stored.own_lane_change,
        };
        experience.validate().map_err(|e| corrupt(e.to_string()))?;
        // A file steers the planner: its weights must pass the planner's own
        // convexity check, as `palc plan` requires of the weights it is given.
        palc_planner::check_convexity(&experience.weights)
            .map_err(|e| corrupt(format!("its weights: {e}")))?;
        Ok(experience)
    }
}
