//! A network that carries CDR-encoded messages to and from a ROS 2 graph, for the Lua
//! host's `simROS2` module and the graph's topics. They encode and decode
//! (gantry-protocol's `ros` codec); the network moves bytes. gantry's implementation
//! speaks DDS (gantry-ros2); tests may give a loopback.

use std::fmt;

/// ROS 2 quality of service, as much of it as scripts and the graph choose.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RosQos {
    /// Reliable (ROS's default) or best effort (sensor data).
    pub reliable: bool,
    /// Transient local: late subscribers get the last `depth` messages (latched topics
    /// such as `/tf_static` and `/robot_description`); volatile otherwise.
    pub transient_local: bool,
    /// History depth (keep last).
    pub depth: u32,
}

impl Default for RosQos {
    /// ROS 2's default profile: reliable, volatile, keep last 10.
    fn default() -> Self {
        Self {
            reliable: true,
            transient_local: false,
            depth: 10,
        }
    }
}

/// Which way an endpoint carries messages.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// gantry writes.
    Publish,
    /// gantry reads.
    Subscribe,
}

/// One DDS endpoint to open.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EndpointSpec {
    /// Publisher or subscription.
    pub direction: Direction,
    /// The DDS topic name (`rt/cmd_vel`, `rq/set_flagRequest`).
    pub dds_topic: String,
    /// The DDS type name (`geometry_msgs::msg::dds_::Twist_`).
    pub dds_type: String,
    /// Its quality of service.
    pub qos: RosQos,
}

/// One message received, as it came: the CDR body after the encapsulation header.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RosSample {
    /// The CDR body.
    pub body: Vec<u8>,
    /// Byte order the writer used (CDR_LE or CDR_BE).
    pub little_endian: bool,
}

/// An endpoint's identity in a network.
pub type EndpointId = u64;

/// Why the network refused something: the implementation's own words (a DDS error, a
/// closed endpoint), passed on to the script or the log as they are.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct NetworkError(pub String);

/// A ROS 2 network (see the module docs). Its calls never wait on the network: writes
/// are queued (and dropped, counted, when the queue is full), reads return what has
/// arrived.
pub trait RosNetwork: Send + Sync + fmt::Debug {
    /// Opens an endpoint.
    ///
    /// # Errors
    /// The network could not be started, or the endpoint not created.
    fn open(&self, spec: &EndpointSpec) -> Result<EndpointId, NetworkError>;
    /// Queues a message (its CDR body, little-endian) on a publishing endpoint.
    ///
    /// # Errors
    /// No such publishing endpoint, or the network has stopped.
    fn write(&self, id: EndpointId, body: Vec<u8>) -> Result<(), NetworkError>;
    /// Up to `max` messages received on a subscribing endpoint since the last call,
    /// oldest first.
    fn take(&self, id: EndpointId, max: usize) -> Vec<RosSample>;
    /// Closes an endpoint (unknown ids are ignored).
    fn close(&self, id: EndpointId);
    /// How many remote endpoints of its topic an endpoint has matched, as last seen
    /// (subscriptions for a publisher, publishers for a subscription): 0 until
    /// discovery finds one.
    fn matched(&self, id: EndpointId) -> usize;
}
