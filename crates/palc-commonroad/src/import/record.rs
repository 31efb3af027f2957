//! The recorded lane changes as data: [`RecordedLaneChange`] for one lane change and
//! [`RecordedLaneChanges`], the file that holds them with their sources and counts.
//!
//! The file is JSON, `{"format": "palc-recorded-lane-changes", "version": 1, ...}`. Every
//! struct denies unknown fields on read, and [`RecordedLaneChanges::read`] validates what
//! serde cannot: the format and version, finite numbers, positive sizes, ordered time
//! steps and increasing trace times.
//!
//! The lateral trace runs from up to [`TRACE_MARGIN_S`](super::params::TRACE_MARGIN_S)
//! before the start to as much after the end, at the recording's time step. Its times are
//! relative to the start: negative in the margin before it, `0` at the start,
//! `duration_s` at the end. Its lateral positions are relative to the start lane's centre,
//! positive towards the target lane, so a lane change runs from about 0 to about
//! `lane_width_m`.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::error::ReadError;

/// The `format` of the file.
pub const FORMAT: &str = "palc-recorded-lane-changes";
/// The file's `version`.
pub const VERSION: u32 = 1;

/// The side of the target lane.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Direction {
    /// The target lane is on the left.
    Left,
    /// The target lane is on the right.
    Right,
}

/// Where the start lane's centre comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CentreSource {
    /// The map's centre (midpoints of the lanelet's bounds).
    Map,
    /// The median lateral position of the vehicles keeping the lane within the lanelet,
    /// which differed from the map's by more than
    /// [`CENTRE_TOLERANCE_M`](super::params::CENTRE_TOLERANCE_M).
    Traffic,
}

/// One sample of a lateral trace.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LateralSample {
    /// Time since the lane change's start (s); negative in the margin before it.
    pub time_s: f64,
    /// Lateral position relative to the start lane's centre, positive towards the target
    /// lane (m).
    pub lateral_m: f64,
}

/// A vehicle next to the lane-changing one at the start.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Neighbour {
    /// The other vehicle's obstacle id.
    pub vehicle_id: i64,
    /// Bumper-to-bumper gap along the start lane (m): the distance of the centres less
    /// half of each vehicle's length; negative when they overlap.
    pub net_gap_m: f64,
    /// Speed at which the gap shrinks (m/s): the follower's speed less the leader's.
    pub closing_speed_mps: f64,
    /// The net gap divided by the lane-changing vehicle's speed (s); `None` when that
    /// speed is below [`HEADWAY_MIN_SPEED_MPS`](super::params::HEADWAY_MIN_SPEED_MPS).
    pub time_headway_s: Option<f64>,
}

/// The traffic around the lane-changing vehicle at the start, each `None` when no vehicle
/// is there within the map at that time step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StartContext {
    /// The nearest vehicle ahead in the start lane.
    pub ahead: Option<Neighbour>,
    /// The nearest vehicle ahead in the target lane.
    pub target_lead: Option<Neighbour>,
    /// The nearest vehicle behind in the target lane.
    pub target_lag: Option<Neighbour>,
}

/// The fields that say what a file is.
#[derive(Deserialize)]
struct Header {
    #[serde(default)]
    format: String,
    #[serde(default)]
    version: u32,
}

/// `Ok` for [`FORMAT`] version [`VERSION`], else the error naming the field.
fn check_header(format: &str, version: u32, path: &Path) -> Result<(), ReadError> {
    if format != FORMAT {
        return Err(ReadError::Invalid {
            path: path.to_owned(),
            field: "format".to_owned(),
            value: format!("{format:?}"),
            bound: format!("\"{FORMAT}\" (a file written by `palc import commonroad`)"),
        });
    }
    if version != VERSION {
        return Err(ReadError::Invalid {
            path: path.to_owned(),
            field: "version".to_owned(),
            value: version.to_string(),
            bound: format!("{VERSION}, the version this palc reads (import the scenarios again)"),
        });
    }
    Ok(())
}

/// One lane change of a recorded vehicle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecordedLaneChange {
    /// The scenario's `benchmarkID`.
    pub scenario: String,
    /// The vehicle's obstacle id.
    pub vehicle_id: i64,
    /// The obstacle's `type` in the scenario (`car`, `truck`, ...).
    pub vehicle_type: String,
    /// The vehicle's length (m).
    pub vehicle_length_m: f64,
    /// The vehicle's width (m).
    pub vehicle_width_m: f64,
    /// The recording's time step (s).
    pub dt_s: f64,
    /// The vehicle's first time step in the recording.
    pub first_time_step: i64,
    /// The vehicle's last time step in the recording.
    pub last_time_step: i64,
    /// The time step at which the lane change starts.
    pub start_time_step: i64,
    /// The time step at which it ends.
    pub end_time_step: i64,
    /// The side of the target lane.
    pub direction: Direction,
    /// The start lane's lanelet (the last one before the crossing).
    pub start_lanelet: i64,
    /// The target lane's lanelet (the first one after the crossing).
    pub target_lanelet: i64,
    /// `(end_time_step - start_time_step) * dt_s` (s).
    pub duration_s: f64,
    /// The largest lateral speed towards the target between start and end (m/s).
    pub peak_lateral_speed_mps: f64,
    /// The vehicle's speed at the start (m/s).
    pub speed_at_start_mps: f64,
    /// The distance between the start lane's and the target lane's centres at the
    /// crossing (m).
    pub lane_width_m: f64,
    /// The traffic around the vehicle at the start.
    pub context: StartContext,
    /// Whether the start lane ends within the map while the target lane goes on (an
    /// on-ramp or auxiliary lane): a lane change the driver had to make.
    pub merge: bool,
    /// Where the start lane's centre comes from.
    pub centre_source: CentreSource,
    /// The lateral trace (see the module's documentation).
    pub trace: Vec<LateralSample>,
}

/// Why a vehicle was left out.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SkipReason {
    /// Its time steps do not increase by one from sample to sample (the track is not
    /// split: a lane change across a gap cannot be measured).
    TimeGap,
    /// A position, speed, size or orientation is NaN or infinite, or a position
    /// lies beyond ±1e9 m.
    NonFinite,
    /// It has no rectangle shape, no position point or no integer time step.
    Incomplete,
}

/// A vehicle left out of the import.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SkippedVehicle {
    /// The scenario's `benchmarkID`.
    pub scenario: String,
    /// The obstacle id.
    pub vehicle_id: i64,
    /// Why it was left out.
    pub reason: SkipReason,
    /// The first time step at which the problem shows.
    pub time_step: Option<i64>,
}

/// What an import found, per scenario or summed over all.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Counts {
    /// Dynamic obstacles in the scenario(s).
    pub vehicles: usize,
    /// Vehicles skipped for a gap in their time steps.
    pub skipped_time_gap: usize,
    /// Vehicles skipped for a non-finite number.
    pub skipped_non_finite: usize,
    /// Vehicles skipped for a missing shape, position or time.
    pub skipped_incomplete: usize,
    /// Changes of lanelet between laterally adjacent lanelets.
    pub crossings: usize,
    /// Lane changes recorded (including merges).
    pub lane_changes: usize,
    /// Of those, merges.
    pub merges: usize,
    /// Lane changes skipped because the lateral speed is still above the threshold at the
    /// track's first or last sample.
    pub cut_by_recording: usize,
    /// Crossings without a lateral speed above the threshold (a vehicle on the marking).
    pub slow_crossings: usize,
    /// Crossings within a lane change already found (a double lane change in one sweep,
    /// or a wobble over the marking).
    pub repeated_crossings: usize,
    /// Changes of lanelet between lanelets that are neither longitudinally nor laterally
    /// linked (two lanes in one step, or a lanelet the map does not link).
    pub unlinked_transitions: usize,
    /// Lanelets whose centre was taken from the traffic.
    pub traffic_centres: usize,
}

impl Counts {
    /// Adds `other` to `self`.
    pub fn add(&mut self, other: &Self) {
        self.vehicles += other.vehicles;
        self.skipped_time_gap += other.skipped_time_gap;
        self.skipped_non_finite += other.skipped_non_finite;
        self.skipped_incomplete += other.skipped_incomplete;
        self.crossings += other.crossings;
        self.lane_changes += other.lane_changes;
        self.merges += other.merges;
        self.cut_by_recording += other.cut_by_recording;
        self.slow_crossings += other.slow_crossings;
        self.repeated_crossings += other.repeated_crossings;
        self.unlinked_transitions += other.unlinked_transitions;
        self.traffic_centres += other.traffic_centres;
    }
}

/// One imported scenario.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Source {
    /// The file's name (without its directory, so that the output does not depend on
    /// where the input was).
    pub file: String,
    /// The scenario's `benchmarkID`.
    pub benchmark_id: String,
    /// The scenario's `commonRoadVersion`.
    pub commonroad_version: String,
    /// The scenario's time step (s).
    pub dt_s: f64,
    /// What was found in it.
    pub counts: Counts,
}

/// The file of recorded lane changes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecordedLaneChanges {
    /// Always [`FORMAT`].
    pub format: String,
    /// Always [`VERSION`].
    pub version: u32,
    /// The scenarios read, in order.
    pub sources: Vec<Source>,
    /// The sum of the sources' counts.
    pub counts: Counts,
    /// The vehicles left out, with the reason.
    pub skipped_vehicles: Vec<SkippedVehicle>,
    /// The lane changes, by source, vehicle and start.
    pub lane_changes: Vec<RecordedLaneChange>,
}

impl RecordedLaneChanges {
    /// An empty file with the current format and version.
    pub fn new() -> Self {
        Self {
            format: FORMAT.to_owned(),
            version: VERSION,
            sources: Vec::new(),
            counts: Counts::default(),
            skipped_vehicles: Vec::new(),
            lane_changes: Vec::new(),
        }
    }

    /// The file as pretty JSON with a final newline.
    pub fn to_json(&self) -> String {
        let mut text = serde_json::to_string_pretty(self).unwrap_or_default();
        text.push('\n');
        text
    }

    /// Reads and validates a file written by [`to_json`](Self::to_json).
    ///
    /// # Errors
    /// [`ReadError`] naming the file, and for a bad value the field, the value and its
    /// bound.
    pub fn read(path: &Path) -> Result<Self, ReadError> {
        let text = super::read_bounded(path).map_err(|error| ReadError::Io {
            path: path.to_owned(),
            error,
        })?;
        // A UTF-8 byte-order mark (some editors write one) is not part of the JSON.
        let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
        let json_error = |e: serde_json::Error| ReadError::Json {
            path: path.to_owned(),
            line: e.line(),
            column: e.column(),
            message: e.to_string(),
        };
        // The format and version first, so that another file or version is named
        // as such rather than by the first field it lacks.
        let header: Header = serde_json::from_str(text).map_err(json_error)?;
        check_header(&header.format, header.version, path)?;
        let file: Self = serde_json::from_str(text).map_err(json_error)?;
        file.validate(path)?;
        Ok(file)
    }

    /// Checks what serde cannot (see the module's documentation); `path` names the file in
    /// the error.
    ///
    /// # Errors
    /// [`ReadError::Invalid`] for the first bad value.
    pub fn validate(&self, path: &Path) -> Result<(), ReadError> {
        let bad = |field: String, value: String, bound: &str| ReadError::Invalid {
            path: PathBuf::from(path),
            field,
            value,
            bound: bound.to_owned(),
        };
        if self.format != FORMAT {
            return Err(bad(
                "format".into(),
                format!("{:?}", self.format),
                &format!("{FORMAT:?}"),
            ));
        }
        if self.version != VERSION {
            return Err(bad(
                "version".into(),
                self.version.to_string(),
                &VERSION.to_string(),
            ));
        }
        let positive = |field: String, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(bad(field, v.to_string(), "positive and finite"))
            }
        };
        let finite = |field: String, v: f64| {
            if v.is_finite() {
                Ok(())
            } else {
                Err(bad(field, v.to_string(), "finite"))
            }
        };
        for (i, s) in self.sources.iter().enumerate() {
            positive(format!("sources[{i}].dt_s"), s.dt_s)?;
        }
        for (i, c) in self.lane_changes.iter().enumerate() {
            let f = |name: &str| format!("lane_changes[{i}].{name}");
            positive(f("vehicle_length_m"), c.vehicle_length_m)?;
            positive(f("vehicle_width_m"), c.vehicle_width_m)?;
            positive(f("dt_s"), c.dt_s)?;
            positive(f("duration_s"), c.duration_s)?;
            positive(f("lane_width_m"), c.lane_width_m)?;
            finite(f("peak_lateral_speed_mps"), c.peak_lateral_speed_mps)?;
            finite(f("speed_at_start_mps"), c.speed_at_start_mps)?;
            let steps = [
                ("first_time_step", c.first_time_step),
                ("start_time_step", c.start_time_step),
                ("end_time_step", c.end_time_step),
                ("last_time_step", c.last_time_step),
            ];
            for w in steps.windows(2) {
                let (strict, bound) = if w[0].0 == "start_time_step" {
                    (true, "above")
                } else {
                    (false, "at least")
                };
                if w[1].1 < w[0].1 || (strict && w[1].1 == w[0].1) {
                    return Err(bad(
                        f(w[1].0),
                        w[1].1.to_string(),
                        &format!("{bound} {} = {}", w[0].0, w[0].1),
                    ));
                }
            }
            for (name, n) in [
                ("ahead", c.context.ahead),
                ("target_lead", c.context.target_lead),
                ("target_lag", c.context.target_lag),
            ] {
                if let Some(n) = n {
                    finite(f(&format!("context.{name}.net_gap_m")), n.net_gap_m)?;
                    finite(
                        f(&format!("context.{name}.closing_speed_mps")),
                        n.closing_speed_mps,
                    )?;
                    if let Some(h) = n.time_headway_s {
                        finite(f(&format!("context.{name}.time_headway_s")), h)?;
                    }
                }
            }
            if c.trace.len() < 2 {
                return Err(bad(
                    f("trace"),
                    format!("{} samples", c.trace.len()),
                    "at least 2 samples",
                ));
            }
            let mut previous = f64::NEG_INFINITY;
            for (k, s) in c.trace.iter().enumerate() {
                finite(f(&format!("trace[{k}].time_s")), s.time_s)?;
                finite(f(&format!("trace[{k}].lateral_m")), s.lateral_m)?;
                if s.time_s <= previous {
                    return Err(bad(
                        f(&format!("trace[{k}].time_s")),
                        s.time_s.to_string(),
                        &format!("above the previous time {previous}"),
                    ));
                }
                previous = s.time_s;
            }
        }
        Ok(())
    }
}

impl Default for RecordedLaneChanges {
    fn default() -> Self {
        Self::new()
    }
}
