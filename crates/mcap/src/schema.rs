//! The ROS 2 message types the recorder writes, as `ros2msg` schema text.
//!
//! An MCAP schema of encoding `ros2msg` holds the type's `.msg` definition followed by
//! the definition of every type it uses, each after a line of 80 `=` and a line
//! `MSG: package/Type`, as rosbag2 writes them; readers (Foxglove, Rerun, the `mcap`
//! Python reader, `rosbags`) need the whole closure to decode a message. Comments of
//! the upstream `.msg` files are left out; fields, order, constants and types are
//! those of ROS 2 (Humble and later).

/// A ROS 2 message type: its name and its own definition, and the types it uses.
#[derive(Debug)]
pub struct MessageType {
    /// The full name, `package/msg/Type`.
    pub name: &'static str,
    /// The `.msg` text: one field or constant per line.
    pub definition: &'static str,
    /// Types named in `definition` (not builtin), in the order they are first used.
    pub uses: &'static [&'static MessageType],
}

/// The line before each dependency's definition.
const SEPARATOR: &str = "================================================================================";

/// `builtin_interfaces/msg/Time`.
pub static TIME: MessageType = MessageType {
    name: "builtin_interfaces/msg/Time",
    definition: "int32 sec\nuint32 nanosec\n",
    uses: &[],
};

/// `std_msgs/msg/Header`.
pub static HEADER: MessageType = MessageType {
    name: "std_msgs/msg/Header",
    definition: "builtin_interfaces/Time stamp\nstring frame_id\n",
    uses: &[&TIME],
};

/// `geometry_msgs/msg/Vector3`.
pub static VECTOR3: MessageType = MessageType {
    name: "geometry_msgs/msg/Vector3",
    definition: "float64 x\nfloat64 y\nfloat64 z\n",
    uses: &[],
};

/// `geometry_msgs/msg/Quaternion`.
pub static QUATERNION: MessageType = MessageType {
    name: "geometry_msgs/msg/Quaternion",
    definition: "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n",
    uses: &[],
};

/// `geometry_msgs/msg/Transform`.
pub static TRANSFORM: MessageType = MessageType {
    name: "geometry_msgs/msg/Transform",
    definition: "geometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation\n",
    uses: &[&VECTOR3, &QUATERNION],
};

/// `geometry_msgs/msg/TransformStamped`.
pub static TRANSFORM_STAMPED: MessageType = MessageType {
    name: "geometry_msgs/msg/TransformStamped",
    definition: "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/Transform transform\n",
    uses: &[&HEADER, &TRANSFORM],
};

/// `tf2_msgs/msg/TFMessage`: `/tf` and `/tf_static`.
pub static TF_MESSAGE: MessageType = MessageType {
    name: "tf2_msgs/msg/TFMessage",
    definition: "geometry_msgs/TransformStamped[] transforms\n",
    uses: &[&TRANSFORM_STAMPED],
};

/// `sensor_msgs/msg/JointState`: `/joint_states`.
pub static JOINT_STATE: MessageType = MessageType {
    name: "sensor_msgs/msg/JointState",
    definition: "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\nfloat64[] effort\n",
    uses: &[&HEADER],
};

/// `rcl_interfaces/msg/Log`: `/rosout`.
pub static LOG: MessageType = MessageType {
    name: "rcl_interfaces/msg/Log",
    definition: "byte DEBUG=10\nbyte INFO=20\nbyte WARN=30\nbyte ERROR=40\nbyte FATAL=50\n\
                 builtin_interfaces/Time stamp\nuint8 level\nstring name\nstring msg\nstring file\n\
                 string function\nuint32 line\n",
    uses: &[&TIME],
};

/// `std_msgs/msg/Float64`: graph streams.
pub static FLOAT64: MessageType = MessageType {
    name: "std_msgs/msg/Float64",
    definition: "float64 data\n",
    uses: &[],
};

/// `std_msgs/msg/Int32`: int32 signals.
pub static INT32: MessageType = MessageType {
    name: "std_msgs/msg/Int32",
    definition: "int32 data\n",
    uses: &[],
};

/// `std_msgs/msg/String`: string signals.
pub static STRING: MessageType = MessageType {
    name: "std_msgs/msg/String",
    definition: "string data\n",
    uses: &[],
};

/// `sensor_msgs/msg/Image`: vision sensor images.
pub static IMAGE: MessageType = MessageType {
    name: "sensor_msgs/msg/Image",
    definition: "std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\nuint8 is_bigendian\n\
                 uint32 step\nuint8[] data\n",
    uses: &[&HEADER],
};

/// `gantry_msgs/msg/Input`: `/gantry/input`, what reached the simulation from outside
/// (see [`crate::input`]). Not a ROS type: readers that do not know it decode it from
/// this definition or skip it.
pub static INPUT: MessageType = MessageType {
    name: "gantry_msgs/msg/Input",
    definition: "uint64 step
uint32 boundary
string kind
string name
int64 client
uint8[] args
",
    uses: &[],
};

/// `sensor_msgs/msg/Range`: proximity sensors.
pub static RANGE: MessageType = MessageType {
    name: "sensor_msgs/msg/Range",
    definition: "uint8 ULTRASOUND=0\nuint8 INFRARED=1\nstd_msgs/Header header\nuint8 radiation_type\n\
                 float32 field_of_view\nfloat32 min_range\nfloat32 max_range\nfloat32 range\n",
    uses: &[&HEADER],
};

impl MessageType {
    /// `package/Type`, the spelling of a `MSG:` line and of a field's type.
    pub fn short_name(&self) -> String {
        self.name.replacen("/msg/", "/", 1)
    }

    /// The schema text: this type's definition, then every type it uses, directly or
    /// not, once each, depth first in order of use.
    pub fn schema_text(&self) -> String {
        let mut out = self.definition.to_owned();
        let mut seen: Vec<&'static str> = vec![self.name];
        let mut stack: Vec<&'static MessageType> = self.uses.iter().rev().copied().collect();
        while let Some(t) = stack.pop() {
            if seen.contains(&t.name) {
                continue;
            }
            seen.push(t.name);
            out.push_str(SEPARATOR);
            out.push_str("\nMSG: ");
            out.push_str(&t.short_name());
            out.push('\n');
            out.push_str(t.definition);
            stack.extend(t.uses.iter().rev().copied());
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The `MSG:` names of a schema text, in order.
    fn sections(text: &str) -> Vec<&str> {
        text.lines().filter_map(|l| l.strip_prefix("MSG: ")).collect()
    }

    #[test]
    fn tf_message_carries_its_whole_closure_once_each() {
        let text = TF_MESSAGE.schema_text();
        assert!(text.starts_with("geometry_msgs/TransformStamped[] transforms\n"));
        assert_eq!(
            sections(&text),
            [
                "geometry_msgs/TransformStamped",
                "std_msgs/Header",
                "builtin_interfaces/Time",
                "geometry_msgs/Transform",
                "geometry_msgs/Vector3",
                "geometry_msgs/Quaternion",
            ]
        );
        assert!(text.contains(&format!(
            "{SEPARATOR}\nMSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\n"
        )));
    }

    #[test]
    fn a_type_used_twice_is_defined_once() {
        // Header and Log's stamp both use Time.
        let text = JOINT_STATE.schema_text();
        assert_eq!(sections(&text), ["std_msgs/Header", "builtin_interfaces/Time"]);
        assert_eq!(sections(&LOG.schema_text()), ["builtin_interfaces/Time"]);
        assert_eq!(sections(&FLOAT64.schema_text()), Vec::<&str>::new());
    }

    #[test]
    fn every_named_type_is_defined_in_the_schema() {
        const BUILTIN: &[&str] = &[
            "bool", "byte", "char", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64",
            "float32", "float64", "string",
        ];
        for t in [&TF_MESSAGE, &JOINT_STATE, &LOG, &FLOAT64, &RANGE] {
            let text = t.schema_text();
            let defined = sections(&text);
            for line in text
                .lines()
                .filter(|l| !l.is_empty() && !l.starts_with('=') && !l.starts_with("MSG:"))
            {
                let ty = line
                    .split_whitespace()
                    .next()
                    .unwrap_or_default()
                    .trim_end_matches("[]");
                assert!(
                    BUILTIN.contains(&ty) || defined.contains(&ty),
                    "{}: {ty} is used but not defined",
                    t.name
                );
            }
        }
    }

    #[test]
    fn the_separator_is_eighty_equals_signs() {
        assert_eq!(SEPARATOR.len(), 80);
        assert!(SEPARATOR.bytes().all(|b| b == b'='));
        assert_eq!(TF_MESSAGE.short_name(), "tf2_msgs/TFMessage");
    }
}
