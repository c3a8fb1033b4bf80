//! gantry's DDS participant: one thread that owns every RustDDS endpoint, fed over a
//! channel, so that the simulation thread never waits on the network. Writes are
//! queued (bounded: dropped and counted when full); what arrives waits in one bounded
//! inbox per subscription until the Lua host or the graph takes it.
//!
//! The participant starts on the first endpoint opened: a run that never touches ROS
//! sends nothing on the network.

use std::collections::{HashMap, VecDeque};
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::mpsc::{self, Receiver, Sender, SyncSender};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::JoinHandle;
use std::time::Duration as StdDuration;

use gantry_ros::{Direction, EndpointId, EndpointSpec, NetworkError, RosNetwork, RosQos, RosSample};
use rustdds::mio1::{Events, Interest, Poll, Token, Waker};
use rustdds::no_key::{DataReader, DataWriter};
use rustdds::policy::{Durability, History, Reliability};
use rustdds::{DomainParticipantBuilder, QosPolicies, QosPolicyBuilder, RTPSEntity, TopicKind};

use crate::config::RosConfig;
use crate::raw::{RawAdapter, RawCdr};

/// Writes queued for the DDS thread, at most: beyond, writes are dropped (and counted)
/// rather than growing memory while the network is slow.
pub const MAX_QUEUED_WRITES: usize = 1024;

/// The largest message body accepted from the network, bytes (a 2048 x 2048 RGB image
/// is 12 MiB): larger ones are dropped and counted.
pub const MAX_RECEIVED_BODY: usize = 64 << 20;

/// The poll token of the command channel's waker.
const WAKE: Token = Token(usize::MAX);

/// How often the DDS thread refreshes the publishers' matched subscriptions.
const MATCH_REFRESH: StdDuration = StdDuration::from_millis(20);

/// How long the DDS thread sleeps without an event before it looks at its readers
/// anyway (a safety net under edge-triggered readiness).
const IDLE_POLL: StdDuration = StdDuration::from_millis(20);

/// One endpoint's traffic, for the viewer's topic list and the logs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EndpointStats {
    /// The endpoint.
    pub id: EndpointId,
    /// Which way.
    pub direction: Direction,
    /// Its DDS topic name.
    pub dds_topic: String,
    /// Its DDS type name.
    pub dds_type: String,
    /// Messages written or received.
    pub messages: u64,
    /// Messages dropped: writes over the queue bound, or received ones over an inbox's
    /// depth or [`MAX_RECEIVED_BODY`].
    pub dropped: u64,
}

enum Command {
    Open {
        id: EndpointId,
        spec: EndpointSpec,
        done: SyncSender<Result<(), NetworkError>>,
    },
    Write {
        id: EndpointId,
        body: Vec<u8>,
    },
    Close(EndpointId),
    Shutdown,
}

/// What the simulation side and the DDS thread share about one endpoint.
#[derive(Debug)]
struct Shared {
    spec: EndpointSpec,
    messages: AtomicU64,
    dropped: AtomicU64,
    /// Subscriptions a publisher has matched, refreshed by the DDS thread.
    matched: AtomicUsize,
    /// Received messages not yet taken (subscriptions only), oldest first.
    inbox: Mutex<VecDeque<RosSample>>,
}

#[derive(Debug)]
struct Running {
    commands: Sender<Command>,
    waker: Arc<Waker>,
    thread: Option<JoinHandle<()>>,
}

/// A ROS 2 network on RustDDS (see the module docs).
#[derive(Debug)]
pub struct DdsNetwork {
    config: RosConfig,
    running: Mutex<Option<Running>>,
    /// Why the participant could not start, once it failed (not retried every call).
    failed: Mutex<Option<String>>,
    endpoints: Arc<Mutex<HashMap<EndpointId, Arc<Shared>>>>,
    next_id: AtomicU64,
    queued: Arc<AtomicUsize>,
}

impl DdsNetwork {
    /// A network on `config`'s domain and interfaces; nothing starts until an endpoint
    /// is opened.
    pub fn new(config: RosConfig) -> Self {
        Self {
            config,
            running: Mutex::new(None),
            failed: Mutex::new(None),
            endpoints: Arc::new(Mutex::new(HashMap::new())),
            next_id: AtomicU64::new(1),
            queued: Arc::new(AtomicUsize::new(0)),
        }
    }

    /// A network that refuses every endpoint with `why` (the environment named a
    /// domain gantry cannot join): scripts get the reason when they use `simROS2`.
    pub fn unavailable(why: String) -> Self {
        let n = Self::new(RosConfig {
            domain_id: 0,
            range: crate::config::DiscoveryRange::Localhost,
        });
        *n.failed.lock().unwrap_or_else(PoisonError::into_inner) = Some(why);
        n
    }

    /// Starts the participant now rather than on first use, to report a failure early.
    ///
    /// # Errors
    /// Why it cannot start.
    pub fn start_now(&self) -> Result<(), NetworkError> {
        self.started().map(|_| ())
    }

    /// The configuration it joins with.
    pub fn config(&self) -> RosConfig {
        self.config
    }

    /// Every open endpoint's traffic, by id.
    pub fn stats(&self) -> Vec<EndpointStats> {
        let endpoints = self.endpoints.lock().unwrap_or_else(PoisonError::into_inner);
        let mut out: Vec<EndpointStats> = endpoints
            .iter()
            .map(|(id, s)| EndpointStats {
                id: *id,
                direction: s.spec.direction,
                dds_topic: s.spec.dds_topic.clone(),
                dds_type: s.spec.dds_type.clone(),
                messages: s.messages.load(Ordering::Relaxed),
                dropped: s.dropped.load(Ordering::Relaxed),
            })
            .collect();
        out.sort_by_key(|s| s.id);
        out
    }

    /// Starts the DDS thread unless it runs; its command sender and waker.
    fn started(&self) -> Result<(Sender<Command>, Arc<Waker>), NetworkError> {
        if let Some(why) = self.failed.lock().unwrap_or_else(PoisonError::into_inner).as_ref() {
            return Err(NetworkError(why.clone()));
        }
        let mut running = self.running.lock().unwrap_or_else(PoisonError::into_inner);
        if let Some(r) = running.as_ref() {
            return Ok((r.commands.clone(), r.waker.clone()));
        }
        match start(self.config, self.endpoints.clone(), self.queued.clone()) {
            Ok(r) => {
                let out = (r.commands.clone(), r.waker.clone());
                *running = Some(r);
                Ok(out)
            }
            Err(why) => {
                *self.failed.lock().unwrap_or_else(PoisonError::into_inner) = Some(why.clone());
                Err(NetworkError(why))
            }
        }
    }

    fn send(&self, command: Command) -> Result<(), NetworkError> {
        self.send_waking(command, true)
    }

    /// Sends `command`, waking the DDS thread when `wake` (a wake is a system call:
    /// writes wake it only when it may be asleep, see [`Node::run`]).
    fn send_waking(&self, command: Command, wake: bool) -> Result<(), NetworkError> {
        let (tx, waker) = self.started()?;
        tx.send(command)
            .map_err(|_| NetworkError("the ROS 2 network thread has stopped".to_owned()))?;
        if wake {
            // A failed wake leaves the command for the thread's next idle poll.
            let _ = waker.wake();
        }
        Ok(())
    }
}

impl RosNetwork for DdsNetwork {
    fn open(&self, spec: &EndpointSpec) -> Result<EndpointId, NetworkError> {
        let id = self.next_id.fetch_add(1, Ordering::Relaxed);
        let (done, wait) = mpsc::sync_channel(1);
        self.endpoints.lock().unwrap_or_else(PoisonError::into_inner).insert(
            id,
            Arc::new(Shared {
                spec: spec.clone(),
                messages: AtomicU64::new(0),
                dropped: AtomicU64::new(0),
                matched: AtomicUsize::new(0),
                inbox: Mutex::new(VecDeque::new()),
            }),
        );
        let opened = self
            .send(Command::Open {
                id,
                spec: spec.clone(),
                done,
            })
            .and_then(|()| {
                // Creating an endpoint is local work on the DDS thread (no network round
                // trip), so waiting for it is short; the bound guards a wedged thread.
                wait.recv_timeout(StdDuration::from_secs(5))
                    .map_err(|_| NetworkError("the ROS 2 network thread did not answer".to_owned()))?
            });
        if opened.is_err() {
            self.endpoints
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .remove(&id);
        }
        opened.map(|()| id)
    }

    fn write(&self, id: EndpointId, body: Vec<u8>) -> Result<(), NetworkError> {
        let shared = self
            .endpoints
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .get(&id)
            .cloned()
            .filter(|s| s.spec.direction == Direction::Publish)
            .ok_or_else(|| NetworkError(format!("no publisher {id}")))?;
        let before = self.queued.fetch_add(1, Ordering::AcqRel);
        if before >= MAX_QUEUED_WRITES {
            self.queued.fetch_sub(1, Ordering::AcqRel);
            shared.dropped.fetch_add(1, Ordering::Relaxed);
            return Ok(());
        }
        // With writes already queued the thread is awake, or will not sleep before it
        // has taken them all (see `Node::run`): only the first needs a wake.
        self.send_waking(Command::Write { id, body }, before == 0)
    }

    fn take(&self, id: EndpointId, max: usize) -> Vec<RosSample> {
        let Some(shared) = self
            .endpoints
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .get(&id)
            .cloned()
        else {
            return Vec::new();
        };
        let mut inbox = shared.inbox.lock().unwrap_or_else(PoisonError::into_inner);
        let n = inbox.len().min(max);
        inbox.drain(..n).collect()
    }

    fn matched(&self, id: EndpointId) -> usize {
        self.endpoints
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .get(&id)
            .map_or(0, |s| s.matched.load(Ordering::Relaxed))
    }

    fn close(&self, id: EndpointId) {
        if self
            .endpoints
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .remove(&id)
            .is_some()
        {
            let _ = self.send(Command::Close(id));
        }
    }
}

impl Drop for DdsNetwork {
    fn drop(&mut self) {
        let running = self.running.get_mut().unwrap_or_else(PoisonError::into_inner).take();
        if let Some(mut r) = running {
            let _ = r.commands.send(Command::Shutdown);
            let _ = r.waker.wake();
            if let Some(t) = r.thread.take() {
                let _ = t.join();
            }
        }
    }
}

/// RustDDS's QoS for a ROS profile.
fn dds_qos(q: RosQos) -> QosPolicies {
    QosPolicyBuilder::new()
        .reliability(if q.reliable {
            Reliability::Reliable {
                max_blocking_time: rustdds::Duration::from_millis(100),
            }
        } else {
            Reliability::BestEffort
        })
        .durability(if q.transient_local {
            Durability::TransientLocal
        } else {
            Durability::Volatile
        })
        .history(History::KeepLast {
            depth: i32::try_from(q.depth.max(1)).unwrap_or(i32::MAX),
        })
        .build()
}

/// Starts the participant and its thread.
fn start(
    config: RosConfig,
    endpoints: Arc<Mutex<HashMap<EndpointId, Arc<Shared>>>>,
    queued: Arc<AtomicUsize>,
) -> Result<Running, String> {
    let poll = Poll::new().map_err(|e| format!("cannot poll for the ROS 2 network: {e}"))?;
    let waker = Arc::new(Waker::new(poll.registry(), WAKE).map_err(|e| format!("cannot wake the ROS 2 thread: {e}"))?);
    let mut builder = DomainParticipantBuilder::new(config.domain_id);
    if let Some(ifs) = config.interfaces() {
        builder = builder.with_only_networks(ifs);
    }
    let participant = builder
        .build()
        .map_err(|e| format!("cannot join ROS 2 domain {}: {e}", config.domain_id))?;
    let (tx, rx) = mpsc::channel();
    let thread = std::thread::Builder::new()
        .name("gantry-ros2".to_owned())
        .spawn(move || {
            let mut node = Node {
                participant,
                poll,
                writers: HashMap::new(),
                readers: HashMap::new(),
                endpoints,
                queued,
                seen: HashMap::new(),
            };
            node.run(&rx);
        })
        .map_err(|e| format!("cannot start the ROS 2 thread: {e}"))?;
    tracing::info!("ROS 2: joined domain {} ({:?})", config.domain_id, config.range);
    Ok(Running {
        commands: tx,
        waker,
        thread: Some(thread),
    })
}

/// The DDS thread's state.
struct Node {
    participant: rustdds::DomainParticipant,
    poll: Poll,
    writers: HashMap<EndpointId, DataWriter<RawCdr, RawAdapter>>,
    readers: HashMap<EndpointId, DataReader<RawCdr, RawAdapter>>,
    endpoints: Arc<Mutex<HashMap<EndpointId, Arc<Shared>>>>,
    queued: Arc<AtomicUsize>,
    /// Each endpoint's match count at the last refresh.
    seen: HashMap<EndpointId, usize>,
}

impl Node {
    fn run(&mut self, commands: &Receiver<Command>) {
        let mut events = Events::with_capacity(64);
        let mut last_matched = std::time::Instant::now();
        loop {
            if let Err(e) = self.poll.poll(&mut events, Some(IDLE_POLL))
                && e.kind() != std::io::ErrorKind::Interrupted
            {
                tracing::error!("ROS 2: polling failed, the network thread stops: {e}");
                return;
            }
            // Writes are counted in `queued` before they are sent, and a writer wakes
            // this thread only when the count was 0. So the count is lowered only
            // after the channel ran dry, and while it is still above 0 a write is on
            // its way (counted, not yet in the channel): take it before sleeping.
            loop {
                let mut writes = 0;
                while let Ok(c) = commands.try_recv() {
                    match c {
                        Command::Open { id, spec, done } => {
                            let _ = done.send(self.open(id, &spec));
                        }
                        Command::Write { id, body } => {
                            writes += 1;
                            self.write(id, body);
                        }
                        Command::Close(id) => {
                            self.writers.remove(&id);
                            if let Some(mut r) = self.readers.remove(&id) {
                                let _ = self.poll.registry().deregister(&mut r);
                            }
                        }
                        Command::Shutdown => return,
                    }
                }
                if self.queued.fetch_sub(writes, Ordering::AcqRel) == writes {
                    break;
                }
                std::thread::yield_now();
            }
            self.receive();
            if last_matched.elapsed() >= MATCH_REFRESH {
                last_matched = std::time::Instant::now();
                self.refresh_matches();
            }
        }
    }

    /// Notes how many remote endpoints of each endpoint's topic discovery has found:
    /// subscriptions for a publisher, publishers for a subscription (RustDDS's
    /// per-writer match status is not implemented). A count is reported once it has
    /// held for two refreshes: discovery's database learns of a reader a moment
    /// before the writer itself sends to it, and a request written in that moment
    /// would be lost.
    fn refresh_matches(&mut self) {
        let mine = self.participant.guid().prefix;
        let mut seen = std::mem::take(&mut self.seen);
        // Subscriptions for our writers and publications for our readers, by topic
        // name, each marked whether it is this participant's own.
        let readers: Vec<(bool, String)> = if self.writers.is_empty() {
            Vec::new()
        } else {
            self.participant
                .discovered_readers()
                .into_iter()
                .map(|r| {
                    (
                        r.reader_proxy.remote_reader_guid.prefix == mine,
                        r.subscription_topic_data.topic_name().clone(),
                    )
                })
                .collect()
        };
        let writers: Vec<(bool, String)> = if self.readers.is_empty() {
            Vec::new()
        } else {
            self.participant
                .discovered_writers()
                .into_iter()
                .map(|w| {
                    (
                        w.writer_proxy.remote_writer_guid.prefix == mine,
                        w.publication_topic_data.topic_name().clone(),
                    )
                })
                .collect()
        };
        let ours = self
            .writers
            .keys()
            .map(|id| (*id, &readers))
            .chain(self.readers.keys().map(|id| (*id, &writers)));
        for (id, remote) in ours {
            let Some(s) = self.shared(id) else { continue };
            let n = remote
                .iter()
                .filter(|(own, topic)| !own && *topic == s.spec.dds_topic)
                .count();
            let before = seen.insert(id, n).unwrap_or(0);
            s.matched.store(n.min(before), Ordering::Relaxed);
        }
        seen.retain(|id, _| self.writers.contains_key(id) || self.readers.contains_key(id));
        self.seen = seen;
    }

    fn open(&mut self, id: EndpointId, spec: &EndpointSpec) -> Result<(), NetworkError> {
        let qos = dds_qos(spec.qos);
        let topic = self
            .participant
            .create_topic(spec.dds_topic.clone(), spec.dds_type.clone(), &qos, TopicKind::NoKey)
            .map_err(|e| NetworkError(format!("cannot create topic {}: {e}", spec.dds_topic)))?;
        match spec.direction {
            Direction::Publish => {
                let publisher = self
                    .participant
                    .create_publisher(&qos)
                    .map_err(|e| NetworkError(format!("cannot publish {}: {e}", spec.dds_topic)))?;
                let w = publisher
                    .create_datawriter_no_key::<RawCdr, RawAdapter>(&topic, Some(qos))
                    .map_err(|e| NetworkError(format!("cannot publish {}: {e}", spec.dds_topic)))?;
                self.writers.insert(id, w);
            }
            Direction::Subscribe => {
                let subscriber = self
                    .participant
                    .create_subscriber(&qos)
                    .map_err(|e| NetworkError(format!("cannot subscribe to {}: {e}", spec.dds_topic)))?;
                let mut r = subscriber
                    .create_datareader_no_key::<RawCdr, RawAdapter>(&topic, Some(qos))
                    .map_err(|e| NetworkError(format!("cannot subscribe to {}: {e}", spec.dds_topic)))?;
                let token = usize::try_from(id).unwrap_or(0);
                if let Err(e) = self.poll.registry().register(&mut r, Token(token), Interest::READABLE) {
                    // The idle poll still reads it, only later.
                    tracing::debug!("ROS 2: {} not registered for readiness: {e}", spec.dds_topic);
                }
                self.readers.insert(id, r);
            }
        }
        Ok(())
    }

    fn shared(&self, id: EndpointId) -> Option<Arc<Shared>> {
        self.endpoints
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .get(&id)
            .cloned()
    }

    fn write(&mut self, id: EndpointId, body: Vec<u8>) {
        let (Some(w), Some(shared)) = (self.writers.get(&id), self.shared(id)) else {
            return;
        };
        let data = RawCdr {
            body: body.into(),
            little_endian: true,
        };
        match w.write(data, None) {
            Ok(()) => {
                shared.messages.fetch_add(1, Ordering::Relaxed);
            }
            Err(e) => {
                shared.dropped.fetch_add(1, Ordering::Relaxed);
                tracing::debug!("ROS 2: a write to {} failed: {e}", shared.spec.dds_topic);
            }
        }
    }

    /// Moves every sample that arrived into its endpoint's inbox.
    fn receive(&mut self) {
        for (id, reader) in &mut self.readers {
            let Some(shared) = self
                .endpoints
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .get(id)
                .cloned()
            else {
                continue;
            };
            let depth = usize::try_from(shared.spec.qos.depth.max(1)).unwrap_or(usize::MAX);
            loop {
                match reader.take_next_sample() {
                    Ok(Some(sample)) => {
                        let raw = sample.into_value();
                        if raw.body.len() > MAX_RECEIVED_BODY {
                            shared.dropped.fetch_add(1, Ordering::Relaxed);
                            continue;
                        }
                        shared.messages.fetch_add(1, Ordering::Relaxed);
                        let mut inbox = shared.inbox.lock().unwrap_or_else(PoisonError::into_inner);
                        if inbox.len() >= depth {
                            inbox.pop_front();
                            shared.dropped.fetch_add(1, Ordering::Relaxed);
                        }
                        inbox.push_back(RosSample {
                            body: raw.body.to_vec(),
                            little_endian: raw.little_endian,
                        });
                    }
                    Ok(None) => break,
                    Err(e) => {
                        // A sample RustDDS could not read (an unsupported representation):
                        // dropped, the reader goes on.
                        shared.dropped.fetch_add(1, Ordering::Relaxed);
                        tracing::debug!("ROS 2: a sample on {} was unreadable: {e}", shared.spec.dds_topic);
                        break;
                    }
                }
            }
        }
    }
}
