//! The lane-change planner from Python: `Problem`, `Planner` and `Plan`
//! (palc-planner, paper Eqs. 9-23).
//!
//! A `Problem` is read from the JSON of `palc plan` (the whole input, whose
//! `config` it keeps, or the `problem` object alone); a `Planner` is built from the
//! fields of `PlannerConfig` as keyword arguments; a `Plan` hands its trajectory,
//! controls and features out as NumPy arrays. Plans run with the GIL released.

use numpy::{PyArray1, PyArray2};
use palc_planner::{
    FEATURE_COUNT, LateralBound, PlanError, PlannerConfig, Position, SolveStatus, StageWeights,
    State, Terminal, Weights,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde::Deserialize;
use serde_json::Value;

use crate::arrays::{matrix, to_matrix, to_vector, vector};
use crate::convert::{from_json, serialize, to_json, to_python};
use crate::errors::{self, guard};

/// The names of the ten stage weights `w1..w10` (Eq. 15), in the order of the rows of
/// `Plan.features` and of a (10, K) weight array.
pub(crate) const STAGE_WEIGHT_NAMES: [&str; FEATURE_COUNT] = [
    "l_squared",
    "l",
    "phi_squared",
    "phi",
    "l_delta",
    "phi_delta",
    "s_delta",
    "delta_squared",
    "dist_preceding",
    "dist_adjacent",
];

/// The UTF-8 byte-order mark some editors write at the start of a file; skipped, as
/// `palc plan` does.
const BYTE_ORDER_MARK: char = '\u{feff}';

/// The weights of a (10, K) array, or of a dict of stage weights by name (the same at
/// every stage).
fn weights(py: Python<'_>, obj: &Bound<'_, PyAny>, horizon: usize) -> PyResult<Weights> {
    if let Ok(dict) = obj.cast::<PyDict>() {
        let value = to_json(py, dict.as_any(), "weights")?;
        let stage: StageWeights = from_json(py, value).map_err(|e| {
            // The path inside the dict is relative to `weights`.
            prefix_field(py, e, "weights")
        })?;
        return Ok(Weights::uniform(horizon, stage));
    }
    let (rows, k, values) = matrix(py, obj, "weights", None)?;
    if rows != FEATURE_COUNT || k != horizon {
        return Err(errors::message(
            py,
            &errors::Raise::field("ShapeError", "weights"),
            &format!(
                "`weights` has shape [{rows}, {k}], expected ({FEATURE_COUNT}, {horizon}): one column per step"
            ),
        ));
    }
    let columns = (0..k)
        .map(|c| std::array::from_fn(|r| values[r * k + c]))
        .collect();
    Ok(Weights::from_columns(columns))
}

/// `error` with its `field` prefixed by `prefix` (a dict read inside an argument).
fn prefix_field(py: Python<'_>, error: PyErr, prefix: &str) -> PyErr {
    let value = error.value(py);
    let field = value
        .getattr("field")
        .ok()
        .and_then(|f| f.extract::<Option<String>>().ok())
        .flatten();
    let full = match field {
        Some(f) if !f.is_empty() => format!("{prefix}.{f}"),
        _ => prefix.to_owned(),
    };
    // Setting an attribute of a fresh exception cannot fail in practice; if it does,
    // the error keeps its own field.
    let _ = value.setattr("field", full);
    error
}

/// The positions of a (K, 2) array of `[s, l]`.
fn positions(py: Python<'_>, obj: &Bound<'_, PyAny>, argument: &str) -> PyResult<Vec<Position>> {
    let (_, _, values) = matrix(py, obj, argument, Some(2))?;
    Ok(values
        .chunks_exact(2)
        .map(|p| Position { s: p[0], l: p[1] })
        .collect())
}

/// The lateral bounds of a (K+1, 2) array of `[min, max]`; an infinite side is no bound.
fn lateral_bounds(py: Python<'_>, obj: &Bound<'_, PyAny>) -> PyResult<Vec<Option<LateralBound>>> {
    let (_, _, values) = matrix(py, obj, "lateral_bounds", Some(2))?;
    let side = |x: f64| (!x.is_infinite()).then_some(x);
    Ok(values
        .chunks_exact(2)
        .map(|b| match (side(b[0]), side(b[1])) {
            (None, None) => None,
            (min, max) => Some(LateralBound { min, max }),
        })
        .collect())
}

/// The input of `palc plan`: a planner config and a problem.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PlanInput {
    #[serde(default)]
    config: Option<Value>,
    problem: palc_planner::Problem,
}

/// One lane change to plan (`palc_planner::Problem`).
#[pyclass(module = "palc", frozen)]
pub struct Problem {
    pub(crate) inner: palc_planner::Problem,
    /// The planner config of a whole `palc plan` input, if it had one.
    config: Option<Value>,
}

#[pymethods]
impl Problem {
    /// A problem from arrays, each checked as ``palc plan`` checks its input (an error
    /// names the argument and, for a number, its index):
    ///
    /// - ``initial``: ``[s, v, l, phi]``, the state ``X_0`` (s relative to the ego's
    ///   start is recommended);
    /// - ``reference_speed``: (K,) speeds (m/s), which set the horizon K;
    /// - ``weights``: (10, K) weights ``w1..w10`` per step (Eq. 15; the rows named in
    ///   ``STAGE_WEIGHT_NAMES``), or a dict of stage weights by name, the same at every step;
    /// - ``preceding``, ``adjacent``: (K, 2) predicted ``[s, l]`` of the preceding
    ///   vehicle and of the adjacent one on the target lane;
    /// - ``terminal_v``, ``terminal_l``: the target speed and lateral position;
    ///   ``terminal_s`` fixes ``s_K`` (free if ``None``);
    /// - ``lateral_bounds``: (K+1, 2) ``[min, max]`` per step, an infinite side
    ///   unbounded (no bound at all if ``None``); ``curvature`` of the road (1/m).
    #[new]
    #[pyo3(signature = (initial, reference_speed, weights, preceding, adjacent, terminal_v, terminal_l, *, terminal_s = None, lateral_bounds = None, curvature = 0.0))]
    fn new(
        py: Python<'_>,
        initial: &Bound<'_, PyAny>,
        reference_speed: &Bound<'_, PyAny>,
        weights: &Bound<'_, PyAny>,
        preceding: &Bound<'_, PyAny>,
        adjacent: &Bound<'_, PyAny>,
        terminal_v: f64,
        terminal_l: f64,
        terminal_s: Option<f64>,
        lateral_bounds: Option<&Bound<'_, PyAny>>,
        curvature: f64,
    ) -> PyResult<Problem> {
        guard(py, "Problem()", || {
            let x = vector(py, initial, "initial", Some(4))?;
            let speeds = vector(py, reference_speed, "reference_speed", None)?;
            let k = speeds.len();
            let plan = |e: PlanError| errors::plan(py, &e);
            let mut builder = palc_planner::Problem::builder(k)
                .initial(State {
                    s: x[0],
                    v: x[1],
                    l: x[2],
                    phi: x[3],
                })
                .map_err(plan)?
                .reference_speed(speeds)
                .map_err(plan)?
                .curvature(curvature)
                .map_err(plan)?
                .weights(self::weights(py, weights, k)?)
                .map_err(plan)?
                .preceding(positions(py, preceding, "preceding")?)
                .map_err(plan)?
                .adjacent(positions(py, adjacent, "adjacent")?)
                .map_err(plan)?
                .terminal(Terminal {
                    s: terminal_s,
                    v: terminal_v,
                    l: terminal_l,
                })
                .map_err(plan)?;
            if let Some(bounds) = lateral_bounds {
                builder = builder
                    .lateral_bounds(self::lateral_bounds(py, bounds)?)
                    .map_err(plan)?;
            }
            Ok(Problem {
                inner: builder.build().map_err(plan)?,
                config: None,
            })
        })
    }

    /// Reads a problem from JSON: the whole input of ``palc plan`` (an object with
    /// ``config`` and ``problem``; the config is kept as ``Problem.config``) or the
    /// ``problem`` object alone. An error is a ``ConfigError`` naming the field.
    #[staticmethod]
    fn from_json(py: Python<'_>, text: &str) -> PyResult<Problem> {
        guard(py, "Problem.from_json", || {
            let text = text.strip_prefix(BYTE_ORDER_MARK).unwrap_or(text);
            let value: Value = serde_json::from_str(text).map_err(|e| {
                errors::message(
                    py,
                    &errors::Raise::class("ConfigError"),
                    &format!("the problem is not valid JSON: {e}"),
                )
            })?;
            let whole = value.as_object().is_some_and(|o| o.contains_key("problem"));
            if whole {
                let input: PlanInput = from_json(py, value)?;
                Ok(Problem {
                    inner: input.problem,
                    config: Some(
                        input
                            .config
                            .unwrap_or_else(|| Value::Object(Default::default())),
                    ),
                })
            } else {
                Ok(Problem {
                    inner: from_json(py, value)?,
                    config: None,
                })
            }
        })
    }

    /// The problem as JSON (the ``problem`` object of ``palc plan``'s input).
    fn to_json(&self, py: Python<'_>) -> PyResult<String> {
        guard(py, "Problem.to_json", || {
            serde_json::to_string(&self.inner).map_err(|e| {
                errors::message(py, &errors::Raise::class("PalcError"), &e.to_string())
            })
        })
    }

    /// The planner config that came with the problem (a dict for ``Planner(**config)``),
    /// or ``None`` when the JSON held the problem alone.
    #[getter]
    fn config<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.config.as_ref().map(|c| to_python(py, c)).transpose()
    }

    /// Reads a problem from a JSON file, as ``Problem.from_json`` reads its text.
    #[staticmethod]
    fn load(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Problem> {
        let text = std::fs::read_to_string(&path).map_err(|e| {
            errors::message(
                py,
                &errors::Raise::class("PalcError"),
                &format!("cannot read {}: {e}", path.display()),
            )
        })?;
        Problem::from_json(py, &text).inspect_err(|e| {
            let value = e.value(py);
            let message = format!("{}: {value}", path.display());
            // The message names the file; the class and attributes stay.
            let _ = value.setattr("args", (message,));
        })
    }

    /// The weights ``w1..w10`` per step as a (10, K) array (rows as ``STAGE_WEIGHT_NAMES``).
    #[getter]
    fn weights<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let columns = self.inner.weights.columns();
        let k = columns.len();
        let mut values = vec![0.0; FEATURE_COUNT * k];
        for (c, column) in columns.iter().enumerate() {
            for (r, x) in column.iter().enumerate() {
                values[r * k + c] = *x;
            }
        }
        to_matrix(py, FEATURE_COUNT, k, values)
    }

    /// The number of steps K: the length of ``reference_speed``.
    #[getter]
    fn horizon(&self) -> usize {
        self.inner.reference_speed.len()
    }

    fn __repr__(&self) -> String {
        format!("Problem(horizon={})", self.inner.reference_speed.len())
    }
}

/// The lane-change MPC (`palc_planner::Planner`); it reuses its QP structure between
/// plans of the same shape.
#[pyclass(module = "palc")]
pub struct Planner {
    inner: palc_planner::Planner,
}

#[pymethods]
impl Planner {
    /// A planner from the fields of ``PlannerConfig`` (``horizon``, ``dt``,
    /// ``wheelbase``, ``acceleration_penalty``, ``steering_min``, ``steering_max``,
    /// ``lateral_bounds_mode``, ``backend``, ``solver``), each optional, as in the
    /// ``config`` object of ``palc plan``'s input.
    #[new]
    #[pyo3(signature = (**config))]
    fn new(py: Python<'_>, config: Option<&Bound<'_, PyDict>>) -> PyResult<Planner> {
        guard(py, "Planner()", || {
            let value = match config {
                Some(dict) => to_json(py, dict.as_any(), "")?,
                None => Value::Object(Default::default()),
            };
            let config: PlannerConfig = from_json(py, value)?;
            let inner = palc_planner::Planner::new(config).map_err(|e| errors::plan(py, &e))?;
            Ok(Planner { inner })
        })
    }

    /// Plans one lane change; the GIL is released while it solves.
    fn plan(&mut self, py: Python<'_>, problem: &Problem) -> PyResult<Plan> {
        guard(py, "Planner.plan", || {
            let planner = &mut self.inner;
            let problem = &problem.inner;
            match py.detach(|| planner.plan(problem)) {
                Ok(inner) => Ok(Plan { inner }),
                Err(e) => Err(errors::plan(py, &e)),
            }
        })
    }

    /// Re-plans from ``previous``, warm-started when it is this planner's last plan.
    fn replan(&mut self, py: Python<'_>, problem: &Problem, previous: &Plan) -> PyResult<Plan> {
        guard(py, "Planner.replan", || {
            let planner = &mut self.inner;
            let (problem, previous) = (&problem.inner, &previous.inner);
            match py.detach(|| planner.replan(problem, previous)) {
                Ok(inner) => Ok(Plan { inner }),
                Err(e) => Err(errors::plan(py, &e)),
            }
        })
    }

    /// The planner's config, every field filled in.
    #[getter]
    fn config<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        serialize(py, self.inner.config())
    }

    fn __repr__(&self) -> String {
        format!("Planner(horizon={})", self.inner.config().horizon)
    }
}

/// An optimal lane change (`palc_planner::Plan`).
#[pyclass(module = "palc", frozen)]
pub struct Plan {
    pub(crate) inner: palc_planner::Plan,
}

#[pymethods]
impl Plan {
    /// ``X_0..X_K`` as a (K+1, 4) array of ``[s, v, l, phi]`` (m, m/s, m, rad).
    #[getter]
    fn states<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let states = &self.inner.states;
        let values = states.iter().flat_map(|x| [x.s, x.v, x.l, x.phi]).collect();
        to_matrix(py, states.len(), 4, values)
    }

    /// ``U_0..U_{K-1}`` as a (K, 2) array of ``[a, delta]`` (m/s², rad).
    #[getter]
    fn controls<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let controls = &self.inner.controls;
        let values = controls.iter().flat_map(|u| [u.a, u.delta]).collect();
        to_matrix(py, controls.len(), 2, values)
    }

    /// ``Φ(ψ)`` of Eq. (34) as a (10, K) array: column ``i - 1`` is stage ``i``.
    #[getter]
    fn features<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let columns = self.inner.features.columns();
        let k = columns.len();
        let mut values = vec![0.0; 10 * k];
        for (c, column) in columns.iter().enumerate() {
            for (r, x) in column.iter().enumerate() {
                values[r * k + c] = *x;
            }
        }
        to_matrix(py, 10, k, values)
    }

    /// The soft lateral bounds' violation per step ``0..=K`` (m).
    #[getter]
    fn lateral_violation<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        to_vector(py, self.inner.lateral_violation.clone())
    }

    /// The whole objective: ``learned_cost`` plus the extra terms.
    #[getter]
    fn objective(&self) -> f64 {
        self.inner.objective
    }

    /// The learned part ``w · Φ(ψ)`` (Eq. 15).
    #[getter]
    fn learned_cost(&self) -> f64 {
        self.inner.learned_cost
    }

    /// The extra terms: ``acceleration``, ``tracking``, ``lateral_slack``.
    #[getter]
    fn extras<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        serialize(py, &self.inner.extras)
    }

    /// Solver statistics: ``status``, ``iterations``, ``build_seconds``,
    /// ``solve_seconds``, ``structure_reused``.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        serialize(py, &self.inner.stats)
    }

    /// The plan as JSON, as ``palc plan`` writes it (without ``status``).
    fn to_json(&self, py: Python<'_>) -> PyResult<String> {
        guard(py, "Plan.to_json", || {
            serde_json::to_string(&self.inner).map_err(|e| {
                errors::message(py, &errors::Raise::class("PalcError"), &e.to_string())
            })
        })
    }

    fn __repr__(&self) -> String {
        let status = match self.inner.stats.status {
            SolveStatus::Solved => "solved",
            _ => "almost_solved",
        };
        format!(
            "Plan(horizon={}, objective={:?}, status={status:?})",
            self.inner.controls.len(),
            self.inner.objective
        )
    }
}
