//! Rust errors as Python exceptions, and the guard that keeps panics out of Python.
//!
//! The exception classes live in Python (`palc._errors`), so that they carry typed,
//! documented attributes (`field`, `value`, `bound`, `kind`). Each Rust error becomes
//! the class of its kind with its message and attributes, and each error of its
//! `source()` chain a `PalcError` set as the `__cause__` of the one before.
//! [`guard`] runs an entry point and turns a panic into a `PalcError` that names it.

use std::error::Error;
use std::panic::{AssertUnwindSafe, catch_unwind};

use palc_harness::HarnessError;
use palc_planner::PlanError;
use palc_zone_filter::ZoneError;
use pyo3::prelude::*;

/// The Python module that defines the exception classes.
const ERRORS_MODULE: &str = "palc._errors";

/// A value an error reports: a number or a name.
#[derive(Debug, Clone)]
pub(crate) enum Value {
    /// A number.
    Number(f64),
    /// A name or another text.
    Text(String),
}

/// The class and attributes of one exception.
#[derive(Debug, Clone, Default)]
pub(crate) struct Raise {
    /// The class name in `palc._errors`.
    pub class: &'static str,
    /// Dotted path of the field at fault.
    pub field: Option<String>,
    /// The value found there.
    pub value: Option<Value>,
    /// The bound it violates, in words.
    pub bound: Option<String>,
    /// A refusal's kind.
    pub kind: Option<String>,
}

impl Raise {
    /// An exception of `class` without attributes.
    pub fn class(class: &'static str) -> Self {
        Raise {
            class,
            ..Raise::default()
        }
    }

    /// An exception of `class` that names `field`.
    pub fn field(class: &'static str, field: impl Into<String>) -> Self {
        Raise {
            class,
            field: Some(field.into()).filter(|f: &String| !f.is_empty()),
            ..Raise::default()
        }
    }

    /// An exception of `class` with a field, a number and a bound.
    pub fn bounded(
        class: &'static str,
        field: impl Into<String>,
        value: f64,
        bound: impl Into<String>,
    ) -> Self {
        Raise {
            value: Some(Value::Number(value)),
            bound: Some(bound.into()),
            ..Raise::field(class, field)
        }
    }
}

/// The exception for `raise` with `message`, its attributes set and `cause` chained.
fn build(py: Python<'_>, raise: &Raise, message: &str, cause: Option<PyErr>) -> PyErr {
    match instance(py, raise, message) {
        Ok(err) => {
            if cause.is_some() {
                err.set_cause(py, cause);
            }
            err
        }
        Err(err) => err,
    }
}

fn instance(py: Python<'_>, raise: &Raise, message: &str) -> PyResult<PyErr> {
    let class = py.import(ERRORS_MODULE)?.getattr(raise.class)?;
    let exception = class.call1((message,))?;
    if let Some(field) = &raise.field {
        exception.setattr("field", field)?;
    }
    match &raise.value {
        Some(Value::Number(v)) => exception.setattr("value", *v)?,
        Some(Value::Text(t)) => exception.setattr("value", t)?,
        None => {}
    }
    if let Some(bound) = &raise.bound {
        exception.setattr("bound", bound)?;
    }
    if let Some(kind) = &raise.kind {
        exception.setattr("kind", kind)?;
    }
    Ok(PyErr::from_value(exception))
}

/// The `source()` chain of `error` as `PalcError`s, each the `__cause__` of the one before.
fn causes(py: Python<'_>, error: Option<&(dyn Error + 'static)>) -> Option<PyErr> {
    let error = error?;
    let cause = causes(py, error.source());
    Some(build(
        py,
        &Raise::class("PalcError"),
        &error.to_string(),
        cause,
    ))
}

/// The exception of `error`, raised as `raise` with its causes chained.
pub(crate) fn raise(py: Python<'_>, raise: &Raise, error: &(dyn Error + 'static)) -> PyErr {
    let cause = causes(py, error.source());
    build(py, raise, &error.to_string(), cause)
}

/// As [`raise`], the message prefixed with `context` (e.g. the file it is in).
pub(crate) fn raise_in(
    py: Python<'_>,
    raise: &Raise,
    context: &str,
    error: &(dyn Error + 'static),
) -> PyErr {
    let cause = causes(py, error.source());
    build(py, raise, &format!("{context}: {error}"), cause)
}

/// A `ShapeError` (or another class) with a message and no Rust error behind it.
pub(crate) fn message(py: Python<'_>, raise: &Raise, message: &str) -> PyErr {
    build(py, raise, message, None)
}

/// The class and attributes of a planner error.
pub(crate) fn classify_plan(error: &PlanError) -> Raise {
    match error {
        PlanError::Config(palc_planner::ConfigError::OutOfRange {
            field,
            value,
            bound,
        }) => Raise::bounded("ConfigError", *field, *value, *bound),
        PlanError::Config(_) => Raise::class("ConfigError"),
        PlanError::OutOfRange {
            field,
            value,
            bound,
        } => Raise::bounded("PlanError", field.clone(), *value, *bound),
        PlanError::NonFinite { field, value } => Raise {
            value: Some(Value::Number(*value)),
            bound: Some("a finite number".to_owned()),
            ..Raise::field("PlanError", field.clone())
        },
        PlanError::DimensionMismatch { field, .. } | PlanError::MissingField { field } => {
            Raise::field("PlanError", *field)
        }
        PlanError::SolverFailed { .. } => Raise::class("SolverFailed"),
        _ => Raise::class("PlanError"),
    }
}

/// The exception of a planner error.
pub(crate) fn plan(py: Python<'_>, error: &PlanError) -> PyErr {
    raise(py, &classify_plan(error), error)
}

/// The class and attributes of a zone filter error.
pub(crate) fn classify_zone(error: &ZoneError) -> Raise {
    match error {
        ZoneError::InvalidConfig {
            field,
            value,
            bound,
        } => Raise::bounded("ConfigError", *field, *value, *bound),
        ZoneError::NonFinite { field, value } | ZoneError::NonPositiveSpeed { field, value } => {
            Raise {
                value: Some(Value::Number(*value)),
                ..Raise::field("ZoneError", field.clone())
            }
        }
        ZoneError::DimensionMismatch { what, .. } => Raise::field("ZoneError", what.clone()),
        _ => Raise::class("ZoneError"),
    }
}

/// The exception of a zone filter error.
pub(crate) fn zone(py: Python<'_>, error: &ZoneError) -> PyErr {
    raise(py, &classify_zone(error), error)
}

/// The class and attributes of a traffic config error.
fn classify_traffic(error: &palc_traffic::ConfigError) -> Raise {
    use palc_traffic::ConfigError as E;
    match error {
        E::Toml { path, .. } => Raise::field("ConfigError", path.clone()),
        E::OutOfRange {
            field,
            value,
            bound,
        } => Raise::bounded("ConfigError", field.clone(), *value, bound.clone()),
        E::Empty { field } => Raise::field("ConfigError", field.clone()),
        _ => Raise::class("ConfigError"),
    }
}

/// The class and attributes of a harness error.
pub(crate) fn classify_harness(error: &HarnessError) -> Raise {
    match error {
        HarnessError::InvalidConfig {
            field,
            value,
            bound,
        } => Raise::bounded("ConfigError", field.clone(), *value, bound.clone()),
        HarnessError::MissingTable { table, .. } => Raise::field("ConfigError", *table),
        HarnessError::UnknownStyle { name, expected } => Raise {
            value: Some(Value::Text(name.clone())),
            bound: Some(format!("one of {expected}")),
            ..Raise::field("ConfigError", "user.style")
        },
        HarnessError::UnknownSpeedCase { name, defined } => Raise {
            value: Some(Value::Text(name.clone())),
            bound: Some(format!("one of {defined}")),
            ..Raise::field("ConfigError", "cell.speed_case")
        },
        HarnessError::Toml { path, .. } => Raise::field("ConfigError", path.clone()),
        HarnessError::Refused { refusal, .. } => Raise {
            kind: Some(refusal.kind()),
            ..Raise::class("ScenarioRefused")
        },
        HarnessError::World { .. } => Raise::class("SimulatorError"),
        HarnessError::TrafficConfig(e) => classify_traffic(e),
        HarnessError::Planner(e) => classify_plan(e),
        HarnessError::Zone(e) => classify_zone(e),
        _ => Raise::class("PalcError"),
    }
}

/// The exception of a harness error.
pub(crate) fn harness(py: Python<'_>, error: &HarnessError) -> PyErr {
    raise(py, &classify_harness(error), error)
}

/// Runs the entry point `name`; a panic inside it becomes a `PalcError` naming the
/// entry point and the panic's message instead of reaching Python.
pub(crate) fn guard<T>(py: Python<'_>, name: &str, f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(result) => result,
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| (*s).to_owned())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "a panic without a message".to_owned());
            Err(message(
                py,
                &Raise::class("PalcError"),
                &format!("internal error in palc's {name}: it panicked ({what}); please report it"),
            ))
        }
    }
}
