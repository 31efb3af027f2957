//! The evaluation from Python: `evaluate` runs an evaluation config as `palc eval`
//! does (palc-eval), with the GIL released, and reports progress to a callable or a
//! tqdm bar.
//!
//! The outputs are written as by the command line: into a staging directory that
//! replaces `out` only when every file is written, so a failure leaves the previous
//! results. Progress is reported from the evaluation's worker threads, each call
//! with the GIL held; an exception in the callback stops the evaluation (no run is
//! started after it, nothing is written) and is raised, and the callback is not
//! called again.
//!
//! The runs go on in a thread of their own while the calling thread waits with the
//! GIL released and looks for signals every [`SIGNAL_POLL`]: Ctrl-C (or any signal
//! whose handler raises) cancels the evaluation in the same way and its exception
//! (`KeyboardInterrupt`) is raised once the runs in progress have ended.

use std::path::PathBuf;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Duration;

use palc_eval::{EvalError, EvalOptions, Progress, RunRow};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{self, Raise, guard};

/// Progress shown through a Python callable `progress(done, total)` or an object
/// with tqdm's `update(n)` (its `total` set when the runs are known).
struct PythonProgress {
    target: Option<Py<PyAny>>,
    total: AtomicUsize,
    done: AtomicUsize,
    raised: Mutex<Option<PyErr>>,
    /// Set when a signal handler raised: the evaluation is to stop.
    interrupted: AtomicBool,
}

/// How often the waiting thread looks for signals: short enough that Ctrl-C feels
/// immediate, long enough to cost nothing next to a run (milliseconds each).
const SIGNAL_POLL: Duration = Duration::from_millis(50);

impl PythonProgress {
    /// Calls the target with the GIL held, unless it raised before.
    fn call(&self, f: impl FnOnce(Python<'_>, &Bound<'_, PyAny>) -> PyResult<()>) {
        let Some(target) = &self.target else {
            return;
        };
        let Ok(mut raised) = self.raised.lock() else {
            return;
        };
        if raised.is_some() {
            return;
        }
        Python::attach(|py| {
            if let Err(error) = f(py, target.bind(py)) {
                *raised = Some(error);
            }
        });
    }
}

/// Whether `target` is a tqdm-like bar (it has `update`) rather than a callable.
fn is_bar(target: &Bound<'_, PyAny>) -> bool {
    target.hasattr("update").unwrap_or(false) && !target.is_callable()
}

impl Progress for PythonProgress {
    fn started(&self, total: usize) {
        self.total.store(total, Ordering::Relaxed);
        self.call(|_, target| {
            if is_bar(target) {
                target.setattr("total", total)?;
                if target.hasattr("refresh")? {
                    target.call_method0("refresh")?;
                }
            } else {
                target.call1((0, total))?;
            }
            Ok(())
        });
    }

    fn cancelled(&self) -> bool {
        self.interrupted.load(Ordering::Relaxed)
            || self.raised.lock().map_or(true, |raised| raised.is_some())
    }

    fn finished(&self, _row: &RunRow) {
        let done = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        let total = self.total.load(Ordering::Relaxed);
        self.call(|_, target| {
            if is_bar(target) {
                target.call_method1("update", (1,))?;
            } else {
                target.call1((done, total))?;
            }
            Ok(())
        });
    }
}

/// The class and attributes of an evaluation error.
fn classify(error: &EvalError) -> Raise {
    match error {
        EvalError::InFile { source, .. } => classify(source),
        EvalError::Toml { path, .. } => Raise::field("ConfigError", path.clone()),
        EvalError::InvalidConfig { field, bound, .. } => Raise {
            bound: Some(bound.clone()),
            ..Raise::field("ConfigError", field.clone())
        },
        EvalError::Unknown { field, .. } => Raise::field("ConfigError", field.clone()),
        // An option of the command line is a keyword argument here (`--jobs`: `jobs`).
        EvalError::InvalidOption {
            option,
            value,
            bound,
        } => Raise {
            value: Some(errors::Value::Text(value.clone())),
            bound: Some(bound.clone()),
            ..Raise::field("ConfigError", option.trim_start_matches('-'))
        },
        EvalError::Harness(e) | EvalError::Run { source: e, .. } => errors::classify_harness(e),
        _ => Raise::class("PalcError"),
    }
}

/// Runs the evaluation ``config`` (TOML, as ``palc eval --config``) and writes its
/// results into ``out`` (``REPORT.md``, ``runs.csv``, ``runs.json``, the figures),
/// replacing the previous results only when all are written. ``quick`` runs the
/// config's ``[quick]`` subset, ``jobs`` sets the worker threads (every core if
/// ``None``); the results do not depend on it. ``progress`` is a callable
/// ``progress(done, total)`` or a tqdm bar. The GIL is released while the runs go on.
///
/// Returns a dict with ``report`` (the path of ``REPORT.md``), ``runs``, ``wall_s`` and
/// ``idle_experiments`` (one message per experiment none of whose runs ran; ``palc
/// eval`` exits non-zero for them). Ctrl-C stops the evaluation: no run starts after
/// it, nothing is written, and ``KeyboardInterrupt`` is raised when the runs in
/// progress end.
#[pyfunction]
#[pyo3(signature = (config = PathBuf::from("configs/reproduce.toml"), *, out = PathBuf::from("target/reproduce-paper"), quick = false, jobs = None, progress = None))]
pub fn evaluate<'py>(
    py: Python<'py>,
    config: PathBuf,
    out: PathBuf,
    quick: bool,
    jobs: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    guard(py, "evaluate", || {
        if jobs == Some(0) {
            return Err(errors::message(
                py,
                &Raise {
                    value: Some(errors::Value::Number(0.0)),
                    bound: Some("at least 1 thread".to_owned()),
                    ..Raise::field("ConfigError", "jobs")
                },
                "`jobs` is 0, expected at least 1 thread (or None for every core)",
            ));
        }
        let options = EvalOptions {
            config,
            out,
            quick,
            jobs,
            shard: None,
        };
        let shown = PythonProgress {
            target: progress,
            total: AtomicUsize::new(0),
            done: AtomicUsize::new(0),
            raised: Mutex::new(None),
            interrupted: AtomicBool::new(false),
        };
        let (outcome, signal) = run_watching_signals(py, &options, &shown);
        if let Some(error) = signal {
            return Err(error);
        }
        if let Some(error) = shown.raised.lock().ok().and_then(|mut r| r.take()) {
            return Err(error);
        }
        let outcome = outcome.map_err(|e| errors::raise(py, &classify(&e), &e))?;
        let dict = PyDict::new(py);
        dict.set_item("report", outcome.report)?;
        dict.set_item("runs", outcome.runs)?;
        dict.set_item("wall_s", outcome.wall_s)?;
        let idle: Vec<String> = outcome.idle.iter().map(|e| e.to_string()).collect();
        dict.set_item("idle_experiments", idle)?;
        Ok(dict)
    })
}

/// Runs the evaluation in a scoped thread; this thread waits with the GIL released
/// and, every [`SIGNAL_POLL`], runs Python's signal handlers. The first exception
/// a handler raises cancels the evaluation and is returned beside its result.
fn run_watching_signals(
    py: Python<'_>,
    options: &EvalOptions,
    shown: &PythonProgress,
) -> (Result<palc_eval::Outcome, EvalError>, Option<PyErr>) {
    std::thread::scope(|scope| {
        let runs = scope.spawn(|| palc_eval::evaluate(options, shown));
        let mut signal = None;
        while !runs.is_finished() {
            py.detach(|| std::thread::sleep(SIGNAL_POLL));
            if signal.is_none() {
                if let Err(error) = py.check_signals() {
                    shown.interrupted.store(true, Ordering::Relaxed);
                    signal = Some(error);
                }
            }
        }
        match runs.join() {
            Ok(outcome) => (outcome, signal),
            Err(panic) => std::panic::resume_unwind(panic),
        }
    })
}
