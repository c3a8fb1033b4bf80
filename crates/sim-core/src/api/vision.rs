//! API functions of this capability (see the module of the same name).

use super::ApiFunction;

/// The `sim.*` vision functions this file implements.
pub(super) const FUNCTIONS: &[ApiFunction] = &[];

/// The `simVision.*` functions.
pub(super) const SIM_VISION_FUNCTIONS: &[ApiFunction] = &[];
