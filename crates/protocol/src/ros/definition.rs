//! Parses the `.msg`-style definition text of the [`catalog`](super::catalog) into
//! unresolved types: field names, types (nested ones by full name), array shapes and
//! defaults.
//!
//! The grammar is the subset of ROS 2's `.msg`/`.srv` files the catalog needs:
//! `TYPE NAME`, `TYPE NAME DEFAULT` (numbers and booleans), `TYPE NAME=VALUE`
//! (a constant: kept in the text, skipped by the codec), `TYPE[]` (sequence),
//! `TYPE[N]` (fixed array), `#` comments, and `---` between a service's request and
//! response (and between an action's goal, result and feedback). Bounded sequences and strings (`[<=N]`, `string<=N`) are refused rather
//! than silently treated as unbounded, since the catalog has none.

use super::primitive::Primitive;
use crate::Value;

/// How many values a field holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Arity {
    /// One value.
    Single,
    /// Exactly this many, with no count on the wire.
    Fixed(usize),
    /// Any number, after a `u32` count.
    Sequence,
}

/// A field's element type before nested names are resolved.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum RawKind {
    Primitive(Primitive),
    /// A message type by full name, `pkg/msg/Type`.
    Message(String),
}

/// One field as written.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct RawField {
    pub(crate) name: String,
    pub(crate) kind: RawKind,
    pub(crate) arity: Arity,
    /// The declared default of a primitive field (`float64 w 1`), if any.
    pub(crate) default: Option<Value>,
}

/// One message type as written.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct RawType {
    /// Full name, `pkg/msg/Type` (or `pkg/srv/Type_Request` for a service's halves).
    pub(crate) name: String,
    /// Its own lines (fields and constants), one per line.
    pub(crate) definition: String,
    pub(crate) fields: Vec<RawField>,
}

/// A service type as written: its name and the names of its two halves.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct RawService {
    pub(crate) name: String,
    pub(crate) request: String,
    pub(crate) response: String,
}

/// An action type as written: its name and its parts' names. The goal, result and
/// feedback are written in the catalog; the rest is what rcl_action builds around them.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct RawAction {
    /// `pkg/action/Type`.
    pub(crate) name: String,
    /// `pkg/action/Type_Goal`, `_Result`, `_Feedback`.
    pub(crate) goal: String,
    pub(crate) result: String,
    pub(crate) feedback: String,
    /// `pkg/action/Type_FeedbackMessage`: a feedback with its goal's id.
    pub(crate) feedback_message: String,
    /// The services `pkg/action/Type_SendGoal` and `pkg/action/Type_GetResult`.
    pub(crate) send_goal: String,
    pub(crate) get_result: String,
}

/// A field of a nested message type given by full name.
fn message_field(name: &str, ty: &str) -> RawField {
    RawField {
        name: name.to_owned(),
        kind: RawKind::Message(ty.to_owned()),
        arity: Arity::Single,
        default: None,
    }
}

/// A type made of the given fields, with its definition text (nested action parts by
/// their full `pkg/action/Type_Part` names, as rosidl writes them).
fn composed(name: String, fields: Vec<RawField>, definition: &str) -> RawType {
    RawType {
        name,
        definition: definition.to_owned(),
        fields,
    }
}

/// What [`parse_actions`] finds: the actions, their services and their message types.
pub(crate) type ParsedActions = (Vec<RawAction>, Vec<RawService>, Vec<RawType>);

/// Parses one package's action definitions: sections headed `ACTION: Type`, goal,
/// result and feedback separated by `---`. Returns the actions, the services each
/// implies (`_SendGoal`, `_GetResult`) and every message type they need, as
/// `rosidl_generator` derives them for rcl_action.
pub(crate) fn parse_actions(package: &str, text: &str) -> Result<ParsedActions, String> {
    const UUID: &str = "unique_identifier_msgs/msg/UUID";
    let mut actions = Vec::new();
    let mut services = Vec::new();
    let mut types = Vec::new();
    for (short, lines) in sections(text)? {
        let name = format!("{package}/action/{short}");
        let dashes: Vec<usize> = lines
            .iter()
            .enumerate()
            .filter(|(_, l)| l.trim() == "---")
            .map(|(i, _)| i)
            .collect();
        let [a, b] = dashes[..] else {
            return Err(format!(
                "{name}: expected goal, result and feedback separated by two `---`"
            ));
        };
        let part = |suffix: &str| format!("{name}_{suffix}");
        let (goal, result, feedback) = (part("Goal"), part("Result"), part("Feedback"));
        types.push(parse_type(package, goal.clone(), &lines[..a])?);
        types.push(parse_type(package, result.clone(), &lines[a + 1..b])?);
        types.push(parse_type(package, feedback.clone(), &lines[b + 1..])?);
        let uuid = || message_field("goal_id", UUID);
        let (send_goal, get_result) = (part("SendGoal"), part("GetResult"));
        types.push(composed(
            format!("{send_goal}_Request"),
            vec![uuid(), message_field("goal", &goal)],
            &format!("unique_identifier_msgs/UUID goal_id\n{goal} goal\n"),
        ));
        types.push(composed(
            format!("{send_goal}_Response"),
            vec![
                RawField {
                    name: "accepted".to_owned(),
                    kind: RawKind::Primitive(Primitive::Bool),
                    arity: Arity::Single,
                    default: None,
                },
                message_field("stamp", "builtin_interfaces/msg/Time"),
            ],
            "bool accepted\nbuiltin_interfaces/Time stamp\n",
        ));
        types.push(composed(
            format!("{get_result}_Request"),
            vec![uuid()],
            "unique_identifier_msgs/UUID goal_id\n",
        ));
        types.push(composed(
            format!("{get_result}_Response"),
            vec![
                RawField {
                    name: "status".to_owned(),
                    kind: RawKind::Primitive(Primitive::Int8),
                    arity: Arity::Single,
                    default: None,
                },
                message_field("result", &result),
            ],
            &format!("int8 status\n{result} result\n"),
        ));
        let feedback_message = part("FeedbackMessage");
        types.push(composed(
            feedback_message.clone(),
            vec![uuid(), message_field("feedback", &feedback)],
            &format!("unique_identifier_msgs/UUID goal_id\n{feedback} feedback\n"),
        ));
        for service in [&send_goal, &get_result] {
            services.push(RawService {
                name: service.clone(),
                request: format!("{service}_Request"),
                response: format!("{service}_Response"),
            });
        }
        actions.push(RawAction {
            name,
            goal,
            result,
            feedback,
            feedback_message,
            send_goal,
            get_result,
        });
    }
    Ok((actions, services, types))
}

/// Parses one package's message definitions: sections headed `MSG: Type`.
pub(crate) fn parse_messages(package: &str, text: &str) -> Result<Vec<RawType>, String> {
    sections(text)?
        .into_iter()
        .map(|(short, lines)| {
            let name = format!("{package}/msg/{short}");
            parse_type(package, name, &lines)
        })
        .collect()
}

/// Parses one package's service definitions: sections headed `SRV: Type`, request and
/// response separated by `---`. Returns the services and their request and response
/// message types (`pkg/srv/Type_Request`, `pkg/srv/Type_Response`).
pub(crate) fn parse_services(package: &str, text: &str) -> Result<(Vec<RawService>, Vec<RawType>), String> {
    let mut services = Vec::new();
    let mut types = Vec::new();
    for (short, lines) in sections(text)? {
        let name = format!("{package}/srv/{short}");
        let split = lines
            .iter()
            .position(|l| l.trim() == "---")
            .ok_or_else(|| format!("{name}: no `---` between request and response"))?;
        let request = format!("{name}_Request");
        let response = format!("{name}_Response");
        types.push(parse_type(package, request.clone(), &lines[..split])?);
        types.push(parse_type(package, response.clone(), &lines[split + 1..])?);
        services.push(RawService {
            name,
            request,
            response,
        });
    }
    Ok((services, types))
}

/// Splits text into `(short name, lines)` sections at `MSG: ` / `SRV: ` / `ACTION: `
/// headers.
fn sections(text: &str) -> Result<Vec<(&str, Vec<&str>)>, String> {
    let mut out: Vec<(&str, Vec<&str>)> = Vec::new();
    for line in text.lines() {
        let header = line
            .strip_prefix("MSG: ")
            .or_else(|| line.strip_prefix("SRV: "))
            .or_else(|| line.strip_prefix("ACTION: "));
        match (header, out.last_mut()) {
            (Some(short), _) => out.push((short.trim(), Vec::new())),
            (None, Some((_, lines))) => lines.push(line),
            (None, None) if line.trim().is_empty() => {}
            (None, None) => return Err(format!("definition line {line:?} before any `MSG:` header")),
        }
    }
    Ok(out)
}

/// Parses the lines of one type.
fn parse_type(package: &str, name: String, lines: &[&str]) -> Result<RawType, String> {
    let mut fields = Vec::new();
    let mut definition = String::new();
    for line in lines {
        // Comments go; the definition text keeps only fields and constants.
        let code = line.split('#').next().unwrap_or("").trim();
        if code.is_empty() {
            continue;
        }
        definition.push_str(code);
        definition.push('\n');
        if let Some(field) = parse_line(package, code).map_err(|e| format!("{name}: {e} in {code:?}"))? {
            if fields.iter().any(|f: &RawField| f.name == field.name) {
                return Err(format!("{name}: field {:?} declared twice", field.name));
            }
            fields.push(field);
        }
    }
    Ok(RawType {
        name,
        definition,
        fields,
    })
}

/// Parses one non-empty line: a field, or `None` for a constant.
fn parse_line(package: &str, code: &str) -> Result<Option<RawField>, String> {
    let mut words = code.split_whitespace();
    let (Some(ty), Some(rest)) = (words.next(), words.next()) else {
        return Err("expected `TYPE NAME`".into());
    };
    if code[ty.len()..].contains('=') {
        // `uint8 INFRARED=1` or `uint8 INFRARED = 1`: a constant, not on the wire.
        return Ok(None);
    }
    let default = words.next();
    if words.next().is_some() {
        return Err("unexpected words after the default".into());
    }
    let (base, arity) = match ty.split_once('[') {
        None => (ty, Arity::Single),
        Some((base, "]")) => (base, Arity::Sequence),
        Some((base, dims)) => {
            let n = dims
                .strip_suffix(']')
                .and_then(|n| n.parse::<usize>().ok())
                .ok_or("only `[]` and `[N]` arrays are supported")?;
            (base, Arity::Fixed(n))
        }
    };
    if !is_identifier(rest) {
        return Err(format!("bad field name {rest:?}"));
    }
    let kind = match Primitive::parse(base) {
        Some(p) => RawKind::Primitive(p),
        None => RawKind::Message(qualify(package, base)?),
    };
    let default = match (default, &kind, arity) {
        (None, ..) => None,
        (Some(text), RawKind::Primitive(p), Arity::Single) => Some(parse_default(*p, text)?),
        (Some(_), ..) => return Err("defaults are supported on single builtin fields only".into()),
    };
    Ok(Some(RawField {
        name: rest.to_owned(),
        kind,
        arity,
        default,
    }))
}

/// The full name of a nested type: `Header` is `std_msgs`' (a ROS 1 leftover the ROS 2
/// tools keep), other bare names are in the same package.
fn qualify(package: &str, base: &str) -> Result<String, String> {
    let full = match base.split('/').collect::<Vec<_>>()[..] {
        ["Header"] => "std_msgs/msg/Header".to_owned(),
        [ty] => format!("{package}/msg/{ty}"),
        [pkg, ty] => format!("{pkg}/msg/{ty}"),
        [pkg, "msg", ty] => format!("{pkg}/msg/{ty}"),
        _ => return Err(format!("bad type name {base:?}")),
    };
    if full.split('/').all(is_identifier) {
        Ok(full)
    } else {
        Err(format!("bad type name {base:?} (bounded strings are not supported)"))
    }
}

/// A declared default, checked against the field's type.
fn parse_default(p: Primitive, text: &str) -> Result<Value, String> {
    let bad = || format!("bad default {text:?} for {}", p.name());
    match p {
        Primitive::Bool => match text {
            "true" => Ok(Value::Bool(true)),
            "false" => Ok(Value::Bool(false)),
            _ => Err(bad()),
        },
        Primitive::Float32 | Primitive::Float64 => text.parse::<f64>().map(Value::Float).map_err(|_| bad()),
        Primitive::String => Err("string defaults are not supported".into()),
        _ => {
            let (lo, hi) = p.int_range().ok_or_else(bad)?;
            match text.parse::<i64>() {
                Ok(i) if (lo..=hi).contains(&i) => Ok(Value::Int(i)),
                _ => Err(bad()),
            }
        }
    }
}

/// ASCII letters, digits and `_`, not starting with a digit.
fn is_identifier(s: &str) -> bool {
    s.chars().next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_constants_arrays_and_defaults() {
        let text = "MSG: T\n# comment\nuint8 KIND=3\nHeader header\nfloat64[9] k # trailing\n\
                    geometry_msgs/Vector3[] v\nfloat64 w 1\nstring s\n";
        let types = parse_messages("pkg", text).unwrap();
        assert_eq!(types.len(), 1);
        let t = &types[0];
        assert_eq!(t.name, "pkg/msg/T");
        assert_eq!(
            t.definition,
            "uint8 KIND=3\nHeader header\nfloat64[9] k\ngeometry_msgs/Vector3[] v\nfloat64 w 1\nstring s\n"
        );
        let names: Vec<&str> = t.fields.iter().map(|f| f.name.as_str()).collect();
        assert_eq!(names, ["header", "k", "v", "w", "s"]);
        assert_eq!(t.fields[0].kind, RawKind::Message("std_msgs/msg/Header".into()));
        assert_eq!(t.fields[1].arity, Arity::Fixed(9));
        assert_eq!(t.fields[2].kind, RawKind::Message("geometry_msgs/msg/Vector3".into()));
        assert_eq!(t.fields[2].arity, Arity::Sequence);
        assert_eq!(t.fields[3].default, Some(Value::Float(1.0)));
    }

    #[test]
    fn services_split_at_dashes() {
        let (srvs, types) = parse_services("s", "SRV: Set\nbool data\n---\nbool ok\n").unwrap();
        assert_eq!(srvs[0].name, "s/srv/Set");
        assert_eq!(types[0].name, "s/srv/Set_Request");
        assert_eq!(types[1].name, "s/srv/Set_Response");
        assert_eq!(types[1].fields[0].name, "ok");
    }

    #[test]
    fn unsupported_syntax_is_refused() {
        for bad in [
            "int32[<=3] a",
            "string<=5 s",
            "float64 x y z",
            "int8 a 300",
            "T 1bad",
            "x",
        ] {
            let text = format!("MSG: T\n{bad}\n");
            assert!(parse_messages("p", &text).is_err(), "{bad} should be refused");
        }
        assert!(parse_messages("p", "MSG: T\nint8 a\nint8 a\n").is_err());
        assert!(parse_services("p", "SRV: S\nint8 a\n").is_err());
        assert!(parse_actions("p", "ACTION: A\nint8 a\n---\nint8 b\n").is_err());
    }
}
