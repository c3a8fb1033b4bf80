//! A step plan: one action of a Gymnasium environment (set targets from the action,
//! step, read the observation) as a list of registry calls that an in-process client
//! carries out in one Python call, with the GIL released throughout.
//!
//! Why: a vector environment steps many simulations on several threads, and only what
//! runs without the GIL overlaps. For a cheap physics step (a kinematic arm: a few
//! microseconds) the task's Python around it (a dozen `sim.*` calls, each converted
//! under the GIL) costs more than the step, and caps what threads can give. A plan
//! names the same registry functions the task's Python would call (this is a converter,
//! not a second implementation of them), so a plan's run and the Python it replaces give
//! the same numbers, bit for bit.

use gantry_sim_core::Value;
use gantry_sim_core::api::Target;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::convert::to_value;

/// Sets `set(handle, value)` where `value` is `action[index] * scale`, multiplied in
/// single precision (as numpy multiplies a `float32` action by a Python float), plus,
/// when `read` is given, `read(handle)` (the current value, for increments).
pub(crate) struct ActOp {
    pub set: Target,
    pub handle: Value,
    pub read: Option<Target>,
    pub index: usize,
    pub scale: f32,
}

/// Calls `get(args...)`; its numbers (one, or an array of them) extend the observation.
pub(crate) struct ObserveOp {
    pub get: Target,
    pub args: Vec<Value>,
}

/// What one action does, for `Engine.run_plan`: the act calls in order, `steps`
/// simulation steps, then the observe calls, whose numbers make the returned `float64`
/// array.
#[pyclass(frozen, module = "gantry._gantry")]
pub struct StepPlan {
    pub(crate) act: Vec<ActOp>,
    pub(crate) steps: u64,
    pub(crate) observe: Vec<ObserveOp>,
    /// The action's length the act calls read: one more than their largest index.
    pub(crate) action_size: usize,
}

/// A registry function by name; host functions (`sim.step`, simulation control) and
/// script code are refused: the plan's own steps are the only stepping.
fn core_function(name: &str) -> PyResult<Target> {
    match Target::resolve(name) {
        Some(target @ Target::Core { .. }) => Ok(target),
        Some(_) => Err(PyValueError::new_err(format!(
            "StepPlan: {name} is not a registry function (no stepping, control or script calls in a plan)"
        ))),
        None => Err(PyValueError::new_err(format!("StepPlan: no such function: {name}"))),
    }
}

/// One act call as Python gives it: `(set, handle, read or None, index, scale)`.
type ActArgs<'py> = (String, Bound<'py, PyAny>, Option<String>, usize, f64);

#[pymethods]
impl StepPlan {
    /// `act`: `(set, handle, read or None, index, scale)` tuples; `steps`: simulation
    /// steps per action; `observe`: `(get, [args...])` pairs. Names as `client.call`
    /// takes them (`"sim.setJointTargetPosition"`).
    #[new]
    fn new(act: Vec<ActArgs<'_>>, steps: u64, observe: Vec<(String, Vec<Bound<'_, PyAny>>)>) -> PyResult<Self> {
        let act = act
            .into_iter()
            .map(|(set, handle, read, index, scale)| {
                Ok(ActOp {
                    set: core_function(&set)?,
                    handle: to_value(&handle)?,
                    read: read.as_deref().map(core_function).transpose()?,
                    index,
                    // The action is float32, and numpy multiplies it in float32.
                    scale: scale as f32,
                })
            })
            .collect::<PyResult<Vec<_>>>()?;
        let observe = observe
            .into_iter()
            .map(|(get, args)| {
                Ok(ObserveOp {
                    get: core_function(&get)?,
                    args: args.iter().map(to_value).collect::<PyResult<_>>()?,
                })
            })
            .collect::<PyResult<Vec<_>>>()?;
        let action_size = act.iter().map(|op| op.index + 1).max().unwrap_or(0);
        Ok(Self {
            act,
            steps,
            observe,
            action_size,
        })
    }

    /// The simulation steps per action.
    #[getter]
    fn steps(&self) -> u64 {
        self.steps
    }

    fn __repr__(&self) -> String {
        format!(
            "<gantry StepPlan: {} act calls, {} steps, {} observe calls>",
            self.act.len(),
            self.steps,
            self.observe.len()
        )
    }
}

/// Appends a reply's numbers (one number, or an array of numbers) to `out`; `None` when
/// the reply holds anything else.
pub(crate) fn push_numbers(reply: &[Value], out: &mut Vec<f64>) -> Option<()> {
    for v in reply {
        match v {
            Value::Array(items) => {
                for item in items {
                    out.push(item.as_f64()?);
                }
            }
            other => out.push(other.as_f64()?),
        }
    }
    Some(())
}

/// Plans' observations, one row each, as a `(n, m)` `float64` array; an error if the
/// rows differ in length.
pub(crate) fn rows_array(py: Python<'_>, rows: Vec<Vec<f64>>) -> PyResult<Bound<'_, PyAny>> {
    let m = rows.first().map_or(0, Vec::len);
    if rows.iter().any(|r| r.len() != m) {
        return Err(PyValueError::new_err("the plans observe different numbers of values"));
    }
    let n = rows.len();
    let flat: Vec<f64> = rows.into_iter().flatten().collect();
    Ok(PyArray1::from_vec(py, flat).reshape([n, m])?.into_any())
}
