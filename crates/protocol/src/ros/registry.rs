//! The type table: the [`catalog`](super::catalog) parsed once, nested names resolved
//! to indices, and checked (every referenced type exists, no type contains itself,
//! nesting within [`MAX_DEPTH`]).

use std::sync::OnceLock;

use super::action_type::{ActionParts, ActionType};
use super::catalog;
use super::definition::{self, Arity, RawAction, RawKind, RawType};
use super::field::{Field, Kind};
use super::msg_type::MsgType;
use super::srv_type::SrvType;

/// Deepest nesting of message types the codec follows (the top-level message is depth
/// 1). The catalog's deepest types nest 4 levels (`tf2_msgs/msg/TFMessage` >
/// `TransformStamped` > `Header` > `Time`); the limit guards the recursion against a
/// future catalog entry, not against input, which cannot add nesting.
pub const MAX_DEPTH: usize = 16;

/// Every known type, sorted by name.
#[derive(Debug)]
pub(crate) struct Registry {
    /// Messages, including the `_Request`/`_Response` halves of services.
    pub(crate) types: Vec<MsgType>,
    pub(crate) services: Vec<SrvType>,
    pub(crate) actions: Vec<ActionType>,
}

/// The table, built on first use.
pub(crate) fn registry() -> &'static Registry {
    static REGISTRY: OnceLock<Registry> = OnceLock::new();
    // The catalog is a constant of this crate and `build` is unit-tested on it, so a
    // failure here is a bug in the catalog, found by `cargo test`, never an input error.
    REGISTRY.get_or_init(|| build().unwrap_or_else(|e| panic!("invalid built-in ROS 2 type catalog: {e}")))
}

/// The message type at `index` (an index taken from a [`Kind::Message`]).
pub(crate) fn nested(index: usize) -> &'static MsgType {
    &registry().types[index]
}

/// Parses and resolves the whole catalog.
pub(crate) fn build() -> Result<Registry, String> {
    let mut raw: Vec<RawType> = Vec::new();
    for (package, text) in catalog::MESSAGES {
        raw.extend(definition::parse_messages(package, text)?);
    }
    let mut raw_services = Vec::new();
    for (package, text) in catalog::SERVICES {
        let (services, types) = definition::parse_services(package, text)?;
        raw_services.extend(services);
        raw.extend(types);
    }
    let mut raw_actions: Vec<RawAction> = Vec::new();
    for (package, text) in catalog::ACTIONS {
        let (actions, services, types) = definition::parse_actions(package, text)?;
        raw_actions.extend(actions);
        raw_services.extend(services);
        raw.extend(types);
    }
    raw.sort_by(|a, b| a.name.cmp(&b.name));
    if let Some(w) = raw.windows(2).find(|w| w[0].name == w[1].name) {
        return Err(format!("{} is defined twice", w[0].name));
    }
    let index_of = |name: &str| raw.binary_search_by(|t| t.name.as_str().cmp(name)).ok();

    let mut types = Vec::with_capacity(raw.len());
    for t in &raw {
        let mut fields = Vec::with_capacity(t.fields.len());
        for f in &t.fields {
            let kind = match &f.kind {
                RawKind::Primitive(p) => Kind::Primitive(*p),
                RawKind::Message(name) => {
                    Kind::Message(index_of(name).ok_or_else(|| format!("{}.{}: unknown type {name}", t.name, f.name))?)
                }
            };
            fields.push(Field {
                name: f.name.clone(),
                kind,
                arity: f.arity,
                default: f.default.clone(),
            });
        }
        types.push(MsgType::new(t.name.clone(), t.definition.clone(), fields));
    }

    // Minimum wire sizes, innermost first; a type still unsized after MAX_DEPTH rounds
    // contains itself or nests too deep.
    let mut min_sizes: Vec<Option<usize>> = vec![None; types.len()];
    for _ in 0..=MAX_DEPTH {
        for i in 0..types.len() {
            if min_sizes[i].is_none() {
                min_sizes[i] = min_size(&types[i], &min_sizes);
            }
        }
    }
    for (t, size) in types.iter_mut().zip(&min_sizes) {
        let size = size.ok_or_else(|| format!("{} contains itself or nests deeper than {MAX_DEPTH}", t.name()))?;
        t.set_min_size(size);
    }

    let mut services = Vec::with_capacity(raw_services.len());
    for s in raw_services {
        let (Some(request), Some(response)) = (index_of(&s.request), index_of(&s.response)) else {
            return Err(format!("{}: request or response missing", s.name));
        };
        services.push(SrvType::new(s.name, request, response));
    }
    services.sort_by(|a, b| a.name().cmp(b.name()));
    let service_of = |name: &str| {
        services
            .binary_search_by(|s| s.name().cmp(name))
            .map_err(|_| format!("service {name} missing"))
    };
    let type_of = |name: &str| index_of(name).ok_or_else(|| format!("type {name} missing"));
    let mut actions = Vec::with_capacity(raw_actions.len());
    for a in raw_actions {
        let parts = ActionParts {
            goal: type_of(&a.goal)?,
            result: type_of(&a.result)?,
            feedback: type_of(&a.feedback)?,
            feedback_message: type_of(&a.feedback_message)?,
            send_goal: service_of(&a.send_goal)?,
            get_result: service_of(&a.get_result)?,
        };
        actions.push(ActionType::new(a.name, parts));
    }
    actions.sort_by(|a, b| a.name().cmp(b.name()));
    Ok(Registry {
        types,
        services,
        actions,
    })
}

/// The fewest bytes a message of type `t` takes (padding aside), if every nested type's
/// is known already. An empty message still takes its one placeholder byte.
fn min_size(t: &MsgType, known: &[Option<usize>]) -> Option<usize> {
    let mut total = 0usize;
    for f in t.fields() {
        let element = match f.kind {
            Kind::Primitive(p) => p.size(),
            Kind::Message(i) => known[i]?,
        };
        total += match f.arity {
            Arity::Single => element,
            Arity::Fixed(n) => element * n,
            Arity::Sequence => 4,
        };
    }
    Some(total.max(1))
}

/// Looks a name up among `names` (sorted), mapping ROS 1 style `pkg/Type` to
/// `pkg/{dir}/Type`; on failure, lists close names in the same package.
pub(crate) fn lookup<'a, T>(
    items: &'a [T],
    name_of: impl Fn(&T) -> &str,
    dir: &str,
    kind: &'static str,
    name: &str,
) -> Result<&'a T, super::RosTypeError> {
    let full = match name.split('/').collect::<Vec<_>>()[..] {
        [pkg, ty] => format!("{pkg}/{dir}/{ty}"),
        _ => name.to_owned(),
    };
    if let Ok(i) = items.binary_search_by(|t| name_of(t).cmp(&full)) {
        return Ok(&items[i]);
    }
    let package = full.split('/').next().unwrap_or("");
    let wanted = full.rsplit('/').next().unwrap_or("").to_ascii_lowercase();
    let mut close: Vec<(usize, &str)> = items
        .iter()
        .map(&name_of)
        .filter(|n| n.split('/').next() == Some(package))
        .filter_map(|n| {
            let short = n.rsplit('/').next().unwrap_or("").to_ascii_lowercase();
            let d = edit_distance(&short, &wanted);
            (d <= 2 || short.contains(&wanted) || wanted.contains(&short)).then_some((d, n))
        })
        .collect();
    close.sort();
    Err(super::RosTypeError::Unknown {
        kind,
        name: name.to_owned(),
        suggestions: close.into_iter().take(3).map(|(_, n)| n.to_owned()).collect(),
    })
}

/// Levenshtein distance, for "did you mean"; names are short, so the quadratic table is
/// nothing. Longer inputs are cut off at 64 characters to keep it so.
fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().take(64).collect();
    let b: Vec<char> = b.chars().take(64).collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.iter().enumerate() {
        let mut row = vec![i + 1; b.len() + 1];
        for (j, cb) in b.iter().enumerate() {
            let substitute = prev[j] + usize::from(ca != cb);
            row[j + 1] = substitute.min(prev[j + 1] + 1).min(row[j] + 1);
        }
        prev = row;
    }
    prev[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_catalog_builds_and_every_referenced_type_resolves() {
        let reg = build().expect("catalog is valid");
        for t in &reg.types {
            for f in t.fields() {
                if let Kind::Message(i) = f.kind {
                    assert!(i < reg.types.len(), "{}.{} points past the table", t.name(), f.name);
                }
            }
        }
        // Sorted and unique, as lookups assume.
        assert!(reg.types.windows(2).all(|w| w[0].name() < w[1].name()));
        assert!(reg.services.windows(2).all(|w| w[0].name() < w[1].name()));
        assert!(reg.actions.windows(2).all(|w| w[0].name() < w[1].name()));
        assert!(reg.types.len() > 80, "{} types", reg.types.len());
    }

    #[test]
    fn every_named_type_in_the_catalog_text_is_a_known_type() {
        // Independent of `build`: re-parse the text and look each nested name up.
        let reg = build().unwrap();
        for (package, text) in catalog::MESSAGES {
            for t in definition::parse_messages(package, text).unwrap() {
                for f in t.fields {
                    if let RawKind::Message(name) = f.kind {
                        assert!(
                            reg.types.iter().any(|t| t.name() == name),
                            "{}.{} refers to unknown {name}",
                            t.name,
                            f.name
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn a_type_containing_itself_is_found() {
        let mut sizes = vec![None];
        let t = MsgType::new(
            "p/msg/Loop".into(),
            String::new(),
            vec![Field {
                name: "me".into(),
                kind: Kind::Message(0),
                arity: Arity::Single,
                default: None,
            }],
        );
        for _ in 0..MAX_DEPTH {
            sizes[0] = min_size(&t, &sizes);
        }
        assert_eq!(sizes[0], None);
    }

    #[test]
    fn minimum_sizes() {
        let reg = registry();
        let size = |n: &str| reg.types.iter().find(|t| t.name() == n).unwrap().min_size();
        assert_eq!(size("std_msgs/msg/Empty"), 1);
        assert_eq!(size("std_msgs/msg/Header"), 12);
        assert_eq!(size("geometry_msgs/msg/Twist"), 48);
        assert_eq!(size("geometry_msgs/msg/PoseWithCovariance"), 56 + 36 * 8);
        assert_eq!(size("sensor_msgs/msg/JointState"), 12 + 16);
    }

    /// Levels of message nesting in `t`, itself included.
    fn depth(t: &MsgType) -> usize {
        1 + t
            .fields()
            .iter()
            .filter_map(|f| match f.kind {
                Kind::Message(i) => Some(depth(nested(i))),
                Kind::Primitive(_) => None,
            })
            .max()
            .unwrap_or(0)
    }

    #[test]
    fn the_catalog_nests_four_levels_deep_at_most() {
        // What the MAX_DEPTH docs say; TFMessage > TransformStamped > Header > Time.
        let deepest = registry().types.iter().map(depth).max().unwrap();
        assert_eq!(deepest, 4);
        assert!(deepest < MAX_DEPTH);
    }

    #[test]
    fn edit_distances() {
        assert_eq!(edit_distance("twist", "twst"), 1);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("pose", "pose"), 0);
    }
}
