//! [`MsgType`]: one known ROS 2 message type, its name and fields (its codec entry
//! points are in `codec.rs`).

use super::field::Field;

/// A ROS 2 message type known to gantry.
///
/// Obtained from [`message_type`](super::message_type) (or a service's
/// [`request`](super::SrvType::request) and [`response`](super::SrvType::response));
/// lives for the whole program.
#[derive(Debug)]
pub struct MsgType {
    /// `pkg/msg/Type`.
    name: String,
    /// The `.msg` text of its own fields and constants.
    definition: String,
    fields: Vec<Field>,
    /// Fewest bytes one value takes on the wire (padding aside; at least 1), which bounds
    /// what a sequence count may claim.
    min_size: usize,
}

impl MsgType {
    /// A type with its fields resolved (by the registry).
    pub(crate) fn new(name: String, definition: String, fields: Vec<Field>) -> MsgType {
        MsgType {
            name,
            definition,
            fields,
            min_size: 1,
        }
    }

    pub(crate) fn set_min_size(&mut self, size: usize) {
        self.min_size = size;
    }

    pub(crate) fn min_size(&self) -> usize {
        self.min_size
    }

    pub(crate) fn fields(&self) -> &[Field] {
        &self.fields
    }

    /// The field names, comma-separated, for "does not exist" errors.
    pub(crate) fn field_list(&self) -> String {
        let names: Vec<&str> = self.fields.iter().map(|f| f.name.as_str()).collect();
        if names.is_empty() {
            "none".to_owned()
        } else {
            names.join(", ")
        }
    }

    /// The canonical name, `geometry_msgs/msg/Twist` (service halves:
    /// `std_srvs/srv/SetBool_Request`).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The DDS type name the rmw layer registers: `geometry_msgs::msg::dds_::Twist_`.
    pub fn dds_type_name(&self) -> String {
        let mut parts = self.name.rsplitn(2, '/');
        let short = parts.next().unwrap_or_default();
        let scope = parts.next().unwrap_or_default().replace('/', "::");
        format!("{scope}::dds_::{short}_")
    }

    /// The `.msg`-style text of its own fields (and constants), one per line, nested types
    /// by name, as ROS 2 writes them: for documentation and MCAP `ros2msg` schemas.
    pub fn definition(&self) -> &str {
        &self.definition
    }
}

#[cfg(test)]
mod tests {
    use super::super::message_type;
    use crate::Value;

    #[test]
    fn dds_names() {
        let t = message_type("geometry_msgs/msg/Twist").unwrap();
        assert_eq!(t.dds_type_name(), "geometry_msgs::msg::dds_::Twist_");
        assert_eq!(t.definition(), "Vector3 linear\nVector3 angular\n");
    }

    #[test]
    fn defaults_follow_the_definitions() {
        let q = message_type("geometry_msgs/msg/Quaternion").unwrap().default_value();
        assert_eq!(q.get("w"), Some(&Value::Float(1.0)));
        assert_eq!(q.get("x"), Some(&Value::Float(0.0)));
        let info = message_type("sensor_msgs/msg/CameraInfo").unwrap().default_value();
        assert_eq!(info.get("k"), Some(&Value::floats(&[0.0; 9])));
        assert_eq!(info.get("d"), Some(&Value::Array(vec![])));
        assert_eq!(
            info.get("roi").and_then(|r| r.get("do_rectify")),
            Some(&Value::Bool(false))
        );
        let img = message_type("sensor_msgs/msg/Image").unwrap().default_value();
        assert_eq!(img.get("data"), Some(&Value::Bytes(vec![])));
        assert_eq!(img.get("encoding"), Some(&Value::Str(String::new())));
        assert_eq!(
            img.get("header")
                .and_then(|h| h.get("stamp"))
                .and_then(|s| s.get("nanosec")),
            Some(&Value::Int(0))
        );
    }
}
