//! Helpers for the graph's tests: an in-memory ROS network that keeps every endpoint
//! ever opened and every sample written, and decoding of what was written. Temp dirs and
//! repository paths are `gantry_test_support`'s.

use std::collections::HashMap;
use std::sync::Mutex;

use gantry_ros::{Direction, EndpointId, EndpointSpec, NetworkError, RosNetwork, RosSample};
use gantry_sim_core::Value;

/// A network that only remembers: what was opened (with its QoS), what is still open
/// and what was written, by DDS topic. Nothing arrives on subscriptions.
#[derive(Debug, Default)]
pub struct Memory {
    inner: Mutex<Inner>,
}

#[derive(Debug, Default)]
struct Inner {
    next: EndpointId,
    open: HashMap<EndpointId, EndpointSpec>,
    opened: Vec<EndpointSpec>,
    writes: Vec<(String, Vec<u8>)>,
}

impl Memory {
    /// Every endpoint opened so far, closed ones included, in order.
    pub fn opened(&self) -> Vec<EndpointSpec> {
        self.inner.lock().expect("not poisoned").opened.clone()
    }

    /// The DDS topics of the endpoints open now, sorted.
    pub fn open_topics(&self) -> Vec<String> {
        let mut t: Vec<String> = self
            .inner
            .lock()
            .expect("not poisoned")
            .open
            .values()
            .map(|s| s.dds_topic.clone())
            .collect();
        t.sort();
        t
    }

    /// The bodies written on DDS topic `topic`, oldest first.
    pub fn written(&self, topic: &str) -> Vec<Vec<u8>> {
        self.inner
            .lock()
            .expect("not poisoned")
            .writes
            .iter()
            .filter(|(t, _)| t == topic)
            .map(|(_, b)| b.clone())
            .collect()
    }
}

impl RosNetwork for Memory {
    fn open(&self, spec: &EndpointSpec) -> Result<EndpointId, NetworkError> {
        let mut i = self.inner.lock().expect("not poisoned");
        i.next += 1;
        let id = i.next;
        i.open.insert(id, spec.clone());
        i.opened.push(spec.clone());
        Ok(id)
    }

    fn write(&self, id: EndpointId, body: Vec<u8>) -> Result<(), NetworkError> {
        let mut i = self.inner.lock().expect("not poisoned");
        match i.open.get(&id) {
            Some(s) if s.direction == Direction::Publish => {
                let topic = s.dds_topic.clone();
                i.writes.push((topic, body));
                Ok(())
            }
            _ => Err(NetworkError(format!("no publisher {id}"))),
        }
    }

    fn take(&self, _: EndpointId, _: usize) -> Vec<RosSample> {
        Vec::new()
    }

    fn close(&self, id: EndpointId) {
        self.inner.lock().expect("not poisoned").open.remove(&id);
    }

    fn matched(&self, _: EndpointId) -> usize {
        0
    }
}

/// A body (CDR after the encapsulation header, little-endian) of ROS type `ty`.
pub fn decode(ty: &str, body: &[u8]) -> Value {
    gantry_protocol::ros::message_type(ty)
        .unwrap_or_else(|e| panic!("{ty}: {e}"))
        .decode_body(body, true, 0)
        .unwrap_or_else(|e| panic!("a {ty}: {e}"))
}

/// A text field of a decoded message.
pub fn text<'a>(v: &'a Value, field: &str) -> &'a str {
    v.get(field)
        .and_then(Value::as_str)
        .unwrap_or_else(|| panic!("no text {field} in {v:?}"))
}

/// A number field of a decoded message.
pub fn number(v: &Value, field: &str) -> f64 {
    v.get(field)
        .and_then(Value::as_f64)
        .unwrap_or_else(|| panic!("no number {field} in {v:?}"))
}

/// The items of an array field of a decoded message.
pub fn items<'a>(v: &'a Value, field: &str) -> &'a [Value] {
    match v.get(field) {
        Some(Value::Array(a)) => a,
        other => panic!("no array {field} in {v:?}: {other:?}"),
    }
}
