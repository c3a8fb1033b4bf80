//! A resolved field of a message type: its name, element type, arity and default.

use super::definition::Arity;
use super::primitive::Primitive;
use crate::Value;

/// A field's element type, resolved.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kind {
    Primitive(Primitive),
    /// Index of a message type in [`Registry::types`].
    Message(usize),
}

/// One field of a message type.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Field {
    pub(crate) name: String,
    pub(crate) kind: Kind,
    pub(crate) arity: Arity,
    /// The declared default of a single builtin field; `None` means zero, false or "".
    pub(crate) default: Option<Value>,
}
