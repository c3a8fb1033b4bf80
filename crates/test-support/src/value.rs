//! [`Value`]s read as the test expects them; anything else fails the test with what
//! came instead.

use gantry_protocol::Value;

/// A number (an integer or a float).
///
/// # Panics
/// If `v` is not a number.
#[track_caller]
pub fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("expected a number, got {v:?}"))
}

/// An integer: `Value::Int` only, so a float where the API promises an integer (a
/// handle, a count) fails the test.
///
/// # Panics
/// If `v` is not an integer.
#[track_caller]
pub fn int(v: &Value) -> i64 {
    match v {
        Value::Int(i) => *i,
        other => panic!("expected an integer, got {other:?}"),
    }
}

/// A string.
///
/// # Panics
/// If `v` is not a string.
#[track_caller]
pub fn text(v: &Value) -> &str {
    v.as_str().unwrap_or_else(|| panic!("expected a string, got {v:?}"))
}

/// An array of numbers (a position, a quaternion, a matrix).
///
/// # Panics
/// If `v` is not an array or an item is not a number.
#[track_caller]
pub fn floats(v: &Value) -> Vec<f64> {
    match v {
        Value::Array(items) => items.iter().map(num).collect(),
        other => panic!("expected an array of numbers, got {other:?}"),
    }
}

/// An array of integers (handles), each a `Value::Int` as [`int`] requires.
///
/// # Panics
/// If `v` is not an array or an item is not an integer.
#[track_caller]
pub fn ints(v: &Value) -> Vec<i64> {
    match v {
        Value::Array(items) => items.iter().map(int).collect(),
        other => panic!("expected an array of integers, got {other:?}"),
    }
}
