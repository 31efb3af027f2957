//! Plain Python data (dicts, lists, numbers, strings) to and from the JSON and TOML
//! values that the Rust crates read through serde.
//!
//! Python values are read into a `serde_json::Value` first, with the dotted path of
//! every value kept for errors (`planning.standard_alc`, `weights[3]`); a config
//! given as a dict is then written as TOML and read by the same parser as a file.

use numpy::PyUntypedArray;
use pyo3::IntoPyObjectExt;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use serde::de::DeserializeOwned;
use serde_json::{Map, Number, Value};

use crate::errors::{Raise, message};

/// A `ConfigError` at `path` with `text`.
fn config_error(py: Python<'_>, path: &str, text: String) -> PyErr {
    message(py, &Raise::field("ConfigError", path), &text)
}

/// `path.key`, or `key` at the top.
fn child(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_owned()
    } else {
        format!("{path}.{key}")
    }
}

/// `obj` as a JSON value; `path` names it in errors.
pub(crate) fn to_json(py: Python<'_>, obj: &Bound<'_, PyAny>, path: &str) -> PyResult<Value> {
    if obj.is_none() {
        return Ok(Value::Null);
    }
    if let Ok(b) = obj.cast::<PyBool>() {
        return Ok(Value::Bool(b.is_true()));
    }
    if obj.is_instance_of::<PyInt>() {
        if let Ok(i) = obj.extract::<i64>() {
            return Ok(Value::from(i));
        }
        if let Ok(u) = obj.extract::<u64>() {
            return Ok(Value::from(u));
        }
        return Err(config_error(
            py,
            path,
            format!("`{path}` is an integer too large for 64 bits"),
        ));
    }
    if obj.is_instance_of::<PyFloat>() {
        let x: f64 = obj.extract()?;
        return Number::from_f64(x).map(Value::Number).ok_or_else(|| {
            config_error(
                py,
                path,
                format!("`{path}` is {x}, expected a finite number"),
            )
        });
    }
    if let Ok(s) = obj.cast::<PyString>() {
        return Ok(Value::String(s.to_cow()?.into_owned()));
    }
    if let Ok(dict) = obj.cast::<PyDict>() {
        let mut map = Map::new();
        for (key, value) in dict.iter() {
            let key: String = key.extract().map_err(|_| {
                config_error(py, path, format!("`{path}` has a key that is not a string"))
            })?;
            let value = to_json(py, &value, &child(path, &key))?;
            map.insert(key, value);
        }
        return Ok(Value::Object(map));
    }
    if obj.is_instance_of::<PyList>()
        || obj.is_instance_of::<PyTuple>()
        || obj.is_instance_of::<PyUntypedArray>()
    {
        let mut items = Vec::new();
        for (i, item) in obj.try_iter()?.enumerate() {
            items.push(to_json(py, &item?, &format!("{path}[{i}]"))?);
        }
        return Ok(Value::Array(items));
    }
    // NumPy scalars (np.float64 is a float, the others are not) and the like.
    if obj.hasattr("item")? {
        let item = obj.call_method0("item")?;
        if !item.is(obj) {
            return to_json(py, &item, path);
        }
    }
    Err(config_error(
        py,
        path,
        format!(
            "`{path}` is a {}, expected a number, a string, a bool, a list or a dict",
            obj.get_type().name()?
        ),
    ))
}

/// Deserializes `value` into `T`; an error is a `ConfigError` naming the field's path.
pub(crate) fn from_json<T: DeserializeOwned>(py: Python<'_>, value: Value) -> PyResult<T> {
    serde_path_to_error::deserialize(value).map_err(|e| {
        let path = e.path().to_string();
        let path = if path == "." { String::new() } else { path };
        let text = if path.is_empty() {
            e.inner().to_string()
        } else {
            format!("`{path}`: {}", e.inner())
        };
        config_error(py, &path, text)
    })
}

/// `value` as a TOML value; `null` has no TOML form and is an error at its path.
pub(crate) fn to_toml(py: Python<'_>, value: &Value, path: &str) -> PyResult<toml::Value> {
    Ok(match value {
        Value::Null => {
            return Err(config_error(
                py,
                path,
                format!("`{path}` is None, which a TOML config cannot hold; leave the key out"),
            ));
        }
        Value::Bool(b) => toml::Value::Boolean(*b),
        Value::Number(n) => match (n.as_i64(), n.as_f64()) {
            (Some(i), _) => toml::Value::Integer(i),
            (None, Some(x)) if !n.is_u64() => toml::Value::Float(x),
            _ => {
                return Err(config_error(
                    py,
                    path,
                    format!("`{path}` = {n} does not fit a TOML integer"),
                ));
            }
        },
        Value::String(s) => toml::Value::String(s.clone()),
        Value::Array(items) => toml::Value::Array(
            items
                .iter()
                .enumerate()
                .map(|(i, item)| to_toml(py, item, &format!("{path}[{i}]")))
                .collect::<PyResult<_>>()?,
        ),
        Value::Object(map) => {
            let mut table = toml::Table::new();
            for (key, item) in map {
                table.insert(key.clone(), to_toml(py, item, &child(path, key))?);
            }
            toml::Value::Table(table)
        }
    })
}

/// `value` as plain Python data.
pub(crate) fn to_python<'py>(py: Python<'py>, value: &Value) -> PyResult<Bound<'py, PyAny>> {
    match value {
        Value::Null => Ok(py.None().into_bound(py)),
        Value::Bool(b) => b.into_bound_py_any(py),
        Value::Number(n) => match (n.as_i64(), n.as_u64(), n.as_f64()) {
            (Some(i), _, _) => i.into_bound_py_any(py),
            (None, Some(u), _) => u.into_bound_py_any(py),
            (_, _, Some(x)) => x.into_bound_py_any(py),
            _ => Ok(py.None().into_bound(py)),
        },
        Value::String(s) => s.into_bound_py_any(py),
        Value::Array(items) => {
            let list = PyList::empty(py);
            for item in items {
                list.append(to_python(py, item)?)?;
            }
            Ok(list.into_any())
        }
        Value::Object(map) => {
            let dict = PyDict::new(py);
            for (key, item) in map {
                dict.set_item(key, to_python(py, item)?)?;
            }
            Ok(dict.into_any())
        }
    }
}

/// Any serializable value as plain Python data.
pub(crate) fn serialize<'py, T: serde::Serialize>(
    py: Python<'py>,
    value: &T,
) -> PyResult<Bound<'py, PyAny>> {
    let value = serde_json::to_value(value).map_err(|e| {
        message(
            py,
            &Raise::class("PalcError"),
            &format!("cannot convert a result to Python: {e}"),
        )
    })?;
    to_python(py, &value)
}
