//! gantry on a ROS 2 graph, with nothing installed but gantry.
//!
//! ROS 2 nodes talk DDS/RTPS; RustDDS speaks it in pure Rust, so gantry joins a graph
//! without a ROS distribution or a C toolchain. This crate sits above the simulation,
//! on the simulation thread's side of a channel like every other transport:
//!
//! - [`config`]: the domain and discovery range, from ROS's environment variables;
//! - [`node`]: the DDS participant on its own thread, which carries CDR bodies for the
//!   Lua host's `simROS2` module (the [`gantry_ros::RosNetwork`] it
//!   implements) and for the graph;
//! - [`graph`]: `/clock`, `/tf`, `/joint_states` and camera topics after each step;
//! - [`description`]: URDF robots as robot_state_publisher presents them
//!   (`/robot_description`, TF frames named by URDF link).
//!
//! See docs/ros2.md.

pub mod config;
pub mod description;
pub mod graph;
pub mod node;
mod raw;
mod topics;

pub use config::{ConfigError, DiscoveryRange, RosConfig};
pub use graph::{GraphOptions, RosGraph};

/// What a front end runs ROS 2 with.
#[derive(Debug, Clone)]
pub struct RosSetup {
    /// The network (started on first use, or by [`DdsNetwork::start_now`]).
    pub network: std::sync::Arc<DdsNetwork>,
    /// Publish the graph's topics with these options (`--ros2`); `None`: only what
    /// scripts publish.
    pub graph: Option<GraphOptions>,
}

impl RosSetup {
    /// The set-up of a front end, on the domain and range of ROS's environment
    /// variables ([`RosConfig::from_env`]). Without `graph` the network starts on first
    /// use, and a bad environment is the reason scripts' `simROS2` calls get. With it,
    /// the network starts now, so that a domain that cannot be joined fails the run.
    ///
    /// # Errors
    /// With `graph`: the environment names no valid domain or range, or the
    /// participant cannot start.
    pub fn from_env(graph: Option<GraphOptions>) -> Result<Self, String> {
        let config = RosConfig::from_env();
        let network = match (config, graph) {
            (Ok(c), _) => DdsNetwork::new(c),
            (Err(e), None) => DdsNetwork::unavailable(e.to_string()),
            (Err(e), Some(_)) => return Err(e.to_string()),
        };
        if graph.is_some() {
            network.start_now().map_err(|e| e.to_string())?;
        }
        Ok(Self {
            network: std::sync::Arc::new(network),
            graph,
        })
    }

    /// The graph's publisher when asked for; `None` otherwise, or (logged) when the
    /// network cannot open its topics.
    pub fn graph(&self) -> Option<RosGraph> {
        let options = self.graph?;
        RosGraph::new(self.network.clone(), options)
            .map_err(|e| tracing::error!("ROS 2: the graph's topics are not published: {e}"))
            .ok()
    }
}
pub use node::{DdsNetwork, EndpointStats};
