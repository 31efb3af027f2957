//! Recorded drivers: every lane change of an imported file (`palc import
//! commonroad`) becomes a user who changes lanes with that shape and decides on
//! that start context, in palc's scenes.
//!
//! A recorded lane change says how one person moved (the lateral trace) and in
//! what traffic they started (headway to the vehicle ahead, gaps to the target
//! lane's lead and lag). The driver built from it, a [`UserConfig`] with a
//! custom style, assumes:
//! - **shape and duration**: the trace from start to end, smoothed by
//!   palc-user's recorded profile (its stated noise [`NOISE_M`]), stretched to
//!   the scene's lane width; the duration is the recorded one;
//! - **start**: the time headway to the vehicle ahead at which they started is
//!   their threshold (the paper's start rule, palc's simulated users' cue);
//! - **gap acceptance**: the gaps they took bound their thresholds from above;
//!   one lane change does not show how much smaller a gap they would have
//!   taken, so each threshold is the smaller of the gap taken and the neutral
//!   style's: lead 0.6 s, lag 0 s (any positive gap, so the lag's gap taken
//!   changes nothing).
//!
//! A lane change that cannot be such a driver is refused with a reason, counted
//! in REPORT.md: a merge (a lane change the lane's end forced, not a choice on
//! the headway), no vehicle ahead or no positive headway to it (nothing to start
//! on), a trace the smoothing refuses (an outlier, a lane change that turns
//! back). A long headway is kept: a driver who changed lanes far behind its
//! leader starts early in palc's scenes too, or the scene refuses it, counted
//! with the other refusals of its runs.

use std::path::{Path, PathBuf};

use palc_commonroad::import::{RecordedLaneChange, RecordedLaneChanges};
use palc_harness::config::{UserConfig, UserStyle};
use palc_harness::user::{Family, LateralProfile, ProfilePoint, RecordedProfile, Style};

use crate::EvalError;
use crate::config::UserKind;

/// The noise level of recorded traces (m): the default of palc-user's recorded
/// profile, the order of NGSIM's lateral position errors.
pub const NOISE_M: f64 = palc_harness::user::DEFAULT_NOISE_M;

/// A recorded lane change accepted as a driver.
#[derive(Debug, Clone)]
pub struct Driver {
    /// `scenario:vehicle:start step`.
    pub id: String,
    /// The driver as a user config (custom style, recorded profile).
    pub user: UserConfig,
    /// Root mean square distance between the trace and the smoothed shape (m).
    pub rms_residual_m: f64,
}

/// A recorded lane change refused as a driver.
#[derive(Debug, Clone, PartialEq)]
pub struct Refused {
    /// `scenario:vehicle:start step`.
    pub id: String,
    /// The reason's kind: `merge`, `no-vehicle-ahead`, `no-headway`, `profile`.
    pub kind: &'static str,
    /// The reason in words.
    pub detail: String,
}

/// The drivers of one recorded user kind.
#[derive(Debug, Clone)]
pub struct RecordedDrivers {
    /// The user kind's name.
    pub kind: String,
    /// The file read.
    pub file: PathBuf,
    /// Lane changes in the file.
    pub lane_changes: usize,
    /// Lane changes cut by the recording's end, as the import counted them.
    pub cut_by_recording: usize,
    /// The accepted drivers.
    pub accepted: Vec<Driver>,
    /// The refused lane changes.
    pub refused: Vec<Refused>,
}

impl RecordedDrivers {
    /// Reads `kind`'s file (relative to `config_dir`) and builds its drivers.
    pub fn load(kind: &UserKind, config_dir: &Path) -> Result<Option<RecordedDrivers>, EvalError> {
        let Some(relative) = &kind.recorded else {
            return Ok(None);
        };
        let file = config_dir.join(relative);
        let recorded =
            RecordedLaneChanges::read(&file).map_err(|error| EvalError::InvalidConfig {
                field: format!("users.{}.recorded", kind.name),
                value: file.display().to_string(),
                bound: format!("a file of recorded lane changes: {error}"),
            })?;
        let mut accepted = Vec::new();
        let mut refused = Vec::new();
        for lane_change in &recorded.lane_changes {
            match driver(lane_change) {
                Ok(driver) => accepted.push(driver),
                Err(refusal) => refused.push(refusal),
            }
        }
        Ok(Some(RecordedDrivers {
            kind: kind.name.clone(),
            file,
            lane_changes: recorded.lane_changes.len(),
            cut_by_recording: recorded.counts.cut_by_recording,
            accepted,
            refused,
        }))
    }

    /// The driver named `id`, if accepted.
    pub fn driver(&self, id: &str) -> Option<&Driver> {
        self.accepted.iter().find(|d| d.id == id)
    }
}

/// The id of a recorded lane change: `scenario:vehicle:start step`.
pub fn lane_change_id(lane_change: &RecordedLaneChange) -> String {
    format!(
        "{}:{}:{}",
        lane_change.scenario, lane_change.vehicle_id, lane_change.start_time_step
    )
}

/// The driver of one recorded lane change, or why there is none; see the module
/// documentation for the assumptions.
pub fn driver(lane_change: &RecordedLaneChange) -> Result<Driver, Refused> {
    let id = lane_change_id(lane_change);
    let refuse = |kind: &'static str, detail: String| Refused {
        id: id.clone(),
        kind,
        detail,
    };
    if lane_change.merge {
        return Err(refuse(
            "merge",
            "its lane ends: the lane change was forced, not a choice on the headway".to_owned(),
        ));
    }
    let context = &lane_change.context;
    let Some(ahead) = context.ahead else {
        return Err(refuse(
            "no-vehicle-ahead",
            "no vehicle ahead in its lane at the start: no headway to start on".to_owned(),
        ));
    };
    let headway = ahead.time_headway_s.unwrap_or(f64::NAN);
    if !(headway.is_finite() && headway > 0.0) {
        return Err(refuse(
            "no-headway",
            format!(
                "its headway at the start is {headway:.2} s (the vehicle ahead overlaps it, or it \
                 was nearly stopped): no headway to start on"
            ),
        ));
    }
    let neutral = Style::NEUTRAL;
    let lead_gap = context
        .target_lead
        .and_then(|lead| lead.time_headway_s)
        .map_or(neutral.min_lead_gap_s, |gap| {
            gap.min(neutral.min_lead_gap_s)
        });
    let samples: Vec<ProfilePoint> = (lane_change.trace.iter())
        .filter(|s| (0.0..=lane_change.duration_s + 1e-9).contains(&s.time_s))
        .map(|s| ProfilePoint {
            time_s: s.time_s,
            offset_m: s.lateral_m,
        })
        .collect();
    let profile = RecordedProfile::new(samples, NOISE_M);
    let rms_residual_m = match profile.fit("recorded.profile") {
        Ok(fit) => fit.rms_residual_m,
        Err(error) => return Err(refuse("profile", error.to_string())),
    };
    let user = UserConfig {
        style: UserStyle::Custom,
        custom: Some(Style {
            time_headway_s: headway,
            lane_change_duration_s: lane_change.duration_s,
            min_lead_gap_s: lead_gap.max(0.01),
            min_lag_gap_s: neutral.min_lag_gap_s,
        }),
        family: Some(Family {
            profile: LateralProfile::Recorded(profile),
            ..Family::default()
        }),
        spread: None,
    };
    Ok(Driver {
        id,
        user,
        rms_residual_m,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use palc_commonroad::import::{
        CentreSource, Direction, LateralSample, Neighbour, StartContext,
    };
    use palc_harness::user::quintic;

    fn neighbour(net_gap_m: f64, time_headway_s: Option<f64>) -> Neighbour {
        Neighbour {
            vehicle_id: 7,
            net_gap_m,
            closing_speed_mps: 1.0,
            time_headway_s,
        }
    }

    fn lane_change() -> RecordedLaneChange {
        let duration_s = 3.0;
        let trace = (-5..=35)
            .map(|i| {
                let time_s = i as f64 * 0.1;
                let wobble = 0.03 * (i as f64 * 1.7).sin();
                LateralSample {
                    time_s,
                    lateral_m: 3.6 * quintic(time_s / duration_s) + wobble,
                }
            })
            .collect();
        RecordedLaneChange {
            scenario: "USA_Test-1_1_T-1".into(),
            vehicle_id: 42,
            vehicle_type: "car".into(),
            vehicle_length_m: 4.5,
            vehicle_width_m: 1.8,
            dt_s: 0.1,
            first_time_step: 0,
            last_time_step: 60,
            start_time_step: 10,
            end_time_step: 40,
            direction: Direction::Left,
            start_lanelet: 1,
            target_lanelet: 2,
            duration_s,
            peak_lateral_speed_mps: 2.2,
            speed_at_start_mps: 12.0,
            lane_width_m: 3.6,
            context: StartContext {
                ahead: Some(neighbour(18.0, Some(1.5))),
                target_lead: Some(neighbour(30.0, Some(2.5))),
                target_lag: None,
            },
            merge: false,
            centre_source: CentreSource::Map,
            trace,
        }
    }

    #[test]
    fn a_lane_change_becomes_a_driver_with_its_headway_duration_and_shape() {
        let driver = driver(&lane_change()).unwrap();
        assert_eq!(driver.id, "USA_Test-1_1_T-1:42:10");
        let style = driver.user.custom.unwrap();
        assert!((style.time_headway_s - 1.5).abs() < 1e-12);
        assert!((style.lane_change_duration_s - 3.0).abs() < 1e-12);
        // The lead gap taken (2.5 s) bounds the threshold; the neutral style's is smaller.
        assert!((style.min_lead_gap_s - Style::NEUTRAL.min_lead_gap_s).abs() < 1e-12);
        assert!(driver.rms_residual_m <= NOISE_M + 1e-6);
        let simulated = driver.user.simulated(0.3).unwrap();
        assert!(format!("{simulated:?}").contains("Recorded"));
    }

    #[test]
    fn merges_and_lane_changes_without_a_leader_are_refused_with_their_reason() {
        let mut merge = lane_change();
        merge.merge = true;
        assert_eq!(driver(&merge).unwrap_err().kind, "merge");
        let mut alone = lane_change();
        alone.context.ahead = None;
        assert_eq!(driver(&alone).unwrap_err().kind, "no-vehicle-ahead");
        let mut overlapping = lane_change();
        overlapping.context.ahead = Some(neighbour(-1.0, Some(-0.1)));
        assert_eq!(driver(&overlapping).unwrap_err().kind, "no-headway");
        let mut outlier = lane_change();
        outlier.trace[20].lateral_m += 3.0;
        let refused = driver(&outlier).unwrap_err();
        assert_eq!(refused.kind, "profile");
        assert!(refused.detail.contains("samples[15]"), "{}", refused.detail);
    }
}
