//! Why a `simUI` operation was refused.

use gantry_scene::SimError;

use crate::{MAX_UIS, MAX_XML_LEN};

/// A refused `simUI` operation. Messages follow simUI's wording where it has one
/// ("invalid ui handle", "invalid widget id: 3"), so ported scripts see familiar errors;
/// the API layer appends `(in function 'simUI.x')`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum UiError {
    /// The text is not well-formed XML.
    #[error("invalid UI XML at line {line}, column {column}: {message}")]
    Syntax {
        /// 1-based line of the problem.
        line: u32,
        /// 1-based column of the problem.
        column: u32,
        /// What the XML parser found.
        message: String,
    },
    /// Well-formed XML that is not a valid UI: an unknown element, a bad attribute value,
    /// a duplicate id, a limit exceeded.
    #[error("{element} at line {line}, column {column}: {message}")]
    Element {
        /// The element as simUI names it, e.g. `hslider[id=1]`.
        element: String,
        /// 1-based line where the element starts.
        line: u32,
        /// 1-based column where the element starts.
        column: u32,
        /// What is wrong with it.
        message: String,
    },
    /// The XML text is longer than [`MAX_XML_LEN`].
    #[error("UI XML too long: {0} bytes (at most {MAX_XML_LEN})")]
    TooLong(usize),
    /// [`MAX_UIS`] UIs exist already.
    #[error("too many UIs: at most {MAX_UIS} may exist at once; destroy unused ones with simUI.destroy")]
    TooManyUis,
    /// No UI has this handle (never created, or destroyed).
    #[error("invalid ui handle: {0}")]
    NoSuchUi(i64),
    /// The UI has no widget with this id.
    #[error("invalid widget id: {0}")]
    NoSuchWidget(i64),
    /// The widget exists but is of another kind than the function handles.
    #[error("invalid widget type. expected {expected} (widget {id} is a {actual})")]
    WrongWidgetType {
        /// The widget id.
        id: i64,
        /// What the function needs, e.g. "slider".
        expected: &'static str,
        /// What the widget is, e.g. "label".
        actual: &'static str,
    },
    /// A value the widget cannot take (a checkbox value of 5, a text over the size limit).
    #[error("{0}")]
    InvalidValue(String),
    /// A simulated user action on something a user could not act on (a disabled widget,
    /// a hidden window, a label without links).
    #[error("{0}")]
    NotInteractive(String),
}

/// A `simUI` failure as the registry returns it, with the same text: missing UIs and
/// widgets are missing items, bad XML and values argument errors, limits and actions a
/// user could not take refusals.
impl From<UiError> for SimError {
    fn from(e: UiError) -> Self {
        let message = e.to_string();
        match e {
            UiError::NoSuchUi(_) | UiError::NoSuchWidget(_) => SimError::NoSuchItem(message),
            UiError::Syntax { .. }
            | UiError::Element { .. }
            | UiError::TooLong(_)
            | UiError::WrongWidgetType { .. }
            | UiError::InvalidValue(_) => SimError::BadArgument(message),
            UiError::TooManyUis | UiError::NotInteractive(_) => SimError::Refused(message),
        }
    }
}
