//! What the Lua host keeps for `simROS2`: the front end's network, and the endpoints the
//! scripts of this run opened, each with the script that owns it and its callback.
//! Endpoints close when the simulation stops, as CoppeliaSim's plugin shuts down what a
//! run created.

use std::cell::{Cell, RefCell};
use std::collections::BTreeMap;
use std::sync::Arc;

use gantry_protocol::ros::{MsgType, SrvType};
use gantry_ros::{Direction, EndpointId, EndpointSpec, NetworkError, RosNetwork, RosQos};
use gantry_sim_core::Handle;

use super::action::{ActionClient, ActionServer};
use super::callback::Callback;

/// What an endpoint handle stands for.
pub(crate) enum Kind {
    /// `createPublisher` / `advertise`.
    Publisher {
        /// The network's endpoint.
        id: EndpointId,
        /// The message type.
        ty: &'static MsgType,
    },
    /// `createSubscription` / `subscribe`.
    Subscription {
        /// The network's endpoint.
        id: EndpointId,
        /// The message type.
        ty: &'static MsgType,
        /// Called with each message.
        callback: Callback,
        /// Whether a malformed message was reported (once per subscription).
        warned: Cell<bool>,
    },
    /// `createService`: requests in, replies out (rmw_cyclonedds' mapping: each sample
    /// starts with the client's id and sequence number).
    Service {
        /// Requests arrive here.
        requests: EndpointId,
        /// Replies go here.
        replies: EndpointId,
        /// The service type.
        ty: &'static SrvType,
        /// Called with each request; returns the response.
        callback: Callback,
    },
    /// `createClient`.
    Client {
        /// Requests go here.
        requests: EndpointId,
        /// Replies arrive here.
        replies: EndpointId,
        /// The service type.
        ty: &'static SrvType,
        /// This client's id in request headers.
        guid: u64,
        /// The last sequence number sent.
        seq: Cell<i64>,
    },
    /// `createActionServer`.
    ActionServer(Box<ActionServer>),
    /// `createActionClient`.
    ActionClient(Box<ActionClient>),
}

impl Kind {
    fn network_ids(&self) -> Vec<EndpointId> {
        match self {
            Kind::Publisher { id, .. } | Kind::Subscription { id, .. } => vec![*id],
            Kind::Service { requests, replies, .. } | Kind::Client { requests, replies, .. } => {
                vec![*requests, *replies]
            }
            Kind::ActionServer(s) => s.network_ids(),
            Kind::ActionClient(c) => c.network_ids(),
        }
    }
}

/// One endpoint a script opened.
pub(crate) struct Endpoint {
    /// The object of the script that opened it (its callbacks run there).
    pub(crate) script: Option<Handle>,
    /// What it is.
    pub(crate) kind: Kind,
}

/// The Lua host's `simROS2` state (see the module docs).
#[derive(Default)]
pub(crate) struct RosHost {
    /// The front end's network; `None` in embeddings without one.
    pub(crate) network: RefCell<Option<Arc<dyn RosNetwork>>>,
    /// Open endpoints by the handle scripts hold.
    pub(crate) endpoints: RefCell<BTreeMap<i64, Endpoint>>,
    next_handle: Cell<i64>,
    /// The shared `/tf` publisher of `sendTransform(s)`, opened on first use.
    pub(crate) tf: Cell<Option<EndpointId>>,
    /// Whether the ROS 1 notice was logged.
    pub(crate) ros1_noticed: Cell<bool>,
    /// ROS 1's parameters (`simROS.setParam*`), kept across stops.
    pub(crate) params: RefCell<super::param_store::Params>,
}

/// The network is missing.
pub(crate) const NO_NETWORK: &str =
    "no ROS 2 network in this embedding: run the scene with `gantry run` (or `gantry.Client(..., ros2=True)`)";

impl RosHost {
    /// The network, or why there is none.
    pub(crate) fn network(&self) -> Result<Arc<dyn RosNetwork>, NetworkError> {
        self.network
            .borrow()
            .clone()
            .ok_or_else(|| NetworkError(NO_NETWORK.to_owned()))
    }

    /// Runs `f` on action server `h` with the network; `None` without a network or
    /// without such a server (a callback may have shut it down).
    pub(crate) fn with_action_server<T>(
        &self,
        h: i64,
        f: impl FnOnce(&ActionServer, &dyn RosNetwork) -> T,
    ) -> Option<T> {
        let net = self.network().ok()?;
        match self.endpoints.borrow().get(&h).map(|e| &e.kind) {
            Some(Kind::ActionServer(s)) => Some(f(s, net.as_ref())),
            _ => None,
        }
    }

    /// [`Self::with_action_server`] for action client `h`.
    pub(crate) fn with_action_client<T>(
        &self,
        h: i64,
        f: impl FnOnce(&ActionClient, &dyn RosNetwork) -> T,
    ) -> Option<T> {
        let net = self.network().ok()?;
        match self.endpoints.borrow().get(&h).map(|e| &e.kind) {
            Some(Kind::ActionClient(c)) => Some(f(c, net.as_ref())),
            _ => None,
        }
    }

    /// Opens one network endpoint.
    pub(crate) fn open(
        &self,
        direction: Direction,
        dds_topic: String,
        dds_type: String,
        qos: RosQos,
    ) -> Result<EndpointId, NetworkError> {
        self.network()?.open(&EndpointSpec {
            direction,
            dds_topic,
            dds_type,
            qos,
        })
    }

    /// Keeps an endpoint; its handle for scripts.
    pub(crate) fn insert(&self, endpoint: Endpoint) -> i64 {
        let h = self.next_handle.get() + 1;
        self.next_handle.set(h);
        self.endpoints.borrow_mut().insert(h, endpoint);
        h
    }

    /// Closes the endpoint `handle`; whether it existed.
    pub(crate) fn remove(&self, handle: i64) -> bool {
        let e = self.endpoints.borrow_mut().remove(&handle);
        match e {
            Some(e) => {
                if let Ok(n) = self.network() {
                    for id in e.kind.network_ids() {
                        n.close(id);
                    }
                }
                true
            }
            None => false,
        }
    }

    /// The run ended: every endpoint closes (the shared `/tf` publisher too).
    pub(crate) fn simulation_ended(&self) {
        let handles: Vec<i64> = self.endpoints.borrow().keys().copied().collect();
        for h in handles {
            self.remove(h);
        }
        if let (Some(id), Ok(n)) = (self.tf.take(), self.network()) {
            n.close(id);
        }
    }
}
