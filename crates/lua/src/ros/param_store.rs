//! [`Params`]: what ROS 1's parameter server holds for `simROS` scripts (the functions
//! are in `params.rs`).

use std::collections::BTreeMap;

/// A parameter's value.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Param {
    Int(i64),
    Double(f64),
    Bool(bool),
    Str(String),
}

/// Parameters by full name (`/robot/gain`).
pub(crate) type Params = BTreeMap<String, Param>;

/// Most parameters kept: a script setting names in a loop cannot grow memory without end.
pub(crate) const MAX_PARAMS: usize = 10_000;
