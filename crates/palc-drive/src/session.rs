//! A study session: the protocol's scenes in order, each a lesson-learning loop
//! driven lane change by lane change by the participant ([`Session::tick`]),
//! recorded as it goes, and resumable from its record ([`Session::open`]).

use std::path::{Path, PathBuf};

use palc_aggregator::Experience;
use palc_harness::driver::DriverEstimate;
use palc_harness::live::{LiveLaneChange, LiveStatus};
use palc_harness::record::Outcome;
use palc_harness::{LearnConfig, LearningLoop, NoObserver};
use serde::Serialize;

use crate::DriveError;
use crate::control::Control;
use crate::protocol::Protocol;
use crate::record::{Event, RECORD_FORMAT_VERSION, RecordWriter, read_events};

/// The record's file name in the output directory.
pub const RECORD_FILE: &str = "session.jsonl";

/// The experience's file name in the output directory, written after every lesson.
pub const EXPERIENCE_FILE: &str = "experience.json";

/// Where a session stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Phase {
    /// Waiting for the participant to start the next lane change.
    Ready,
    /// A lane change is being driven.
    Driving,
    /// A lane change was interrupted (the page went away); start goes on.
    Paused,
    /// Every scene is done.
    Done,
}

/// What the page draws after a tick.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Frame {
    /// Where the session stands.
    pub phase: Phase,
    /// Scene index and count.
    pub scene: usize,
    /// Scenes in the protocol.
    pub scenes: usize,
    /// Lane changes driven in this scene.
    pub lane_changes: usize,
    /// Takeovers in this scene.
    pub takeovers: usize,
    /// Step of the lane change and its last step.
    pub step: usize,
    /// The lane change's last step `K`.
    pub horizon: usize,
    /// The step length (s).
    pub dt: f64,
    /// The ego `s` (plan frame), `l`, `v`.
    pub ego: [f64; 3],
    /// Other vehicles: `s` (plan frame), `l`, length, width.
    pub vehicles: Vec<[f64; 4]>,
    /// The plan ahead, `(s, l)`, when the protocol shows it.
    pub plan: Vec<[f64; 2]>,
    /// Whether the participant has taken over.
    pub taken_over: bool,
}

/// The lane change in progress.
#[derive(Debug)]
struct Current {
    lane_change: LiveLaneChange,
    controls: Vec<Control>,
    /// Taking over latches for the lane change.
    taken_over: bool,
}

/// A study session.
#[derive(Debug)]
pub struct Session {
    protocol: Protocol,
    base: LearnConfig,
    out_dir: PathBuf,
    /// `None` while replaying a record.
    writer: Option<RecordWriter>,
    scene: usize,
    learning: Option<LearningLoop>,
    carried: Option<Experience>,
    current: Option<Current>,
    phase: Phase,
}

impl Session {
    /// Opens the session of `protocol` (scenes set up from `base`) writing to
    /// `out_dir`: a new record, or with `resume` the record there, whose completed
    /// lane changes are driven again and checked.
    ///
    /// # Errors
    /// An existing record without `resume` or none with it; a record that does
    /// not replay; the loop's errors.
    pub fn open(
        protocol: Protocol,
        base: LearnConfig,
        out_dir: &Path,
        resume: bool,
    ) -> Result<Session, DriveError> {
        std::fs::create_dir_all(out_dir).map_err(|source| DriveError::Io {
            path: out_dir.to_path_buf(),
            source,
        })?;
        let path = out_dir.join(RECORD_FILE);
        let mut session = Session {
            learning: Some(LearningLoop::new(&protocol.scene_config(&base, 0), None)?),
            protocol,
            base,
            out_dir: out_dir.to_path_buf(),
            writer: None,
            scene: 0,
            carried: None,
            current: None,
            phase: Phase::Ready,
        };
        if !resume {
            if path.exists() {
                return Err(DriveError::Record {
                    path,
                    line: 0,
                    message: "a record exists: resume it with --resume or choose another --out"
                        .to_owned(),
                });
            }
            let mut writer = RecordWriter::open(&path, true)?;
            writer.append(&Event::Session {
                format_version: RECORD_FORMAT_VERSION,
                protocol: Box::new(session.protocol.clone()),
            })?;
            writer.sync()?;
            session.writer = Some(writer);
            return Ok(session);
        }
        let events = read_events(&path)?;
        let mut replayed = 0;
        for (line, event) in events.iter().enumerate() {
            if let Event::LaneChange {
                scene,
                controls,
                record,
                ..
            } = event
            {
                let mismatch = |message: String| DriveError::Record {
                    path: path.clone(),
                    line: line + 1,
                    message,
                };
                if *scene != session.scene {
                    return Err(mismatch(format!(
                        "a lane change of scene {scene} where scene {} was expected",
                        session.scene
                    )));
                }
                session.start()?;
                for control in controls {
                    session.tick(*control)?;
                }
                let again = session.last_record();
                let same = again.is_some_and(|r| {
                    r.takeover.map(|t| t.step) == record.takeover.map(|t| t.step)
                        && r.driven_l.len() == record.driven_l.len()
                        && (r.driven_l.iter().zip(&record.driven_l))
                            .all(|(a, b)| (a - b).abs() < 1e-9)
                });
                if !same || session.phase == Phase::Driving {
                    return Err(mismatch(
                        "the lane change does not replay as recorded".to_owned(),
                    ));
                }
                replayed += 1;
            }
        }
        let mut writer = RecordWriter::open(&path, false)?;
        writer.append(&Event::Resumed {
            lane_changes: replayed,
        })?;
        writer.sync()?;
        session.writer = Some(writer);
        Ok(session)
    }

    /// The last lane change's record in the current scene (or the scene before,
    /// when it just ended).
    fn last_record(&self) -> Option<&palc_harness::LaneChangeRecord> {
        self.learning.as_ref().and_then(|l| l.records().last())
    }

    /// The protocol.
    pub fn protocol(&self) -> &Protocol {
        &self.protocol
    }

    /// The planning step (s): a tick's length in real time.
    pub fn dt(&self) -> f64 {
        self.base.planning.dt
    }

    /// Where the session stands.
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// Starts the next lane change, or goes on after a pause.
    ///
    /// # Errors
    /// The loop's errors.
    pub fn start(&mut self) -> Result<(), DriveError> {
        match self.phase {
            Phase::Ready => {
                if let Some(learning) = &self.learning {
                    let lane_change = learning.begin_live(self.protocol.limits)?;
                    self.current = Some(Current {
                        lane_change,
                        controls: Vec::new(),
                        taken_over: false,
                    });
                    self.phase = Phase::Driving;
                }
            }
            Phase::Paused => self.phase = Phase::Driving,
            Phase::Driving | Phase::Done => {}
        }
        Ok(())
    }

    /// Pauses a lane change in progress (the page went away).
    pub fn pause(&mut self) {
        if self.phase == Phase::Driving {
            self.phase = Phase::Paused;
        }
    }

    /// One tick: while driving, the next step with `control`; at the lane
    /// change's end, its record, its lesson, and the scene's end when its rule
    /// says so. Returns what the page draws.
    ///
    /// # Errors
    /// The loop's and the record's errors.
    pub fn tick(&mut self, control: Control) -> Result<Frame, DriveError> {
        if self.phase == Phase::Driving {
            self.drive_step(control)?;
        }
        Ok(self.frame())
    }

    /// Drives one step and, at the end, finishes the lane change.
    fn drive_step(&mut self, control: Control) -> Result<(), DriveError> {
        let (Some(learning), Some(current)) = (&mut self.learning, &mut self.current) else {
            return Ok(());
        };
        current.taken_over |= control.take_over;
        let control = Control {
            take_over: current.taken_over,
            ..control
        };
        let status = (current.lane_change)
            .advance(learning.setup(), control.input(&self.protocol.limits))?;
        current.controls.push(control);
        if let Some(writer) = &mut self.writer {
            let lane_change = &current.lane_change;
            let ego = lane_change.driven().last().copied().unwrap_or_default();
            let frame = |p: Option<&palc_traffic::Vehicle>| {
                p.map_or([1e4, 0.0], |v| {
                    [v.state.s - learning.setup().origin_s, v.state.l]
                })
            };
            writer.append(&Event::Tick {
                scene: self.scene,
                lane_change: learning.records().len(),
                step: lane_change.step() - 1,
                ego: [ego.s, ego.l, ego.v],
                others: [
                    frame(lane_change.scene().preceding()),
                    frame(lane_change.scene().adjacent()),
                ],
                control,
            })?;
        }
        if status == LiveStatus::Done {
            self.finish_lane_change()?;
        }
        Ok(())
    }

    /// Records and learns from the finished lane change, and ends the scene when
    /// its rule says so.
    fn finish_lane_change(&mut self) -> Result<(), DriveError> {
        let (Some(learning), Some(current)) = (&mut self.learning, self.current.take()) else {
            return Ok(());
        };
        let record = learning
            .finish_live(current.lane_change, &mut NoObserver)?
            .clone();
        self.phase = Phase::Ready;
        let mut driver = None;
        if record.takeover.is_some() {
            learning
                .experience()
                .save(self.out_dir.join(EXPERIENCE_FILE))?;
        }
        if record.takeover.is_some() && self.writer.is_some() {
            let duration_s = self.base.planning.standard_alc.lane_change_duration_s;
            driver = DriverEstimate::from_onsets(&learning.experience().onsets, duration_s)
                .map(|estimate| estimate.describe());
        }
        if let Some(writer) = &mut self.writer {
            writer.append(&Event::LaneChange {
                scene: self.scene,
                controls: current.controls,
                record: Box::new(record),
                driver,
            })?;
            writer.sync()?;
        }
        let scene = &self.protocol.scene[self.scene];
        let ended = learning.termination().or_else(|| {
            (learning.records().len() >= scene.max_lane_changes).then_some(Outcome::CapReached)
        });
        if let Some(outcome) = ended {
            self.end_scene(outcome)?;
        }
        Ok(())
    }

    /// Ends the current scene with `outcome`: its run record, and the next scene.
    fn end_scene(&mut self, outcome: Outcome) -> Result<(), DriveError> {
        let Some(learning) = self.learning.take() else {
            return Ok(());
        };
        let result = learning.into_result(outcome);
        let name = format!("scene-{}.json", self.scene);
        let mut json = serde_json::to_vec_pretty(&result).map_err(|e| DriveError::Io {
            path: self.out_dir.join(&name),
            source: e.into(),
        })?;
        json.push(b'\n');
        palc_aggregator::output::write(&self.out_dir.join(&name), &json)?;
        if let Some(writer) = &mut self.writer {
            writer.append(&Event::SceneEnd {
                scene: self.scene,
                outcome,
                result: name,
            })?;
            writer.sync()?;
        }
        if self.protocol.carry_experience {
            self.carried = Some(result.experience);
        }
        self.scene += 1;
        if self.scene >= self.protocol.scene.len() {
            self.phase = Phase::Done;
            return Ok(());
        }
        let config = self.protocol.scene_config(&self.base, self.scene);
        self.learning = Some(LearningLoop::new(&config, self.carried.as_ref())?);
        self.phase = Phase::Ready;
        Ok(())
    }

    /// What the page draws now.
    pub fn frame(&self) -> Frame {
        let scenes = self.protocol.scene.len();
        let Some(learning) = &self.learning else {
            return Frame {
                phase: self.phase,
                scene: self.scene.min(scenes),
                scenes,
                lane_changes: 0,
                takeovers: 0,
                step: 0,
                horizon: 0,
                dt: 0.1,
                ego: [0.0; 3],
                vehicles: Vec::new(),
                plan: Vec::new(),
                taken_over: false,
            };
        };
        let setup = learning.setup();
        let (scene, step, ego, taken_over) = match &self.current {
            Some(current) => {
                let lane_change = &current.lane_change;
                let ego = lane_change.driven().last().copied();
                (
                    lane_change.scene(),
                    lane_change.step(),
                    ego,
                    current.taken_over,
                )
            }
            None => (&setup.scene, 0, None, false),
        };
        let ego = ego.map_or([0.0, 0.0, setup.ego_speed], |x| [x.s, x.l, x.v]);
        let ego_id = scene.ego().map(|v| v.id);
        let vehicles = (scene.vehicles().iter())
            .filter(|v| Some(v.id) != ego_id)
            .map(|v| [v.state.s - setup.origin_s, v.state.l, v.length, v.width])
            .collect();
        let plan = if self.protocol.show_plan {
            let states = &learning.next_plan().states;
            states.iter().map(|x| [x.s, x.l]).collect()
        } else {
            Vec::new()
        };
        let records = learning.records();
        Frame {
            phase: self.phase,
            scene: self.scene,
            scenes,
            lane_changes: records.len(),
            takeovers: records.iter().filter(|r| r.takeover.is_some()).count(),
            step,
            horizon: setup.horizon,
            dt: setup.dt,
            ego,
            vehicles,
            plan,
            taken_over,
        }
    }
}
