//! Argument checking shared by every `sim.*` function.
//!
//! Each accessor names the argument's position and the expected type, so a wrong call
//! fails with e.g. "argument 2: expected number, got string (in function
//! 'sim.setJointPosition')" — the front end appends the function name.

use crate::Value;
use crate::error::SimError;
use crate::math::Vec3;
use crate::world::Handle;

/// A cursor over a call's arguments.
pub struct Args<'a> {
    values: &'a [Value],
}

impl<'a> Args<'a> {
    /// Wraps the arguments of one call.
    pub fn new(values: &'a [Value]) -> Self {
        Self { values }
    }

    /// Number of arguments given (trailing nils included).
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// Whether no argument was given.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// Argument `i` (0-based), `Nil` when absent.
    pub fn get(&self, i: usize) -> &'a Value {
        const NIL: &Value = &Value::Nil;
        self.values.get(i).unwrap_or(NIL)
    }

    fn bad(&self, i: usize, expected: &str) -> SimError {
        let got = match self.values.get(i) {
            None => "no value",
            Some(v) => v.type_name(),
        };
        SimError::bad_argument(format!("argument {}: expected {expected}, got {got}", i + 1))
    }

    /// A required number.
    pub fn f64(&self, i: usize) -> Result<f64, SimError> {
        self.get(i).as_f64().ok_or_else(|| self.bad(i, "number"))
    }

    /// A required finite number.
    pub fn finite(&self, i: usize) -> Result<f64, SimError> {
        let v = self.f64(i)?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(SimError::bad_argument(format!(
                "argument {}: expected a finite number, got {v}",
                i + 1
            )))
        }
    }

    /// An optional number.
    pub fn opt_f64(&self, i: usize, default: f64) -> Result<f64, SimError> {
        match self.get(i) {
            Value::Nil => Ok(default),
            _ => self.f64(i),
        }
    }

    /// A required integer (a float with no fraction is accepted).
    pub fn int(&self, i: usize) -> Result<i64, SimError> {
        self.get(i).as_i64().ok_or_else(|| self.bad(i, "integer"))
    }

    /// An optional integer.
    pub fn opt_int(&self, i: usize, default: i64) -> Result<i64, SimError> {
        match self.get(i) {
            Value::Nil => Ok(default),
            _ => self.int(i),
        }
    }

    /// A required handle.
    pub fn handle(&self, i: usize) -> Result<Handle, SimError> {
        self.int(i)
    }

    /// A required boolean (numbers are accepted, non-zero meaning true, as Lua clients
    /// of the 4.1 API pass 0/1).
    pub fn bool(&self, i: usize) -> Result<bool, SimError> {
        match self.get(i) {
            Value::Bool(b) => Ok(*b),
            Value::Int(n) => Ok(*n != 0),
            _ => Err(self.bad(i, "boolean")),
        }
    }

    /// An optional boolean.
    pub fn opt_bool(&self, i: usize, default: bool) -> Result<bool, SimError> {
        match self.get(i) {
            Value::Nil => Ok(default),
            _ => self.bool(i),
        }
    }

    /// A required string.
    pub fn str(&self, i: usize) -> Result<&'a str, SimError> {
        match self.get(i) {
            Value::Str(s) => Ok(s),
            _ => Err(self.bad(i, "string")),
        }
    }

    /// A required string or byte string, as bytes.
    pub fn bytes(&self, i: usize) -> Result<Vec<u8>, SimError> {
        match self.get(i) {
            Value::Str(s) => Ok(s.as_bytes().to_vec()),
            Value::Bytes(b) => Ok(b.clone()),
            _ => Err(self.bad(i, "string")),
        }
    }

    /// A required array of exactly `N` finite numbers.
    pub fn floats<const N: usize>(&self, i: usize) -> Result<[f64; N], SimError> {
        let expected = || format!("table of {N} numbers");
        let Value::Array(items) = self.get(i) else {
            return Err(self.bad(i, &expected()));
        };
        if items.len() < N {
            return Err(SimError::bad_argument(format!(
                "argument {}: expected {}, got {} values",
                i + 1,
                expected(),
                items.len()
            )));
        }
        let mut out = [0.0; N];
        for (k, v) in items.iter().take(N).enumerate() {
            match v.as_f64() {
                Some(f) if f.is_finite() => out[k] = f,
                _ => {
                    return Err(SimError::bad_argument(format!(
                        "argument {}: element {} must be a finite number",
                        i + 1,
                        k + 1
                    )));
                }
            }
        }
        Ok(out)
    }

    /// An optional table of finite numbers: `None` for nil (item data, parameter
    /// lists), every element checked.
    pub fn opt_numbers(&self, i: usize) -> Result<Option<Vec<f64>>, SimError> {
        match self.get(i) {
            Value::Nil => Ok(None),
            Value::Array(items) => items
                .iter()
                .enumerate()
                .map(|(k, v)| {
                    v.as_f64().filter(|f| f.is_finite()).ok_or_else(|| {
                        SimError::bad_argument(format!(
                            "argument {}: element {} must be a finite number, got {}",
                            i + 1,
                            k + 1,
                            match v.as_f64() {
                                Some(f) => f.to_string(),
                                None => v.type_name().to_owned(),
                            }
                        ))
                    })
                })
                .collect::<Result<Vec<f64>, SimError>>()
                .map(Some),
            other => Err(SimError::bad_argument(format!(
                "argument {}: expected table of numbers or nil, got {}",
                i + 1,
                other.type_name()
            ))),
        }
    }

    /// A required table of finite numbers (see [`Args::opt_numbers`]).
    pub fn numbers(&self, i: usize) -> Result<Vec<f64>, SimError> {
        self.opt_numbers(i)?.ok_or_else(|| self.bad(i, "table of numbers"))
    }

    /// A required 3-vector.
    pub fn vec3(&self, i: usize) -> Result<Vec3, SimError> {
        self.floats::<3>(i).map(Vec3::from)
    }

    /// Whether argument `i` is an array (used to tell CoppeliaSim's two argument orders apart).
    pub fn is_array(&self, i: usize) -> bool {
        matches!(self.get(i), Value::Array(_))
    }
}
