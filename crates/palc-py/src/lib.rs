//! palc from Python: the native module `palc._palc` of the `palc` package.
//!
//! A thin layer over the library crates, built by maturin into one abi3 wheel for
//! CPython >= 3.9 (`pip install .` at the repository root):
//!
//! - `planner.rs`: `Problem` (the JSON of `palc plan`), `Planner(**config)` with
//!   `plan` and `replan`, and `Plan`, whose states, controls and features are
//!   NumPy arrays;
//! - `zone.rs`: `ZoneModel`, the zone filter's GDA under scikit-learn's names;
//! - `learn.rs`: `LearnConfig`, `Experience`, `learn`, `LearningLoop` and
//!   `LearnResult`, the lesson-learning loop with a built-in simulated user or a
//!   driver written in Python (`user.rs`), in palc's own traffic or in a simulator
//!   driven from Python (`world.rs`);
//! - `evaluate.rs`: `evaluate`, an evaluation config run as `palc eval` runs it;
//! - `errors.rs`: every Rust error as a `palc.PalcError` subclass with its field,
//!   value, bound and cause chain, and the guard that turns a panic into one;
//! - `arrays.rs` and `convert.rs`: arrays and plain data in and out.
//!
//! The Python package (`python/palc/`) re-exports this module and defines the
//! exception classes; `python/palc/_palc.pyi` types it. Long runs release the GIL.
//!
//! ```python
//! import palc
//! problem = palc.Problem.from_json(open("configs/examples/plan-problem.json").read())
//! plan = palc.Planner(**problem.config).plan(problem)
//! print(plan.states[-1], plan.objective)
//! ```
#![deny(missing_docs)]
#![forbid(unsafe_code)]
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

use pyo3::prelude::*;
use pyo3::types::PyTuple;

mod arrays;
mod convert;
mod errors;
mod evaluate;
mod learn;
mod planner;
mod user;
mod world;
mod zone;

/// The native part of the `palc` package; import `palc` instead.
#[pymodule]
fn _palc(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<planner::Problem>()?;
    m.add_class::<planner::Planner>()?;
    m.add_class::<planner::Plan>()?;
    m.add_class::<zone::ZoneModel>()?;
    m.add_class::<learn::LearnConfig>()?;
    m.add_class::<learn::Experience>()?;
    m.add_class::<learn::LearnResult>()?;
    m.add_class::<learn::LearningLoop>()?;
    m.add_function(wrap_pyfunction!(learn::learn, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate::evaluate, m)?)?;
    m.add(
        "STAGE_WEIGHT_NAMES",
        PyTuple::new(m.py(), planner::STAGE_WEIGHT_NAMES)?,
    )?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
