//! ROS 2 messages: the dynamic [`Value`](crate::Value)s scripts give to and from the
//! CDR bytes DDS carries, for the types in gantry's catalog, plus ROS 2 names to DDS
//! topic names.
//!
//! [`typed`] holds the messages gantry makes itself (`/tf`, `/joint_states`, images...),
//! encoded straight from Rust values on the same CDR rules, for the recorder and the
//! ROS 2 graph.
//!
//! Pure: the DDS transport lives elsewhere and hands this module bytes. Like every
//! decoder in this crate, [`MsgType::decode`] is total (never panics) and bounded (a
//! length read from the input never reserves more than the input can back), and is
//! fuzzed (`fuzz/fuzz_targets/ros_cdr.rs`).
//!
//! # Types
//!
//! The catalog (`catalog.rs`) holds ROS 2 Humble's definitions of `builtin_interfaces`,
//! `std_msgs`, `geometry_msgs`, `sensor_msgs`, `nav_msgs`, `rosgraph_msgs` and
//! `tf2_msgs` messages, `std_srvs` services, the action plumbing of `action_msgs` and
//! `unique_identifier_msgs`, and `example_interfaces`' tutorial service and action, in
//! `.msg` text parsed once on first use. Look types up with [`message_type`],
//! [`service_type`] and [`action_type`]; list them with [`known_message_types`],
//! [`known_service_types`] and [`known_action_types`].
//!
//! simROS2's interface names are found too: a service's `pkg/srv/TypeRequest` is
//! `pkg/srv/Type_Request`, an action's `pkg/action/TypeGoal` is `pkg/action/Type_Goal`
//! (likewise `Response`, `Result` and `Feedback`).
//!
//! # Values
//!
//! * A message is a [`Value::Map`](crate::Value::Map) of field name to value. Missing
//!   fields (and `nil`) take ROS's default, so `{linear = {x = 1}}` is a whole `Twist`;
//!   an unknown field name is an error (but for `Header.seq`, ROS 1's, which is
//!   ignored). An empty array (an empty Lua table) or `nil` is an all-default message.
//! * Integer fields take integers, and finite floats with any fraction dropped (toward
//!   zero, as CoppeliaSim's plugins convert numbers), range-checked for their type; float fields take any number (`float32` rounds; NaN and infinities are
//!   data); `bool` takes booleans only; `string` takes strings (or UTF-8 bytes).
//!   `byte`, `char` and `uint8` are numbers.
//! * A `builtin_interfaces` `Time` or `Duration` also takes a number of seconds (ROS 1's
//!   plugin took times that way).
//! * Arrays and sequences take arrays (an empty map counts as empty); arrays of
//!   `uint8`, `byte` and `char` also take bytes or strings, copied in one go (images).
//! * Decoding gives maps in field order, integers as `Int`, floats as `Float`, strings
//!   as `Str`, `uint8[]`/`byte[]` as `Bytes` and other arrays as `Array`. A `uint64`
//!   above `i64::MAX` does not fit a script integer and is an error.
//!
//! # Wire format
//!
//! Plain CDR (XCDR1) as the ROS 2 rmw implementations write it: a 4-byte encapsulation
//! header (`00 01 00 00`, little-endian; big-endian `00 00` is read too), then the
//! fields in order, each primitive aligned to its size (8 for 64-bit types) counting
//! from the end of the header. Strings are a `u32` length counting a trailing NUL, the
//! bytes and the NUL; sequences a `u32` count and the elements; fixed arrays just the
//! elements; nested messages inline. `bool` is one byte, and decoding refuses bytes
//! other than 0 and 1 (as Fast CDR does) so that whatever decodes re-encodes to the
//! same bytes. An empty message is one `0` byte (the C mapping's placeholder member);
//! a top-level one also decodes from nothing. Bytes after a message are ignored: RTPS
//! pads payloads to a multiple of 4.

mod action_type;
mod catalog;
mod cdr;
mod codec;
mod decode;
mod definition;
mod encode;
mod error;
mod field;
mod msg_type;
mod names;
mod path;
mod primitive;
mod registry;
mod srv_type;
pub mod typed;

pub use action_type::ActionType;
pub use cdr::CDR_LE_HEADER;
pub use error::{DecodeError, EncodeError, NameError, RosTypeError};
pub use msg_type::MsgType;
pub use names::{
    ActionTopics, action_topics, ros_topic_name, service_reply_topic, service_request_topic, topic_from_parts,
    topic_name,
};
pub use srv_type::SrvType;

pub use registry::MAX_DEPTH;
use registry::lookup;
pub(crate) use registry::registry;

/// Looks up a message type by name: `pkg/msg/Type`, or ROS 1 style `pkg/Type` (taken
/// as `pkg/msg/Type`). The halves of services (`std_srvs/srv/SetBool_Request`) are
/// found too.
///
/// # Errors
/// The type is not in the catalog; the error suggests close names in the same package.
pub fn message_type(name: &str) -> Result<&'static MsgType, RosTypeError> {
    let types = &registry().types;
    lookup(types, MsgType::name, "msg", "message", name).or_else(|e| {
        // simROS2 names the parts of services and actions without the underscore.
        const PARTS: [&str; 5] = ["Request", "Response", "Goal", "Result", "Feedback"];
        let (dir, short) = name.rsplit_once('/').ok_or(e.clone())?;
        let part = PARTS
            .iter()
            .find(|p| short.len() > p.len() && short.ends_with(*p) && !short.ends_with(&format!("_{p}")))
            .ok_or(e.clone())?;
        let base = &short[..short.len() - part.len()];
        lookup(types, MsgType::name, "msg", "message", &format!("{dir}/{base}_{part}")).map_err(|_| e)
    })
}

/// Looks up a service type by name: `pkg/srv/Type`, or `pkg/Type` (taken as
/// `pkg/srv/Type`).
///
/// # Errors
/// The type is not in the catalog; the error suggests close names in the same package.
pub fn service_type(name: &str) -> Result<&'static SrvType, RosTypeError> {
    lookup(&registry().services, SrvType::name, "srv", "service", name)
}

/// Looks up an action type by name: `pkg/action/Type`, or `pkg/Type` (taken as
/// `pkg/action/Type`).
///
/// # Errors
/// The type is not in the catalog; the error suggests close names in the same package.
pub fn action_type(name: &str) -> Result<&'static ActionType, RosTypeError> {
    lookup(&registry().actions, ActionType::name, "action", "action", name)
}

/// Every known action type, sorted by name.
pub fn known_action_types() -> impl Iterator<Item = &'static ActionType> {
    registry().actions.iter()
}

/// Every known message type (not the halves of services), sorted by name.
pub fn known_message_types() -> impl Iterator<Item = &'static MsgType> {
    registry().types.iter().filter(|t| t.name().contains("/msg/"))
}

/// Every known service type (not the services of actions), sorted by name.
pub fn known_service_types() -> impl Iterator<Item = &'static SrvType> {
    registry().services.iter().filter(|s| s.name().contains("/srv/"))
}
