//! Helpers that the tests of several gantry crates share, so that each is written once:
//!
//! - [`TempDir`]: a fresh folder under the system temp dir, removed when dropped;
//! - [`repo`] and [`coppelia_files`]: where the repository's files and the shared
//!   CoppeliaSim scenes are, whichever crate's test asks;
//! - [`load`]: a scene file loaded from disk, or a failed test naming the file;
//! - [`free_port`]: a loopback TCP port nothing listens on;
//! - [`num`], [`int`], [`text`], [`floats`], [`ints`]: a [`Value`] read as the test
//!   expects it, or a failed test showing what came instead;
//! - [`assert_close`] and [`assert_contains`].
//!
//! The crate sits on gantry-scene and gantry-protocol only, so that the tests of every
//! crate from gantry-world up can use it without a dependency cycle (a cycle would link
//! two copies of the crate under test). Not here: helpers over a `Sim`, an `Engine` or
//! the Lua host, and anything only one crate's tests need; those stay in that crate's
//! `tests/util`.
//!
//! [`Value`]: gantry_protocol::Value

mod assert;
mod net;
mod paths;
mod scene;
mod temp_dir;
mod value;

pub use assert::{assert_close, assert_contains};
pub use net::free_port;
pub use paths::{coppelia_files, pyrep_assets, repo};
pub use scene::load;
pub use temp_dir::TempDir;
pub use value::{floats, int, ints, num, text};
