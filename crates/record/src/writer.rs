//! The writer thread's side: turns [`Snapshot`]s into MCAP messages.
//!
//! Channels: `/tf`, `/joint_states` and `/rosout` from the start; one `/graph/...` and
//! one `/proximity/...` channel per stream or sensor, when its first value arrives.
//! Message log and publish times are the snapshot's recording time; stamps inside the
//! messages are simulation time.

use std::collections::{BTreeMap, HashMap};
use std::io::{Seek, Write};
use std::sync::Arc;

use mcap::records::{MessageHeader, Metadata};
use mcap::{Attachment, Compression, McapError, WriteOptions, Writer};

use gantry_mcap::format::{AttachedFile, JOINT_STATES_TOPIC, ROSOUT_TOPIC, TF_STATIC_TOPIC, TF_TOPIC, topic_name};
use gantry_mcap::input::{INPUT_TOPIC, Input};
use gantry_mcap::schema::{self, MessageType};
use gantry_ros::msg::{self, LogLevel, Time};
use gantry_ros::{LogSample, SignalSample, Snapshot, TfFrames};

/// An MCAP file being written: the channels so far and their message counts.
pub struct McapSink<W: Write + Seek> {
    mcap: Writer<W>,
    /// Channel ids by topic.
    channels: HashMap<Arc<str>, u16>,
    /// Schema ids by type name.
    schemas: HashMap<&'static str, u16>,
    /// Next sequence number of each channel.
    sequence: HashMap<u16, u32>,
    /// Messages written.
    messages: u64,
    /// The last log time written, so that times never go back in the file.
    last_log_ns: u64,
    /// Which frames go on `/tf_static` and which on `/tf`.
    frames: TfFrames,
}

impl<W: Write + Seek> McapSink<W> {
    /// Starts an MCAP file on `w` (profile `ros2`, zstd chunks, with the summary's
    /// chunk indexes and statistics).
    ///
    /// # Errors
    /// The header could not be written.
    pub fn new(w: W) -> Result<Self, McapError> {
        let mcap = WriteOptions::new()
            .profile("ros2")
            .library(concat!("gantry-record ", env!("CARGO_PKG_VERSION")))
            .compression(Some(Compression::Zstd))
            // zstd's fastest level: about twice the speed of its default (3) for a few
            // percent more bytes; the writer shares the machine with the simulation.
            .compression_level(1)
            // Compress on the writer thread itself: the machine's other cores belong
            // to the simulation.
            .compression_threads(0)
            .create(w)?;
        let mut sink = Self {
            mcap,
            channels: HashMap::new(),
            schemas: HashMap::new(),
            sequence: HashMap::new(),
            messages: 0,
            last_log_ns: 0,
            frames: TfFrames::exact(),
        };
        for (topic, ty) in [
            (TF_TOPIC, &schema::TF_MESSAGE),
            (TF_STATIC_TOPIC, &schema::TF_MESSAGE),
            (JOINT_STATES_TOPIC, &schema::JOINT_STATE),
            (ROSOUT_TOPIC, &schema::LOG),
        ] {
            sink.channel(topic, ty)?;
        }
        Ok(sink)
    }

    /// The metadata record `gantry` (version, command line, time step...).
    ///
    /// # Errors
    /// The record could not be written.
    pub fn metadata(&mut self, entries: &BTreeMap<String, String>) -> Result<(), McapError> {
        self.metadata_named("gantry", entries)
    }

    /// A metadata record named `name` (`gantry_end`: what is known at the end).
    ///
    /// # Errors
    /// The record could not be written.
    pub fn metadata_named(&mut self, name: &str, entries: &BTreeMap<String, String>) -> Result<(), McapError> {
        self.mcap.write_metadata(&Metadata {
            name: name.to_owned(),
            metadata: entries.clone(),
        })
    }

    /// Writes inputs on `/gantry/input`, each at its recording time.
    ///
    /// # Errors
    /// A write failed.
    pub fn inputs(&mut self, inputs: &[(u64, Input)]) -> Result<(), McapError> {
        if inputs.is_empty() {
            return Ok(());
        }
        let ch = self.channel(INPUT_TOPIC, &schema::INPUT)?;
        for (log_time_ns, input) in inputs {
            self.message(ch, *log_time_ns, &input.encode())?;
        }
        Ok(())
    }

    /// Attaches `file`.
    ///
    /// # Errors
    /// The attachment could not be written.
    pub fn attach(&mut self, file: &AttachedFile) -> Result<(), McapError> {
        self.mcap.attach(&Attachment {
            log_time: 0,
            create_time: 0,
            name: file.name.clone(),
            media_type: file.media_type.clone(),
            data: std::borrow::Cow::Borrowed(&file.data),
        })
    }

    /// The channel of `topic`, created with schema `ty` the first time.
    fn channel(&mut self, topic: &str, ty: &'static MessageType) -> Result<u16, McapError> {
        if let Some(&id) = self.channels.get(topic) {
            return Ok(id);
        }
        let schema = match self.schemas.get(ty.name) {
            Some(&id) => id,
            None => {
                let id = self.mcap.add_schema(ty.name, "ros2msg", ty.schema_text().as_bytes())?;
                self.schemas.insert(ty.name, id);
                id
            }
        };
        let id = self.mcap.add_channel(schema, topic, "cdr", &BTreeMap::new())?;
        self.channels.insert(topic.into(), id);
        Ok(id)
    }

    /// Writes one message on `channel` at `log_time_ns` (moved up to the last time
    /// written if earlier, so the file's times never go back).
    fn message(&mut self, channel: u16, log_time_ns: u64, data: &[u8]) -> Result<(), McapError> {
        let log_time = log_time_ns.max(self.last_log_ns);
        self.last_log_ns = log_time;
        let seq = self.sequence.entry(channel).or_insert(0);
        let sequence = *seq;
        *seq = seq.wrapping_add(1);
        self.messages += 1;
        self.mcap.write_to_known_channel(
            &MessageHeader {
                channel_id: channel,
                sequence,
                log_time,
                publish_time: log_time,
            },
            data,
        )
    }

    /// Writes the messages of one snapshot: its log lines and graph samples (which
    /// happened during the step, so before it ends), then `/tf`, `/joint_states` and
    /// the proximity sensors.
    ///
    /// # Errors
    /// A write failed.
    pub fn snapshot(&mut self, s: &Snapshot) -> Result<(), McapError> {
        self.logs(&s.logs)?;
        for g in &s.graphs {
            let ch = self.channel(&g.topic, &schema::FLOAT64)?;
            self.message(ch, g.log_time_ns, &msg::float64(g.value))?;
        }
        let stamp = Time::from_nanos(s.stamp_ns);
        let frame = |h| s.frame(h);
        let (statics, tf_data) = self.frames.messages(s);
        if let Some(data) = statics {
            let ch = self.channel(TF_STATIC_TOPIC, &schema::TF_MESSAGE)?;
            self.message(ch, s.log_time_ns, &data)?;
        }
        let tf = self.channel(TF_TOPIC, &schema::TF_MESSAGE)?;
        self.message(tf, s.log_time_ns, &tf_data)?;
        if !s.joints.is_empty() {
            let names: Vec<&str> = s.joints.iter().map(|j| frame(j.handle)).collect();
            let position: Vec<f64> = s.joints.iter().map(|j| j.position).collect();
            let velocity: Vec<f64> = s.joints.iter().map(|j| j.velocity).collect();
            let effort: Vec<f64> = s.joints.iter().map(|j| j.effort).collect();
            let ch = self.channel(JOINT_STATES_TOPIC, &schema::JOINT_STATE)?;
            self.message(
                ch,
                s.log_time_ns,
                &msg::joint_state(stamp, &names, &position, &velocity, &effort),
            )?;
        }
        for sig in &s.signals {
            let (topic, ty, data) = match sig {
                SignalSample::Int32(name, v) => {
                    (topic_name(&["signal", "int32", name]), &schema::INT32, msg::int32(*v))
                }
                SignalSample::Float(name, v) => (
                    topic_name(&["signal", "float", name]),
                    &schema::FLOAT64,
                    msg::float64(*v),
                ),
                SignalSample::String(name, v) => (
                    topic_name(&["signal", "string", name]),
                    &schema::STRING,
                    msg::string(&String::from_utf8_lossy(v)),
                ),
            };
            let ch = self.channel(&topic, ty)?;
            self.message(ch, s.log_time_ns, &data)?;
        }
        for img in &s.images {
            let name = frame(img.handle);
            let ch = self.channel(&topic_name(&["vision", name, "image"]), &schema::IMAGE)?;
            let [w, h] = img.resolution;
            self.message(ch, s.log_time_ns, &msg::image(stamp, name, w, h, &img.rgb))?;
        }
        for r in &s.ranges {
            let name = frame(r.handle);
            let ch = self.channel(&topic_name(&["proximity", name]), &schema::RANGE)?;
            // float32 on the wire, as sensor_msgs/Range has it.
            let data = msg::range(
                stamp,
                name,
                r.field_of_view as f32,
                r.min_range as f32,
                r.max_range as f32,
                r.range as f32,
            );
            self.message(ch, s.log_time_ns, &data)?;
        }
        Ok(())
    }

    /// Writes log lines on `/rosout`.
    ///
    /// # Errors
    /// A write failed.
    pub fn logs(&mut self, lines: &[LogSample]) -> Result<(), McapError> {
        if lines.is_empty() {
            return Ok(());
        }
        let ch = self.channel(ROSOUT_TOPIC, &schema::LOG)?;
        for l in lines {
            let data = msg::log(
                Time::from_nanos(l.stamp_ns),
                LogLevel::from_verbosity(l.verbosity),
                &l.source,
                &l.message,
            );
            self.message(ch, l.log_time_ns, &data)?;
        }
        Ok(())
    }

    /// Messages written so far.
    pub fn messages(&self) -> u64 {
        self.messages
    }

    /// Ends the file: the last chunk, then the summary (schemas, channels, chunk
    /// indexes, statistics) and the footer.
    ///
    /// # Errors
    /// A write failed.
    pub fn finish(&mut self) -> Result<(), McapError> {
        self.mcap.finish().map(|_| ())
    }

    /// Flushes the current chunk to the file, so that what was recorded so far can
    /// be read even if the process dies.
    ///
    /// # Errors
    /// A write failed.
    pub fn flush(&mut self) -> Result<(), McapError> {
        self.mcap.flush()
    }
}
