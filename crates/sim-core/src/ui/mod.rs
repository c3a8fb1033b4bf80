//! Custom UIs (`simUI`): the widget model built from CoppeliaSim's XML, its values, and
//! the callback events queued for scripts. The viewer renders it; tests drive it through
//! the API.

/// Every UI of the scene.
#[derive(Debug, Clone, Default)]
pub struct Uis {}
