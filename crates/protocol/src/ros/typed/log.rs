//! `rcl_interfaces/msg/Log` (`/rosout`): scripts' log lines.

use super::cdr_writer::CdrWriter;
use super::time::Time;

/// Levels of `rcl_interfaces/msg/Log`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum LogLevel {
    /// `DEBUG`.
    Debug = 10,
    /// `INFO`.
    Info = 20,
    /// `WARN`.
    Warn = 30,
    /// `ERROR`.
    Error = 40,
}

impl LogLevel {
    /// The level of a CoppeliaSim verbosity (200 errors, 300 warnings, 450 script
    /// infos, 500 infos, above that debug and trace).
    pub fn from_verbosity(v: i64) -> Self {
        match v {
            ..=200 => LogLevel::Error,
            201..=300 => LogLevel::Warn,
            301..=500 => LogLevel::Info,
            _ => LogLevel::Debug,
        }
    }

    /// The level of a level number read back (anything above 40, `FATAL` among them,
    /// counts as an error).
    pub fn from_number(n: u8) -> Self {
        match n {
            ..=10 => LogLevel::Debug,
            11..=20 => LogLevel::Info,
            21..=30 => LogLevel::Warn,
            _ => LogLevel::Error,
        }
    }
}

/// `rcl_interfaces/msg/Log`: a line `msg` from `name` (a script).
pub fn log(stamp: Time, level: LogLevel, name: &str, msg: &str) -> Vec<u8> {
    let mut w = CdrWriter::with_capacity(32 + name.len() * 2 + msg.len());
    stamp.encode(&mut w);
    w.u8(level as u8);
    w.string(name);
    w.string(msg);
    w.string(name); // file: the script's name is also where the line came from
    w.string(""); // function: not known
    w.u32(0); // line: not known
    w.into_bytes()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_log_line_is_stamp_level_strings_and_line() {
        let bytes = log(Time { sec: 3, nanosec: 0 }, LogLevel::Warn, "s", "hi");
        let mut expected = vec![0, 1, 0, 0];
        expected.extend([3, 0, 0, 0, 0, 0, 0, 0]);
        expected.push(30); // level, at 8
        expected.extend([0, 0, 0]); // pad to 12
        expected.extend([2, 0, 0, 0, b's', 0]); // name, ends at 18
        expected.extend([0, 0]);
        expected.extend([3, 0, 0, 0, b'h', b'i', 0]); // msg, ends at 27
        expected.push(0);
        expected.extend([2, 0, 0, 0, b's', 0]); // file, ends at 34
        expected.extend([0, 0]);
        expected.extend([1, 0, 0, 0, 0]); // function "", ends at 41
        expected.extend([0, 0, 0]);
        expected.extend([0, 0, 0, 0]); // line
        assert_eq!(bytes, expected);
        assert_eq!(LogLevel::from_verbosity(100), LogLevel::Error);
        assert_eq!(LogLevel::from_verbosity(300), LogLevel::Warn);
        assert_eq!(LogLevel::from_verbosity(450), LogLevel::Info);
        assert_eq!(LogLevel::from_verbosity(600), LogLevel::Debug);
        assert_eq!(LogLevel::from_number(30), LogLevel::Warn);
        assert_eq!(LogLevel::from_number(50), LogLevel::Error);
    }
}
