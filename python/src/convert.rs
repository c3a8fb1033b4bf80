//! Python objects to and from [`Value`], with the shapes CoppeliaSim's Python client
//! gives: a list for an array, a dict for a map, `bytes` for a buffer; one return value
//! as itself, several as a tuple, none as `None`.
//!
//! What the client's CBOR encoder accepts is accepted here too (numpy arrays and
//! scalars included), so a program's arguments mean the same in-process as remotely.

use gantry_sim_core::Value;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyByteArray, PyBytes, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

/// How deep nested lists and dicts may go: a self-referencing list would otherwise
/// recurse until the stack overflows.
const MAX_DEPTH: usize = 64;

/// Converts one argument.
///
/// # Errors
/// An object with no CoppeliaSim equivalent: `illegal argument ...`, the text the
/// remote client raises when its encoder refuses an argument.
pub fn to_value(obj: &Bound<'_, PyAny>) -> PyResult<Value> {
    to_value_at(obj, 0)
}

fn to_value_at(obj: &Bound<'_, PyAny>, depth: usize) -> PyResult<Value> {
    if depth > MAX_DEPTH {
        return Err(PyException::new_err(format!(
            "illegal argument: nested deeper than {MAX_DEPTH} levels"
        )));
    }
    if obj.is_none() {
        return Ok(Value::Nil);
    }
    // bool before int: Python's bool is an int.
    if let Ok(b) = obj.cast::<PyBool>() {
        return Ok(Value::Bool(b.is_true()));
    }
    if let Ok(i) = obj.cast::<PyInt>() {
        return i
            .extract::<i64>()
            .map(Value::Int)
            .map_err(|_| PyException::new_err("illegal argument: integer out of the 64-bit range"));
    }
    if let Ok(f) = obj.cast::<PyFloat>() {
        return Ok(Value::Float(f.value()));
    }
    if let Ok(s) = obj.cast::<PyString>() {
        return Ok(Value::Str(s.to_str()?.to_owned()));
    }
    if let Ok(b) = obj.cast::<PyBytes>() {
        return Ok(Value::Bytes(b.as_bytes().to_vec()));
    }
    if let Ok(b) = obj.cast::<PyByteArray>() {
        return Ok(Value::Bytes(b.to_vec()));
    }
    if let Ok(l) = obj.cast::<PyList>() {
        return l
            .iter()
            .map(|x| to_value_at(&x, depth + 1))
            .collect::<PyResult<_>>()
            .map(Value::Array);
    }
    if let Ok(t) = obj.cast::<PyTuple>() {
        return t
            .iter()
            .map(|x| to_value_at(&x, depth + 1))
            .collect::<PyResult<_>>()
            .map(Value::Array);
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        return d
            .iter()
            .map(|(k, v)| Ok((to_value_at(&k, depth + 1)?, to_value_at(&v, depth + 1)?)))
            .collect::<PyResult<_>>()
            .map(Value::Map);
    }
    // numpy: arrays as their nested lists (as the remote client sends them), scalars
    // by their integer or float value.
    if obj.hasattr("tolist")? {
        let list = obj.call_method0("tolist")?;
        if !list.is(obj) {
            return to_value_at(&list, depth + 1);
        }
    }
    if let Ok(i) = obj.extract::<i64>() {
        return Ok(Value::Int(i));
    }
    if let Ok(f) = obj.extract::<f64>() {
        return Ok(Value::Float(f));
    }
    let type_name = obj.get_type().name().map(|n| n.to_string()).unwrap_or_default();
    Err(PyException::new_err(format!(
        "illegal argument: cannot pass a {type_name} to the simulator (use numbers, strings, bytes, lists, tuples, dicts or None)"
    )))
}

/// Converts one value back.
pub fn to_py(py: Python<'_>, v: &Value) -> PyResult<Py<PyAny>> {
    Ok(match v {
        Value::Nil => py.None(),
        Value::Bool(b) => PyBool::new(py, *b).to_owned().into_any().unbind(),
        Value::Int(i) => i.into_pyobject(py)?.into_any().unbind(),
        Value::Float(f) => PyFloat::new(py, *f).into_any().unbind(),
        Value::Str(s) => PyString::new(py, s).into_any().unbind(),
        Value::Bytes(b) => PyBytes::new(py, b).into_any().unbind(),
        Value::Array(items) => {
            let list = PyList::empty(py);
            for x in items {
                list.append(to_py(py, x)?)?;
            }
            list.into_any().unbind()
        }
        Value::Map(pairs) => {
            let dict = PyDict::new(py);
            for (k, x) in pairs {
                // A dict key must be hashable: an array key becomes a tuple.
                let key = match k {
                    Value::Array(_) => PyTuple::new(py, to_py(py, k)?.bind(py).cast::<PyList>()?.iter())?
                        .into_any()
                        .unbind(),
                    _ => to_py(py, k)?,
                };
                dict.set_item(key, to_py(py, x)?)?;
            }
            dict.into_any().unbind()
        }
    })
}

/// The results of a call as the remote client returns them: nothing is `None`, one
/// value is itself, several are a tuple.
pub fn results(py: Python<'_>, values: &[Value]) -> PyResult<Py<PyAny>> {
    match values {
        [] => Ok(py.None()),
        [one] => to_py(py, one),
        many => {
            let items = many.iter().map(|v| to_py(py, v)).collect::<PyResult<Vec<_>>>()?;
            Ok(PyTuple::new(py, items)?.into_any().unbind())
        }
    }
}
