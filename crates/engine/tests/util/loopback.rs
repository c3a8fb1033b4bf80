//! An in-memory ROS 2 network for the `simROS2` tests: each write reaches every
//! subscription of the same DDS topic, and "matched" counts the other direction's
//! endpoints of the topic, as DDS discovery would once settled.

use std::collections::HashMap;
use std::sync::Mutex;

use gantry_ros::{Direction, EndpointId, EndpointSpec, NetworkError, RosNetwork, RosSample};

/// Delivers writes to the subscriptions of the same topic, in memory.
#[derive(Debug, Default)]
pub struct Loopback {
    pub endpoints: Mutex<HashMap<EndpointId, (EndpointSpec, Vec<RosSample>)>>,
    next: Mutex<EndpointId>,
    pub writes: Mutex<Vec<(String, Vec<u8>)>>,
}

impl Loopback {
    pub fn open_topics(&self) -> Vec<String> {
        let mut t: Vec<String> = self
            .endpoints
            .lock()
            .unwrap()
            .values()
            .map(|(s, _)| s.dds_topic.clone())
            .collect();
        t.sort();
        t
    }

    /// Delivers `body` as if a remote node had written it on `topic`.
    pub fn inject(&self, topic: &str, body: Vec<u8>) {
        for (spec, inbox) in self.endpoints.lock().unwrap().values_mut() {
            if spec.dds_topic == topic && spec.direction == Direction::Subscribe {
                inbox.push(RosSample {
                    body: body.clone(),
                    little_endian: true,
                });
            }
        }
    }
}

impl RosNetwork for Loopback {
    fn open(&self, spec: &EndpointSpec) -> Result<EndpointId, NetworkError> {
        let mut next = self.next.lock().unwrap();
        *next += 1;
        self.endpoints.lock().unwrap().insert(*next, (spec.clone(), Vec::new()));
        Ok(*next)
    }

    fn write(&self, id: EndpointId, body: Vec<u8>) -> Result<(), NetworkError> {
        let topic = match self.endpoints.lock().unwrap().get(&id) {
            Some((s, _)) if s.direction == Direction::Publish => s.dds_topic.clone(),
            _ => return Err(NetworkError(format!("no publisher {id}"))),
        };
        self.writes.lock().unwrap().push((topic.clone(), body.clone()));
        self.inject(&topic, body);
        Ok(())
    }

    fn take(&self, id: EndpointId, max: usize) -> Vec<RosSample> {
        let mut e = self.endpoints.lock().unwrap();
        let Some((_, inbox)) = e.get_mut(&id) else {
            return Vec::new();
        };
        let n = inbox.len().min(max);
        inbox.drain(..n).collect()
    }

    fn close(&self, id: EndpointId) {
        self.endpoints.lock().unwrap().remove(&id);
    }

    fn matched(&self, id: EndpointId) -> usize {
        let e = self.endpoints.lock().unwrap();
        let Some((spec, _)) = e.get(&id) else { return 0 };
        e.values()
            .filter(|(s, _)| s.dds_topic == spec.dds_topic && s.direction != spec.direction)
            .count()
    }
}
