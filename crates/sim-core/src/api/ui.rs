//! API functions of this capability (see the module of the same name).

use super::ApiFunction;

/// The functions this file implements.
pub(super) const FUNCTIONS: &[ApiFunction] = &[];

/// The `simUI.*` constants.
pub(super) const CONSTANTS: &[(&str, i64)] = &[];
