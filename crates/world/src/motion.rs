//! The state of jerk-limited trajectory generators (`sim.ruckigPos`/`ruckigVel`), on
//! `rsruckig`. The API functions that create and step them are in `api::ruckig`; the
//! generators live in [`crate::sim::Sim`], so they disappear with the simulation when it
//! stops, as CoppeliaSim removes a script's objects with the script.

use std::collections::BTreeMap;

use rsruckig::prelude::{InputParameter, OutputParameter, Ruckig, RuckigError, RuckigErrorHandler};

use crate::error::SimError;

/// Most generators alive at once, so a script that never removes them
/// (`sim.ruckigRemove`) fails clearly instead of growing memory without end.
pub const MAX_OBJECTS: usize = 10_000;

/// Ruckig's error policy here: an invalid input stops the calculation with its reason
/// (reported as `ErrorInvalidInput`, -100, and logged), a failed calculation returns its
/// own result code (-101 to -111), as the C++ library does.
#[derive(Debug, Clone, Copy, Default)]
pub struct ResultCodes;

impl RuckigErrorHandler for ResultCodes {
    fn handle_validation_error(message: &str) -> Result<(), RuckigError> {
        Err(RuckigError::ValidationError(message.to_owned()))
    }

    fn handle_calculator_error(_: &str) -> Result<(), RuckigError> {
        Ok(())
    }
}

/// One generator.
#[derive(Debug)]
pub struct RuckigObject {
    /// The generator (its state is in `input`/`output`).
    pub otg: Ruckig<0, ResultCodes>,
    /// The current state (fed back from each step's output) and the fixed target and limits.
    pub input: InputParameter<0>,
    /// The last step's output.
    pub output: OutputParameter<0>,
    /// Degrees of freedom, the length of every vector in `input` and `output`.
    pub dofs: usize,
    /// The smallest cycle time the caller declared, s; every step is a multiple of it.
    pub base_cycle: f64,
    /// Time stepped so far, s.
    pub elapsed: f64,
    /// The trajectory's duration, s, known after the first successful step.
    pub duration: Option<f64>,
    /// Whether the reason for an invalid input was logged already (once per generator).
    pub warned: bool,
}

/// The Ruckig generators of a world, by handle (handles count up from 0 and are not reused).
#[derive(Debug, Default)]
pub struct RuckigObjects {
    /// The live generators, by handle.
    pub objects: BTreeMap<i64, RuckigObject>,
    next_handle: i64,
}

impl RuckigObjects {
    /// Adds a generator and returns its new handle; refused past [`MAX_OBJECTS`].
    pub fn insert(&mut self, object: RuckigObject) -> Result<i64, SimError> {
        if self.objects.len() >= MAX_OBJECTS {
            return Err(SimError::BadArgument(format!(
                "too many Ruckig objects ({MAX_OBJECTS}): remove finished ones with sim.ruckigRemove"
            )));
        }
        let h = self.next_handle;
        self.next_handle += 1;
        self.objects.insert(h, object);
        Ok(h)
    }

    /// The generator of handle `h`, if alive.
    pub fn get_mut(&mut self, h: i64) -> Option<&mut RuckigObject> {
        self.objects.get_mut(&h)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rsruckig::prelude::Ruckig;

    #[test]
    fn handles_count_up_and_are_not_reused() {
        let mut objs = RuckigObjects::default();
        let make = || RuckigObject {
            otg: Ruckig::new(Some(1), 0.001),
            input: InputParameter::new(Some(1)),
            output: OutputParameter::new(Some(1)),
            dofs: 1,
            base_cycle: 0.001,
            elapsed: 0.0,
            duration: None,
            warned: false,
        };
        let a = objs.insert(make()).expect("room");
        let b = objs.insert(make()).expect("room");
        assert_eq!((a, b), (0, 1));
        objs.objects.remove(&a);
        assert_eq!(objs.insert(make()).expect("room"), 2);
    }
}
