//! The bounds on every input of the UI subsystem, so that scripts and the viewer cannot
//! grow memory or recursion without limit.

/// The handle of the first UI; later ones count up and are never reused.
pub const FIRST_UI_HANDLE: i64 = 1000;
/// UIs that may exist at once.
pub const MAX_UIS: usize = 64;
/// Elements (widgets, groups, stretches) per UI.
pub const MAX_WIDGETS: usize = 256;
/// Bytes of XML `simUI.create` accepts.
pub const MAX_XML_LEN: usize = 64 * 1024;
/// Levels of nested groups, the window being level 1. Bounds the parser's recursion.
pub const MAX_DEPTH: usize = 16;
/// Bytes of a label's or an edit's text set after creation.
pub const MAX_TEXT_LEN: usize = 64 * 1024;
/// Callback events waiting for their scripts; past this the oldest is dropped (with a
/// warning), so a UI driven while no script runs cannot grow memory.
pub const MAX_EVENTS: usize = 1024;
