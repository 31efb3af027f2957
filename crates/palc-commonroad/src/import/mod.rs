//! Reading CommonRoad 2020a scenarios and finding their lane changes.
//!
//! [`import_file`] (or [`import_str`]) reads one scenario with quick-xml's serde
//! deserializer ([`xml`](self) types; unknown elements are skipped), builds the lanelet
//! map, turns each dynamic obstacle into a track, finds every lane change (the rule is in
//! `detect.rs`, its constants in [`params`]) and describes each as a
//! [`RecordedLaneChange`]. [`import_files`] does so for several scenarios and gathers the
//! results in a [`RecordedLaneChanges`] file with its sources and [`Counts`].
//!
//! What is an error and what is counted:
//! - malformed XML, a root that is not `commonRoad`, a version other than `2020a`, a bad
//!   `timeStepSize` or an unusable lanelet are [`ImportError`]s;
//! - a vehicle with a gap in its time steps, a non-finite number or a missing shape,
//!   position or time is skipped and listed with its [`SkipReason`] (the rest of the
//!   scenario is still used);
//! - a scenario without lane changes is not an error: its counts say zero;
//! - a lane change cut by the recording, a slow crossing, a repeated crossing and an
//!   unlinked lanelet change are counted and skipped; a merge is kept and flagged.
//!
//! ```no_run
//! use palc_commonroad::import::import_files;
//! let file = import_files(&["USA_US101-4_1_T-1.xml"])?;
//! println!("{} lane changes", file.counts.lane_changes);
//! # Ok::<(), palc_commonroad::import::ImportError>(())
//! ```

mod detect;
mod error;
mod geometry;
mod map;
pub mod params;
mod record;
mod tracks;
mod xml;

use std::path::Path;

pub use error::{ImportError, ReadError};
pub use record::{
    CentreSource, Counts, Direction, FORMAT, LateralSample, Neighbour, RecordedLaneChange,
    RecordedLaneChanges, SkipReason, SkippedVehicle, Source, StartContext, VERSION,
};

/// The one CommonRoad version read.
pub const SUPPORTED_VERSION: &str = "2020a";

/// One imported scenario.
#[derive(Debug, Clone, PartialEq)]
pub struct ScenarioImport {
    /// The scenario, with its counts.
    pub source: Source,
    /// The vehicles left out.
    pub skipped: Vec<SkippedVehicle>,
    /// The lane changes, by vehicle (in file order) and start.
    pub lane_changes: Vec<RecordedLaneChange>,
}

/// Imports the scenario in `text`; `file` names it in errors and in the [`Source`].
///
/// # Errors
/// [`ImportError`] for malformed XML, another root or version, a bad time step or an
/// unusable lanelet.
pub fn import_str(text: &str, file: &str) -> Result<ScenarioImport, ImportError> {
    xml::check_root(text, file)?;
    let root = xml::parse(text, file)?;
    let dt = root.time_step_size;
    if !(dt.is_finite() && dt > 0.0) {
        return Err(ImportError::InvalidTimeStep {
            source_name: file.to_owned(),
            value: dt,
        });
    }
    let mut lanelets = Vec::new();
    let mut obstacles = Vec::new();
    for child in root.children {
        match child {
            xml::XmlChild::Lanelet(l) => lanelets.push(l),
            xml::XmlChild::DynamicObstacle(o) => obstacles.push(o),
            xml::XmlChild::Other => {}
        }
    }
    let map = map::Map::new(&lanelets, file)?;
    let mut counts = Counts {
        vehicles: obstacles.len(),
        ..Counts::default()
    };
    let mut skipped = Vec::new();
    let mut kept = Vec::new();
    for obstacle in &obstacles {
        match tracks::track(obstacle, dt) {
            Ok(track) => kept.push(track),
            Err((reason, time_step)) => {
                match reason {
                    SkipReason::TimeGap => counts.skipped_time_gap += 1,
                    SkipReason::NonFinite => counts.skipped_non_finite += 1,
                    SkipReason::Incomplete => counts.skipped_incomplete += 1,
                }
                skipped.push(SkippedVehicle {
                    scenario: root.benchmark_id.clone(),
                    vehicle_id: obstacle.id,
                    reason,
                    time_step,
                });
            }
        }
    }
    let lane_changes =
        detect::lane_changes(&map, &kept, dt, (file, &root.benchmark_id), &mut counts)?;
    Ok(ScenarioImport {
        source: Source {
            file: file.to_owned(),
            benchmark_id: root.benchmark_id,
            commonroad_version: root.version,
            dt_s: dt,
            counts,
        },
        skipped,
        lane_changes,
    })
}

/// The most bytes read from one input file (64 MiB), as for every input of `palc`.
pub const MAX_FILE_BYTES: u64 = 64 * 1024 * 1024;

/// The text of the file at `path`, refused past [`MAX_FILE_BYTES`] (from its size
/// for a regular file, after reading that many bytes for a stream).
pub(crate) fn read_bounded(path: &Path) -> std::io::Result<String> {
    use std::io::Read;
    let too_large = |size: Option<u64>| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            match size {
                Some(size) => format!(
                    "it holds {size} bytes, more than the bound of {MAX_FILE_BYTES} bytes on an input file"
                ),
                None => format!(
                    "it holds more than the bound of {MAX_FILE_BYTES} bytes on an input file"
                ),
            },
        )
    };
    let file = std::fs::File::open(path)?;
    let metadata = file.metadata()?;
    if metadata.is_file() && metadata.len() > MAX_FILE_BYTES {
        return Err(too_large(Some(metadata.len())));
    }
    let mut text = String::new();
    file.take(MAX_FILE_BYTES + 1).read_to_string(&mut text)?;
    if text.len() as u64 > MAX_FILE_BYTES {
        return Err(too_large(None));
    }
    Ok(text)
}

/// Imports the scenario in the file at `path` (named by its file name in the [`Source`]).
///
/// # Errors
/// [`ImportError::Io`] when the file cannot be read, otherwise as [`import_str`].
pub fn import_file(path: &Path) -> Result<ScenarioImport, ImportError> {
    let text = read_bounded(path).map_err(|error| ImportError::Io {
        path: path.to_owned(),
        error,
    })?;
    let name = path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    import_str(&text, &name)
}

/// Imports several scenarios into one file of recorded lane changes, in the order given.
///
/// # Errors
/// The first scenario's [`ImportError`].
pub fn import_files<P: AsRef<Path>>(paths: &[P]) -> Result<RecordedLaneChanges, ImportError> {
    let mut file = RecordedLaneChanges::new();
    for path in paths {
        file.push(import_file(path.as_ref())?);
    }
    Ok(file)
}

impl RecordedLaneChanges {
    /// Appends one scenario's import and adds its counts.
    pub fn push(&mut self, import: ScenarioImport) {
        self.counts.add(&import.source.counts);
        self.sources.push(import.source);
        self.skipped_vehicles.extend(import.skipped);
        self.lane_changes.extend(import.lane_changes);
    }
}
