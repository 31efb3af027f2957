//! The evaluation from Python: `evaluate` runs an evaluation config as `palc eval`
//! does (palc-eval), with the GIL released, and reports progress to a callable or a
//! tqdm bar.
//!
//! The outputs are written as by the command line: into a staging directory that
//! replaces `out` only when every file is written, so a failure leaves the previous
//! results. Progress is reported from the evaluation's worker threads, each call
//! with the GIL held; an exception in the callback is raised when the evaluation
//! ends, and the callback is not called again.

use std::path::PathBuf;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

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
}

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
/// Returns a dict with ``report`` (the path of ``REPORT.md``), ``runs`` and ``wall_s``.
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
        };
        let shown = PythonProgress {
            target: progress,
            total: AtomicUsize::new(0),
            done: AtomicUsize::new(0),
            raised: Mutex::new(None),
        };
        let outcome = py.detach(|| palc_eval::evaluate(&options, &shown));
        if let Some(error) = shown.raised.lock().ok().and_then(|mut r| r.take()) {
            return Err(error);
        }
        let outcome = outcome.map_err(|e| errors::raise(py, &classify(&e), &e))?;
        let dict = PyDict::new(py);
        dict.set_item("report", outcome.report)?;
        dict.set_item("runs", outcome.runs)?;
        dict.set_item("wall_s", outcome.wall_s)?;
        Ok(dict)
    })
}
