//! The lesson-learning loop from Python: `LearnConfig`, `Experience`, `learn` and
//! its `LearnResult` (palc-harness, paper Fig. 2).
//!
//! A config is read by the same TOML reader as `palc learn --config` (a dict is
//! written as TOML first), so that an error keeps the dotted path of its field.
//! `learn` runs the loop with the config's built-in simulated user, with the GIL
//! released, and returns what `palc learn --record` writes: the summary and every
//! lane change, whose lateral paths are NumPy arrays.

use std::path::PathBuf;
use std::sync::Mutex;

use palc_aggregator::Experience as RustExperience;
use palc_harness::advanced::GapAcceptanceSet;
use palc_harness::driver::DriverEstimate;
use palc_harness::{HarnessError, LaneChangeRecord, NoObserver, RunResult};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::to_vector;
use crate::convert::{serialize, to_json, to_toml};
use crate::errors::{self, Raise, guard};
use crate::user::{PythonUser, Raised};
use crate::world::PythonWorld;

/// The config of one learning run (`palc_harness::LearnConfig`), validated.
#[pyclass(module = "palc", frozen)]
pub struct LearnConfig {
    inner: palc_harness::LearnConfig,
}

/// The built-in run config, as `palc learn` without `--config` uses it.
const DEFAULT_CONFIG: &str = include_str!("../../../configs/learn.toml");

/// `over` merged into `base`: tables key by key, any other value replaced.
fn merge(base: &mut toml::Table, over: toml::Table) {
    for (key, value) in over {
        match (base.get_mut(&key), value) {
            (Some(toml::Value::Table(inner)), toml::Value::Table(value)) => merge(inner, value),
            (_, value) => {
                base.insert(key, value);
            }
        }
    }
}

/// A parsed and validated config from TOML text; `source` names it in errors.
fn parse(py: Python<'_>, text: &str, source: &str) -> PyResult<palc_harness::LearnConfig> {
    palc_harness::LearnConfig::from_toml_str(text).map_err(|e| {
        let raise = errors::classify_harness(&e);
        errors::raise_in(py, &raise, &format!("in {source}"), &e)
    })
}

#[pymethods]
impl LearnConfig {
    /// Reads a run config (TOML, e.g. ``configs/learn.toml``) as ``palc learn
    /// --config`` does; an error is a ``ConfigError`` whose ``field`` is the dotted
    /// path (e.g. ``loop.max_takeovers``).
    #[staticmethod]
    fn from_toml(py: Python<'_>, path: PathBuf) -> PyResult<LearnConfig> {
        guard(py, "LearnConfig.from_toml", || {
            let text = std::fs::read_to_string(&path).map_err(PyErr::from)?;
            Ok(LearnConfig {
                inner: parse(py, &text, &path.display().to_string())?,
            })
        })
    }

    /// Reads a run config from TOML text.
    #[staticmethod]
    fn from_toml_str(py: Python<'_>, text: &str) -> PyResult<LearnConfig> {
        guard(py, "LearnConfig.from_toml_str", || {
            Ok(LearnConfig {
                inner: parse(py, text, "the TOML text")?,
            })
        })
    }

    /// The built-in run config: ``configs/learn.toml``, as ``palc learn`` uses it
    /// without ``--config``.
    #[new]
    fn new(py: Python<'_>) -> PyResult<LearnConfig> {
        guard(py, "LearnConfig()", || {
            Ok(LearnConfig {
                inner: parse(py, DEFAULT_CONFIG, "the built-in configs/learn.toml")?,
            })
        })
    }

    /// Reads a run config from a dict shaped like the TOML file (``tomllib.load``'s
    /// result, for instance); keys it leaves out take the values of the built-in
    /// ``configs/learn.toml``. It is written as TOML and read like a file.
    #[staticmethod]
    fn from_dict(py: Python<'_>, d: &Bound<'_, PyDict>) -> PyResult<LearnConfig> {
        guard(py, "LearnConfig.from_dict", || {
            let value = to_json(py, d.as_any(), "")?;
            let table = match to_toml(py, &value, "")? {
                toml::Value::Table(table) => {
                    let mut base: toml::Table = toml::from_str(DEFAULT_CONFIG).map_err(|e| {
                        errors::message(
                            py,
                            &Raise::class("PalcError"),
                            &format!("the built-in configs/learn.toml does not parse: {e}"),
                        )
                    })?;
                    merge(&mut base, table);
                    base
                }
                _ => {
                    return Err(errors::message(
                        py,
                        &Raise::class("ConfigError"),
                        "a config is a dict of tables",
                    ));
                }
            };
            let text = toml::to_string(&table).map_err(|e| {
                errors::message(
                    py,
                    &Raise::class("ConfigError"),
                    &format!("the dict cannot be written as TOML: {e}"),
                )
            })?;
            Ok(LearnConfig {
                inner: parse(py, &text, "the dict")?,
            })
        })
    }

    /// The config as a dict, every default filled in.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        serialize(py, &self.inner)
    }

    /// The scenario, e.g. ``collector-high / 40 m / seed 1 / neutral``.
    #[getter]
    fn label(&self) -> String {
        self.inner.label()
    }

    /// The learning method: ``paper`` or ``palc``.
    #[getter]
    fn method(&self) -> String {
        self.inner.method.name().to_owned()
    }

    fn __repr__(&self) -> String {
        format!(
            "LearnConfig({:?}, method={:?})",
            self.inner.label(),
            self.inner.method.name()
        )
    }
}

/// What a run learned (`palc_aggregator::Experience`): weights, zone model and
/// onsets, to be saved or carried into another run.
#[pyclass(module = "palc", frozen)]
pub struct Experience {
    inner: RustExperience,
}

#[pymethods]
impl Experience {
    /// Reads an experience saved by ``Experience.save`` or ``palc learn
    /// --save-experience``.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Experience> {
        guard(py, "Experience.load", || {
            let inner = RustExperience::load(&path)
                .map_err(|e| errors::raise(py, &Raise::class("PalcError"), &e))?;
            Ok(Experience { inner })
        })
    }

    /// Writes the experience atomically (a failure leaves the previous file).
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        guard(py, "Experience.save", || {
            self.inner
                .save(&path)
                .map_err(|e| errors::raise(py, &Raise::class("PalcError"), &e))
        })
    }

    fn __repr__(&self) -> String {
        "Experience(...)".to_owned()
    }
}

/// Everything a learning run produced (`palc_harness::RunResult`).
#[pyclass(module = "palc", frozen)]
pub struct LearnResult {
    inner: RunResult,
}

/// One lane change as a dict, its lateral paths as NumPy arrays.
fn record<'py>(py: Python<'py>, record: &LaneChangeRecord) -> PyResult<Bound<'py, PyAny>> {
    let dict = serialize(py, record)?;
    for (key, values) in [
        ("planned_l", &record.planned_l),
        ("expected_l", &record.expected_l),
        ("driven_l", &record.driven_l),
    ] {
        dict.set_item(key, to_vector(py, values.clone()))?;
    }
    Ok(dict)
}

#[pymethods]
impl LearnResult {
    /// How the run ended: ``personalized`` or ``cap_reached``.
    #[getter]
    fn outcome<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        serialize(py, &self.inner.summary.outcome)
    }

    /// Takeovers that happened in the run.
    #[getter]
    fn takeovers(&self) -> usize {
        self.inner.summary.takeovers
    }

    /// The paper's count: the takeovers of a personalized run, else the cap.
    #[getter]
    fn counted_takeovers(&self) -> usize {
        self.inner.summary.counted_takeovers()
    }

    /// Lane changes driven.
    #[getter]
    fn lane_changes(&self) -> usize {
        self.inner.summary.lane_changes
    }

    /// The run summary as a dict (as in ``palc learn --record``'s ``summary``).
    #[getter]
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        serialize(py, &self.inner.summary)
    }

    /// One dict per lane change (as in ``--record``'s ``records``), with
    /// ``planned_l``, ``expected_l`` and ``driven_l`` as arrays over steps ``0..=K`` (m).
    #[getter]
    fn records<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyAny>>> {
        self.inner.records.iter().map(|r| record(py, r)).collect()
    }

    /// The scenario's label.
    #[getter]
    fn label(&self) -> String {
        self.inner.label.clone()
    }

    /// Planning horizon K.
    #[getter]
    fn horizon(&self) -> usize {
        self.inner.horizon
    }

    /// Step of the plan (s).
    #[getter]
    fn dt(&self) -> f64 {
        self.inner.dt
    }

    /// What was learned.
    #[getter]
    fn experience(&self) -> Experience {
        Experience {
            inner: self.inner.experience.clone(),
        }
    }

    /// The whole result as JSON, as ``palc learn --record`` writes it.
    fn to_json(&self, py: Python<'_>) -> PyResult<String> {
        guard(py, "LearnResult.to_json", || {
            serde_json::to_string_pretty(&self.inner)
                .map_err(|e| errors::message(py, &Raise::class("PalcError"), &e.to_string()))
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "LearnResult({:?}, {:?}, takeovers={}, lane_changes={})",
            self.inner.label,
            self.inner.summary.outcome,
            self.inner.summary.takeovers,
            self.inner.summary.lane_changes
        )
    }
}

/// The loop of a run: the config's built-in simulated user, or a Python driver; in
/// palc's own traffic, or in a simulator driven from Python (`world`).
fn loop_for(
    py: Python<'_>,
    config: &palc_harness::LearnConfig,
    experience: Option<&RustExperience>,
    user: Option<Py<PyAny>>,
    world: Option<Py<PyAny>>,
    raised: &Raised,
) -> PyResult<palc_harness::LearningLoop> {
    let made = match user {
        None => py.detach(|| palc_harness::LearningLoop::new(config, experience)),
        Some(object) => {
            let threshold = config.planning.takeover_threshold_m;
            let user = PythonUser::new(py, object, threshold, raised.clone());
            py.detach(|| palc_harness::LearningLoop::with_user(config, experience, Box::new(user)))
        }
    };
    let made = made.map_err(|e| harness_or_raised(py, &e, raised))?;
    Ok(match world {
        None => made,
        Some(object) => made.in_world(Box::new(PythonWorld::new(py, object, raised.clone()))),
    })
}

/// The exception of a harness error, or the Python driver's own exception that
/// caused it (with its traceback).
fn harness_or_raised(py: Python<'_>, error: &HarnessError, raised: &Raised) -> PyErr {
    match take(raised) {
        Some(original) => original,
        None => errors::harness(py, error),
    }
}

/// The exception a Python driver raised, if it did.
fn take(raised: &Raised) -> Option<PyErr> {
    raised.lock().ok().and_then(|mut slot| slot.take())
}

/// The result of a run, or the Python driver's exception if it raised on the way
/// (from `takes_over`, which cannot stop the run itself).
fn finish(
    py: Python<'_>,
    result: Result<RunResult, HarnessError>,
    raised: &Raised,
) -> PyResult<LearnResult> {
    if let Some(original) = take(raised) {
        return Err(original);
    }
    match result {
        Ok(inner) => Ok(LearnResult { inner }),
        Err(e) => Err(errors::harness(py, &e)),
    }
}

/// Runs the lesson-learning loop of ``config`` (as ``palc learn``), starting from
/// ``experience`` if given, with the config's built-in simulated user or with
/// ``user``, a driver written in Python (a ``palc.User``), in palc's own traffic or
/// in ``world``, a simulator driven from Python (a ``palc.World``). The GIL is
/// released while the loop runs, and taken again for each call into Python.
#[pyfunction]
#[pyo3(signature = (config, experience = None, user = None, world = None))]
pub fn learn(
    py: Python<'_>,
    config: &LearnConfig,
    experience: Option<&Experience>,
    user: Option<Py<PyAny>>,
    world: Option<Py<PyAny>>,
) -> PyResult<LearnResult> {
    guard(py, "learn", || {
        let raised = Raised::default();
        let experience = experience.map(|e| &e.inner);
        let learning = loop_for(py, &config.inner, experience, user, world, &raised)?;
        let result = py.detach(|| learning.run(&mut NoObserver));
        finish(py, result, &raised)
    })
}

/// The lesson-learning loop lane change by lane change: iterating it drives one lane
/// change per step (the user judges it and, on a takeover, the method learns) and
/// yields its record, as ``LearnResult.records`` holds them, until the run is over;
/// ``result()`` then gives the whole result (running to the end if needed).
#[pyclass(module = "palc")]
pub struct LearningLoop {
    /// The loop; `None` once `result()` took it. Locked while it steps, so that a
    /// driver cannot step its own loop.
    inner: Mutex<Option<palc_harness::LearningLoop>>,
    raised: Raised,
}

/// The error of a loop that is stepping already or whose result was taken.
fn unavailable(py: Python<'_>, what: &str) -> PyErr {
    errors::message(py, &Raise::class("PalcError"), what)
}

impl LearningLoop {
    /// Runs `f` on the loop, or fails when it is busy or finished.
    fn with<T>(
        &self,
        py: Python<'_>,
        f: impl FnOnce(&mut Option<palc_harness::LearningLoop>) -> PyResult<T>,
    ) -> PyResult<T> {
        let mut slot = self.inner.try_lock().map_err(|_| {
            unavailable(
                py,
                "the learning loop is busy: a driver cannot step its own loop",
            )
        })?;
        if slot.is_none() {
            return Err(unavailable(
                py,
                "the learning loop is finished: its result() was taken",
            ));
        }
        f(&mut slot)
    }
}

#[pymethods]
impl LearningLoop {
    /// Prepares the run of ``config`` as ``learn`` does (the scenario, the planner, the
    /// first plan), with the built-in user or the Python driver ``user``, in palc's
    /// own traffic or in the Python simulator ``world``.
    #[new]
    #[pyo3(signature = (config, user = None, experience = None, world = None))]
    fn new(
        py: Python<'_>,
        config: &LearnConfig,
        user: Option<Py<PyAny>>,
        experience: Option<&Experience>,
        world: Option<Py<PyAny>>,
    ) -> PyResult<LearningLoop> {
        guard(py, "LearningLoop()", || {
            let raised = Raised::default();
            let experience = experience.map(|e| &e.inner);
            let inner = loop_for(py, &config.inner, experience, user, world, &raised)?;
            Ok(LearningLoop {
                inner: Mutex::new(Some(inner)),
                raised,
            })
        })
    }

    fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    /// Drives the next lane change and returns its record; ``StopIteration`` once the
    /// run is over.
    fn __next__<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        guard(py, "LearningLoop.__next__", || {
            self.with(py, |slot| {
                let Some(learning) = slot.as_mut() else {
                    return Ok(None);
                };
                if learning.termination().is_some() {
                    return Ok(None);
                }
                let stepped = py.detach(|| learning.step(&mut NoObserver).cloned());
                if let Some(original) = take(&self.raised) {
                    return Err(original);
                }
                match stepped {
                    Ok(r) => record(py, &r).map(Some),
                    Err(e) => Err(errors::harness(py, &e)),
                }
            })
        })
    }

    /// How the run ended (``personalized`` or ``cap_reached``), or ``None`` while it
    /// goes on.
    #[getter]
    fn outcome<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.with(py, |slot| {
            slot.as_ref()
                .and_then(|learning| learning.termination())
                .map(|o| serialize(py, &o))
                .transpose()
        })
    }

    /// What palc believes about the driver's start after the lessons so far, in one
    /// line: the most probable start model (the cue and its threshold, the reaction,
    /// the gaps accepted) with its cue's posterior mass, or that no start model explains
    /// every scene the driver was seen in; ``None`` before a start was recorded.
    fn driver_estimate(&self, py: Python<'_>) -> PyResult<Option<String>> {
        self.with(py, |slot| {
            Ok(slot.as_ref().and_then(|learning| {
                let duration_s = learning.setup().standard_alc.lane_change_duration_s;
                DriverEstimate::from_onsets(&learning.experience().onsets, duration_s)
                    .map(|estimate| estimate.describe())
            }))
        })
    }

    /// The gap-acceptance drivers the starts so far allow, in one line: the cue, its
    /// threshold (or the interval waits bound it to) and the gaps to the target lane's
    /// leader and follower; the start carried into a new scene for the cues it reads is
    /// the one most of them lead to. ``None`` before a start was recorded.
    fn gap_acceptance(&self, py: Python<'_>) -> PyResult<Option<String>> {
        self.with(py, |slot| {
            Ok(slot.as_ref().and_then(|learning| {
                GapAcceptanceSet::from_onsets(&learning.experience().onsets)
                    .map(|set| set.describe())
            }))
        })
    }

    /// The whole run's result: the summary, every record and the experience. Runs the
    /// loop to its end first if it is not over; the loop cannot step after it.
    fn result(&self, py: Python<'_>) -> PyResult<LearnResult> {
        guard(py, "LearningLoop.result", || {
            let learning = self.with(py, |slot| Ok(slot.take()))?;
            let Some(learning) = learning else {
                return Err(unavailable(py, "the learning loop is finished"));
            };
            let result = py.detach(|| learning.run(&mut NoObserver));
            finish(py, result, &self.raised)
        })
    }

    fn __repr__(&self) -> String {
        match self.inner.try_lock().as_deref() {
            Ok(Some(learning)) => {
                format!("LearningLoop(lane_changes={})", learning.records().len())
            }
            Ok(None) => "LearningLoop(finished)".to_owned(),
            Err(_) => "LearningLoop(stepping)".to_owned(),
        }
    }
}
