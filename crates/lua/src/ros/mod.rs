//! `simROS2` (and ROS 1's `simROS`, served on the same graph): publishers,
//! subscriptions, services and clients for scripts, on the front end's [`RosNetwork`]
//! (gantry-ros's trait, re-exported here for the front ends that hand one over).
//! Messages are encoded and decoded here with gantry-protocol's `ros` codec; the
//! network only carries bytes. Callbacks run in `crate::ros_dispatch`.

pub(crate) mod action;
mod action_api;
pub(crate) mod callback;
mod error;
pub(crate) mod goal;
pub(crate) mod host;
pub(crate) mod lua_api;
pub(crate) mod module;
mod param_store;
mod params;
pub(crate) mod wire;

pub use gantry_ros::{Direction, EndpointId, EndpointSpec, NetworkError, RosNetwork, RosQos, RosSample};
pub use lua_api::CALL_TIMEOUT_S;
pub use module::{FUNCTIONS, ROS1_FUNCTIONS};
