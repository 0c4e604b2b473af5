//! Python values to scene TOML and mote's errors to Python exceptions.

use pyo3::exceptions::{PyOSError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

use crate::{MoteError, UnstableError};

/// A Python value as TOML: bool, int, float, str, list/tuple, dict (keys
/// are strings); `at` names the key for messages.
pub fn to_toml(value: &Bound<'_, PyAny>, at: &str) -> PyResult<toml::Value> {
    if value.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(value.extract()?));
    }
    if value.is_instance_of::<PyInt>() {
        return Ok(toml::Value::Integer(value.extract()?));
    }
    if value.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(value.extract()?));
    }
    if value.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(value.extract()?));
    }
    if let Ok(d) = value.cast::<PyDict>() {
        let mut table = toml::Table::new();
        for (k, v) in d.iter() {
            let key: String = k
                .extract()
                .map_err(|_| PyTypeError::new_err(format!("{at}: keys must be strings")))?;
            let here = if at.is_empty() {
                key.clone()
            } else {
                format!("{at}.{key}")
            };
            table.insert(key, to_toml(&v, &here)?);
        }
        return Ok(toml::Value::Table(table));
    }
    if value.is_instance_of::<PyList>() || value.is_instance_of::<PyTuple>() {
        let items: Vec<Bound<'_, PyAny>> = value.try_iter()?.collect::<PyResult<_>>()?;
        return Ok(toml::Value::Array(
            items
                .iter()
                .enumerate()
                .map(|(k, v)| to_toml(v, &format!("{at}[{k}]")))
                .collect::<PyResult<_>>()?,
        ));
    }
    // numpy scalars and arrays: as floats or lists of them.
    if let Ok(x) = value.extract::<f64>() {
        return Ok(toml::Value::Float(x));
    }
    if let Ok(list) = value.call_method0("tolist") {
        return to_toml(&list, at);
    }
    Err(PyTypeError::new_err(format!(
        "{at}: {} is not a scene value (bool, int, float, str, list, dict)",
        value.get_type().name()?
    )))
}

/// A scene as a dict, written as TOML text (then parsed by the one parser).
pub fn dict_to_toml(d: &Bound<'_, PyDict>) -> PyResult<String> {
    match to_toml(d.as_any(), "")? {
        toml::Value::Table(t) => toml::to_string(&t)
            .map_err(|e| PyValueError::new_err(format!("the scene dict as TOML: {e}"))),
        _ => unreachable!("a dict is a table"),
    }
}

/// Bad input (a scene's `file:line: message`) is a ValueError; what went
/// wrong while running is a MoteError.
pub fn front_error(e: mote_front::FrontError) -> PyErr {
    use mote_front::FrontError as F;
    match e {
        e if e.is_bad_input() => PyValueError::new_err(e.to_string()),
        e if e.is_unstable() => UnstableError::new_err(e.to_string()),
        F::Io(e) => PyOSError::new_err(e.to_string()),
        other => MoteError::new_err(other.to_string()),
    }
}
