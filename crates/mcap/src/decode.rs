//! CDR *decoding* of the messages gantry records (the inverse of gantry-protocol's
//! typed encoders, [`gantry_protocol::ros::typed`]), for
//! reading recordings back: `gantry replay` and `gantry verify`.
//!
//! Pure and total: bytes in, a borrowed message or a [`DecodeError`] out. Nothing here
//! panics or allocates in proportion to a length read from the bytes: every count is
//! checked against the bytes that are left before anything is reserved, so a hostile
//! message costs at most its own size. Only little-endian plain CDR (encapsulation
//! `00 01`, what every ROS 2 middleware and gantry write) is read; alignment counts from
//! the end of the 4-byte encapsulation header, as in [`CdrWriter`].
//!
//! Typed like the encoders, not the catalog's dynamic decoder: reading a recording
//! decodes every `/tf` message of it, and borrowed strings and plain numbers keep that
//! to a copy of the poses.
//!
//! [`CdrWriter`]: gantry_protocol::ros::typed::CdrWriter

use gantry_protocol::ros::CDR_LE_HEADER;
use gantry_protocol::ros::typed::{LogLevel, Time};

/// Why a message could not be decoded.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DecodeError {
    /// The message ends before a field does.
    #[error("the message ends at byte {len}, inside a field at byte {at} that needs {need} bytes")]
    Truncated {
        /// Where the field starts (after alignment), counted from the message's start.
        at: usize,
        /// Bytes the field needs.
        need: usize,
        /// The message's length.
        len: usize,
    },
    /// Not little-endian plain CDR.
    #[error("not little-endian CDR: the encapsulation header is {0:02x?} (expected 00 01 00 00)")]
    Encapsulation([u8; 4]),
    /// A string is not UTF-8, or lacks its terminating NUL.
    #[error("a string at byte {0} is not NUL-terminated UTF-8")]
    BadString(usize),
    /// A sequence claims more elements than the bytes left could hold.
    #[error("a sequence at byte {at} claims {count} elements, more than the {left} bytes left can hold")]
    Count {
        /// Where the count is.
        at: usize,
        /// The count read.
        count: u32,
        /// Bytes left after it.
        left: usize,
    },
}

/// Reads one CDR message field by field (see the module docs).
#[derive(Debug, Clone)]
pub struct CdrReader<'a> {
    buf: &'a [u8],
    /// The next byte to read, counted from the start of `buf` (header included).
    pos: usize,
}

impl<'a> CdrReader<'a> {
    /// A reader of `buf`, after checking its encapsulation header.
    ///
    /// # Errors
    /// Shorter than the header, or not little-endian plain CDR.
    pub fn new(buf: &'a [u8]) -> Result<Self, DecodeError> {
        let Some(header) = buf.get(..CDR_LE_HEADER.len()) else {
            return Err(DecodeError::Truncated {
                at: 0,
                need: CDR_LE_HEADER.len(),
                len: buf.len(),
            });
        };
        // The last two bytes are options, which CDR readers ignore.
        if header[..2] != CDR_LE_HEADER[..2] {
            let mut h = [0; 4];
            h.copy_from_slice(header);
            return Err(DecodeError::Encapsulation(h));
        }
        Ok(Self {
            buf,
            pos: CDR_LE_HEADER.len(),
        })
    }

    /// Skips the padding before a primitive of `n` bytes.
    fn align(&mut self, n: usize) {
        let offset = self.pos - CDR_LE_HEADER.len();
        self.pos = self.pos.saturating_add((n - offset % n) % n);
    }

    /// The next `n` bytes.
    fn take(&mut self, n: usize) -> Result<&'a [u8], DecodeError> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.buf.len());
        match end {
            Some(end) => {
                let s = &self.buf[self.pos..end];
                self.pos = end;
                Ok(s)
            }
            None => Err(DecodeError::Truncated {
                at: self.pos,
                need: n,
                len: self.buf.len(),
            }),
        }
    }

    /// `N` bytes after aligning to `N`.
    fn array<const N: usize>(&mut self) -> Result<[u8; N], DecodeError> {
        self.align(N);
        let mut out = [0; N];
        out.copy_from_slice(self.take(N)?);
        Ok(out)
    }

    /// A `uint8` (or `byte`, `char`, `bool`).
    ///
    /// # Errors
    /// The message ends here.
    pub fn u8(&mut self) -> Result<u8, DecodeError> {
        Ok(self.array::<1>()?[0])
    }

    /// A `uint32`.
    ///
    /// # Errors
    /// The message ends here.
    pub fn u32(&mut self) -> Result<u32, DecodeError> {
        self.array().map(u32::from_le_bytes)
    }

    /// An `int32`.
    ///
    /// # Errors
    /// The message ends here.
    pub fn i32(&mut self) -> Result<i32, DecodeError> {
        self.array().map(i32::from_le_bytes)
    }

    /// A `float64`.
    ///
    /// # Errors
    /// The message ends here.
    pub fn f64(&mut self) -> Result<f64, DecodeError> {
        self.array().map(f64::from_le_bytes)
    }

    /// A `string`, borrowed.
    ///
    /// # Errors
    /// The message ends inside it, or it is not NUL-terminated UTF-8.
    pub fn string(&mut self) -> Result<&'a str, DecodeError> {
        let at = self.pos;
        let n = self.u32()? as usize;
        let bytes = self.take(n)?;
        // The length counts the terminating NUL, so an empty string is 1; some writers
        // send 0 for it, which is accepted.
        match bytes.split_last() {
            None => Ok(""),
            Some((0, text)) => std::str::from_utf8(text).map_err(|_| DecodeError::BadString(at)),
            Some(_) => Err(DecodeError::BadString(at)),
        }
    }

    /// The element count of a sequence whose elements take at least `min_size` bytes
    /// each, checked against the bytes left, so that a caller may reserve that many.
    ///
    /// # Errors
    /// The message ends here, or the count cannot fit in what is left.
    pub fn sequence_len(&mut self, min_size: usize) -> Result<usize, DecodeError> {
        let at = self.pos;
        let count = self.u32()?;
        let left = self.buf.len().saturating_sub(self.pos);
        let n = count as usize;
        if n.saturating_mul(min_size.max(1)) > left && n > 0 {
            return Err(DecodeError::Count { at, count, left });
        }
        Ok(n)
    }

    /// A `uint8[]`, borrowed.
    ///
    /// # Errors
    /// The message ends inside it.
    pub fn bytes(&mut self) -> Result<&'a [u8], DecodeError> {
        let n = self.sequence_len(1)?;
        self.take(n)
    }

    /// A `float64[]`.
    ///
    /// # Errors
    /// The message ends inside it.
    pub fn f64_sequence(&mut self) -> Result<Vec<f64>, DecodeError> {
        let n = self.sequence_len(8)?;
        let mut out = Vec::with_capacity(n);
        for _ in 0..n {
            out.push(self.f64()?);
        }
        Ok(out)
    }

    /// A `builtin_interfaces/msg/Time`.
    ///
    /// # Errors
    /// The message ends inside it.
    pub fn time(&mut self) -> Result<Time, DecodeError> {
        Ok(Time {
            sec: self.i32()?,
            nanosec: self.u32()?,
        })
    }

    /// A `std_msgs/msg/Header`: stamp and frame id.
    ///
    /// # Errors
    /// The message ends inside it.
    pub fn header(&mut self) -> Result<(Time, &'a str), DecodeError> {
        Ok((self.time()?, self.string()?))
    }
}

/// One decoded `geometry_msgs/msg/TransformStamped`, strings borrowed from the message.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transform<'a> {
    /// When.
    pub stamp: Time,
    /// The parent frame.
    pub frame_id: &'a str,
    /// The frame whose pose this is.
    pub child_frame_id: &'a str,
    /// Translation (m) then rotation quaternion `x, y, z, w`, in the parent's frame.
    pub pose: [f64; 7],
}

/// The smallest encoded `TransformStamped`: stamp, two empty strings, seven `float64`s.
const MIN_TRANSFORM: usize = 8 + 4 + 4 + 7 * 8;

/// A `tf2_msgs/msg/TFMessage` (`/tf`, `/tf_static`).
///
/// # Errors
/// See [`DecodeError`].
pub fn tf_message(bytes: &[u8]) -> Result<Vec<Transform<'_>>, DecodeError> {
    let mut r = CdrReader::new(bytes)?;
    let n = r.sequence_len(MIN_TRANSFORM)?;
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        let (stamp, frame_id) = r.header()?;
        let child_frame_id = r.string()?;
        let mut pose = [0.0; 7];
        for v in &mut pose {
            *v = r.f64()?;
        }
        out.push(Transform {
            stamp,
            frame_id,
            child_frame_id,
            pose,
        });
    }
    Ok(out)
}

/// A decoded `sensor_msgs/msg/JointState`.
#[derive(Debug, Clone, PartialEq)]
pub struct JointState<'a> {
    /// When.
    pub stamp: Time,
    /// Joint names (frame ids of the joints).
    pub name: Vec<&'a str>,
    /// Positions, rad or m; empty or as long as `name`.
    pub position: Vec<f64>,
    /// Velocities, rad/s or m/s; empty or as long as `name`.
    pub velocity: Vec<f64>,
    /// Efforts, N·m or N; empty or as long as `name`.
    pub effort: Vec<f64>,
}

/// A `sensor_msgs/msg/JointState` (`/joint_states`).
///
/// # Errors
/// See [`DecodeError`].
pub fn joint_state(bytes: &[u8]) -> Result<JointState<'_>, DecodeError> {
    let mut r = CdrReader::new(bytes)?;
    let (stamp, _frame) = r.header()?;
    let n = r.sequence_len(4)?;
    let mut name = Vec::with_capacity(n);
    for _ in 0..n {
        name.push(r.string()?);
    }
    Ok(JointState {
        stamp,
        name,
        position: r.f64_sequence()?,
        velocity: r.f64_sequence()?,
        effort: r.f64_sequence()?,
    })
}

/// A decoded `rcl_interfaces/msg/Log`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Log<'a> {
    /// Simulation time of the line.
    pub stamp: Time,
    /// The level's number (10 debug, 20 info, 30 warn, 40 error, 50 fatal).
    pub level: u8,
    /// Who logged it (a script's name).
    pub name: &'a str,
    /// The text.
    pub msg: &'a str,
}

impl Log<'_> {
    /// The level as gantry writes it (anything above 40 counts as an error).
    pub fn level(&self) -> LogLevel {
        LogLevel::from_number(self.level)
    }
}

/// An `rcl_interfaces/msg/Log` (`/rosout`); `file`, `function` and `line` are read and
/// dropped (gantry writes the script's name and nothing else there).
///
/// # Errors
/// See [`DecodeError`].
pub fn log(bytes: &[u8]) -> Result<Log<'_>, DecodeError> {
    let mut r = CdrReader::new(bytes)?;
    let stamp = r.time()?;
    let level = r.u8()?;
    let name = r.string()?;
    let msg = r.string()?;
    let _file = r.string()?;
    let _function = r.string()?;
    let _line = r.u32()?;
    Ok(Log {
        stamp,
        level,
        name,
        msg,
    })
}

/// A `std_msgs/msg/Float64` (graph streams).
///
/// # Errors
/// See [`DecodeError`].
pub fn float64(bytes: &[u8]) -> Result<f64, DecodeError> {
    CdrReader::new(bytes)?.f64()
}

/// A decoded `sensor_msgs/msg/Image`, pixels borrowed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Image<'a> {
    /// When.
    pub stamp: Time,
    /// The sensor's frame id.
    pub frame_id: &'a str,
    /// Rows.
    pub height: u32,
    /// Columns.
    pub width: u32,
    /// Pixel encoding, e.g. `rgb8`.
    pub encoding: &'a str,
    /// Bytes per row.
    pub step: u32,
    /// `height * step` bytes, the top row first (ROS's convention).
    pub data: &'a [u8],
}

/// A `sensor_msgs/msg/Image` (vision sensors).
///
/// # Errors
/// See [`DecodeError`].
pub fn image(bytes: &[u8]) -> Result<Image<'_>, DecodeError> {
    let mut r = CdrReader::new(bytes)?;
    let (stamp, frame_id) = r.header()?;
    let height = r.u32()?;
    let width = r.u32()?;
    let encoding = r.string()?;
    let _big_endian = r.u8()?;
    let step = r.u32()?;
    let data = r.bytes()?;
    Ok(Image {
        stamp,
        frame_id,
        height,
        width,
        encoding,
        step,
        data,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use gantry_protocol::ros::typed::{self as msg, CdrWriter, TransformStamped};

    #[test]
    fn a_tf_message_decodes_to_what_was_encoded() {
        let stamp = Time { sec: 3, nanosec: 7 };
        let written = [
            TransformStamped {
                stamp,
                frame_id: "world",
                child_frame_id: "a",
                translation: [1.0, -2.0, 3.5],
                rotation: [0.0, 0.0, 0.6, 0.8],
            },
            TransformStamped {
                stamp,
                frame_id: "a",
                child_frame_id: "a/b[1]",
                translation: [0.0; 3],
                rotation: [0.0, 0.0, 0.0, 1.0],
            },
        ];
        let bytes = msg::tf_message(&written);
        let read = tf_message(&bytes).expect("decodes");
        assert_eq!(read.len(), 2);
        for (r, w) in read.iter().zip(&written) {
            assert_eq!(r.stamp, w.stamp);
            assert_eq!(r.frame_id, w.frame_id);
            assert_eq!(r.child_frame_id, w.child_frame_id);
            assert_eq!(&r.pose[..3], &w.translation);
            assert_eq!(&r.pose[3..], &w.rotation);
        }
        assert_eq!(tf_message(&msg::tf_message(&[])).expect("empty"), vec![]);
    }

    #[test]
    fn joint_states_logs_and_floats_round_trip() {
        let bytes = msg::joint_state(
            Time { sec: 1, nanosec: 2 },
            &["j1", "arm/j2"],
            &[0.5, -1.0],
            &[],
            &[2.0, 3.0],
        );
        let js = joint_state(&bytes).expect("decodes");
        assert_eq!(js.stamp, Time { sec: 1, nanosec: 2 });
        assert_eq!(js.name, vec!["j1", "arm/j2"]);
        assert_eq!(js.position, vec![0.5, -1.0]);
        assert!(js.velocity.is_empty());
        assert_eq!(js.effort, vec![2.0, 3.0]);

        let bytes = msg::log(Time { sec: 4, nanosec: 0 }, LogLevel::Warn, "robot.lua", "héllo");
        let l = log(&bytes).expect("decodes");
        assert_eq!((l.stamp.sec, l.level, l.name, l.msg), (4, 30, "robot.lua", "héllo"));
        assert_eq!(l.level(), LogLevel::Warn);

        assert_eq!(float64(&msg::float64(-0.25)), Ok(-0.25));
    }

    #[test]
    fn an_image_decodes_with_its_pixels() {
        let mut w = CdrWriter::new();
        w.i32(1);
        w.u32(5);
        w.string("cam");
        w.u32(2); // height
        w.u32(1); // width
        w.string("rgb8");
        w.u8(0);
        w.u32(3);
        w.sequence_len(6);
        for b in [1, 2, 3, 4, 5, 6] {
            w.u8(b);
        }
        let bytes = w.into_bytes();
        let img = image(&bytes).expect("decodes");
        assert_eq!((img.height, img.width, img.step, img.encoding), (2, 1, 3, "rgb8"));
        assert_eq!(img.frame_id, "cam");
        assert_eq!(img.data, &[1, 2, 3, 4, 5, 6]);
    }

    #[test]
    fn every_cut_of_a_message_is_an_error_not_a_panic() {
        let bytes = msg::tf_message(&[TransformStamped {
            stamp: Time::default(),
            frame_id: "world",
            child_frame_id: "x",
            translation: [1.0; 3],
            rotation: [0.0, 0.0, 0.0, 1.0],
        }]);
        for n in 0..bytes.len() {
            assert!(tf_message(&bytes[..n]).is_err(), "cut at {n}");
        }
        let js = msg::joint_state(Time::default(), &["a"], &[1.0], &[1.0], &[1.0]);
        for n in 0..js.len() {
            assert!(joint_state(&js[..n]).is_err(), "cut at {n}");
        }
    }

    #[test]
    fn hostile_counts_and_headers_are_refused_without_allocating() {
        // A TFMessage claiming 4 billion transforms in 8 bytes.
        let bytes = [0, 1, 0, 0, 0xff, 0xff, 0xff, 0xff];
        assert!(matches!(
            tf_message(&bytes),
            Err(DecodeError::Count { count: u32::MAX, .. })
        ));
        // A string longer than the message.
        let bytes = [0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xff, 0xff, 0, 0, b'a'];
        assert!(matches!(log(&bytes), Err(DecodeError::Truncated { .. })));
        // Big-endian CDR.
        assert_eq!(float64(&[0, 0, 0, 0]), Err(DecodeError::Encapsulation([0, 0, 0, 0])));
        // A string without its NUL.
        let mut w = CdrWriter::new();
        w.u32(1);
        w.u8(b'a');
        let bytes = w.into_bytes();
        assert_eq!(
            CdrReader::new(&bytes).and_then(|mut r| r.string().map(str::len)),
            Err(DecodeError::BadString(4))
        );
    }
}
