//! The widgets of a custom UI and the layout tree that holds them.
//!
//! These are plain data: the parser builds them, [`Uis`](crate::Uis) changes their values,
//! and the viewer reads them to draw the window. Field names follow simUI's XML
//! attributes (`on-change` becomes `on_change`).

/// A widget: what every kind shares, plus the kind with its own state.
#[derive(Debug, Clone, PartialEq)]
pub struct Widget {
    /// The `id` attribute: positive when the XML gave one; negative and assigned in
    /// document order (-1, -2, ...) otherwise, as simUI does so the two never collide.
    pub id: i64,
    /// `enabled` (default true): a disabled widget is drawn greyed and ignores the user.
    pub enabled: bool,
    /// `visible` (default true).
    pub visible: bool,
    /// `style`: a Qt stylesheet, kept verbatim for the viewer.
    pub style: String,
    /// `stretch`: the widget's stretch factor in a vbox/hbox layout; `None` when not given.
    pub stretch: Option<i64>,
    /// `geometry` as x, y, width, height in pixels; only allowed in `layout="none"`.
    pub geometry: Option<[i64; 4]>,
    /// The kind and its kind-specific state.
    pub kind: WidgetKind,
}

/// The kinds of widget gantry implements, with their state.
#[derive(Debug, Clone, PartialEq)]
pub enum WidgetKind {
    /// `<hslider>` / `<vslider>`.
    Slider(Slider),
    /// `<button>`.
    Button(Button),
    /// `<label>`.
    Label(Label),
    /// `<edit>`: a one-line text field.
    Edit(Edit),
    /// `<checkbox>`.
    Checkbox(Checkbox),
    /// `<radiobutton>`.
    Radiobutton(Radiobutton),
    /// `<spinbox>`.
    Spinbox(Spinbox),
    /// `<group>`: a frame holding a nested layout.
    Group(Group),
    /// `<stretch>`: empty space in a vbox/hbox layout.
    Stretch(Stretch),
}

impl WidgetKind {
    /// The XML element name (`"hslider"`, `"button"`, ...), also used in error messages.
    pub fn name(&self) -> &'static str {
        match self {
            WidgetKind::Slider(s) => match s.orientation {
                Orientation::Horizontal => "hslider",
                Orientation::Vertical => "vslider",
            },
            WidgetKind::Button(_) => "button",
            WidgetKind::Label(_) => "label",
            WidgetKind::Edit(_) => "edit",
            WidgetKind::Checkbox(_) => "checkbox",
            WidgetKind::Radiobutton(_) => "radiobutton",
            WidgetKind::Spinbox(_) => "spinbox",
            WidgetKind::Group(_) => "group",
            WidgetKind::Stretch(_) => "stretch",
        }
    }
}

/// A slider's direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Orientation {
    /// `<hslider>`.
    Horizontal,
    /// `<vslider>`.
    Vertical,
}

/// Where a slider draws tick marks (`tick-position`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TickPosition {
    /// `none` (the default).
    None,
    /// `both-sides`.
    BothSides,
    /// `above`.
    Above,
    /// `below`.
    Below,
    /// `left`.
    Left,
    /// `right`.
    Right,
}

/// An integer slider. Invariant: `minimum <= value <= maximum`.
#[derive(Debug, Clone, PartialEq)]
pub struct Slider {
    /// Horizontal or vertical.
    pub orientation: Orientation,
    /// `minimum` (default 0).
    pub minimum: i64,
    /// `maximum` (default 100).
    pub maximum: i64,
    /// The current value (`value`, default 0, clamped into range).
    pub value: i64,
    /// `tick-interval` (default 0: Qt picks one).
    pub tick_interval: i64,
    /// `tick-position`.
    pub tick_position: TickPosition,
    /// `inverted`: the maximum is drawn at the left / bottom.
    pub inverted: bool,
    /// `on-change`: called `f(ui, id, newValue)`.
    pub on_change: Option<String>,
}

/// A push button.
#[derive(Debug, Clone, PartialEq)]
pub struct Button {
    /// `text` (default "???", as simUI).
    pub text: String,
    /// `default`: drawn as the dialog's default button.
    pub default: bool,
    /// `checkable`: the button toggles `checked` when clicked.
    pub checkable: bool,
    /// `checked`: the toggle state of a checkable button.
    pub checked: bool,
    /// `on-click`: called `f(ui, id)`.
    pub on_click: Option<String>,
}

/// A text label.
#[derive(Debug, Clone, PartialEq)]
pub struct Label {
    /// `text` (Qt rich text is allowed; kept verbatim).
    pub text: String,
    /// `word-wrap`.
    pub word_wrap: bool,
    /// `on-link-activated`: called `f(ui, id, href)` when a link in the text is clicked.
    pub on_link_activated: Option<String>,
}

/// A one-line text field.
#[derive(Debug, Clone, PartialEq)]
pub struct Edit {
    /// The current text (`value`).
    pub value: String,
    /// `on-change`: called `f(ui, id, text)` whenever the text changes.
    pub on_change: Option<String>,
    /// `on-editing-finished`: called `f(ui, id, text)` when the user presses Enter.
    pub on_editing_finished: Option<String>,
}

/// A check box. Its value uses Qt's check states, as simUI: 0 unchecked, 1 partially
/// checked, 2 checked.
#[derive(Debug, Clone, PartialEq)]
pub struct Checkbox {
    /// `text`.
    pub text: String,
    /// 0, 1 or 2 (`checked="true"` gives 2).
    pub value: i64,
    /// `on-change`: called `f(ui, id, value)` with 0, 1 or 2.
    pub on_change: Option<String>,
}

/// A radio button. Checking one unchecks the radio buttons of the same container, as
/// Qt's auto-exclusive radio buttons do.
#[derive(Debug, Clone, PartialEq)]
pub struct Radiobutton {
    /// `text`.
    pub text: String,
    /// `checked`.
    pub checked: bool,
    /// `on-click`: called `f(ui, id)`.
    pub on_click: Option<String>,
}

/// A number field with arrows. Invariant: `minimum <= value <= maximum`, and `value` is
/// whole when `float` is false.
#[derive(Debug, Clone, PartialEq)]
pub struct Spinbox {
    /// The current value.
    pub value: f64,
    /// `minimum` (default 0).
    pub minimum: f64,
    /// `maximum` (default 100).
    pub maximum: f64,
    /// `step` (default 1).
    pub step: f64,
    /// `decimals` shown; `None` for the default (6 for float spin boxes).
    pub decimals: Option<i64>,
    /// `float`: a real-valued spin box. Defaults to true when `minimum`, `maximum` or
    /// `step` has a fraction or `decimals` is given, as simUI.
    pub float: bool,
    /// `prefix` shown before the number.
    pub prefix: String,
    /// `suffix` shown after the number.
    pub suffix: String,
    /// `on-change`: called `f(ui, id, value)` (an integer unless `float`).
    pub on_change: Option<String>,
}

/// A frame around a nested layout.
#[derive(Debug, Clone, PartialEq)]
pub struct Group {
    /// `text`: the frame's title.
    pub text: String,
    /// `flat`: no frame is drawn, only the layout.
    pub flat: bool,
    /// The children.
    pub content: Container,
}

/// Empty space that takes the slack of a vbox/hbox layout.
#[derive(Debug, Clone, PartialEq)]
pub struct Stretch {
    /// `factor` (default 0).
    pub factor: i64,
}

/// How a container arranges its children (`layout` attribute).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layout {
    /// `vbox` (the default): top to bottom.
    VBox,
    /// `hbox`: left to right.
    HBox,
    /// `grid`: rows separated by `<br/>` elements.
    Grid,
    /// `form`: rows of two widgets, a label and a field.
    Form,
    /// `none`: children placed by their own `geometry`.
    None,
}

/// The children of the window or of a group, arranged in rows as simUI stores them.
///
/// * `vbox`, `hbox` and `none`: one widget per row, in document order (for `hbox` the
///   "rows" are laid out left to right);
/// * `form`: two widgets per row (label, field);
/// * `grid`: the rows the XML separated with `<br/>` (a row may be empty).
#[derive(Debug, Clone, PartialEq)]
pub struct Container {
    /// The `layout` attribute.
    pub layout: Layout,
    /// `content-margins` as left, top, right, bottom in pixels (default 7 each).
    pub margins: [i64; 4],
    /// The children, row by row.
    pub rows: Vec<Vec<Widget>>,
}

impl Container {
    /// Every widget in this container and below, depth first, in document order.
    pub fn widgets(&self) -> Vec<&Widget> {
        let mut out = Vec::new();
        self.collect(&mut out);
        out
    }

    fn collect<'a>(&'a self, out: &mut Vec<&'a Widget>) {
        for w in self.rows.iter().flatten() {
            out.push(w);
            if let WidgetKind::Group(g) = &w.kind {
                g.content.collect(out);
            }
        }
    }

    /// The widget with `id`, searched through nested groups.
    pub fn find(&self, id: i64) -> Option<&Widget> {
        self.rows.iter().flatten().find_map(|w| {
            if w.id == id {
                Some(w)
            } else if let WidgetKind::Group(g) = &w.kind {
                g.content.find(id)
            } else {
                None
            }
        })
    }

    /// The widget with `id`, mutably.
    pub(crate) fn find_mut(&mut self, id: i64) -> Option<&mut Widget> {
        for w in self.rows.iter_mut().flatten() {
            if w.id == id {
                return Some(w);
            }
            if let WidgetKind::Group(g) = &mut w.kind
                && let Some(found) = g.content.find_mut(id)
            {
                return Some(found);
            }
        }
        None
    }

    /// The container that directly holds widget `id` (for radio-button exclusivity).
    pub(crate) fn parent_of_mut(&mut self, id: i64) -> Option<&mut Container> {
        if self.rows.iter().flatten().any(|w| w.id == id) {
            return Some(self);
        }
        for w in self.rows.iter_mut().flatten() {
            if let WidgetKind::Group(g) = &mut w.kind
                && let Some(found) = g.content.parent_of_mut(id)
            {
                return Some(found);
            }
        }
        None
    }
}
