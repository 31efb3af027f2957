//! A simulator driven from Python, as a `palc_harness::World` of the learning loop.
//!
//! A Python object with `place(scene)` and `step(ego)` (a subclass of `palc.World`)
//! is called with the GIL held. `place` receives the scene at the trigger as a dict:
//! `dt`, `lanes`, `lane_width` and `vehicles`,
//! a list of dicts (`id`, `role` = `ego`, `preceding`, `adjacent` or `other`, `lane`,
//! `s` the front bumper, `l`, `v`, `length`, `width`, and `idm`: the IDM parameters
//! `v0`, `t`, `s0`, `a`, `b`, `delta` the vehicle follows in palc's own traffic; a
//! platoon leader at scripted speeds has `v0` its current speed). `step` receives the
//! ego's state at the end of the step (`s`, `l`, `v`, `heading`) and returns every
//! other vehicle's state as a list of dicts (`id`, `s`, `l`, `v`).
//!
//! A Python exception inside the world stops the run; the exception itself is kept
//! and raised again to the caller with its own traceback.

use palc_harness::{World, WorldError};
use palc_traffic::{Driver, EgoState, IdmParams, Observed, Scene, VehicleId};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use serde::Deserialize;

use crate::user::Raised;

/// One vehicle's report after a step.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Report {
    id: u32,
    s: f64,
    l: f64,
    v: f64,
}

/// A simulator written in Python.
#[derive(Debug)]
pub(crate) struct PythonWorld {
    object: Py<PyAny>,
    name: String,
    raised: Raised,
}

impl PythonWorld {
    /// The world `object`; its first exception goes to `raised`.
    pub(crate) fn new(py: Python<'_>, object: Py<PyAny>, raised: Raised) -> Self {
        let name = object
            .bind(py)
            .getattr("name")
            .and_then(|n| n.extract::<String>())
            .or_else(|_| object.bind(py).get_type().name().map(|n| n.to_string()))
            .unwrap_or_else(|_| "python".to_owned());
        PythonWorld {
            object,
            name,
            raised,
        }
    }

    /// `f` with the GIL held; a Python exception is kept and becomes a [`WorldError`].
    fn call<T>(
        &self,
        method: &str,
        f: impl FnOnce(Python<'_>, &Bound<'_, PyAny>) -> PyResult<T>,
    ) -> Result<T, WorldError> {
        Python::attach(|py| {
            f(py, self.object.bind(py)).map_err(|error| {
                let message = format!("`{method}` raised {error}");
                if let Ok(mut slot) = self.raised.lock() {
                    slot.get_or_insert(error);
                }
                WorldError::new(message)
            })
        })
    }
}

impl World for PythonWorld {
    fn name(&self) -> &str {
        &self.name
    }

    fn place(&mut self, scene: &Scene, dt: f64) -> Result<(), WorldError> {
        self.call("place", |py, object| {
            object.call_method1("place", (scene_dict(py, scene, dt)?,))?;
            Ok(())
        })
    }

    fn step(&mut self, ego: &EgoState) -> Result<Vec<Observed>, WorldError> {
        self.call("step", |py, object| {
            let state = PyDict::new(py);
            for (key, value) in [
                ("s", ego.s),
                ("l", ego.l),
                ("v", ego.v),
                ("heading", ego.heading),
            ] {
                state.set_item(key, value)?;
            }
            let answer = object.call_method1("step", (state,))?;
            let value = crate::convert::to_json(py, &answer, "step")?;
            let reports: Vec<Report> = crate::convert::from_json(py, value)?;
            Ok(reports
                .into_iter()
                .map(|r| Observed {
                    id: VehicleId(r.id),
                    s: r.s,
                    l: r.l,
                    v: r.v,
                })
                .collect())
        })
    }
}

/// The scene at the trigger as the dict `place` receives.
fn scene_dict<'py>(py: Python<'py>, scene: &Scene, dt: f64) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    let road = scene.road();
    dict.set_item("dt", dt)?;
    dict.set_item("lanes", road.lanes)?;
    dict.set_item("lane_width", road.lane_width)?;
    let vehicles = PyList::empty(py);
    let preceding = scene.preceding().map(|v| v.id);
    let adjacent = scene.adjacent().map(|v| v.id);
    for vehicle in scene.vehicles() {
        let entry = PyDict::new(py);
        let role = match &vehicle.driver {
            Driver::External { .. } => "ego",
            _ if Some(vehicle.id) == preceding => "preceding",
            _ if Some(vehicle.id) == adjacent => "adjacent",
            _ => "other",
        };
        let state = vehicle.state;
        entry.set_item("id", vehicle.id.0)?;
        entry.set_item("role", role)?;
        entry.set_item("lane", vehicle.lane.0)?;
        for (key, value) in [
            ("s", state.s),
            ("l", state.l),
            ("v", state.v),
            ("length", vehicle.length),
            ("width", vehicle.width),
        ] {
            entry.set_item(key, value)?;
        }
        let idm = match &vehicle.driver {
            Driver::Idm(params) | Driver::External { stand_in: params } => *params,
            Driver::Scripted(_) => IdmParams::treiber_2000(state.v),
        };
        let params = PyDict::new(py);
        for (key, value) in [
            ("v0", idm.v0),
            ("t", idm.t),
            ("s0", idm.s0),
            ("a", idm.a),
            ("b", idm.b),
            ("delta", idm.delta),
        ] {
            params.set_item(key, value)?;
        }
        entry.set_item("idm", params)?;
        vehicles.append(entry)?;
    }
    dict.set_item("vehicles", vehicles)?;
    Ok(dict)
}
