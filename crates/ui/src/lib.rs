//! simUI's widget model: windows, widgets, their values and the callback events queued
//! for scripts, built from CoppeliaSim's XML (`simUI`), plus the floating views and the
//! simulator messages the viewer feeds back. No rendering: the viewer draws it, and
//! tests drive it through the API.
//!
//! It sits below the world (`gantry-world`), whose `Sim` owns a [`Uis`], a
//! [`FloatingViews`] and a [`SimulatorMessages`]: it knows object handles and the
//! world's error type (`gantry-scene`) and the registry's [`Value`](gantry_protocol::Value),
//! and no physics. `gantry_sim_core::ui` re-exports it under its old path.
//!
//! * [`Uis`] owns every UI. `simUI.create(xml)` parses the XML (following simUI's
//!   rules and leniency) into a [`Ui`]: the window's attributes and a [`Container`] tree of
//!   [`Widget`]s. The UI remembers the object of the script that created it.
//! * Widgets change through `simUI.set*` and through [`Uis::interact`], which stands in
//!   for the user. Either may queue a [`UiEvent`]; the Lua host drains them with
//!   [`Uis::take_events`] and calls `callback(ui, id, value)` in the owning script on its
//!   next turn. Nothing here runs Lua.
//! * Non-goals: drawing (the viewer does it), Qt stylesheets (kept as text), and the
//!   widgets gantry does not implement (combobox, tabs, plot, table, tree, image, ...),
//!   which `create` refuses by name.
//!
//! All inputs are bounded: see [`MAX_UIS`], [`MAX_WIDGETS`], [`MAX_XML_LEN`],
//! [`MAX_DEPTH`], [`MAX_TEXT_LEN`] and [`MAX_EVENTS`].

mod error;
mod limits;
mod messages;
mod parse;
mod uis;
mod views;
mod widget;
mod window;

pub use error::UiError;
pub use limits::{FIRST_UI_HANDLE, MAX_DEPTH, MAX_EVENTS, MAX_TEXT_LEN, MAX_UIS, MAX_WIDGETS, MAX_XML_LEN};
pub use messages::{KeyboardModifiers, MESSAGE_CAPACITY, MESSAGE_KEYPRESS, SimulatorMessage, SimulatorMessages, keys};
pub use uis::{UiEvent, Uis};
pub use views::{FloatingView, FloatingViews, MAX_LABEL_LEN, MAX_VIEWS, ViewError};
pub use widget::{
    Button, Checkbox, Container, Edit, Group, Label, Layout, Orientation, Radiobutton, Slider, Spinbox, Stretch,
    TickPosition, Widget, WidgetKind,
};
pub use window::{Placement, Ui};
