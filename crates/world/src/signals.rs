//! Named signals: the blackboard scripts and remote clients share (CoppeliaSim's
//! `sim.setInt32Signal` and friends). Ordered maps keep iteration deterministic.

use std::collections::BTreeMap;

/// Int32, float and string signals, each in its own namespace as in CoppeliaSim.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Signals {
    /// Integer signals.
    pub int32: BTreeMap<String, i32>,
    /// Float signals.
    pub float: BTreeMap<String, f64>,
    /// Double signals (`sim.setDoubleSignal`, CoppeliaSim 4.1's API): a namespace of
    /// their own, apart from the float signals, as in 4.1.
    pub double: BTreeMap<String, f64>,
    /// String (byte) signals.
    pub string: BTreeMap<String, Vec<u8>>,
}
