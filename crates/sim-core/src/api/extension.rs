//! Extension strings: `sim.getExtensionString`. An object's extension string is free
//! text that plugins and task code read; CoppeliaSim files carry it (`Rst`), and
//! RLBench's waypoints keep their commands there (`open_gripper()`,
//! `ignore_collisions;linear`). Gantry keeps one string per object
//! ([`Object::extension`](crate::world::Object)), loaded from the scene and carried by
//! copies and model imports.
//!
//! With a key, the string is read as nested `name {value}` entries, and the key names a
//! path from the innermost name outwards: `shadow@povray` is the value of `shadow`
//! inside the value of `povray`.

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::world::World;

/// The functions this file implements, in alphabetical order.
pub(super) const FUNCTIONS: &[ApiFunction] = &[ApiFunction {
    name: "getExtensionString",
    call: ApiFn::World(get_extension_string),
    cost: Cost::Quick,
}];

/// `sim.getExtensionString(objectHandle, index, key=nil)` → the object's string, or with
/// a key the value it names (empty when the string has no such entry). Handle -1 is the
/// environment, whose string gantry does not keep (empty). `index` selects a compound
/// shape's component in CoppeliaSim; gantry keeps one string per object and ignores it.
fn get_extension_string(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let key = match a.get(2) {
        Value::Nil => "",
        _ => a.str(2)?,
    };
    let text = if h == -1 { "" } else { w.object(h)?.extension.as_str() };
    let out = if key.is_empty() {
        text.to_owned()
    } else {
        lookup(text, key).unwrap_or_default().to_owned()
    };
    Ok(vec![Value::Str(out)])
}

/// The value `key` (`inner@outer@...`) names in `text`, trimmed; `None` when absent.
pub(crate) fn lookup<'t>(text: &'t str, key: &str) -> Option<&'t str> {
    let mut scope = text;
    for name in key.rsplit('@') {
        scope = entries(scope).find(|(n, _)| *n == name)?.1?;
    }
    Some(scope.trim())
}

/// The top-level entries of `text`: each a name and, when braces follow it, what they
/// hold (without the braces). An unbalanced brace ends the entries.
fn entries(text: &str) -> impl Iterator<Item = (&str, Option<&str>)> {
    let mut rest = text;
    std::iter::from_fn(move || {
        rest = rest.trim_start();
        if rest.is_empty() || rest.starts_with('}') {
            // The end, or an unbalanced closing brace: no more entries.
            return None;
        }
        if rest.starts_with('{') {
            // A group without a name: skipped whole.
            let used = group(rest)?.1;
            rest = &rest[used..];
            return Some(("", None));
        }
        let end = rest
            .find(|c: char| c.is_whitespace() || c == '{' || c == '}')
            .unwrap_or(rest.len());
        let name = &rest[..end];
        rest = rest[end..].trim_start();
        if rest.starts_with('{') {
            let (value, used) = group(rest)?;
            rest = &rest[used..];
            Some((name, Some(value)))
        } else {
            Some((name, None))
        }
    })
}

/// A `{...}` group at the start of `text`: its content and the bytes it spans. `None`
/// when `text` does not start with `{` or the braces never balance.
fn group(text: &str) -> Option<(&str, usize)> {
    if !text.starts_with('{') {
        return None;
    }
    let mut depth = 0usize;
    for (i, c) in text.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => {
                depth = depth.checked_sub(1)?;
                if depth == 0 {
                    return Some((&text[1..i], i + 1));
                }
            }
            _ => {}
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::lookup;

    #[test]
    fn keys_name_nested_entries_innermost_first() {
        let s = "povray{ shadow {true} fadeXDist {0.00}} other {x {1}}";
        assert_eq!(lookup(s, "povray"), Some("shadow {true} fadeXDist {0.00}"));
        assert_eq!(lookup(s, "shadow@povray"), Some("true"));
        assert_eq!(lookup(s, "fadeXDist@povray"), Some("0.00"));
        assert_eq!(lookup(s, "x@other"), Some("1"));
        assert_eq!(lookup(s, "x@povray"), None);
        assert_eq!(lookup(s, "Shadow@povray"), None, "keys are case sensitive");
        // Plain words have no value; unbalanced braces end the search without a panic.
        assert_eq!(lookup("ignore_collisions;linear", "linear"), None);
        assert_eq!(lookup("open_gripper()", "open_gripper()"), None);
        assert_eq!(lookup("a {b {c}", "a"), None);
        assert_eq!(lookup("} a {1}", "a"), None);
        assert_eq!(lookup("", "a"), None);
    }
}
