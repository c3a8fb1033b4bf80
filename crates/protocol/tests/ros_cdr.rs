//! The ROS 2 CDR codec from outside: byte-exact layouts worked out by hand, round trips
//! of every known type, every error message, hostile input, and name mapping.

use gantry_protocol::Value;
use gantry_protocol::ros::{
    self, DecodeError, MsgType, action_topics, action_type, known_action_types, known_message_types,
    known_service_types, message_type, ros_topic_name, service_reply_topic, service_request_topic, service_type,
    topic_name,
};

/// `{k = v, ...}` with string keys.
fn map(pairs: &[(&str, Value)]) -> Value {
    Value::Map(pairs.iter().map(|(k, v)| (Value::from(*k), v.clone())).collect())
}

fn ty(name: &str) -> &'static MsgType {
    message_type(name).unwrap_or_else(|e| panic!("{e}"))
}

/// Sets field `key` of a message map (which must have it).
fn set(msg: &mut Value, key: &str, value: Value) {
    let Value::Map(pairs) = msg else {
        panic!("not a map: {msg:?}")
    };
    let slot = pairs
        .iter_mut()
        .find(|(k, _)| k.as_str() == Some(key))
        .expect("field exists");
    slot.1 = value;
}

const HDR: [u8; 4] = [0x00, 0x01, 0x00, 0x00];

fn with_header(body: &[u8]) -> Vec<u8> {
    let mut v = HDR.to_vec();
    v.extend_from_slice(body);
    v
}

// ---- byte-exact layouts ----

#[test]
fn string_hi_layout() {
    let t = ty("std_msgs/msg/String");
    let bytes = t.encode(&map(&[("data", "hi".into())])).unwrap();
    assert_eq!(
        bytes,
        [0x00, 0x01, 0x00, 0x00, 0x03, 0x00, 0x00, 0x00, 0x68, 0x69, 0x00]
    );
    assert_eq!(t.decode(&bytes).unwrap(), map(&[("data", "hi".into())]));
}

#[test]
fn twist_layout_with_missing_fields_defaulted() {
    let t = ty("geometry_msgs/msg/Twist");
    let v = map(&[
        ("linear", map(&[("x", Value::Int(1))])),
        ("angular", map(&[("z", Value::Float(-0.5))])),
    ]);
    let bytes = t.encode(&v).unwrap();
    let mut body = Vec::new();
    for x in [1.0f64, 0.0, 0.0, 0.0, 0.0, -0.5] {
        body.extend_from_slice(&x.to_le_bytes());
    }
    assert_eq!(&body[..8], [0, 0, 0, 0, 0, 0, 0xf0, 0x3f]);
    assert_eq!(&body[40..], [0, 0, 0, 0, 0, 0, 0xe0, 0xbf]);
    assert_eq!(bytes, with_header(&body));
    let back = t.decode(&bytes).unwrap();
    assert_eq!(back.get("linear").and_then(|l| l.get("x")), Some(&Value::Float(1.0)));
    assert_eq!(back.get("angular").and_then(|l| l.get("z")), Some(&Value::Float(-0.5)));
}

#[test]
fn clock_layout() {
    let t = ty("rosgraph_msgs/msg/Clock");
    let v = map(&[("clock", map(&[("sec", Value::Int(5)), ("nanosec", Value::Int(7))]))]);
    let bytes = t.encode(&v).unwrap();
    assert_eq!(bytes, with_header(&[5, 0, 0, 0, 7, 0, 0, 0]));
    assert_eq!(t.decode(&bytes).unwrap(), v);
}

#[test]
fn joint_state_layout_pads_before_the_float64_elements() {
    let t = ty("sensor_msgs/msg/JointState");
    let v = map(&[
        (
            "header",
            map(&[("stamp", map(&[("sec", 1.into()), ("nanosec", 2.into())]))]),
        ),
        ("name", Value::Array(vec!["abcde".into()])),
        ("position", Value::floats(&[1.5])),
        ("effort", Value::Array(vec![Value::Int(-2)])),
    ]);
    let bytes = t.encode(&v).unwrap();
    #[rustfmt::skip]
    let body: &[u8] = &[
        1, 0, 0, 0,                       // 0: stamp.sec
        2, 0, 0, 0,                       // 4: stamp.nanosec
        1, 0, 0, 0, 0,                    // 8: frame_id "" (length 1: the NUL)
        0, 0, 0,                          // 13: pad to 16
        1, 0, 0, 0,                       // 16: name count
        6, 0, 0, 0, b'a', b'b', b'c', b'd', b'e', 0, // 20: "abcde"
        0, 0,                             // 30: pad to 32
        1, 0, 0, 0,                       // 32: position count
        0, 0, 0, 0,                       // 36: pad to 40 for the float64
        0, 0, 0, 0, 0, 0, 0xf8, 0x3f,     // 40: 1.5
        0, 0, 0, 0,                       // 48: velocity count 0
        1, 0, 0, 0,                       // 52: effort count
        0, 0, 0, 0, 0, 0, 0, 0xc0,        // 56: -2.0
    ];
    assert_eq!(bytes, with_header(body));
    let back = t.decode(&bytes).unwrap();
    assert_eq!(back.get("name"), Some(&Value::Array(vec!["abcde".into()])));
    assert_eq!(back.get("position"), Some(&Value::floats(&[1.5])));
    assert_eq!(back.get("velocity"), Some(&Value::Array(vec![])));
    assert_eq!(back.get("effort"), Some(&Value::floats(&[-2.0])));
}

#[test]
fn header_then_float64_alignment_in_twist_stamped() {
    let t = ty("geometry_msgs/msg/TwistStamped");
    let v = map(&[
        (
            "header",
            map(&[
                ("stamp", map(&[("sec", 3.into()), ("nanosec", 4.into())])),
                ("frame_id", "base".into()),
            ]),
        ),
        ("twist", map(&[("linear", map(&[("x", 1.0.into())]))])),
    ]);
    let bytes = t.encode(&v).unwrap();
    let mut body = vec![3, 0, 0, 0, 4, 0, 0, 0, 5, 0, 0, 0, b'b', b'a', b's', b'e', 0];
    body.extend_from_slice(&[0; 7]); // 17 -> 24
    body.extend_from_slice(&1.0f64.to_le_bytes());
    body.extend_from_slice(&[0; 40]);
    assert_eq!(body.len(), 72);
    assert_eq!(bytes, with_header(&body));
    assert_eq!(
        t.decode(&bytes).unwrap().get("header").and_then(|h| h.get("frame_id")),
        Some(&"base".into())
    );
}

#[test]
fn empty_message_is_one_zero_byte_and_decodes_with_or_without_it() {
    let t = ty("std_msgs/msg/Empty");
    assert_eq!(t.encode(&Value::Map(vec![])).unwrap(), with_header(&[0]));
    assert_eq!(t.encode(&Value::Array(vec![])).unwrap(), with_header(&[0]));
    assert_eq!(t.decode(&with_header(&[0])).unwrap(), Value::Map(vec![]));
    assert_eq!(t.decode(&HDR).unwrap(), Value::Map(vec![]));
    let req = service_type("std_srvs/srv/Empty").unwrap().request();
    assert_eq!(req.encode(&Value::Nil).unwrap(), with_header(&[0]));
}

#[test]
fn encode_into_and_decode_body_count_alignment_from_the_body() {
    // A service request: encapsulation header, 16 bytes of request header, then the
    // fields, aligned from the end of the encapsulation header.
    let t = ty("std_msgs/msg/Float64");
    let mut out = HDR.to_vec();
    out.extend_from_slice(&[0xaa; 16]);
    t.encode_into(&map(&[("data", 2.0.into())]), &mut out, 4).unwrap();
    assert_eq!(out.len(), 4 + 16 + 8, "16 is 8-aligned: no padding");
    assert_eq!(&out[20..], 2.0f64.to_le_bytes());
    assert_eq!(
        t.decode_body(&out[4..], true, 16).unwrap(),
        map(&[("data", 2.0.into())])
    );

    // An odd origin: the float goes right at it, since alignment counts from there.
    let mut odd = vec![9, 9, 9];
    t.encode_into(&map(&[("data", 1.0.into())]), &mut odd, 3).unwrap();
    assert_eq!(&odd[3..], 1.0f64.to_le_bytes());

    // After a 4-byte prefix the float needs 4 bytes of padding.
    let mut four = vec![0; 4];
    t.encode_into(&map(&[("data", 1.0.into())]), &mut four, 0).unwrap();
    assert_eq!(four.len(), 16);
    assert_eq!(t.decode_body(&four, true, 4).unwrap(), map(&[("data", 1.0.into())]));

    let set_bool = service_type("std_srvs/SetBool").unwrap();
    let mut req = HDR.to_vec();
    req.extend_from_slice(&[0; 16]);
    set_bool
        .request()
        .encode_into(&map(&[("data", true.into())]), &mut req, 4)
        .unwrap();
    assert_eq!(req.len(), 21);
    assert_eq!(req[20], 1);
    assert!(matches!(
        t.decode_body(&[0; 4], true, 5),
        Err(DecodeError::Truncated { .. })
    ));
}

#[test]
fn big_endian_input_decodes() {
    let t = ty("sensor_msgs/msg/Range");
    #[rustfmt::skip]
    let be: &[u8] = &[
        0x00, 0x00, 0x00, 0x00,       // CDR_BE
        0, 0, 0, 9, 0, 0, 0, 10,      // stamp 9 s 10 ns
        0, 0, 0, 1, 0,                // frame_id ""
        1,                            // radiation_type INFRARED
        0, 0,                         // pad to 16
        0x3f, 0x00, 0x00, 0x00,       // field_of_view 0.5
        0x3e, 0x80, 0x00, 0x00,       // min_range 0.25
        0x40, 0x80, 0x00, 0x00,       // max_range 4
        0x3f, 0x80, 0x00, 0x00,       // range 1
    ];
    let v = t.decode(be).unwrap();
    assert_eq!(v.get("radiation_type"), Some(&Value::Int(1)));
    assert_eq!(v.get("field_of_view"), Some(&Value::Float(0.5)));
    assert_eq!(v.get("min_range"), Some(&Value::Float(0.25)));
    assert_eq!(v.get("max_range"), Some(&Value::Float(4.0)));
    assert_eq!(v.get("range"), Some(&Value::Float(1.0)));
    assert_eq!(
        v.get("header")
            .and_then(|h| h.get("stamp"))
            .and_then(|s| s.get("nanosec")),
        Some(&Value::Int(10))
    );
    // Re-encoded little-endian, it decodes to the same value.
    assert_eq!(t.decode(&t.encode(&v).unwrap()).unwrap(), v);

    let js = ty("sensor_msgs/msg/JointState");
    #[rustfmt::skip]
    let be: &[u8] = &[
        0x00, 0x00, 0x00, 0x00,
        0, 0, 0, 1, 0, 0, 0, 2,       // stamp
        0, 0, 0, 2, b'a', 0,          // frame_id "a"
        0, 0,                         // pad to 16
        0, 0, 0, 0,                   // name: none
        0, 0, 0, 1,                   // position: one, already 8-aligned at 24
        0x3f, 0xf8, 0, 0, 0, 0, 0, 0, // 1.5
        0, 0, 0, 0, 0, 0, 0, 0,       // velocity and effort: none
    ];
    let v = js.decode(be).unwrap();
    assert_eq!(v.get("position"), Some(&Value::floats(&[1.5])));
    assert_eq!(v.get("header").and_then(|h| h.get("frame_id")), Some(&"a".into()));
    let u16_be = ty("std_msgs/msg/UInt16").decode(&[0, 0, 0, 0, 0x12, 0x34]).unwrap();
    assert_eq!(u16_be, map(&[("data", Value::Int(0x1234))]));
}

// ---- round trips ----

/// A sample value of builtin type `base`, chosen to exercise its range.
fn sample(base: &str) -> Option<Value> {
    Some(match base {
        "bool" => Value::Bool(true),
        "string" => "h\u{e9}llo".into(),
        "float32" => Value::Float(0.5),
        "float64" => Value::Float(-1.25e10),
        "int8" => Value::Int(-3),
        "uint8" | "byte" | "char" => Value::Int(200),
        "int16" => Value::Int(-300),
        "uint16" => Value::Int(60_000),
        "int32" => Value::Int(-70_000),
        "uint32" => Value::Int(4_000_000_000),
        "int64" => Value::Int(i64::MIN),
        "uint64" => Value::Int(i64::MAX),
        _ => return None,
    })
}

/// The message type `base` names inside package `pkg`'s definitions.
fn nested_type(pkg: &str, base: &str) -> &'static MsgType {
    match base {
        "Header" => ty("std_msgs/msg/Header"),
        b if b.contains('/') => ty(b),
        b => ty(&format!("{pkg}/msg/{b}")),
    }
}

/// `t`'s default value with every field set to a non-default sample, worked out from
/// the definition text (so `definition()` is checked against the codec too).
fn filled(t: &MsgType) -> Value {
    let pkg = t.name().split('/').next().unwrap();
    let mut v = t.default_value();
    for line in t.definition().lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        if line.contains('=') || words.len() < 2 {
            continue;
        }
        let (base, shape) = match words[0].split_once('[') {
            Some((b, s)) => (b, Some(s.trim_end_matches(']'))),
            None => (words[0], None),
        };
        let one = || sample(base).unwrap_or_else(|| filled(nested_type(pkg, base)));
        let octet = base == "uint8" || base == "byte";
        let value = match shape {
            None => one(),
            Some("") if octet => Value::Bytes(vec![1, 2, 255]),
            Some("") => Value::Array(vec![one(), one()]),
            Some(n) => {
                let n: usize = n.parse().unwrap();
                if octet {
                    Value::Bytes(vec![7; n])
                } else {
                    Value::Array((0..n).map(|_| one()).collect())
                }
            }
        };
        set(&mut v, words[1], value);
    }
    v
}

fn every_type() -> Vec<&'static MsgType> {
    let mut all: Vec<&MsgType> = known_message_types().collect();
    for s in known_service_types() {
        all.push(s.request());
        all.push(s.response());
    }
    for a in known_action_types() {
        all.extend([a.goal(), a.result(), a.feedback(), a.feedback_message()]);
        for s in [a.send_goal(), a.get_result()] {
            all.push(s.request());
            all.push(s.response());
        }
    }
    all
}

#[test]
fn every_type_round_trips_filled_and_default() {
    let all = every_type();
    assert!(all.len() > 80, "{} types", all.len());
    for t in all {
        let v = filled(t);
        let bytes = t.encode(&v).unwrap_or_else(|e| panic!("{}: {e}", t.name()));
        assert_eq!(t.decode(&bytes).unwrap_or_else(|e| panic!("{e}")), v, "{}", t.name());
        let d = t.default_value();
        let bytes = t.encode(&d).unwrap();
        assert_eq!(t.decode(&bytes).unwrap(), d, "{} default", t.name());
        // Nil and an empty table encode as the defaults too.
        assert_eq!(t.encode(&Value::Nil).unwrap(), bytes, "{}", t.name());
        assert_eq!(t.encode(&Value::Map(vec![])).unwrap(), bytes, "{}", t.name());
    }
}

#[test]
fn bytes_and_strings_fill_octet_arrays_and_lists_fill_them_too() {
    let t = ty("sensor_msgs/msg/Image");
    let from_bytes = t.encode(&map(&[("data", Value::Bytes(b"abc".to_vec()))])).unwrap();
    let from_str = t.encode(&map(&[("data", "abc".into())])).unwrap();
    let from_list = t
        .encode(&map(&[(
            "data",
            Value::Array(vec![97.into(), 98.into(), Value::Float(99.0)]),
        )]))
        .unwrap();
    assert_eq!(from_bytes, from_str);
    assert_eq!(from_bytes, from_list);
    assert_eq!(
        t.decode(&from_list).unwrap().get("data"),
        Some(&Value::Bytes(b"abc".to_vec()))
    );
    // An empty Lua table is an empty sequence.
    let empty = t.encode(&map(&[("data", Value::Map(vec![]))])).unwrap();
    assert_eq!(t.decode(&empty).unwrap().get("data"), Some(&Value::Bytes(vec![])));
    // A string field takes UTF-8 bytes.
    let s = ty("std_msgs/msg/String");
    assert_eq!(
        s.encode(&map(&[("data", Value::Bytes(b"hi".to_vec()))])).unwrap(),
        s.encode(&map(&[("data", "hi".into())])).unwrap()
    );
}

#[test]
fn a_vga_image_round_trips_as_bytes() {
    let t = ty("sensor_msgs/msg/Image");
    let data: Vec<u8> = (0..640 * 480 * 3).map(|i| (i % 251) as u8).collect();
    let v = map(&[
        ("height", 480.into()),
        ("width", 640.into()),
        ("encoding", "rgb8".into()),
        ("step", (640 * 3).into()),
        ("data", Value::Bytes(data.clone())),
    ]);
    let bytes = t.encode(&v).unwrap();
    assert_eq!(bytes.len(), 4 + 8 + 4 + 4 + 4 + 4 + 8 + 1 + 3 + 4 + 4 + data.len());
    assert_eq!(&bytes[bytes.len() - data.len()..], &data[..]);
    let back = t.decode(&bytes).unwrap();
    assert_eq!(back.get("data"), Some(&Value::Bytes(data)));
    assert_eq!(back.get("width"), Some(&Value::Int(640)));
}

#[test]
fn floats_keep_nan_and_infinities_and_float32_rounds() {
    let t = ty("std_msgs/msg/Float64");
    let bytes = t.encode(&map(&[("data", f64::NAN.into())])).unwrap();
    let Some(Value::Float(x)) = t.decode(&bytes).unwrap().get("data").cloned() else {
        panic!()
    };
    assert!(x.is_nan());
    let t32 = ty("std_msgs/msg/Float32");
    let bytes = t32.encode(&map(&[("data", Value::Float(0.1))])).unwrap();
    assert_eq!(
        t32.decode(&bytes).unwrap(),
        map(&[("data", Value::Float(f64::from(0.1f32)))])
    );
    let bytes = t32.encode(&map(&[("data", Value::Float(f64::NEG_INFINITY))])).unwrap();
    assert_eq!(&bytes[4..], f32::NEG_INFINITY.to_le_bytes());
}

#[test]
fn integer_limits_encode_and_decode() {
    for (name, lo, hi) in [
        ("Int8", -128, 127),
        ("UInt8", 0, 255),
        ("Int16", -32768, 32767),
        ("UInt16", 0, 65535),
        ("Int32", i64::from(i32::MIN), i64::from(i32::MAX)),
        ("UInt32", 0, i64::from(u32::MAX)),
        ("Int64", i64::MIN, i64::MAX),
        ("UInt64", 0, i64::MAX),
        ("Byte", 0, 255),
        ("Char", 0, 255),
    ] {
        let t = ty(&format!("std_msgs/msg/{name}"));
        for i in [lo, hi] {
            let v = map(&[("data", i.into())]);
            assert_eq!(t.decode(&t.encode(&v).unwrap()).unwrap(), v, "{name} {i}");
        }
        if lo > i64::MIN {
            let e = t.encode(&map(&[("data", (lo - 1).into())])).unwrap_err();
            assert!(e.to_string().contains("is out of range for"), "{e}");
        }
        if hi < i64::MAX {
            assert!(t.encode(&map(&[("data", (hi + 1).into())])).is_err(), "{name}");
        }
    }
    // Integral floats are integers.
    let t = ty("std_msgs/msg/Int32");
    assert_eq!(
        t.encode(&map(&[("data", Value::Float(3.0))])).unwrap(),
        with_header(&[3, 0, 0, 0])
    );
}

// ---- error messages ----

fn encode_err(t: &str, v: Value) -> String {
    ty(t).encode(&v).unwrap_err().to_string()
}

#[test]
fn encode_errors_name_the_type_and_the_field() {
    assert_eq!(
        encode_err("geometry_msgs/msg/Twist", map(&[("linear", map(&[("q", 1.into())]))])),
        "geometry_msgs/msg/Twist: field \"linear.q\" does not exist (fields: x, y, z)"
    );
    assert_eq!(
        encode_err("geometry_msgs/msg/Twist", map(&[("lienar", map(&[]))])),
        "geometry_msgs/msg/Twist: field \"lienar\" does not exist (fields: linear, angular)"
    );
    assert_eq!(
        encode_err(
            "sensor_msgs/msg/JointState",
            map(&[("position", Value::Array(vec![1.into(), 2.0.into(), "x".into()]))])
        ),
        "sensor_msgs/msg/JointState.position[2]: expected a number, got string"
    );
    assert_eq!(
        encode_err("std_msgs/msg/UInt8", map(&[("data", 300.into())])),
        "std_msgs/msg/UInt8.data: 300 is out of range for uint8"
    );
    assert_eq!(
        encode_err(
            "sensor_msgs/msg/CameraInfo",
            map(&[("k", Value::floats(&[1.0, 2.0, 3.0, 4.0]))])
        ),
        "sensor_msgs/msg/CameraInfo.k: expected 9 values, got 4"
    );
    assert_eq!(
        encode_err("std_msgs/msg/Bool", map(&[("data", 1.into())])),
        "std_msgs/msg/Bool.data: expected a boolean, got number"
    );
    assert_eq!(
        encode_err("std_msgs/msg/Int32", map(&[("data", f64::NAN.into())])),
        "std_msgs/msg/Int32.data: expected an integer, got NaN"
    );
    assert_eq!(
        encode_err("std_msgs/msg/UInt8", map(&[("data", 256.5.into())])),
        "std_msgs/msg/UInt8.data: 256 is out of range for uint8"
    );
    assert_eq!(
        encode_err("std_msgs/msg/Int64", map(&[("data", 1e30.into())])),
        "std_msgs/msg/Int64.data: 1000000000000000000000000000000 is out of range for int64"
    );
    assert_eq!(
        encode_err("std_msgs/msg/String", map(&[("data", Value::Bytes(vec![0xff]))])),
        "std_msgs/msg/String.data: expected a string, got bytes that are not UTF-8"
    );
    assert_eq!(
        encode_err("std_msgs/msg/String", 5.into()),
        "std_msgs/msg/String: expected a message (table), got number"
    );
    assert_eq!(
        encode_err(
            "geometry_msgs/msg/PoseArray",
            map(&[("poses", Value::Array(vec![1.into()]))])
        ),
        "geometry_msgs/msg/PoseArray.poses[0]: expected a message (table), got number"
    );
    assert_eq!(
        encode_err("sensor_msgs/msg/JointState", map(&[("name", "a".into())])),
        "sensor_msgs/msg/JointState.name: expected an array, got string"
    );
    assert_eq!(
        encode_err("std_msgs/msg/Empty", Value::Map(vec![(1.into(), 2.into())])),
        "std_msgs/msg/Empty: field names must be strings, got number"
    );
    assert_eq!(
        encode_err("std_msgs/msg/Empty", map(&[("x", 2.into())])),
        "std_msgs/msg/Empty: field \"x\" does not exist (fields: none)"
    );
    assert_eq!(
        encode_err(
            "tf2_msgs/msg/TFMessage",
            map(&[(
                "transforms",
                Value::Array(vec![
                    map(&[]),
                    map(&[("transform", map(&[("rotation", map(&[("w", "1".into())]))]))])
                ])
            )])
        ),
        "tf2_msgs/msg/TFMessage.transforms[1].transform.rotation.w: expected a number, got string"
    );
}

#[test]
fn unknown_types_point_at_the_docs_and_suggest_close_names() {
    assert_eq!(
        message_type("foo_msgs/msg/Bar").unwrap_err().to_string(),
        "unknown message type \"foo_msgs/msg/Bar\" (known: see docs/ros2.md)"
    );
    let e = message_type("geometry_msgs/msg/Twst").unwrap_err().to_string();
    assert!(e.contains("did you mean geometry_msgs/msg/Twist"), "{e}");
    let e = service_type("std_srvs/srv/SetBol").unwrap_err().to_string();
    assert!(e.starts_with("unknown service type \"std_srvs/srv/SetBol\""), "{e}");
    assert!(e.contains("std_srvs/srv/SetBool"), "{e}");
    assert!(message_type("").is_err());
    assert!(message_type("a/b/c/d").is_err());
}

#[test]
fn lookups_accept_ros1_style_names() {
    assert_eq!(ty("geometry_msgs/Twist").name(), "geometry_msgs/msg/Twist");
    let s = service_type("std_srvs/SetBool").unwrap();
    assert_eq!(s.name(), "std_srvs/srv/SetBool");
    assert_eq!(s.dds_request_type_name(), "std_srvs::srv::dds_::SetBool_Request_");
    assert_eq!(s.dds_response_type_name(), "std_srvs::srv::dds_::SetBool_Response_");
    assert_eq!(s.response().definition(), "bool success\nstring message\n");
    assert_eq!(
        ty("sensor_msgs/msg/Image").dds_type_name(),
        "sensor_msgs::msg::dds_::Image_"
    );
    let names: Vec<&str> = known_message_types().map(MsgType::name).collect();
    assert!(names.windows(2).all(|w| w[0] < w[1]));
    assert!(names.iter().all(|n| n.contains("/msg/")));
    let srvs: Vec<&str> = known_service_types().map(|s| s.name()).collect();
    assert_eq!(
        srvs,
        [
            "action_msgs/srv/CancelGoal",
            "example_interfaces/srv/AddTwoInts",
            "std_srvs/srv/Empty",
            "std_srvs/srv/SetBool",
            "std_srvs/srv/Trigger"
        ]
    );
}

fn decode_err(t: &str, bytes: &[u8]) -> String {
    ty(t).decode(bytes).unwrap_err().to_string()
}

#[test]
fn decode_errors_name_the_type_and_the_field() {
    let e = decode_err("std_msgs/msg/String", &HDR);
    assert!(
        e.starts_with("std_msgs/msg/String.data: input truncated at body offset 0"),
        "{e}"
    );
    let e = decode_err(
        "sensor_msgs/msg/JointState",
        &with_header(&[0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0xff, 0xff, 0xff, 0xff]),
    );
    assert_eq!(
        e,
        "sensor_msgs/msg/JointState.name: sequence length 4294967295 exceeds the remaining 0 bytes"
    );
    let e = decode_err("std_msgs/msg/String", &with_header(&[9, 0, 0, 0, b'h', b'i', 0]));
    assert_eq!(
        e,
        "std_msgs/msg/String.data: string length 9 exceeds the remaining 3 bytes"
    );
    let e = decode_err("std_msgs/msg/String", &with_header(&[2, 0, 0, 0, b'h', b'i']));
    assert_eq!(e, "std_msgs/msg/String.data: string is not NUL-terminated");
    let e = decode_err("std_msgs/msg/String", &with_header(&[2, 0, 0, 0, 0xff, 0]));
    assert_eq!(e, "std_msgs/msg/String.data: string is not valid UTF-8");
    let e = decode_err("std_msgs/msg/Bool", &with_header(&[2]));
    assert_eq!(e, "std_msgs/msg/Bool.data: bool byte 2 is neither 0 nor 1");
    let e = decode_err("std_msgs/msg/UInt64", &with_header(&[0xff; 8]));
    assert!(
        e.starts_with("std_msgs/msg/UInt64.data: uint64 value 18446744073709551615 is larger"),
        "{e}"
    );
    // layout: no dims, data_offset 0; data: two uint64 after 4 bytes of padding.
    let mut big = with_header(&[0; 8]);
    big.extend_from_slice(&2u32.to_le_bytes());
    big.extend_from_slice(&[0; 4 + 8]);
    big.extend_from_slice(&u64::MAX.to_le_bytes());
    let e = decode_err("std_msgs/msg/UInt64MultiArray", &big);
    assert!(
        e.starts_with("std_msgs/msg/UInt64MultiArray.data[1]: uint64 value"),
        "{e}"
    );
    let e = decode_err("std_msgs/msg/Bool", &[0x00, 0x07, 0, 0, 1]);
    assert!(
        e.starts_with("std_msgs/msg/Bool: unsupported CDR encapsulation 00 07"),
        "{e}"
    );
    let e = decode_err("std_msgs/msg/Bool", &[0x00]);
    assert!(e.contains("shorter than the 4-byte encapsulation header"), "{e}");
    let e = decode_err("geometry_msgs/msg/PoseArray", &with_header(&[0; 12]));
    assert!(
        e.starts_with("geometry_msgs/msg/PoseArray.poses: input truncated"),
        "{e}"
    );
    // Path: two PoseStamped claimed, 140 bytes given: enough for the bound (2 x 68 bytes
    // without padding), not for the padded layout, so the second pose runs out.
    let mut path = with_header(&[0; 12]);
    path.extend_from_slice(&2u32.to_le_bytes());
    path.extend_from_slice(&[0; 140]);
    let e = decode_err("nav_msgs/msg/Path", &path);
    assert_eq!(
        e,
        "nav_msgs/msg/Path.poses[1].pose.orientation.w: input truncated at body offset 152 (8 bytes needed, 4 left)"
    );
    // Options bytes are ignored, and so is trailing padding.
    assert!(ty("std_msgs/msg/Bool").decode(&[0, 1, 0xab, 0xcd, 1, 0, 0, 0]).is_ok());
    // A zero string length is read as the empty string.
    assert_eq!(
        ty("std_msgs/msg/String").decode(&with_header(&[0, 0, 0, 0])).unwrap(),
        map(&[("data", "".into())])
    );
}

// ---- hostile input ----

#[test]
fn every_truncated_prefix_errors() {
    for t in every_type() {
        let bytes = t.encode(&filled(t)).unwrap();
        for len in 0..bytes.len() {
            let r = t.decode(&bytes[..len]);
            // A top-level empty message may come without its placeholder byte.
            let empty_ok = len == 4 && t.default_value() == Value::Map(vec![]);
            assert_eq!(r.is_err(), !empty_ok, "{} cut at {len}: {r:?}", t.name());
        }
    }
}

/// xorshift64: deterministic pseudo-random bytes.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
}

#[test]
fn random_bytes_never_panic_and_what_decodes_round_trips() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut decoded = 0;
    for name in [
        "std_msgs/msg/String",
        "std_msgs/msg/Empty",
        "sensor_msgs/msg/JointState",
        "sensor_msgs/msg/PointCloud2",
        "sensor_msgs/msg/CameraInfo",
        "tf2_msgs/msg/TFMessage",
        "nav_msgs/msg/Path",
        "std_msgs/msg/Float64MultiArray",
        "sensor_msgs/msg/NavSatFix",
    ] {
        let t = ty(name);
        for _ in 0..10_000 {
            let len = (rng.next() % 96) as usize;
            let small = rng.next() & 1 == 0;
            let mut buf: Vec<u8> = (0..len)
                // Small bytes make plausible counts and lengths, so decoding goes deep.
                .map(|_| {
                    if small {
                        (rng.next() % 3) as u8
                    } else {
                        rng.next() as u8
                    }
                })
                .collect();
            if buf.len() >= 4 && rng.next() & 7 != 0 {
                buf[..4].copy_from_slice(if rng.next() & 1 == 0 { &HDR } else { &[0, 0, 0, 0] });
            }
            if let Ok(v) = t.decode(&buf) {
                decoded += 1;
                let again = t.decode(&t.encode(&v).unwrap()).unwrap();
                assert_eq!(again, v, "{name} {buf:02x?}");
            }
        }
    }
    assert!(
        decoded > 100,
        "only {decoded} random buffers decoded: the test does not reach deep"
    );
}

#[test]
fn a_huge_declared_length_errors_without_allocating() {
    let start = std::time::Instant::now();
    let mut img = with_header(&[0; 12]); // stamp, empty frame_id length... then garbage
    img[12..16].copy_from_slice(&1u32.to_le_bytes());
    img.extend_from_slice(&[0, 0, 0, 0]); // frame_id NUL + pad
    img.extend_from_slice(&[0; 8]); // height, width
    img.extend_from_slice(&[1, 0, 0, 0, 0]); // encoding ""
    img.extend_from_slice(&[0, 0, 0]); // is_bigendian + pad
    img.extend_from_slice(&[0; 4]); // step
    img.extend_from_slice(&0xffff_fff0u32.to_le_bytes()); // data: 4 GiB claimed
    img.extend_from_slice(&[1, 2, 3]);
    let e = ty("sensor_msgs/msg/Image").decode(&img).unwrap_err();
    assert!(
        matches!(
            e,
            DecodeError::LengthTooLong {
                count: 0xffff_fff0,
                left: 3,
                ..
            }
        ),
        "{e}"
    );
    for t in [
        "sensor_msgs/msg/PointCloud2",
        "tf2_msgs/msg/TFMessage",
        "std_msgs/msg/Int64MultiArray",
    ] {
        // Every u32 here is a huge count; the first sequence must refuse it.
        let e = ty(t).decode(&with_header(&[0xfe; 64])).unwrap_err();
        assert!(!matches!(e, DecodeError::NoHeader { .. }), "{e}");
    }
    assert!(start.elapsed().as_secs() < 5, "refusing took {:?}", start.elapsed());
}

#[test]
fn fractions_truncate_and_ros1_header_seq_is_ignored_as_coppeliasims_plugins_do() {
    let t = ty("std_msgs/msg/Int32");
    assert_eq!(
        t.encode(&map(&[("data", 1.9.into())])).unwrap(),
        t.encode(&map(&[("data", 1.into())])).unwrap()
    );
    assert_eq!(
        t.encode(&map(&[("data", (-1.9).into())])).unwrap(),
        t.encode(&map(&[("data", (-1).into())])).unwrap()
    );
    let h = ty("std_msgs/msg/Header");
    let ros1 = map(&[("seq", 7.into()), ("frame_id", "a".into())]);
    assert_eq!(
        h.encode(&ros1).unwrap(),
        h.encode(&map(&[("frame_id", "a".into())])).unwrap()
    );
    assert!(
        ty("std_msgs/msg/String").encode(&map(&[("seq", 7.into())])).is_err(),
        "only in a Header"
    );
}

// ---- actions ----

#[test]
fn fibonacci_action_parts_have_rcl_action_layouts() {
    let a = action_type("example_interfaces/action/Fibonacci").unwrap();
    assert_eq!(action_type("example_interfaces/Fibonacci").unwrap().name(), a.name());
    let uuid: Vec<u8> = (0..16).collect();
    let goal_id = map(&[("uuid", Value::Bytes(uuid.clone()))]);

    // send_goal: the 16 id bytes, then the goal (int32 order, already aligned).
    let rq = a.send_goal().request();
    assert_eq!(
        rq.dds_type_name(),
        "example_interfaces::action::dds_::Fibonacci_SendGoal_Request_"
    );
    let v = map(&[("goal_id", goal_id.clone()), ("goal", map(&[("order", Value::Int(9))]))]);
    let mut want = uuid.clone();
    want.extend(9i32.to_le_bytes());
    assert_eq!(rq.encode(&v).unwrap(), with_header(&want));
    assert_eq!(rq.decode(&with_header(&want)).unwrap(), v);
    assert_eq!(
        a.send_goal().response().definition(),
        "bool accepted\nbuiltin_interfaces/Time stamp\n"
    );

    // get_result's response: int8 status, padding to 4, then the sequence.
    let rs = a.get_result().response();
    assert_eq!(
        rs.dds_type_name(),
        "example_interfaces::action::dds_::Fibonacci_GetResult_Response_"
    );
    let v = map(&[
        ("status", Value::Int(4)),
        (
            "result",
            map(&[("sequence", Value::Array(vec![Value::Int(0), Value::Int(1)]))]),
        ),
    ]);
    let want = [4u8, 0, 0, 0, 2, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0];
    assert_eq!(rs.encode(&v).unwrap(), with_header(&want));

    // feedback: the id, then the sequence.
    let fb = a.feedback_message();
    assert_eq!(
        fb.dds_type_name(),
        "example_interfaces::action::dds_::Fibonacci_FeedbackMessage_"
    );
    let v = map(&[
        ("goal_id", goal_id.clone()),
        ("feedback", map(&[("sequence", Value::Array(vec![Value::Int(7)]))])),
    ]);
    let mut want = uuid.clone();
    want.extend([1, 0, 0, 0, 7, 0, 0, 0]);
    assert_eq!(fb.encode(&v).unwrap(), with_header(&want));

    // The status array every action server keeps.
    let st = ty("action_msgs/msg/GoalStatusArray");
    let v = map(&[(
        "status_list",
        Value::Array(vec![map(&[
            (
                "goal_info",
                map(&[
                    ("goal_id", goal_id),
                    ("stamp", map(&[("sec", Value::Int(3)), ("nanosec", Value::Int(5))])),
                ]),
            ),
            ("status", Value::Int(2)),
        ])]),
    )]);
    let mut want = vec![1, 0, 0, 0];
    want.extend(&uuid);
    want.extend([3, 0, 0, 0, 5, 0, 0, 0, 2]);
    assert_eq!(st.encode(&v).unwrap(), with_header(&want));
    assert_eq!(st.decode(&with_header(&want)).unwrap(), v);
    assert_eq!(
        service_type("action_msgs/srv/CancelGoal")
            .unwrap()
            .dds_request_type_name(),
        "action_msgs::srv::dds_::CancelGoal_Request_"
    );
    let names: Vec<&str> = known_action_types().map(|a| a.name()).collect();
    assert_eq!(names, ["example_interfaces/action/Fibonacci"]);
}

#[test]
fn simros2_interface_names_find_the_parts_of_services_and_actions() {
    for (simros2, canonical) in [
        (
            "example_interfaces/action/FibonacciGoal",
            "example_interfaces/action/Fibonacci_Goal",
        ),
        (
            "example_interfaces/action/FibonacciResult",
            "example_interfaces/action/Fibonacci_Result",
        ),
        (
            "example_interfaces/action/FibonacciFeedback",
            "example_interfaces/action/Fibonacci_Feedback",
        ),
        (
            "example_interfaces/srv/AddTwoIntsRequest",
            "example_interfaces/srv/AddTwoInts_Request",
        ),
        ("std_srvs/srv/SetBoolResponse", "std_srvs/srv/SetBool_Response"),
        ("std_srvs/srv/SetBool_Response", "std_srvs/srv/SetBool_Response"),
    ] {
        assert_eq!(ty(simros2).name(), canonical);
    }
    let e = message_type("example_interfaces/action/FibonacciGaol")
        .unwrap_err()
        .to_string();
    assert!(e.contains("FibonacciGaol"), "{e}");
    assert!(message_type("std_srvs/srv/Request").is_err());
    assert!(action_type("example_interfaces/action/Fib").is_err());
}

// ---- names ----

#[test]
fn topic_names_map_to_dds() {
    assert_eq!(topic_name("/cmd_vel").unwrap(), "rt/cmd_vel");
    assert_eq!(topic_name("cmd_vel").unwrap(), "rt/cmd_vel");
    assert_eq!(topic_name("/a/b").unwrap(), "rt/a/b");
    assert_eq!(topic_name("/robot_1/_private/x9").unwrap(), "rt/robot_1/_private/x9");
    assert_eq!(service_request_topic("/set_flag").unwrap(), "rq/set_flagRequest");
    assert_eq!(service_reply_topic("/set_flag").unwrap(), "rr/set_flagReply");
    assert_eq!(service_reply_topic("ns/set_flag").unwrap(), "rr/ns/set_flagReply");
    assert_eq!(ros_topic_name("rt/cmd_vel").as_deref(), Some("/cmd_vel"));
    assert_eq!(ros_topic_name("rt/a/b").as_deref(), Some("/a/b"));
    assert_eq!(ros_topic_name("rq/set_flagRequest").as_deref(), Some("/set_flag"));
    assert_eq!(ros_topic_name("rr/set_flagReply").as_deref(), Some("/set_flag"));
    assert_eq!(ros_topic_name("DCPSParticipant"), None);
    assert_eq!(ros_topic_name("rt/"), None);
    assert_eq!(ros_topic_name("rq/set_flag"), None);
    let a = action_topics("/fibonacci").unwrap();
    assert_eq!(
        a.send_goal,
        (
            "rq/fibonacci/_action/send_goalRequest".to_owned(),
            "rr/fibonacci/_action/send_goalReply".to_owned()
        )
    );
    assert_eq!(a.cancel_goal.0, "rq/fibonacci/_action/cancel_goalRequest");
    assert_eq!(a.get_result.1, "rr/fibonacci/_action/get_resultReply");
    assert_eq!(a.feedback, "rt/fibonacci/_action/feedback");
    assert_eq!(a.status, "rt/fibonacci/_action/status");
    assert!(action_topics("/fib onacci").is_err());
}

#[test]
fn invalid_names_are_refused_with_the_rule() {
    for (name, why) in [
        ("", "empty"),
        ("/", "namespace"),
        ("/a//b", "'//'"),
        ("//a", "'//'"),
        ("/a/", "end with '/'"),
        ("/9lives", "digit"),
        ("/a/1b", "digit"),
        ("/cmd vel", "spaces"),
        ("/cmd-vel", "only letters"),
        ("/caf\u{e9}", "only letters"),
    ] {
        let e = topic_name(name).unwrap_err().to_string();
        assert!(e.starts_with(&format!("invalid ROS 2 name \"{name}\"")), "{e}");
        assert!(e.contains(why), "{name}: {e}");
        assert!(service_request_topic(name).is_err());
        assert!(service_reply_topic(name).is_err());
    }
    let e = topic_name("~/cmd_vel").unwrap_err().to_string();
    assert!(e.contains("`~`") && e.contains("does not expand"), "{e}");
    let e = topic_name("/{node}/cmd").unwrap_err().to_string();
    assert!(e.contains("substitution"), "{e}");
}

#[test]
fn the_encapsulation_header_constant_is_cdr_le() {
    assert_eq!(ros::CDR_LE_HEADER, HDR);
}

/// Writes the `ros_cdr` fuzz target's seeds: for a few types, the type's index in
/// [`known_message_types`] then a filled message's CDR. Run by hand when the catalog
/// changes: `cargo test -p gantry-protocol --test integration -- --ignored ros_cdr::write_fuzz_seeds`.
#[test]
#[ignore = "writes fuzz/seeds/ros_cdr; run by hand"]
fn write_fuzz_seeds() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/seeds/ros_cdr");
    std::fs::create_dir_all(&dir).unwrap();
    let types: Vec<&MsgType> = known_message_types().collect();
    for name in [
        "std_msgs/msg/String",
        "geometry_msgs/msg/Twist",
        "sensor_msgs/msg/JointState",
        "sensor_msgs/msg/PointCloud2",
        "tf2_msgs/msg/TFMessage",
        "nav_msgs/msg/Odometry",
    ] {
        let index = types.iter().position(|t| t.name() == name).unwrap();
        let t = types[index];
        let mut seed = vec![u8::try_from(index).unwrap()];
        seed.extend(t.encode(&filled(t)).unwrap());
        let file = name.rsplit('/').next().unwrap().to_ascii_lowercase();
        std::fs::write(dir.join(format!("{file}.cdr")), seed).unwrap();
    }
}

#[test]
fn a_hundred_joint_state_round_trips() {
    let t = ty("sensor_msgs/msg/JointState");
    let names: Vec<Value> = (0..100).map(|i| Value::Str(format!("joint_{i}"))).collect();
    let xs: Vec<f64> = (0..100).map(|i| f64::from(i) * 0.01).collect();
    let v = map(&[
        ("header", map(&[("frame_id", "world".into())])),
        ("name", Value::Array(names.clone())),
        ("position", Value::floats(&xs)),
        ("velocity", Value::floats(&xs)),
        ("effort", Value::floats(&xs)),
    ]);
    let bytes = t.encode(&v).unwrap();
    // The three float64 sequences take 3 x (count + 800 bytes) at least.
    assert!(bytes.len() > 3 * 804);
    let back = t.decode(&bytes).unwrap();
    assert_eq!(back.get("name"), Some(&Value::Array(names)));
    assert_eq!(back.get("effort"), Some(&Value::floats(&xs)));
}

#[test]
fn a_time_given_in_seconds_encodes_as_sec_and_nanosec() {
    use gantry_protocol::Value;
    use gantry_protocol::ros::message_type;
    let header = message_type("std_msgs/msg/Header").unwrap();
    let as_number = Value::Map(vec![(Value::Str("stamp".into()), Value::Float(2.25))]);
    let as_table = Value::Map(vec![(
        Value::Str("stamp".into()),
        Value::Map(vec![
            (Value::Str("sec".into()), Value::Int(2)),
            (Value::Str("nanosec".into()), Value::Int(250_000_000)),
        ]),
    )]);
    assert_eq!(header.encode(&as_number).unwrap(), header.encode(&as_table).unwrap());
    let d = message_type("builtin_interfaces/msg/Duration").unwrap();
    let neg = d.decode(&d.encode(&Value::Float(-0.5)).unwrap()).unwrap();
    assert_eq!(neg.get("sec"), Some(&Value::Int(-1)));
    assert_eq!(neg.get("nanosec"), Some(&Value::Int(500_000_000)));
    let err = header
        .encode(&Value::Map(vec![(Value::Str("stamp".into()), Value::Float(f64::NAN))]))
        .unwrap_err()
        .to_string();
    assert!(err.contains("stamp") && err.contains("seconds"), "{err}");
}
