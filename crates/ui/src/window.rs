//! One custom UI: a window with its attributes and its widget tree.

use gantry_scene::Handle;

use crate::widget::{Container, Widget};

/// Where the window opens (`placement`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Placement {
    /// `center` (the default): centred on the main window.
    Center,
    /// `relative`: `position` from the main window's corner (negative = from the far side).
    Relative,
    /// `absolute`: `position` in screen pixels.
    Absolute,
    /// `banner`: a frameless strip across the top of the 3D view.
    Banner,
}

/// A custom UI created by `simUI.create`.
///
/// Read-only outside this module: [`Uis`](crate::Uis) hands out only shared references,
/// and every change goes through its methods so that events are queued consistently.
#[derive(Debug, Clone, PartialEq)]
pub struct Ui {
    /// The handle `simUI.create` returned.
    pub handle: i64,
    /// The object of the script that created the UI; its callbacks run in that script.
    /// `None` when a remote client created it.
    pub owner: Option<Handle>,
    /// `title` (default "Custom UI").
    pub title: String,
    /// `closeable`: the window has a close button.
    pub closeable: bool,
    /// `resizable`.
    pub resizable: bool,
    /// `modal`.
    pub modal: bool,
    /// `activate`: the window takes the keyboard focus when shown.
    pub activate: bool,
    /// `enabled`: a disabled window greys out every widget.
    pub enabled: bool,
    /// Shown or hidden (`simUI.show` / `simUI.hide`, or closed by the user).
    pub visible: bool,
    /// `style`: a Qt stylesheet, kept verbatim.
    pub style: String,
    /// `placement`.
    pub placement: Placement,
    /// `position` in pixels (default 50, 50), as interpreted by `placement`.
    pub position: [i64; 2],
    /// `size` in pixels; -1 means automatic (the default).
    pub size: [i64; 2],
    /// `on-close`: called `f(ui)` when the user closes the window; when present the
    /// window stays open and the script decides.
    pub on_close: Option<String>,
    /// The window's layout and widgets.
    pub content: Container,
}

impl Ui {
    /// The widget with `id` anywhere in the window.
    pub fn widget(&self, id: i64) -> Option<&Widget> {
        self.content.find(id)
    }

    /// Every widget, depth first in document order (groups before their children).
    pub fn widgets(&self) -> Vec<&Widget> {
        self.content.widgets()
    }
}
