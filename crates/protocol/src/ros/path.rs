//! Field paths for error messages (`linear.x`, `position[2]`), kept as a chain of
//! borrowed links on the stack so that the codec pays nothing for them until an error
//! is reported.

use std::fmt::{self, Display, Write as _};

/// Where in a message a value is: a chain from the value up to the message root.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Path<'a> {
    /// The message itself.
    Root,
    /// A field of the message at `.0`.
    Field(&'a Path<'a>, &'a str),
    /// An element of the array at `.0`.
    Index(&'a Path<'a>, usize),
}

impl<'a> Path<'a> {
    /// The path of field `name` under this one.
    pub(crate) fn field(&'a self, name: &'a str) -> Path<'a> {
        Path::Field(self, name)
    }

    /// The path of element `i` under this one.
    pub(crate) fn index(&'a self, i: usize) -> Path<'a> {
        Path::Index(self, i)
    }

    /// `msg_type.path`, or just `msg_type` at the root.
    pub(crate) fn location(&self, msg_type: &str) -> String {
        match self {
            Path::Root => msg_type.to_owned(),
            _ => format!("{msg_type}.{self}"),
        }
    }
}

impl Display for Path<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Path::Root => Ok(()),
            Path::Field(Path::Root, name) => f.write_str(name),
            Path::Field(parent, name) => {
                parent.fmt(f)?;
                f.write_char('.')?;
                f.write_str(name)
            }
            Path::Index(parent, i) => {
                parent.fmt(f)?;
                write!(f, "[{i}]")
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renders_fields_and_indices() {
        let root = Path::Root;
        let a = root.field("poses");
        let b = a.index(3);
        let c = b.field("x");
        assert_eq!(c.to_string(), "poses[3].x");
        assert_eq!(
            c.location("geometry_msgs/msg/PoseArray"),
            "geometry_msgs/msg/PoseArray.poses[3].x"
        );
        assert_eq!(root.location("std_msgs/msg/Empty"), "std_msgs/msg/Empty");
    }
}
