//! Graph streams (`sim.addGraphStream`): named time series kept in memory (bounded) and
//! exportable to CSV.

/// Every graph stream of the scene.
#[derive(Debug, Clone, Default)]
pub struct Graphs {}
