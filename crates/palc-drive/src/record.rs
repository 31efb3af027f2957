//! The session record: one JSON object a line, appended as the study goes
//! ([`Event`]), flushed and synced to disk at the end of every lane change
//! ([`RecordWriter::sync`]), and read back to resume ([`read_events`]).
//!
//! A session killed at any moment leaves every completed lane change on disk,
//! with the participant's controls at every step: resuming drives them again
//! through the loop, which is deterministic, and checks the replay against the
//! record. A torn last line (the kill came mid-write) is ignored.

use std::path::{Path, PathBuf};

use palc_aggregator::output::AppendLog;

use palc_harness::record::{LaneChangeRecord, Outcome};
use serde::{Deserialize, Serialize};

use crate::DriveError;
use crate::control::Control;
use crate::protocol::Protocol;

/// The record format's version.
pub const RECORD_FORMAT_VERSION: u32 = 1;

/// Largest record a session resumes from (bytes).
pub const MAX_RECORD_BYTES: u64 = 1 << 30;

/// One line of the session record.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "event", rename_all = "snake_case")]
pub enum Event {
    /// The session began with this protocol.
    Session {
        /// The record format's version.
        format_version: u32,
        /// The protocol.
        protocol: Box<Protocol>,
    },
    /// The session was resumed after this many completed lane changes.
    Resumed {
        /// Completed lane changes replayed.
        lane_changes: usize,
    },
    /// One server tick of a lane change.
    Tick {
        /// Scene index.
        scene: usize,
        /// Lane change index within the scene.
        lane_change: usize,
        /// Step driven.
        step: usize,
        /// The ego after the step: `s` (plan frame), `l`, `v`.
        ego: [f64; 3],
        /// The preceding and adjacent vehicles `(s, l)` (plan frame).
        others: [[f64; 2]; 2],
        /// The participant's controls.
        control: Control,
    },
    /// A completed lane change: the controls at every step (what resuming
    /// replays), its record, and palc's estimate of the driver after its lesson.
    LaneChange {
        /// Scene index.
        scene: usize,
        /// The controls of steps `0..=K`.
        controls: Vec<Control>,
        /// The loop's record of it.
        record: Box<LaneChangeRecord>,
        /// The driver, as palc believes after the lesson.
        driver: Option<String>,
    },
    /// A scene ended; its run is in `result` (`palc learn --record`'s format).
    SceneEnd {
        /// Scene index.
        scene: usize,
        /// How it ended.
        outcome: Outcome,
        /// The run record's file name in the output directory.
        result: String,
    },
}

/// The appending writer of a session record.
#[derive(Debug)]
pub struct RecordWriter {
    log: AppendLog,
}

impl RecordWriter {
    /// Opens `path` for appending, creating it when `create` (and refusing an
    /// existing file then), else requiring it.
    ///
    /// # Errors
    /// [`DriveError::Output`].
    pub fn open(path: &Path, create: bool) -> Result<Self, DriveError> {
        Ok(Self {
            log: AppendLog::open(path, create)?,
        })
    }

    /// Appends `event` as one line (buffered).
    ///
    /// # Errors
    /// [`DriveError::Output`].
    pub fn append(&mut self, event: &Event) -> Result<(), DriveError> {
        let mut line = serde_json::to_vec(event).map_err(|e| DriveError::Record {
            path: PathBuf::new(),
            line: 0,
            message: e.to_string(),
        })?;
        line.push(b'\n');
        Ok(self.log.append(&line)?)
    }

    /// Flushes the buffer and syncs the file to disk.
    ///
    /// # Errors
    /// [`DriveError::Output`].
    pub fn sync(&mut self) -> Result<(), DriveError> {
        Ok(self.log.sync()?)
    }
}

/// The events of the record at `path`; a last line that does not parse (torn
/// by a kill) is left out.
///
/// # Errors
/// [`DriveError::Io`]; [`DriveError::Record`] for a line before the last that
/// does not parse.
pub fn read_events(path: &Path) -> Result<Vec<Event>, DriveError> {
    let bytes = palc_aggregator::input::read_bounded(path, MAX_RECORD_BYTES).map_err(|e| {
        DriveError::Io {
            path: path.to_path_buf(),
            source: e.into_io(),
        }
    })?;
    let lines: Vec<&[u8]> = bytes
        .split(|&b| b == b'\n')
        .filter(|line| !line.is_empty())
        .collect();
    let mut events = Vec::with_capacity(lines.len());
    for (i, line) in lines.iter().enumerate() {
        match serde_json::from_slice::<Event>(line) {
            Ok(event) => events.push(event),
            Err(_) if i + 1 == lines.len() => {}
            Err(e) => {
                return Err(DriveError::Record {
                    path: path.to_path_buf(),
                    line: i + 1,
                    message: e.to_string(),
                });
            }
        }
    }
    Ok(events)
}
