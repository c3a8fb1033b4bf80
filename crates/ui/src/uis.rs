//! [`Uis`]: every custom UI of the world, the operations on their widgets, and the
//! queue of callback events waiting for their scripts.

use std::collections::{BTreeMap, VecDeque};

use gantry_protocol::Value;
use gantry_scene::Handle;

use crate::error::UiError;
use crate::parse::{self, Diagnostics};
use crate::widget::{Container, Widget, WidgetKind};
use crate::window::Ui;
use crate::{FIRST_UI_HANDLE, MAX_EVENTS, MAX_TEXT_LEN, MAX_UIS};

/// A callback a widget asks its script to run: `callback(ui, widget, value)`.
///
/// Queued by user actions ([`Uis::interact`]) and by setters called with
/// `suppressEvents = false`; the Lua host takes them with [`Uis::take_events`] and calls
/// the function by name in the owning script on that script's next turn.
#[derive(Debug, Clone, PartialEq)]
pub struct UiEvent {
    /// The UI handle, the callback's first argument.
    pub ui: i64,
    /// The widget id, the second argument; 0 for the window itself (`on-close`, which
    /// CoppeliaSim calls as `f(ui)`: the extra arguments are harmless in Lua).
    pub widget: i64,
    /// The global function to call, as named in the XML (`on-change="speedChange_callback"`).
    pub callback: String,
    /// The third argument: the new value (integer for sliders, checkboxes and integer
    /// spin boxes, float for float spin boxes, text for edits and label links), or `Nil`
    /// for clicks and window close.
    pub value: Value,
    /// The object of the script that created the UI; `None` when a remote client did.
    pub script_object: Option<Handle>,
}

/// Every custom UI of the scene.
///
/// Handles start at [`FIRST_UI_HANDLE`] (as the integer handles of older simUI versions did) and
/// are never reused, so a stale handle fails instead of reaching another window.
/// Iteration is in handle order, i.e. creation order.
#[derive(Debug, Clone)]
pub struct Uis {
    uis: BTreeMap<i64, Ui>,
    next_handle: i64,
    /// Producers: setters and `interact`. Consumer: the Lua host via `take_events`.
    /// Bounded by [`MAX_EVENTS`]; the oldest event is dropped when full.
    events: VecDeque<UiEvent>,
    /// Whether an event was dropped since the last `take_events` (warned once per episode).
    overflowed: bool,
    diag: Diagnostics,
    revision: u64,
}

impl Default for Uis {
    fn default() -> Self {
        Self {
            uis: BTreeMap::new(),
            next_handle: FIRST_UI_HANDLE,
            events: VecDeque::new(),
            overflowed: false,
            diag: Diagnostics::default(),
            revision: 0,
        }
    }
}

impl Uis {
    /// `simUI.create`: parses `xml` and opens the window; `owner` is the creating
    /// script's object (callbacks go to that script).
    ///
    /// Parser warnings (unknown attributes, deprecated spellings) wait in
    /// [`take_warnings`](Self::take_warnings), also when parsing fails.
    ///
    /// # Errors
    /// Malformed XML (with line and column), an invalid UI description, or
    /// [`MAX_UIS`] UIs existing already.
    pub fn create(&mut self, xml: &str, owner: Option<Handle>) -> Result<i64, UiError> {
        if self.uis.len() >= MAX_UIS {
            return Err(UiError::TooManyUis);
        }
        let handle = self.next_handle;
        let ui = parse::parse(xml, handle, owner, &mut self.diag)?;
        self.next_handle = self.next_handle.saturating_add(1);
        self.uis.insert(handle, ui);
        self.touch();
        Ok(handle)
    }

    /// `simUI.destroy`: closes the window. Its queued events are dropped, so no callback
    /// ever receives a handle that is already invalid.
    ///
    /// # Errors
    /// [`UiError::NoSuchUi`].
    pub fn destroy(&mut self, ui: i64) -> Result<(), UiError> {
        self.uis.remove(&ui).ok_or(UiError::NoSuchUi(ui))?;
        self.events.retain(|e| e.ui != ui);
        self.touch();
        Ok(())
    }

    /// Destroys every UI created by the script on `owner`, returning how many. For the
    /// host to call when that script is reset or the simulation stops (simUI destroys
    /// child-script UIs at simulation end).
    pub fn destroy_owned_by(&mut self, owner: Handle) -> usize {
        let doomed: Vec<i64> = self
            .uis
            .values()
            .filter(|u| u.owner == Some(owner))
            .map(|u| u.handle)
            .collect();
        for h in &doomed {
            self.uis.remove(h);
        }
        self.events.retain(|e| !doomed.contains(&e.ui));
        if !doomed.is_empty() {
            self.touch();
        }
        doomed.len()
    }

    /// Destroys every UI and drops every queued event. Handles keep counting up.
    pub fn clear(&mut self) {
        self.uis.clear();
        self.events.clear();
        self.touch();
    }

    /// The UI with this handle.
    pub fn get(&self, ui: i64) -> Option<&Ui> {
        self.uis.get(&ui)
    }

    /// Every UI, in creation order: what the viewer draws.
    pub fn iter(&self) -> impl Iterator<Item = &Ui> {
        self.uis.values()
    }

    /// Number of UIs.
    pub fn len(&self) -> usize {
        self.uis.len()
    }

    /// Whether there is no UI.
    pub fn is_empty(&self) -> bool {
        self.uis.is_empty()
    }

    /// A counter bumped by every change (creation, value, visibility, ...), so a viewer
    /// can skip redrawing when it has not moved.
    pub fn revision(&self) -> u64 {
        self.revision
    }

    /// The queued callback events, oldest first, leaving the queue empty.
    pub fn take_events(&mut self) -> Vec<UiEvent> {
        self.overflowed = false;
        self.events.drain(..).collect()
    }

    /// Warnings for the log (unknown XML attributes, deprecated spellings, a full event
    /// queue), leaving none. The API layer moves them to the world log after each call.
    pub fn take_warnings(&mut self) -> Vec<String> {
        std::mem::take(&mut self.diag.warnings)
    }

    /// Parser notes (deprecated spellings) that wait to be logged as information.
    pub fn take_notes(&mut self) -> Vec<String> {
        std::mem::take(&mut self.diag.notes)
    }

    /// The widget `id` of UI `ui`.
    ///
    /// # Errors
    /// [`UiError::NoSuchUi`], [`UiError::NoSuchWidget`].
    pub fn widget(&self, ui: i64, id: i64) -> Result<&Widget, UiError> {
        self.uis
            .get(&ui)
            .ok_or(UiError::NoSuchUi(ui))?
            .widget(id)
            .ok_or(UiError::NoSuchWidget(id))
    }

    /// `simUI.getSliderValue`.
    ///
    /// # Errors
    /// Bad handle or id, or the widget is not a slider.
    pub fn slider_value(&self, ui: i64, id: i64) -> Result<i64, UiError> {
        match &self.widget(ui, id)?.kind {
            WidgetKind::Slider(s) => Ok(s.value),
            other => Err(wrong_type(id, "slider", other)),
        }
    }

    /// `simUI.setSliderValue`: clamps `value` into the slider's range. With
    /// `suppress_events` false, queues `on-change` if the value changed (Qt emits
    /// `valueChanged` only on a change).
    ///
    /// # Errors
    /// Bad handle or id, or the widget is not a slider.
    pub fn set_slider_value(&mut self, ui: i64, id: i64, value: i64, suppress_events: bool) -> Result<(), UiError> {
        let (owner, w) = widget_mut(&mut self.uis, ui, id)?;
        let WidgetKind::Slider(s) = &mut w.kind else {
            return Err(wrong_type(id, "slider", &w.kind));
        };
        let value = value.clamp(s.minimum, s.maximum);
        let changed = value != s.value;
        s.value = value;
        let callback = s.on_change.clone().filter(|_| changed && !suppress_events);
        self.touch();
        self.queue(ui, id, callback, Value::Int(value), owner);
        Ok(())
    }

    /// `simUI.getLabelText`.
    ///
    /// # Errors
    /// Bad handle or id, or the widget is not a label.
    pub fn label_text(&self, ui: i64, id: i64) -> Result<&str, UiError> {
        match &self.widget(ui, id)?.kind {
            WidgetKind::Label(l) => Ok(&l.text),
            other => Err(wrong_type(id, "label", other)),
        }
    }

    /// `simUI.setLabelText`. Labels have no change callback in simUI, so this never
    /// queues an event.
    ///
    /// # Errors
    /// Bad handle or id, not a label, or text over [`MAX_TEXT_LEN`].
    pub fn set_label_text(&mut self, ui: i64, id: i64, text: &str) -> Result<(), UiError> {
        check_text(text)?;
        let (_, w) = widget_mut(&mut self.uis, ui, id)?;
        let WidgetKind::Label(l) = &mut w.kind else {
            return Err(wrong_type(id, "label", &w.kind));
        };
        text.clone_into(&mut l.text);
        self.touch();
        Ok(())
    }

    /// `simUI.getEditValue`.
    ///
    /// # Errors
    /// Bad handle or id, or the widget is not an edit.
    pub fn edit_value(&self, ui: i64, id: i64) -> Result<&str, UiError> {
        match &self.widget(ui, id)?.kind {
            WidgetKind::Edit(e) => Ok(&e.value),
            other => Err(wrong_type(id, "edit", other)),
        }
    }

    /// `simUI.setEditValue`. With `suppress_events` false, queues `on-change` if the
    /// text changed (Qt's `textChanged`); never `on-editing-finished`, which only the
    /// user triggers.
    ///
    /// # Errors
    /// Bad handle or id, not an edit, or text over [`MAX_TEXT_LEN`].
    pub fn set_edit_value(&mut self, ui: i64, id: i64, text: &str, suppress_events: bool) -> Result<(), UiError> {
        check_text(text)?;
        let (owner, w) = widget_mut(&mut self.uis, ui, id)?;
        let WidgetKind::Edit(e) = &mut w.kind else {
            return Err(wrong_type(id, "edit", &w.kind));
        };
        let changed = e.value != text;
        text.clone_into(&mut e.value);
        let callback = e.on_change.clone().filter(|_| changed && !suppress_events);
        self.touch();
        self.queue(ui, id, callback, Value::from(text), owner);
        Ok(())
    }

    /// `simUI.getCheckboxValue`: 0 unchecked, 1 partially checked, 2 checked.
    ///
    /// # Errors
    /// Bad handle or id, or the widget is not a checkbox.
    pub fn checkbox_value(&self, ui: i64, id: i64) -> Result<i64, UiError> {
        match &self.widget(ui, id)?.kind {
            WidgetKind::Checkbox(c) => Ok(c.value),
            other => Err(wrong_type(id, "checkbox", other)),
        }
    }

    /// `simUI.setCheckboxValue` with 0, 1 or 2. With `suppress_events` false, queues
    /// `on-change` if the state changed.
    ///
    /// # Errors
    /// Bad handle or id, not a checkbox, or a value other than 0, 1, 2.
    pub fn set_checkbox_value(&mut self, ui: i64, id: i64, value: i64, suppress_events: bool) -> Result<(), UiError> {
        if !(0..=2).contains(&value) {
            return Err(UiError::InvalidValue(
                "invalid checkbox value: must be 0, 1 or 2".into(),
            ));
        }
        let (owner, w) = widget_mut(&mut self.uis, ui, id)?;
        let WidgetKind::Checkbox(c) = &mut w.kind else {
            return Err(wrong_type(id, "checkbox", &w.kind));
        };
        let changed = c.value != value;
        c.value = value;
        let callback = c.on_change.clone().filter(|_| changed && !suppress_events);
        self.touch();
        self.queue(ui, id, callback, Value::Int(value), owner);
        Ok(())
    }

    /// `simUI.getRadiobuttonValue`: whether it is checked.
    ///
    /// # Errors
    /// Bad handle or id, or the widget is not a radio button.
    pub fn radiobutton_value(&self, ui: i64, id: i64) -> Result<bool, UiError> {
        match &self.widget(ui, id)?.kind {
            WidgetKind::Radiobutton(r) => Ok(r.checked),
            other => Err(wrong_type(id, "radiobutton", other)),
        }
    }

    /// `simUI.setRadiobuttonValue`. Checking unchecks the other radio buttons of the same
    /// container. With `suppress_events` false, queues `on-click` when it becomes checked.
    ///
    /// # Errors
    /// Bad handle or id, or the widget is not a radio button.
    pub fn set_radiobutton_value(
        &mut self,
        ui: i64,
        id: i64,
        checked: bool,
        suppress_events: bool,
    ) -> Result<(), UiError> {
        let (owner, w) = widget_mut(&mut self.uis, ui, id)?;
        let WidgetKind::Radiobutton(r) = &mut w.kind else {
            return Err(wrong_type(id, "radiobutton", &w.kind));
        };
        let changed = r.checked != checked;
        let callback = r.on_click.clone().filter(|_| changed && checked && !suppress_events);
        self.set_radio(ui, id, checked);
        self.touch();
        self.queue(ui, id, callback, Value::Nil, owner);
        Ok(())
    }

    /// `simUI.getSpinboxValue`.
    ///
    /// # Errors
    /// Bad handle or id, or the widget is not a spin box.
    pub fn spinbox_value(&self, ui: i64, id: i64) -> Result<f64, UiError> {
        match &self.widget(ui, id)?.kind {
            WidgetKind::Spinbox(s) => Ok(s.value),
            other => Err(wrong_type(id, "spinbox", other)),
        }
    }

    /// `simUI.setSpinboxValue`: clamped into range, and truncated for an integer spin box
    /// as simUI's `int(value)`. With `suppress_events` false, queues `on-change` if the
    /// value changed.
    ///
    /// # Errors
    /// Bad handle or id, not a spin box, or a non-finite value.
    pub fn set_spinbox_value(&mut self, ui: i64, id: i64, value: f64, suppress_events: bool) -> Result<(), UiError> {
        if !value.is_finite() {
            return Err(UiError::InvalidValue(format!("invalid spinbox value: {value}")));
        }
        let (owner, w) = widget_mut(&mut self.uis, ui, id)?;
        let WidgetKind::Spinbox(s) = &mut w.kind else {
            return Err(wrong_type(id, "spinbox", &w.kind));
        };
        let value = if s.float { value } else { value.trunc() }.clamp(s.minimum, s.maximum);
        let changed = value != s.value;
        s.value = value;
        let callback = s.on_change.clone().filter(|_| changed && !suppress_events);
        let event_value = spinbox_event_value(s.float, value);
        self.touch();
        self.queue(ui, id, callback, event_value, owner);
        Ok(())
    }

    /// Whether widget `id` is enabled (its own flag; a disabled group or window also
    /// greys it out).
    ///
    /// # Errors
    /// Bad handle or id.
    pub fn enabled(&self, ui: i64, id: i64) -> Result<bool, UiError> {
        Ok(self.widget(ui, id)?.enabled)
    }

    /// `simUI.setEnabled`.
    ///
    /// # Errors
    /// Bad handle or id.
    pub fn set_enabled(&mut self, ui: i64, id: i64, enabled: bool) -> Result<(), UiError> {
        let (_, w) = widget_mut(&mut self.uis, ui, id)?;
        w.enabled = enabled;
        self.touch();
        Ok(())
    }

    /// `simUI.isVisible`.
    ///
    /// # Errors
    /// [`UiError::NoSuchUi`].
    pub fn is_visible(&self, ui: i64) -> Result<bool, UiError> {
        Ok(self.uis.get(&ui).ok_or(UiError::NoSuchUi(ui))?.visible)
    }

    /// `simUI.show` / `simUI.hide`.
    ///
    /// # Errors
    /// [`UiError::NoSuchUi`].
    pub fn set_visible(&mut self, ui: i64, visible: bool) -> Result<(), UiError> {
        self.uis.get_mut(&ui).ok_or(UiError::NoSuchUi(ui))?.visible = visible;
        self.touch();
        Ok(())
    }

    /// `simUI.getPosition`: the window's `position` in pixels.
    ///
    /// # Errors
    /// [`UiError::NoSuchUi`].
    pub fn position(&self, ui: i64) -> Result<[i64; 2], UiError> {
        Ok(self.uis.get(&ui).ok_or(UiError::NoSuchUi(ui))?.position)
    }

    /// `simUI.setPosition`: moves the window to `position` in screen pixels. simUI moves
    /// the Qt window to absolute coordinates, so the placement becomes
    /// [`Placement::Absolute`](crate::Placement::Absolute) whatever the XML said.
    ///
    /// # Errors
    /// [`UiError::NoSuchUi`].
    pub fn set_position(&mut self, ui: i64, position: [i64; 2]) -> Result<(), UiError> {
        let window = self.uis.get_mut(&ui).ok_or(UiError::NoSuchUi(ui))?;
        window.position = position;
        window.placement = crate::Placement::Absolute;
        self.touch();
        Ok(())
    }

    /// `simUI.getTitle`.
    ///
    /// # Errors
    /// [`UiError::NoSuchUi`].
    pub fn title(&self, ui: i64) -> Result<&str, UiError> {
        Ok(&self.uis.get(&ui).ok_or(UiError::NoSuchUi(ui))?.title)
    }

    /// `simUI.setTitle`.
    ///
    /// # Errors
    /// [`UiError::NoSuchUi`], or a title over [`MAX_TEXT_LEN`].
    pub fn set_title(&mut self, ui: i64, title: &str) -> Result<(), UiError> {
        check_text(title)?;
        let window = self.uis.get_mut(&ui).ok_or(UiError::NoSuchUi(ui))?;
        title.clone_into(&mut window.title);
        self.touch();
        Ok(())
    }

    /// `simUI.getWidgetVisibility`: the widget's own flag (a hidden group or window
    /// also hides it).
    ///
    /// # Errors
    /// Bad handle or id.
    pub fn widget_visible(&self, ui: i64, id: i64) -> Result<bool, UiError> {
        Ok(self.widget(ui, id)?.visible)
    }

    /// `simUI.setWidgetVisibility`. A hidden widget refuses [`Uis::interact`], as a
    /// user cannot reach it.
    ///
    /// # Errors
    /// Bad handle or id.
    pub fn set_widget_visible(&mut self, ui: i64, id: i64, visible: bool) -> Result<(), UiError> {
        let (_, w) = widget_mut(&mut self.uis, ui, id)?;
        w.visible = visible;
        self.touch();
        Ok(())
    }

    /// `simUI.setButtonText`. Queues no event: Qt's `clicked` does not fire on a
    /// text change.
    ///
    /// # Errors
    /// Bad handle or id, not a button, or text over [`MAX_TEXT_LEN`].
    pub fn set_button_text(&mut self, ui: i64, id: i64, text: &str) -> Result<(), UiError> {
        check_text(text)?;
        let (_, w) = widget_mut(&mut self.uis, ui, id)?;
        let WidgetKind::Button(b) = &mut w.kind else {
            return Err(wrong_type(id, "button", &w.kind));
        };
        text.clone_into(&mut b.text);
        self.touch();
        Ok(())
    }

    /// Acts as the user would (gantry's `simUI.interact`, for the viewer and tests):
    ///
    /// | widget | `value` | effect | event |
    /// |---|---|---|---|
    /// | slider | number (rounded, clamped) | moves it | `on-change(v)` if it moved |
    /// | spinbox | number (clamped; truncated if integer) | sets it | `on-change(v)` if changed |
    /// | edit | text | types it and presses Enter | `on-change(text)` if changed, then `on-editing-finished(text)` |
    /// | checkbox | nil (toggle), boolean, or 0/1/2 | sets it | `on-change(state)` if changed |
    /// | button | ignored | clicks (toggles if checkable) | `on-click` |
    /// | radiobutton | ignored | checks it, unchecks its siblings | `on-click` |
    /// | label | text (a link's href) | follows a link | `on-link-activated(href)` |
    /// | id 0 | ignored | clicks the window's close button | `on-close`, or hides the window without one |
    ///
    /// # Errors
    /// Bad handle or id; a value of the wrong type; a hidden window, a disabled or
    /// invisible widget (or inside a disabled group), a group or stretch, or closing a
    /// window that is not `closeable`: what a user could not do either.
    pub fn interact(&mut self, ui: i64, id: i64, value: &Value) -> Result<(), UiError> {
        let window = self.uis.get(&ui).ok_or(UiError::NoSuchUi(ui))?;
        if !window.visible {
            return Err(UiError::NotInteractive(format!("ui {ui} is hidden")));
        }
        if id == 0 {
            return self.close(ui);
        }
        match reachable(&window.content, id) {
            None => return Err(UiError::NoSuchWidget(id)),
            Some(false) => {
                return Err(UiError::NotInteractive(format!("widget {id} is disabled or hidden")));
            }
            Some(true) if !window.enabled => {
                return Err(UiError::NotInteractive(format!("ui {ui} is disabled")));
            }
            Some(true) => {}
        }
        let (owner, w) = widget_mut(&mut self.uis, ui, id)?;
        let events = user_input(&mut w.kind, id, value)?;
        if matches!(w.kind, WidgetKind::Radiobutton(_)) {
            self.set_radio(ui, id, true);
        }
        self.touch();
        for (callback, value) in events {
            self.queue(ui, id, callback, value, owner);
        }
        Ok(())
    }

    /// The user clicks the window's close button.
    fn close(&mut self, ui: i64) -> Result<(), UiError> {
        let window = self.uis.get_mut(&ui).ok_or(UiError::NoSuchUi(ui))?;
        if !window.closeable {
            return Err(UiError::NotInteractive(format!("ui {ui} is not closeable")));
        }
        // With an on-close callback the window stays open: the script decides (simUI
        // ignores the close event then).
        let (callback, owner) = (window.on_close.clone(), window.owner);
        if callback.is_none() {
            window.visible = false;
        }
        self.touch();
        self.queue(ui, 0, callback, Value::Nil, owner);
        Ok(())
    }

    /// Sets radio button `id` and, when checking it, unchecks the radio buttons beside it.
    fn set_radio(&mut self, ui: i64, id: i64, checked: bool) {
        let Some(parent) = self.uis.get_mut(&ui).and_then(|u| u.content.parent_of_mut(id)) else {
            return;
        };
        for w in parent.rows.iter_mut().flatten() {
            if let WidgetKind::Radiobutton(r) = &mut w.kind {
                if w.id == id {
                    r.checked = checked;
                } else if checked {
                    r.checked = false;
                }
            }
        }
    }

    /// Queues `callback(ui, widget, value)` if there is a callback.
    fn queue(&mut self, ui: i64, widget: i64, callback: Option<String>, value: Value, owner: Option<Handle>) {
        let Some(callback) = callback else {
            return;
        };
        if self.events.len() >= MAX_EVENTS {
            self.events.pop_front();
            if !self.overflowed {
                self.overflowed = true;
                self.diag.warnings.push(format!(
                    "simUI: more than {MAX_EVENTS} UI events are waiting for their scripts; dropping the oldest"
                ));
            }
        }
        self.events.push_back(UiEvent {
            ui,
            widget,
            callback,
            value,
            script_object: owner,
        });
    }

    fn touch(&mut self) {
        self.revision = self.revision.wrapping_add(1);
    }
}

/// Applies a user action to a widget's state; returns the callbacks it triggers (`None`
/// where the widget has no callback or nothing changed), in the order Qt emits them.
fn user_input(kind: &mut WidgetKind, id: i64, value: &Value) -> Result<Vec<(Option<String>, Value)>, UiError> {
    let mut events = Vec::new();
    match kind {
        WidgetKind::Slider(s) => {
            let v = number(value, "slider")?;
            // Clamping in f64 first keeps the cast in range.
            let v = v.round().clamp(s.minimum as f64, s.maximum as f64) as i64;
            let changed = v != s.value;
            s.value = v;
            events.push((s.on_change.clone().filter(|_| changed), Value::Int(v)));
        }
        WidgetKind::Spinbox(s) => {
            let v = number(value, "spinbox")?;
            let v = if s.float { v } else { v.trunc() }.clamp(s.minimum, s.maximum);
            let changed = v != s.value;
            s.value = v;
            events.push((s.on_change.clone().filter(|_| changed), spinbox_event_value(s.float, v)));
        }
        WidgetKind::Edit(e) => {
            let Value::Str(text) = value else {
                return Err(expected("an edit", "text", value));
            };
            check_text(text)?;
            let changed = e.value != *text;
            e.value.clone_from(text);
            events.push((e.on_change.clone().filter(|_| changed), value.clone()));
            events.push((e.on_editing_finished.clone(), value.clone()));
        }
        WidgetKind::Checkbox(c) => {
            let v = match value {
                Value::Nil if c.value == 0 => 2,
                Value::Nil => 0,
                Value::Bool(true) => 2,
                Value::Bool(false) => 0,
                other => match other.as_i64() {
                    Some(v @ 0..=2) => v,
                    _ => {
                        return Err(UiError::InvalidValue(
                            "invalid checkbox value: must be nil (toggle), a boolean, or 0, 1 or 2".into(),
                        ));
                    }
                },
            };
            let changed = v != c.value;
            c.value = v;
            events.push((c.on_change.clone().filter(|_| changed), Value::Int(v)));
        }
        WidgetKind::Button(b) => {
            if b.checkable {
                b.checked = !b.checked;
            }
            events.push((b.on_click.clone(), Value::Nil));
        }
        WidgetKind::Radiobutton(r) => {
            // Qt emits clicked even when the button was already checked.
            events.push((r.on_click.clone(), Value::Nil));
        }
        WidgetKind::Label(l) => {
            let Value::Str(_) = value else {
                return Err(expected("a label", "a link (text)", value));
            };
            events.push((l.on_link_activated.clone(), value.clone()));
        }
        other @ (WidgetKind::Group(_) | WidgetKind::Stretch(_)) => {
            return Err(UiError::NotInteractive(format!(
                "widget {id} is a {}, which takes no input",
                other.name()
            )));
        }
    }
    Ok(events)
}

/// The widget and its UI's owner, borrowing only the map so the caller can still queue.
fn widget_mut(uis: &mut BTreeMap<i64, Ui>, ui: i64, id: i64) -> Result<(Option<Handle>, &mut Widget), UiError> {
    let window = uis.get_mut(&ui).ok_or(UiError::NoSuchUi(ui))?;
    let owner = window.owner;
    let w = window.content.find_mut(id).ok_or(UiError::NoSuchWidget(id))?;
    Ok((owner, w))
}

/// Whether a user could reach widget `id`: it and every group around it enabled and
/// visible. `None` when there is no such widget.
fn reachable(c: &Container, id: i64) -> Option<bool> {
    c.rows.iter().flatten().find_map(|w| {
        let usable = w.enabled && w.visible;
        if w.id == id {
            Some(usable)
        } else if let WidgetKind::Group(g) = &w.kind {
            reachable(&g.content, id).map(|inner| inner && usable)
        } else {
            None
        }
    })
}

fn wrong_type(id: i64, expected: &'static str, actual: &WidgetKind) -> UiError {
    UiError::WrongWidgetType {
        id,
        expected,
        actual: actual.name(),
    }
}

fn check_text(text: &str) -> Result<(), UiError> {
    if text.len() > MAX_TEXT_LEN {
        return Err(UiError::InvalidValue(format!(
            "text too long: {} bytes (at most {MAX_TEXT_LEN})",
            text.len()
        )));
    }
    Ok(())
}

/// A finite number for a slider or spin box.
fn number(value: &Value, what: &str) -> Result<f64, UiError> {
    match value.as_f64() {
        Some(v) if v.is_finite() => Ok(v),
        _ => Err(expected(&format!("a {what}"), "a finite number", value)),
    }
}

fn expected(widget: &str, what: &str, got: &Value) -> UiError {
    UiError::InvalidValue(format!("{widget} takes {what}, got {}", got.type_name()))
}

/// What an `on-change` of a spin box receives: an integer unless it is a float spin box
/// (simUI connects `valueChanged(int)` or `valueChanged(double)`).
fn spinbox_event_value(float: bool, value: f64) -> Value {
    if float {
        Value::Float(value)
    } else {
        Value::Int(value as i64)
    }
}
