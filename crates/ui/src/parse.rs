//! simUI's XML → [`Ui`]: pure, bounded, and as lenient as simUI where it is lenient.
//!
//! What is copied from simUI (`XMLUtils.cpp`, `Widget.cpp`, `LayoutWidget.cpp`):
//! * unknown attributes are ignored with a warning "unknown UI XML attribute 'x' in
//!   widget 'y'"; the tutorial's `resizeable` is read as `resizable`, silently, as
//!   CoppeliaSim runs the tutorial without a warning;
//! * hyphen-less spellings of hyphenated attributes (`onchange`, `tickposition`) are
//!   accepted, with a "deprecated" note once per name (an information line, not a
//!   warning: the seed scripts use them and work as intended);
//! * booleans must be exactly `true` or `false`; integers must parse as 32-bit;
//! * ids must be positive; widgets without one get negative ids; ids are unique per UI;
//! * `<stretch>` only in vbox/hbox, `<br/>` only in grid, `geometry` only in `layout="none"`,
//!   and a form layout needs an even number of children.
//!
//! What differs: the root may also be `<window>`; elements gantry does not implement
//! (combobox, tabs, plot, image, ...) are refused with a message naming the supported
//! ones, rather than silently dropped, so a script never reads a widget that is not there.
//! Errors carry the line and column of the offending element.

use std::collections::BTreeSet;

use gantry_scene::Handle;
use roxmltree::{Document, Node, ParsingOptions};

use crate::error::UiError;
use crate::widget::{
    Button, Checkbox, Container, Edit, Group, Label, Layout, Orientation, Radiobutton, Slider, Spinbox, Stretch,
    TickPosition, Widget, WidgetKind,
};
use crate::window::{Placement, Ui};
use crate::{MAX_DEPTH, MAX_WIDGETS, MAX_XML_LEN};

/// XML nodes of any kind (elements, text, comments) the parser builds at most. Bounds
/// memory before widgets are even counted; generous for [`MAX_WIDGETS`] elements with
/// whitespace and comments between them.
const MAX_XML_NODES: u32 = 8 * MAX_WIDGETS as u32 + 64;

/// What is wrong with one element of simUI's XML: the message of [`UiError::Element`],
/// which adds the element and its position. Wording follows simUI's where it has one.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub(super) enum UiParseError {
    /// The document element is neither `<ui>` nor `<window>`.
    #[error("root element must be <ui>")]
    Root,
    /// `geometry` on a widget whose parent's layout is not `none`.
    #[error("cannot set geometry with current layout")]
    GeometryInLayout,
    /// A form layout with an odd number of children.
    #[error("extra elements in layout (a form layout needs pairs of widgets)")]
    OddForm,
    /// More than [`MAX_WIDGETS`] elements in one UI.
    #[error("too many widgets (at most {MAX_WIDGETS} per UI)")]
    TooManyWidgets,
    /// An `id` that is not a positive 32-bit integer.
    #[error("id must be a positive integer")]
    BadId,
    /// Two widgets of one UI with the same id.
    #[error("id must be unique (within ui scope). duplicate id: {0}")]
    DuplicateId(i64),
    /// `<stretch>` outside a vbox or hbox.
    #[error("stretch must be placed in a widget with vbox/hbox layout")]
    StretchOutsideBox,
    /// Groups nested deeper than [`MAX_DEPTH`].
    #[error("groups nested too deeply (at most {MAX_DEPTH} levels)")]
    TooDeep,
    /// A simUI element gantry does not implement (the tag).
    #[error(
        "<{0}> is not supported by gantry (supported: hslider, vslider, button, label, edit, checkbox, \
         radiobutton, spinbox, group, stretch)"
    )]
    Unsupported(String),
    /// A tag simUI does not know either.
    #[error("invalid element <{0}>")]
    UnknownElement(String),
    /// A boolean attribute other than `true` or `false`.
    #[error("invalid value '{value}' for attribute '{name}': must be true or false")]
    NotBool {
        /// The value as written.
        value: String,
        /// The attribute.
        name: &'static str,
    },
    /// An integer attribute that is not a 32-bit integer.
    #[error("invalid value '{value}' for attribute '{name}': must be a 32-bit integer")]
    NotI32 {
        /// The value as written.
        value: String,
        /// The attribute.
        name: &'static str,
    },
    /// A number attribute that is not a finite number.
    #[error("invalid value '{value}' for attribute '{name}': must be a finite number")]
    NotFinite {
        /// The value as written.
        value: String,
        /// The attribute.
        name: &'static str,
    },
    /// A list attribute (`position`, `geometry`) with the wrong number of elements.
    #[error("attribute '{name}' must have exactly {count} elements")]
    WrongCount {
        /// The attribute.
        name: &'static str,
        /// How many it needs.
        count: usize,
    },
    /// A list attribute with an element that is not a 32-bit integer.
    #[error("invalid value '{value}' for attribute '{name}': must be integers")]
    NotIntegers {
        /// The value as written.
        value: String,
        /// The attribute.
        name: &'static str,
    },
    /// An attribute that must be one of a few words.
    #[error("invalid value for attribute '{name}': '{value}' (must be one of: {valid})")]
    NotAChoice {
        /// The attribute.
        name: &'static str,
        /// The value as written.
        value: String,
        /// The accepted words, quoted and comma-separated.
        valid: String,
    },
}

/// Warnings gathered while parsing, and the deprecated names already reported (simUI
/// reports each once per session; gantry once per world).
#[derive(Debug, Clone, Default)]
pub(super) struct Diagnostics {
    /// Warning lines not yet moved to the log.
    pub warnings: Vec<String>,
    /// Information lines (deprecated spellings) not yet moved to the log.
    pub notes: Vec<String>,
    /// Hyphen-less attribute names already warned about.
    pub deprecated_seen: BTreeSet<String>,
}

/// Parses `xml` into a UI with the given handle and owner.
///
/// Warnings go to `diag` even when parsing then fails, as simUI logs them as it goes.
pub(super) fn parse(xml: &str, handle: i64, owner: Option<Handle>, diag: &mut Diagnostics) -> Result<Ui, UiError> {
    if xml.len() > MAX_XML_LEN {
        return Err(UiError::TooLong(xml.len()));
    }
    let options = ParsingOptions {
        // simUI's tinyxml2 has no DTD support either, and entities are an attack surface.
        allow_dtd: false,
        nodes_limit: MAX_XML_NODES,
    };
    let doc = Document::parse_with_options(xml, options).map_err(|e| {
        let pos = e.pos();
        UiError::Syntax {
            line: pos.row,
            column: pos.col,
            message: e.to_string(),
        }
    })?;
    let mut parser = Parser {
        doc: &doc,
        diag,
        widget_count: 0,
        next_auto_id: -1,
        ids: BTreeSet::new(),
    };
    parser.window(doc.root_element(), handle, owner)
}

struct Parser<'d, 'input> {
    doc: &'d Document<'input>,
    diag: &'d mut Diagnostics,
    /// Elements parsed so far, checked against [`MAX_WIDGETS`].
    widget_count: usize,
    /// The next automatic (negative) id.
    next_auto_id: i64,
    /// Ids in use, for the uniqueness check.
    ids: BTreeSet<i64>,
}

impl<'d, 'input> Parser<'d, 'input> {
    /// An error located at `node`, named as simUI names elements (`hslider[id=1]`).
    fn error(&self, node: Node<'_, '_>, id: Option<i64>, why: UiParseError) -> UiError {
        let pos = self.doc.text_pos_at(node.range().start);
        let tag = node.tag_name().name();
        let element = match id {
            Some(id) if id > 0 => format!("{tag}[id={id}]"),
            _ => tag.to_owned(),
        };
        UiError::Element {
            element,
            line: pos.row,
            column: pos.col,
            message: why.to_string(),
        }
    }

    fn window(&mut self, node: Node<'d, 'input>, handle: i64, owner: Option<Handle>) -> Result<Ui, UiError> {
        let tag = node.tag_name().name();
        if tag != "ui" && tag != "window" {
            return Err(self.error(node, None, UiParseError::Root));
        }
        let mut a = Attrs::new(node);
        let ui = (|| -> Result<Ui, UiParseError> {
            let (layout, margins) = layout_attrs(&mut a)?;
            Ok(Ui {
                handle,
                owner,
                title: a.string("title", "Custom UI"),
                enabled: a.bool("enabled", true)?,
                resizable: a.bool("resizable", false)?,
                closeable: a.bool("closeable", false)?,
                modal: a.bool("modal", false)?,
                on_close: a.callback("on-close"),
                style: a.string("style", ""),
                placement: match a.choice("placement", "center", &["center", "relative", "absolute", "banner"])? {
                    "relative" => Placement::Relative,
                    "absolute" => Placement::Absolute,
                    "banner" => Placement::Banner,
                    _ => Placement::Center,
                },
                position: a.ints::<2>("position", [50, 50])?,
                size: a.ints::<2>("size", [-1, -1])?,
                activate: a.bool("activate", true)?,
                visible: true,
                // Filled below, once the window's own attributes are known to be valid.
                content: Container {
                    layout,
                    margins,
                    rows: Vec::new(),
                },
            })
        })();
        let mut ui = ui.map_err(|m| self.error(node, None, m))?;
        a.finish(tag, self.diag);
        ui.content = self.container(node, None, ui.content.layout, ui.content.margins, 1)?;
        Ok(ui)
    }

    /// The children of the window or of a group, arranged in rows (see [`Container`]).
    fn container(
        &mut self,
        node: Node<'d, 'input>,
        id: Option<i64>,
        layout: Layout,
        margins: [i64; 4],
        depth: usize,
    ) -> Result<Container, UiError> {
        let mut rows = Vec::new();
        let mut row = Vec::new();
        // Text between elements is ignored, as tinyxml2's element walk ignores it.
        for child in node.children().filter(Node::is_element) {
            if child.tag_name().name() == "br" && layout == Layout::Grid {
                rows.push(std::mem::take(&mut row));
                continue;
            }
            let w = self.widget(child, layout, depth)?;
            if w.geometry.is_some() && layout != Layout::None {
                return Err(self.error(child, Some(w.id), UiParseError::GeometryInLayout));
            }
            row.push(w);
            let row_full = match layout {
                Layout::Form => row.len() == 2,
                Layout::Grid => false,
                Layout::VBox | Layout::HBox | Layout::None => true,
            };
            if row_full {
                rows.push(std::mem::take(&mut row));
            }
        }
        if !row.is_empty() {
            if layout == Layout::Grid {
                rows.push(row);
            } else {
                // Only a form's odd last child gets here.
                return Err(self.error(node, id, UiParseError::OddForm));
            }
        }
        Ok(Container { layout, margins, rows })
    }

    fn widget(&mut self, node: Node<'d, 'input>, parent_layout: Layout, depth: usize) -> Result<Widget, UiError> {
        self.widget_count += 1;
        if self.widget_count > MAX_WIDGETS {
            return Err(self.error(node, None, UiParseError::TooManyWidgets));
        }
        let tag = node.tag_name().name();
        let mut a = Attrs::new(node);

        // Common attributes (simUI's Widget::parse).
        let id = match a.get("id") {
            Some(v) => match parse_i32(v) {
                Some(id) if id > 0 => id,
                _ => return Err(self.error(node, None, UiParseError::BadId)),
            },
            None => {
                let id = self.next_auto_id;
                self.next_auto_id -= 1;
                id
            }
        };
        let at = |p: &Self, m: UiParseError| p.error(node, Some(id), m);
        let common = (|| -> Result<_, UiParseError> {
            let geometry = match a.get("geometry") {
                Some(_) => Some(a.ints::<4>("geometry", [-1; 4])?),
                None => None,
            };
            let style = a.string("style", "");
            let enabled = a.bool("enabled", true)?;
            let visible = a.bool("visible", true)?;
            let stretch = a.int("stretch", -1)?;
            Ok((geometry, style, enabled, visible, (stretch != -1).then_some(stretch)))
        })();
        let (geometry, style, enabled, visible, stretch) = common.map_err(|m| at(self, m))?;

        let kind = match tag {
            "hslider" => slider(&mut a, Orientation::Horizontal),
            "vslider" => slider(&mut a, Orientation::Vertical),
            "button" => button(&mut a),
            "label" => label(&mut a),
            "edit" => edit(&mut a),
            "checkbox" => checkbox(&mut a),
            "radiobutton" => radiobutton(&mut a),
            "spinbox" => spinbox(&mut a),
            "stretch" => {
                if !matches!(parent_layout, Layout::VBox | Layout::HBox) {
                    return Err(at(self, UiParseError::StretchOutsideBox));
                }
                a.int("factor", 0).map(|factor| WidgetKind::Stretch(Stretch { factor }))
            }
            "group" => {
                if depth >= MAX_DEPTH {
                    return Err(at(self, UiParseError::TooDeep));
                }
                let text = a.string("text", "");
                let flat = a.bool("flat", false).map_err(|m| at(self, m))?;
                let (layout, margins) = layout_attrs(&mut a).map_err(|m| at(self, m))?;
                // Unknown attributes of the group are reported before its children's, in
                // document order.
                a.finish(tag, self.diag);
                let content = self.container(node, Some(id), layout, margins, depth + 1)?;
                Ok(WidgetKind::Group(Group { text, flat, content }))
            }
            "combobox" | "tabs" | "tab" | "image" | "plot" | "table" | "tree" | "progressbar" | "text-browser"
            | "scene3d" | "svg" | "properties" | "dataflow" => Err(UiParseError::Unsupported(tag.to_owned())),
            _ => Err(UiParseError::UnknownElement(tag.to_owned())),
        }
        .map_err(|m| at(self, m))?;

        if !matches!(kind, WidgetKind::Group(_)) {
            a.finish(tag, self.diag);
        }
        if !self.ids.insert(id) {
            return Err(at(self, UiParseError::DuplicateId(id)));
        }
        Ok(Widget {
            id,
            enabled,
            visible,
            style,
            stretch,
            geometry,
            kind,
        })
    }
}

/// `layout` and `content-margins`, shared by the window and groups.
fn layout_attrs(a: &mut Attrs<'_, '_>) -> Result<(Layout, [i64; 4]), UiParseError> {
    let layout = match a.choice("layout", "vbox", &["vbox", "hbox", "grid", "form", "none"])? {
        "hbox" => Layout::HBox,
        "grid" => Layout::Grid,
        "form" => Layout::Form,
        "none" => Layout::None,
        _ => Layout::VBox,
    };
    let margins = a.ints::<4>("content-margins", [7; 4])?;
    Ok((layout, margins))
}

fn slider(a: &mut Attrs<'_, '_>, orientation: Orientation) -> Result<WidgetKind, UiParseError> {
    let value = a.int("value", 0)?;
    let minimum = a.int("minimum", 0)?;
    let maximum = a.int("maximum", 100)?;
    let tick_interval = a.int("tick-interval", 0)?;
    let tick_position = match a.choice(
        "tick-position",
        "none",
        &["none", "both-sides", "above", "below", "left", "right"],
    )? {
        "both-sides" => TickPosition::BothSides,
        "above" => TickPosition::Above,
        "below" => TickPosition::Below,
        "left" => TickPosition::Left,
        "right" => TickPosition::Right,
        _ => TickPosition::None,
    };
    let inverted = a.bool("inverted", false)?;
    let on_change = a.callback("on-change");
    // Qt's setMinimum then setMaximum leave minimum = maximum when maximum < minimum.
    let minimum = minimum.min(maximum);
    Ok(WidgetKind::Slider(Slider {
        orientation,
        minimum,
        maximum,
        value: value.clamp(minimum, maximum),
        tick_interval,
        tick_position,
        inverted,
        on_change,
    }))
}

fn button(a: &mut Attrs<'_, '_>) -> Result<WidgetKind, UiParseError> {
    let text = a.string("text", "???");
    let default = a.bool("default", false)?;
    // Accepted for compatibility; the viewer does not auto-repeat or draw icons.
    a.bool("auto-repeat", false)?;
    a.int("auto-repeat-delay", 0)?;
    a.int("auto-repeat-interval", 200)?;
    a.bool("auto-exclusive", false)?;
    a.string("icon", "");
    let checked = a.bool("checked", false)?;
    let checkable = a.bool("checkable", false)?;
    let on_click = a.callback("on-click");
    Ok(WidgetKind::Button(Button {
        text,
        default,
        checkable,
        checked,
        on_click,
    }))
}

fn label(a: &mut Attrs<'_, '_>) -> Result<WidgetKind, UiParseError> {
    let text = a.string("text", "");
    let word_wrap = a.bool("word-wrap", false)?;
    let on_link_activated = a.callback("on-link-activated");
    Ok(WidgetKind::Label(Label {
        text,
        word_wrap,
        on_link_activated,
    }))
}

fn edit(a: &mut Attrs<'_, '_>) -> Result<WidgetKind, UiParseError> {
    let value = a.string("value", "");
    let on_change = a.callback("on-change");
    let on_editing_finished = a.callback("on-editing-finished");
    Ok(WidgetKind::Edit(Edit {
        value,
        on_change,
        on_editing_finished,
    }))
}

fn checkbox(a: &mut Attrs<'_, '_>) -> Result<WidgetKind, UiParseError> {
    let text = a.string("text", "???");
    let checked = a.bool("checked", false)?;
    // Accepted for compatibility; a checkbox that cannot be checked is not modelled.
    a.bool("checkable", true)?;
    a.bool("auto-exclusive", false)?;
    let on_change = a.callback("on-change");
    Ok(WidgetKind::Checkbox(Checkbox {
        text,
        value: if checked { 2 } else { 0 },
        on_change,
    }))
}

fn radiobutton(a: &mut Attrs<'_, '_>) -> Result<WidgetKind, UiParseError> {
    let text = a.string("text", "???");
    let checked = a.bool("checked", false)?;
    a.bool("auto-exclusive", true)?;
    let on_click = a.callback("on-click");
    Ok(WidgetKind::Radiobutton(Radiobutton {
        text,
        checked,
        on_click,
    }))
}

fn spinbox(a: &mut Attrs<'_, '_>) -> Result<WidgetKind, UiParseError> {
    let value = a.float("value", 0.0)?;
    let minimum = a.float("minimum", 0.0)?;
    let maximum = a.float("maximum", 100.0)?;
    let prefix = a.string("prefix", "");
    let suffix = a.string("suffix", "");
    let step = a.float("step", 1.0)?;
    let decimals = a.int("decimals", -1)?;
    let on_change = a.callback("on-change");
    let has_fraction = |x: f64| (x - x.floor()).abs() > 1e-6;
    let detected = has_fraction(minimum) || has_fraction(maximum) || has_fraction(step) || decimals > -1;
    let float = a.bool("float", detected)?;
    let (minimum, maximum) = if float {
        (minimum, maximum)
    } else {
        (minimum.trunc(), maximum.trunc())
    };
    let minimum = minimum.min(maximum);
    let value = if float { value } else { value.trunc() };
    Ok(WidgetKind::Spinbox(Spinbox {
        value: value.clamp(minimum, maximum),
        minimum,
        maximum,
        step,
        decimals: (decimals > -1).then_some(decimals),
        float,
        prefix,
        suffix,
        on_change,
    }))
}

/// A 32-bit integer as simUI's `boost::lexical_cast<int>` accepts it (surrounding
/// whitespace is not allowed there either).
fn parse_i32(s: &str) -> Option<i64> {
    s.parse::<i32>().ok().map(i64::from)
}

/// The attributes of one element, remembering which ones the parser asked for so the
/// others can be reported as unknown.
struct Attrs<'a, 'input> {
    node: Node<'a, 'input>,
    known: BTreeSet<String>,
    /// Hyphen-less spellings found, with the name they stand for.
    deprecated: Vec<(String, &'static str)>,
}

impl<'a, 'input> Attrs<'a, 'input> {
    fn new(node: Node<'a, 'input>) -> Self {
        Self {
            node,
            known: BTreeSet::new(),
            deprecated: Vec::new(),
        }
    }

    /// The raw value of `name`, or of its hyphen-less spelling.
    fn get(&mut self, name: &'static str) -> Option<&'a str> {
        self.known.insert(name.to_owned());
        if let Some(v) = self.node.attribute(name) {
            return Some(v);
        }
        // CoppeliaSim's BubbleRob tutorial (and the lab sheet) spell it so, and
        // CoppeliaSim takes it without a word.
        if name == "resizable"
            && let Some(v) = self.node.attribute("resizeable")
        {
            self.known.insert("resizeable".to_owned());
            return Some(v);
        }
        if name.contains('-') {
            let old = name.replace('-', "");
            if let Some(v) = self.node.attribute(old.as_str()) {
                self.known.insert(old.clone());
                self.deprecated.push((old, name));
                return Some(v);
            }
        }
        None
    }

    fn string(&mut self, name: &'static str, default: &str) -> String {
        self.get(name).unwrap_or(default).to_owned()
    }

    /// A callback name; an empty one means none, as in simUI.
    fn callback(&mut self, name: &'static str) -> Option<String> {
        self.get(name).filter(|s| !s.is_empty()).map(str::to_owned)
    }

    fn bool(&mut self, name: &'static str, default: bool) -> Result<bool, UiParseError> {
        match self.get(name) {
            None => Ok(default),
            Some("true") => Ok(true),
            Some("false") => Ok(false),
            Some(v) => Err(UiParseError::NotBool {
                value: v.to_owned(),
                name,
            }),
        }
    }

    fn int(&mut self, name: &'static str, default: i64) -> Result<i64, UiParseError> {
        match self.get(name) {
            None => Ok(default),
            Some(v) => parse_i32(v).ok_or_else(|| UiParseError::NotI32 {
                value: v.to_owned(),
                name,
            }),
        }
    }

    fn float(&mut self, name: &'static str, default: f64) -> Result<f64, UiParseError> {
        match self.get(name) {
            None => Ok(default),
            Some(v) => match v.parse::<f64>() {
                Ok(f) if f.is_finite() => Ok(f),
                _ => Err(UiParseError::NotFinite {
                    value: v.to_owned(),
                    name,
                }),
            },
        }
    }

    /// `N` comma-separated integers, e.g. `position="10,20"`.
    fn ints<const N: usize>(&mut self, name: &'static str, default: [i64; N]) -> Result<[i64; N], UiParseError> {
        let Some(v) = self.get(name) else {
            return Ok(default);
        };
        let parts: Vec<&str> = v.split(',').filter(|p| !p.is_empty()).collect();
        if parts.len() != N {
            return Err(UiParseError::WrongCount { name, count: N });
        }
        let mut out = [0; N];
        for (slot, p) in out.iter_mut().zip(parts) {
            *slot = parse_i32(p.trim()).ok_or_else(|| UiParseError::NotIntegers {
                value: v.to_owned(),
                name,
            })?;
        }
        Ok(out)
    }

    /// One of `valid` (returned as the static string so callers can match on it).
    fn choice(
        &mut self,
        name: &'static str,
        default: &'static str,
        valid: &[&'static str],
    ) -> Result<&'static str, UiParseError> {
        let v = self.get(name).unwrap_or(default);
        valid.iter().copied().find(|c| *c == v).ok_or_else(|| {
            let list: Vec<String> = valid.iter().map(|c| format!("'{c}'")).collect();
            UiParseError::NotAChoice {
                name,
                value: v.to_owned(),
                valid: list.join(", "),
            }
        })
    }

    /// Reports deprecated spellings (once per name) and attributes nobody asked for.
    fn finish(&mut self, widget: &str, diag: &mut Diagnostics) {
        for (old, new) in std::mem::take(&mut self.deprecated) {
            if diag.deprecated_seen.insert(old.clone()) {
                diag.notes.push(format!(
                    "simUI: attribute name '{old}' is deprecated. please use '{new}' instead."
                ));
            }
        }
        for attr in self.node.attributes() {
            if !self.known.contains(attr.name()) {
                diag.warnings.push(format!(
                    "simUI: unknown UI XML attribute '{}' in widget '{widget}'",
                    attr.name()
                ));
            }
        }
    }
}
