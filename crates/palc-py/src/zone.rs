//! The perceived safe zone from Python: `ZoneModel` (palc-zone-filter's GDA, paper
//! Eqs. 5-8) under scikit-learn's names (`fit`, `predict_proba`, `predict`,
//! `decision_function`, `classes_`), so that it reads like `LinearDiscriminantAnalysis`.
//!
//! `X` is an (n, d) array with the model's `d` features per row, `y` the labels:
//! 1 for "not taken over" (safe) and 0 for "taken over" (Eq. 2).

use numpy::{PyArray1, PyArray2};
use palc_zone_filter::{BoundsConfig, Label, Sample, StepBounds, StepScene, ZoneConfig};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde_json::Value;

use crate::arrays::{matrix, to_matrix, vector};
use crate::convert::{from_json, serialize, to_json};
use crate::errors::{self, Raise, guard};

/// The GDA model of the perceived safe zone (`palc_zone_filter::ZoneModel`).
#[pyclass(module = "palc")]
pub struct ZoneModel {
    inner: palc_zone_filter::ZoneModel,
}

impl ZoneModel {
    /// The labelled samples of `x` and `y`, their shapes checked.
    fn samples(
        &self,
        py: Python<'_>,
        x: &Bound<'_, PyAny>,
        y: &Bound<'_, PyAny>,
    ) -> PyResult<Vec<Sample>> {
        let d = self.inner.dimension();
        let (n, _, values) = matrix(py, x, "X", Some(d))?;
        let labels = vector(py, y, "y", Some(n))?;
        values
            .chunks_exact(d.max(1))
            .zip(&labels)
            .enumerate()
            .map(|(i, (row, &label))| {
                let y = if label == 1.0 {
                    Label::Safe
                } else if label == 0.0 {
                    Label::Unsafe
                } else {
                    return Err(errors::message(
                        py,
                        &Raise::field("ShapeError", format!("y[{i}]")),
                        &format!("`y[{i}]` is {label:?}, expected 0 (taken over) or 1 (safe)"),
                    ));
                };
                Ok(Sample::new(row.to_vec(), y))
            })
            .collect()
    }

    /// `p(y=1|x)` for every row of `x`.
    fn posteriors(&self, py: Python<'_>, x: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
        let (n, _, values) = matrix(py, x, "X", Some(self.inner.dimension()))?;
        let mut out = vec![0.0; n];
        self.inner
            .posteriors_safe_into(&values, &mut out)
            .map_err(|e| errors::zone(py, &e))?;
        Ok(out)
    }
}

#[pymethods]
impl ZoneModel {
    /// An empty model from the fields of ``ZoneConfig``: ``feature_set``
    /// (``"paper"``, ``"no_distance"``, ``"time_gap"``), ``discriminant``
    /// (``"linear"``, ``"quadratic"``), ``ridge``, ``quadratic_pooling``.
    #[new]
    #[pyo3(signature = (**config))]
    fn new(py: Python<'_>, config: Option<&Bound<'_, PyDict>>) -> PyResult<ZoneModel> {
        guard(py, "ZoneModel()", || {
            let value = match config {
                Some(dict) => to_json(py, dict.as_any(), "")?,
                None => Value::Object(Default::default()),
            };
            let config: ZoneConfig = from_json(py, value)?;
            let inner =
                palc_zone_filter::ZoneModel::new(config).map_err(|e| errors::zone(py, &e))?;
            Ok(ZoneModel { inner })
        })
    }

    /// Fits the model on ``X`` (n, d) and ``y`` (n,) alone, forgetting earlier
    /// samples; returns the model.
    #[pyo3(name = "fit")]
    #[allow(non_snake_case)]
    fn fit<'py>(
        slf: Bound<'py, Self>,
        X: &Bound<'py, PyAny>,
        y: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, Self>> {
        let py = slf.py();
        guard(py, "ZoneModel.fit", || {
            {
                let mut this = slf.borrow_mut();
                let samples = this.samples(py, X, y)?;
                let config = *this.inner.config();
                this.inner = palc_zone_filter::ZoneModel::fit(config, &samples)
                    .map_err(|e| errors::zone(py, &e))?;
            }
            Ok(slf.clone())
        })
    }

    /// Adds the samples ``X``, ``y`` to those seen (online; equals a batch fit on
    /// all of them); returns the model. On error the model is unchanged.
    #[allow(non_snake_case)]
    fn update<'py>(
        slf: Bound<'py, Self>,
        X: &Bound<'py, PyAny>,
        y: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, Self>> {
        let py = slf.py();
        guard(py, "ZoneModel.update", || {
            {
                let mut this = slf.borrow_mut();
                let samples = this.samples(py, X, y)?;
                this.inner
                    .update(&samples)
                    .map_err(|e| errors::zone(py, &e))?;
            }
            Ok(slf.clone())
        })
    }

    /// ``[p(y=0|x), p(y=1|x)]`` for every row of ``X``, as an (n, 2) array.
    #[allow(non_snake_case)]
    fn predict_proba<'py>(
        &self,
        py: Python<'py>,
        X: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        guard(py, "ZoneModel.predict_proba", || {
            let p = self.posteriors(py, X)?;
            let n = p.len();
            let values = p.into_iter().flat_map(|p1| [1.0 - p1, p1]).collect();
            to_matrix(py, n, 2, values)
        })
    }

    /// The class of every row of ``X``: 1 (safe) where ``p(y=1|x) > p(y=0|x)``, else 0.
    #[allow(non_snake_case)]
    fn predict<'py>(
        &self,
        py: Python<'py>,
        X: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        guard(py, "ZoneModel.predict", || {
            let (n, _, values) = matrix(py, X, "X", Some(self.inner.dimension()))?;
            let d = self.inner.dimension().max(1);
            let mut labels = Vec::with_capacity(n);
            for row in values.chunks_exact(d) {
                let label = self.inner.classify(row).map_err(|e| errors::zone(py, &e))?;
                labels.push(i64::from(label.y()));
            }
            Ok(PyArray1::from_vec(py, labels))
        })
    }

    /// The log-odds ``ln p(y=1|x) - ln p(y=0|x)`` of every row of ``X`` (positive inside
    /// the perceived safe zone).
    #[allow(non_snake_case)]
    fn decision_function<'py>(
        &self,
        py: Python<'py>,
        X: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        guard(py, "ZoneModel.decision_function", || {
            let (_, _, values) = matrix(py, X, "X", Some(self.inner.dimension()))?;
            let d = self.inner.dimension().max(1);
            let odds = values
                .chunks_exact(d)
                .map(|row| self.inner.log_odds_safe(row))
                .collect::<Result<Vec<f64>, _>>()
                .map_err(|e| errors::zone(py, &e))?;
            Ok(PyArray1::from_vec(py, odds))
        })
    }

    /// The lateral bounds of the perceived safe zone at every planning step (Eqs.
    /// 27-32), as a (K, 2) array of ``[l_min, l_max]`` (m): ``[-inf, inf]`` where the
    /// zone says nothing (the model is not informative, or all of the lateral range is
    /// safe) and ``[nan, nan]`` where no point of the range is safe.
    ///
    /// ``ego_s``, ``reference_l`` and ``ego_speed`` are (K,) arrays (the ego's
    /// position, the reference lateral position the bounds are taken around, and its
    /// speed), ``preceding`` and ``adjacent`` (K, 2) arrays of ``[s, l]``. The keyword
    /// arguments are the fields of ``BoundsConfig``: ``projection`` (``"safe_interval"``
    /// or ``"paper"``), ``lateral_range``, ``grid_step``, ``tolerance``.
    #[pyo3(signature = (ego_s, reference_l, ego_speed, preceding, adjacent, **config))]
    fn lateral_bounds<'py>(
        &self,
        py: Python<'py>,
        ego_s: &Bound<'py, PyAny>,
        reference_l: &Bound<'py, PyAny>,
        ego_speed: &Bound<'py, PyAny>,
        preceding: &Bound<'py, PyAny>,
        adjacent: &Bound<'py, PyAny>,
        config: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        guard(py, "ZoneModel.lateral_bounds", || {
            let value = match config {
                Some(dict) => to_json(py, dict.as_any(), "")?,
                None => Value::Object(Default::default()),
            };
            let config: BoundsConfig = from_json(py, value)?;
            let s = vector(py, ego_s, "ego_s", None)?;
            let k = s.len();
            let l = vector(py, reference_l, "reference_l", Some(k))?;
            let v = vector(py, ego_speed, "ego_speed", Some(k))?;
            let (kp, _, p) = matrix(py, preceding, "preceding", Some(2))?;
            let (ka, _, a) = matrix(py, adjacent, "adjacent", Some(2))?;
            for (argument, rows) in [("preceding", kp), ("adjacent", ka)] {
                if rows != k {
                    return Err(errors::message(
                        py,
                        &Raise::field("ShapeError", argument),
                        &format!(
                            "`{argument}` has {rows} rows, expected {k} (one per entry of `ego_s`)"
                        ),
                    ));
                }
            }
            let scenes: Vec<StepScene> = (0..k)
                .map(|i| StepScene {
                    ego_s: s[i],
                    reference_l: l[i],
                    ego_speed: v[i],
                    preceding: [p[2 * i], p[2 * i + 1]],
                    adjacent: [a[2 * i], a[2 * i + 1]],
                })
                .collect();
            let bounds = palc_zone_filter::lateral_bounds(&self.inner, &scenes, &config)
                .map_err(|e| errors::zone(py, &e))?;
            let values = bounds
                .iter()
                .flat_map(|b| match *b {
                    StepBounds::Bounded { min, max } => [min, max],
                    StepBounds::Unconstrained => [f64::NEG_INFINITY, f64::INFINITY],
                    _ => [f64::NAN, f64::NAN],
                })
                .collect();
            to_matrix(py, k, 2, values)
        })
    }

    /// The classes, in the order of ``predict_proba``'s columns: ``[0, 1]``.
    #[getter]
    fn classes_<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        PyArray1::from_vec(py, vec![0, 1])
    }

    /// The number of features per row of ``X``.
    #[getter]
    fn n_features_in_(&self) -> usize {
        self.inner.dimension()
    }

    /// Whether both classes have samples, so that the model has a boundary.
    #[getter]
    fn is_informative(&self) -> bool {
        self.inner.is_informative()
    }

    /// The model's config as a dict.
    #[getter]
    fn config<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        serialize(py, self.inner.config())
    }

    /// The model as JSON (format version, config and per-class statistics), as
    /// ``palc zone fit`` writes it.
    fn to_json(&self, py: Python<'_>) -> PyResult<String> {
        guard(py, "ZoneModel.to_json", || {
            serde_json::to_string(&self.inner)
                .map_err(|e| errors::message(py, &Raise::class("PalcError"), &e.to_string()))
        })
    }

    /// A model read from its JSON; an error names the field.
    #[staticmethod]
    fn from_json(py: Python<'_>, text: &str) -> PyResult<ZoneModel> {
        guard(py, "ZoneModel.from_json", || {
            let value: Value = serde_json::from_str(text).map_err(|e| {
                errors::message(
                    py,
                    &Raise::class("ConfigError"),
                    &format!("the zone model is not valid JSON: {e}"),
                )
            })?;
            Ok(ZoneModel {
                inner: from_json(py, value)?,
            })
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "ZoneModel(n_features_in_={}, informative={})",
            self.inner.dimension(),
            self.inner.is_informative()
        )
    }
}
