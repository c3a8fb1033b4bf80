//! `simROS2` (and ROS 1's `simROS`, served on the same graph): publishers,
//! subscriptions, services and clients for scripts, on the front end's [`RosNetwork`].
//! Messages are encoded and decoded here with gantry-protocol's `ros` codec; the
//! network only carries bytes. Callbacks run in `crate::ros_dispatch`.

pub(crate) mod action;
mod action_api;
pub(crate) mod callback;
pub(crate) mod host;
pub(crate) mod lua_api;
pub(crate) mod module;
mod network;
mod param_store;
mod params;
pub(crate) mod wire;

pub use lua_api::CALL_TIMEOUT_S;
pub use module::{FUNCTIONS, ROS1_FUNCTIONS};
pub use network::{Direction, EndpointId, EndpointSpec, NetworkError, RosNetwork, RosQos, RosSample};
