//! A driver written in Python, as a `palc_user::User` of the learning loop.
//!
//! A Python object with `nominal(scene)` and `next(scene)` (a subclass of
//! `palc.User`) is called with the GIL held, each time with the scene as a dict of
//! NumPy arrays; it returns the lane change it expects as a dict (`start_s`,
//! `duration_s`, optionally `decision_s`, `from_l`, `to_l`). The expected states keep
//! the lane-keeping motion of the scene (the paper's constant speed) and move
//! laterally along a quintic, and the user takes over past the run's deviation
//! threshold (`planning.takeover_threshold_m`).
//!
//! A driver may also define `takes_over(step, ego, expected_l, seen)`, called at
//! every step of a drive, to take over by its own rule instead of the deviation's.
//!
//! A Python exception inside the driver stops the run as a `UserError::Failed` (in
//! `takes_over`, the deviation rule judges the rest of the run); the exception
//! itself is kept and raised again to the caller with its own traceback.

use std::sync::{Arc, Mutex};

use palc_harness::user::{
    Expectation, ExpectedLaneChange, Situation, SpeedRule, TakeoverCause, TakeoverRule, User,
    UserError, UserScene,
};
use palc_planner::State;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde::Deserialize;

use crate::arrays::{to_matrix, to_vector};

/// The longest search window a Python driver is shown (steps); the harness bounds
/// the window far below this, so it only keeps a bad scene from exhausting memory.
const MAX_STEPS: usize = 10_000_000;

/// The first Python exception a driver raised, shared with the caller of the run.
pub(crate) type Raised = Arc<Mutex<Option<PyErr>>>;

/// What a Python driver returns: the lane change it expects.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Answer {
    /// Time of the start of the lateral move, from the start of the plan (s).
    start_s: f64,
    /// Duration of the lateral move (s).
    duration_s: f64,
    /// Time of the decision (s); the start's by default.
    #[serde(default)]
    decision_s: Option<f64>,
    /// Lateral position before the move (m); 0, the current lane's centre.
    #[serde(default)]
    from_l: Option<f64>,
    /// Lateral position after the move (m); the target lane's centre.
    #[serde(default)]
    to_l: Option<f64>,
}

/// A driver written in Python.
#[derive(Debug)]
pub(crate) struct PythonUser {
    object: Py<PyAny>,
    name: String,
    deviation_m: f64,
    raised: Raised,
    /// Whether the object overrides `takes_over` (else the deviation rule decides).
    own_takeover: bool,
    /// Whether the object overrides `acceleration_after_takeover` (else the
    /// built-in users' rule decides).
    own_acceleration: bool,
}

/// Whether `object`'s class defines `method` itself rather than inheriting
/// `palc.User`'s.
fn overrides(py: Python<'_>, object: &Bound<'_, PyAny>, method: &str) -> bool {
    let base = py
        .import("palc._user")
        .and_then(|m| m.getattr("User"))
        .and_then(|user| user.getattr(method));
    match (object.get_type().getattr(method), base) {
        (Ok(own), Ok(base)) => !own.is(&base),
        (Ok(_), Err(_)) => true,
        _ => false,
    }
}

impl PythonUser {
    /// The driver `object`, which takes over past `deviation_m`; its first exception
    /// goes to `raised`.
    pub(crate) fn new(py: Python<'_>, object: Py<PyAny>, deviation_m: f64, raised: Raised) -> Self {
        let name = object
            .bind(py)
            .getattr("name")
            .and_then(|n| n.extract::<String>())
            .or_else(|_| object.bind(py).get_type().name().map(|n| n.to_string()))
            .unwrap_or_else(|_| "python".to_owned());
        let own_takeover = overrides(py, object.bind(py), "takes_over");
        let own_acceleration = overrides(py, object.bind(py), "acceleration_after_takeover");
        PythonUser {
            object,
            name,
            deviation_m,
            raised,
            own_takeover,
            own_acceleration,
        }
    }

    /// Calls `method(scene)` of the Python object and reads its answer; an exception
    /// is kept in `raised` and becomes a [`UserError::Failed`].
    fn call(&self, method: &str, scene: &UserScene<'_>) -> Result<Expectation, UserError> {
        Python::attach(|py| {
            let answer = scene_dict(py, scene)
                .and_then(|dict| self.object.bind(py).call_method1(method, (dict,)))
                .and_then(|answer| read_answer(py, &answer, method));
            match answer {
                Ok(answer) => expectation(&answer, scene, self.deviation_m),
                Err(error) => {
                    let message = error.to_string();
                    if let Ok(mut slot) = self.raised.lock() {
                        slot.get_or_insert(error);
                    }
                    Err(UserError::Failed {
                        user: self.name.clone(),
                        source: format!("`{method}` raised {message}").into(),
                    })
                }
            }
        })
    }
}

impl User for PythonUser {
    fn name(&self) -> &str {
        &self.name
    }

    fn nominal(&self, scene: &UserScene<'_>) -> Result<Expectation, UserError> {
        self.call("nominal", scene)
    }

    fn next(&mut self, scene: &UserScene<'_>) -> Result<Expectation, UserError> {
        self.call("next", scene)
    }

    /// The Python driver's `takes_over(step, ego, expected_l, seen)` if it defines
    /// one (a true answer is reported as a deviation takeover), else the deviation
    /// rule. Once the driver has raised, it is not called again and the run's caller
    /// gets the exception.
    fn takes_over(
        &self,
        expectation: &Expectation,
        step: usize,
        ego: &State,
        seen: &Situation,
    ) -> Option<TakeoverCause> {
        let expected_l = expectation.states.get(step).map_or(ego.l, |x| x.l);
        let rule = || expectation.judge(step, ego, seen);
        if !self.own_takeover || self.raised.lock().map_or(true, |r| r.is_some()) {
            return rule();
        }
        Python::attach(|py| {
            let answer = (|| -> PyResult<bool> {
                let state = PyDict::new(py);
                for (key, value) in [("s", ego.s), ("v", ego.v), ("l", ego.l), ("phi", ego.phi)] {
                    state.set_item(key, value)?;
                }
                let situation = situation_dict(py, seen)?;
                let args = (step, state, expected_l, situation);
                self.object
                    .bind(py)
                    .call_method1("takes_over", args)?
                    .is_truthy()
            })();
            match answer {
                Ok(true) => Some(TakeoverCause::Deviation),
                Ok(false) => None,
                Err(error) => {
                    if let Ok(mut slot) = self.raised.lock() {
                        slot.get_or_insert(error);
                    }
                    rule()
                }
            }
        })
    }

    /// The Python driver's `acceleration_after_takeover(step, speed, acc)` if it
    /// defines one: a finite number (m/s²), which the loop bounds by the ego's limits
    /// as it does the built-in users'. Otherwise, or once the driver has raised or
    /// answered something else, the built-in users' rule.
    fn acceleration_after_takeover(
        &self,
        expectation: &Expectation,
        step: usize,
        speed: f64,
        acc: f64,
    ) -> f64 {
        let built_in = || expectation.acceleration_after_takeover(step, speed, acc);
        if !self.own_acceleration || self.raised.lock().map_or(true, |r| r.is_some()) {
            return built_in();
        }
        Python::attach(|py| {
            let answer = (|| -> PyResult<f64> {
                let value: f64 = (self.object.bind(py))
                    .call_method1("acceleration_after_takeover", (step, speed, acc))?
                    .extract()?;
                if !value.is_finite() {
                    return Err(pyo3::exceptions::PyValueError::new_err(format!(
                        "acceleration_after_takeover returned {value:?} at step {step}, \
                         expected a finite acceleration in m/s²"
                    )));
                }
                Ok(value)
            })();
            answer.unwrap_or_else(|error| {
                if let Ok(mut slot) = self.raised.lock() {
                    slot.get_or_insert(error);
                }
                built_in()
            })
        })
    }
}

/// One step's situation as a dict of numbers (NaN where there is no vehicle).
fn situation_dict<'py>(py: Python<'py>, x: &Situation) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    let or_nan = |x: Option<f64>| x.unwrap_or(f64::NAN);
    for (key, value) in [
        ("time_headway_s", x.time_headway_s),
        ("preceding_gap_m", x.preceding_gap_m),
        ("preceding_speed", or_nan(x.preceding_speed)),
        ("target_lead_gap_m", or_nan(x.target_lead_gap_m)),
        ("target_lag_gap_m", or_nan(x.target_lag_gap_m)),
        ("ego_speed", x.ego_speed),
        ("target_lead_speed", or_nan(x.target_lead_speed)),
        ("target_lag_speed", or_nan(x.target_lag_speed)),
    ] {
        dict.set_item(key, value)?;
    }
    Ok(dict)
}

/// The scene as a dict: `dt`, `set_speed`, `target_l`, `lane_keeping` (n, 2) of
/// `[s - s0, v]`, and `situations`, a dict of (n,) arrays (NaN where there is no
/// vehicle).
fn scene_dict<'py>(py: Python<'py>, scene: &UserScene<'_>) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    dict.set_item("dt", scene.dt)?;
    dict.set_item("set_speed", scene.set_speed)?;
    dict.set_item("target_l", scene.target_l)?;
    let keeping = scene.lane_keeping;
    let values = keeping.iter().flatten().copied().collect();
    dict.set_item("lane_keeping", to_matrix(py, keeping.len(), 2, values)?)?;
    let situations = PyDict::new(py);
    let s = scene.situations;
    let column = |f: &dyn Fn(&Situation) -> f64| s.iter().map(f).collect();
    let or_nan = |x: Option<f64>| x.unwrap_or(f64::NAN);
    let columns: [(&str, Vec<f64>); 8] = [
        ("time_headway_s", column(&|x| x.time_headway_s)),
        ("preceding_gap_m", column(&|x| x.preceding_gap_m)),
        ("preceding_speed", column(&|x| or_nan(x.preceding_speed))),
        (
            "target_lead_gap_m",
            column(&|x| or_nan(x.target_lead_gap_m)),
        ),
        ("target_lag_gap_m", column(&|x| or_nan(x.target_lag_gap_m))),
        ("ego_speed", column(&|x| x.ego_speed)),
        (
            "target_lead_speed",
            column(&|x| or_nan(x.target_lead_speed)),
        ),
        ("target_lag_speed", column(&|x| or_nan(x.target_lag_speed))),
    ];
    for (name, values) in columns {
        situations.set_item(name, to_vector(py, values))?;
    }
    dict.set_item("situations", situations)?;
    Ok(dict)
}

/// The driver's answer, read as a dict; an error names the method and the field.
fn read_answer(py: Python<'_>, answer: &Bound<'_, PyAny>, method: &str) -> PyResult<Answer> {
    let value = crate::convert::to_json(py, answer, method)?;
    crate::convert::from_json(py, value)
}

/// The expectation of `answer` in `scene`: lane keeping, then the quintic move.
fn expectation(
    answer: &Answer,
    scene: &UserScene<'_>,
    deviation_m: f64,
) -> Result<Expectation, UserError> {
    let n = scene.situations.len().min(scene.lane_keeping.len());
    let dt = scene.dt;
    let invalid = |field: &str, value: f64, bound: String| UserError::InvalidConfig {
        field: field.to_owned(),
        value,
        bound,
    };
    let window_s = n.saturating_sub(1) as f64 * dt;
    let within = |field: &str, value: f64| {
        if value.is_finite() && (0.0..=window_s).contains(&value) {
            Ok(value)
        } else {
            Err(invalid(
                field,
                value,
                format!("a time in [0, {window_s:?}] s, the search window"),
            ))
        }
    };
    let start_s = within("start_s", answer.start_s)?;
    let decision_s = within("decision_s", answer.decision_s.unwrap_or(start_s))?;
    if !(answer.duration_s.is_finite() && answer.duration_s > 0.0) {
        return Err(invalid(
            "duration_s",
            answer.duration_s,
            "a positive, finite duration (s)".to_owned(),
        ));
    }
    if n == 0 || n > MAX_STEPS || !(dt.is_finite() && dt > 0.0) {
        return Err(invalid(
            "scene",
            n as f64,
            "a non-empty search window".to_owned(),
        ));
    }
    let lateral = |field: &str, value: Option<f64>, default: f64| {
        let value = value.unwrap_or(default);
        if value.is_finite() {
            Ok(value)
        } else {
            Err(invalid(
                field,
                value,
                "a finite lateral position (m)".to_owned(),
            ))
        }
    };
    let lane_change = ExpectedLaneChange::quintic(
        start_s,
        answer.duration_s,
        lateral("from_l", answer.from_l, 0.0)?,
        lateral("to_l", answer.to_l, scene.target_l)?,
    );
    let states = (0..n)
        .map(|i| {
            let [s, v] = scene.lane_keeping[i];
            State {
                s,
                v,
                l: lane_change.lateral(i as f64 * dt),
                phi: 0.0,
            }
        })
        .collect();
    let step = |t: f64| ((t / dt).round() as usize).min(n - 1);
    Ok(Expectation {
        decision_step: step(decision_s),
        start_step: step(start_s),
        lane_change,
        states,
        takeover: TakeoverRule {
            deviation_m,
            perceived_safety: None,
        },
        speed: SpeedRule::Constant,
        target_speed: scene.set_speed,
    })
}
