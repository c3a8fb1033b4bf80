//! Reading a recording back: [`Recording::open`] reads a file `gantry run --record`
//! wrote into an in-memory index that answers "what was the state at time t" in
//! microseconds, for `gantry replay` (scrubbing) and `gantry verify`. It reads the
//! recording only: rebuilding the recorded scene from the attachments and the metadata
//! is gantry-record's (`gantry_record::scene`), which knows the scene loader.
//!
//! The whole file is read once, record by record, from the start: every complete chunk
//! is decompressed, CRC-checked and its messages decoded ([`crate::decode`]). That is
//! also what makes damaged files readable:
//!
//! - a file cut short (a crash, a full disk, a copy still running) has no summary or
//!   footer; every complete chunk before the cut is read, and [`Recording::warnings`]
//!   says where the file ends;
//! - a chunk whose CRC does not match or that does not decompress is skipped, and the
//!   warning names the time range lost ([`Recording::lost`]); when the damage hides
//!   where the next record starts, the summary's chunk index (if the end of the file is
//!   intact) says where the next chunk is;
//! - foreign bytes, an MCAP file that is not a gantry recording, and a recording from
//!   a newer gantry (a `format_version` above [`FORMAT_VERSION`]) are refused with a [`ReadError`] saying so.
//!
//! Every length read from the file is checked against the bytes that hold it, and a
//! chunk may not decompress to more than [`MAX_CHUNK_BYTES`], nor to more than
//! [`MAX_CHUNK_RATIO`] times its compressed size: what a hostile file costs is bounded
//! by its own size. The record framing is parsed here rather than with
//! the `mcap` crate's whole-record parsers, which trust some lengths; the crate's
//! sans-io reader does the decompression and CRC checks.
//!
//! Times are MCAP log times in nanoseconds: simulation time, continued across a stop
//! and restart of the simulation so that they never go back (see docs/recording.md).
//!
//! The pose of a frame at time t is the latest `/tf_static` message at or before t,
//! overlaid with the latest `/tf` message at or before t (recordings made before
//! `/tf_static` existed carry every frame in `/tf`). A 10-minute showroom recording at
//! 20 Hz (12,000 snapshots, a 4 MB file) takes about 17 MB of memory this way
//! (`gantry replay` on it: 34 MB, against 17 MB for a 10-second recording).

use std::collections::{BTreeMap, HashMap};
use std::ops::Range;
use std::path::{Path, PathBuf};

use mcap::records::op;
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};

use crate::decode;
use crate::format::{AttachedFile, FORMAT_VERSION};

/// The name of gantry's metadata record.
pub const METADATA_NAME: &str = "gantry";

/// Most bytes one chunk may decompress to. gantry writes 1 MiB chunks; other writers'
/// defaults are a few MiB. A chunk claiming more is treated as damaged.
pub const MAX_CHUNK_BYTES: usize = 256 << 20;

/// Most a chunk may claim to decompress to, per compressed byte. zstd exceeds this only
/// on degenerate data (gantry's chunks compress about 10:1); the cap keeps a small
/// hostile file from unpacking into gigabytes.
pub const MAX_CHUNK_RATIO: usize = 1000;

/// Why a recording cannot be read. The texts are for the user: they say what the file
/// is and what to do.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// The file cannot be read at all.
    #[error("cannot read {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the OS said.
        #[source]
        source: std::io::Error,
    },
    /// Not an MCAP file.
    #[error(
        "{path} is not an MCAP file (it does not start with MCAP's magic bytes); gantry replays the .mcap files that `gantry run --record` writes"
    )]
    NotMcap {
        /// The file.
        path: PathBuf,
    },
    /// An MCAP file, but not one gantry wrote.
    #[error(
        "{path} is an MCAP file but not a gantry recording ({reason}); gantry replays the files that `gantry run --record` writes"
    )]
    NotGantry {
        /// The file.
        path: PathBuf,
        /// What is missing or different.
        reason: String,
    },
    /// Written by a gantry whose recording format this one does not know.
    #[error(
        "{path} was recorded by a newer gantry ({writer}) in recording format version {found}; this gantry ({ours}) reads format versions up to {known}: replay it with a newer gantry"
    )]
    Newer {
        /// The file.
        path: PathBuf,
        /// The file's `format_version`, as written.
        found: String,
        /// [`FORMAT_VERSION`].
        known: u32,
        /// The writer's `gantry_version`.
        writer: String,
        /// This gantry's version.
        ours: &'static str,
    },
    /// A gantry recording with nothing that can be replayed.
    #[error("{path} cannot be replayed: {reason}")]
    Unreadable {
        /// The file.
        path: PathBuf,
        /// Why: damaged or empty, and where.
        reason: String,
    },
}

/// A frame (an object) of the recording, by number; [`Recording::frame_name`] gives its
/// id (the object's path without the leading `/`, or `world`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct FrameId(pub u32);

/// One frame's pose in its parent's frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FramePose {
    /// The frame.
    pub child: FrameId,
    /// Its parent (`world` for a root object).
    pub parent: FrameId,
    /// Translation (m) then rotation quaternion `x, y, z, w`, in the parent's frame.
    pub pose: [f64; 7],
}

/// One `/tf` or `/tf_static` message.
#[derive(Debug, Clone, PartialEq)]
struct TfEntry {
    time_ns: u64,
    transforms: Box<[FramePose]>,
}

/// One `/joint_states` message.
#[derive(Debug, Clone, PartialEq)]
pub struct JointSample {
    /// Log time, ns.
    pub time_ns: u64,
    /// The joints (their frames).
    pub names: Vec<FrameId>,
    /// Positions, rad or m (empty, or one per name).
    pub position: Vec<f64>,
    /// Velocities, rad/s or m/s (empty, or one per name).
    pub velocity: Vec<f64>,
    /// Motor torques or forces of the step, N·m or N (empty, or one per name).
    pub effort: Vec<f64>,
}

/// One `/rosout` line.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LogLine {
    /// Log time, ns.
    pub time_ns: u64,
    /// The line's own stamp (simulation time), ns.
    pub stamp_ns: u64,
    /// ROS level: 10 debug, 20 info, 30 warn, 40 error.
    pub level: u8,
    /// Who logged it (a script's name).
    pub name: String,
    /// The text.
    pub msg: String,
}

/// A recorded image, decoded.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ImageFrame {
    /// Log time, ns.
    pub time_ns: u64,
    /// The sensor's frame id.
    pub frame_id: String,
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Pixel encoding (`rgb8`).
    pub encoding: String,
    /// Bytes per row.
    pub step: u32,
    /// The pixels, top row first.
    pub data: Vec<u8>,
}

/// Where an image message is: kept in the file, not in memory (a camera at 10 Hz
/// records 2 MB a second), and decoded when asked for.
#[derive(Debug, Clone, PartialEq)]
enum ImageAt {
    /// In the chunk at this index of [`Recording::chunks`], on this channel with this
    /// sequence number.
    Chunk { chunk: u32, channel: u16, sequence: u32 },
    /// Outside chunks: the message data's bytes in the file.
    File(Range<usize>),
}

/// What a channel carries, decided once when it is defined.
#[derive(Debug, Clone, PartialEq)]
enum Kind {
    Tf,
    TfStatic,
    Joints,
    Log,
    Graph,
    Image,
    /// A topic this reader does not know (`/proximity/...`, `/gantry/input`, another
    /// writer's): skipped, never an error.
    Other,
}

#[derive(Debug, Clone)]
struct ChannelInfo {
    topic: String,
    kind: Kind,
}

/// A recording, read (see the module docs).
#[derive(Debug)]
pub struct Recording {
    path: PathBuf,
    /// The file, for the images decoded on demand.
    bytes: Vec<u8>,
    profile: String,
    metadata: BTreeMap<String, String>,
    attachments: Vec<AttachedFile>,
    frames: Vec<String>,
    frame_ids: HashMap<String, FrameId>,
    tf: Vec<TfEntry>,
    tf_static: Vec<TfEntry>,
    joints: Vec<JointSample>,
    graphs: BTreeMap<String, Vec<(u64, f64)>>,
    logs: Vec<LogLine>,
    images: BTreeMap<String, Vec<(u64, ImageAt)>>,
    /// File ranges of the chunk records read, for [`ImageAt::Chunk`].
    chunks: Vec<Range<usize>>,
    channels: HashMap<u16, ChannelInfo>,
    schemas: HashMap<u16, String>,
    start_ns: u64,
    end_ns: u64,
    messages: u64,
    complete: bool,
    lost: Vec<(u64, u64)>,
    warnings: Vec<String>,
    /// Per topic: messages that did not decode, and the first error.
    undecodable: BTreeMap<String, (u64, String)>,
}

/// A little-endian cursor over one record's body: `None` when a field does not fit.
struct Fields<'a> {
    buf: &'a [u8],
    pos: usize,
}

impl<'a> Fields<'a> {
    fn new(buf: &'a [u8]) -> Self {
        Self { buf, pos: 0 }
    }
    fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.buf.len())?;
        let s = &self.buf[self.pos..end];
        self.pos = end;
        Some(s)
    }
    fn u16(&mut self) -> Option<u16> {
        self.take(2).map(|b| u16::from_le_bytes([b[0], b[1]]))
    }
    fn u32(&mut self) -> Option<u32> {
        let mut a = [0; 4];
        a.copy_from_slice(self.take(4)?);
        Some(u32::from_le_bytes(a))
    }
    fn u64(&mut self) -> Option<u64> {
        let mut a = [0; 8];
        a.copy_from_slice(self.take(8)?);
        Some(u64::from_le_bytes(a))
    }
    /// A `u32`-prefixed UTF-8 string.
    fn string(&mut self) -> Option<&'a str> {
        let n = usize::try_from(self.u32()?).ok()?;
        std::str::from_utf8(self.take(n)?).ok()
    }
    /// `u32`-prefixed bytes.
    fn bytes32(&mut self) -> Option<&'a [u8]> {
        let n = usize::try_from(self.u32()?).ok()?;
        self.take(n)
    }
    /// `u64`-prefixed bytes.
    fn bytes64(&mut self) -> Option<&'a [u8]> {
        let n = usize::try_from(self.u64()?).ok()?;
        self.take(n)
    }
    /// A string-to-string map: its length in bytes, then key and value strings.
    fn string_map(&mut self) -> Option<BTreeMap<String, String>> {
        let mut inner = Fields::new(self.bytes32()?);
        let mut out = BTreeMap::new();
        while inner.pos < inner.buf.len() {
            let k = inner.string()?;
            let v = inner.string()?;
            out.insert(k.to_owned(), v.to_owned());
        }
        Some(out)
    }
    fn rest(&mut self) -> &'a [u8] {
        let s = &self.buf[self.pos..];
        self.pos = self.buf.len();
        s
    }
}

/// The record at `pos`: opcode, body and where the next record starts; `None` when it
/// does not fit in the file or its opcode is not one MCAP defines (damage).
fn frame_at(bytes: &[u8], pos: usize) -> Option<(u8, Range<usize>)> {
    let mut f = Fields::new(bytes.get(pos..)?);
    let opcode = f.take(1)?[0];
    if !(op::HEADER..=op::DATA_END).contains(&opcode) && opcode < 0x80 {
        return None;
    }
    let len = usize::try_from(f.u64()?).ok()?;
    let start = pos + 9;
    let end = start.checked_add(len).filter(|&e| e <= bytes.len())?;
    Some((opcode, start..end))
}

/// The chunk offsets of the summary's chunk indexes, sorted, if the file ends with an
/// intact footer; used only to find the next chunk after damage.
fn summary_chunk_offsets(bytes: &[u8]) -> Vec<usize> {
    let magic = mcap::MAGIC.len();
    // Footer record: opcode, length 20, summary start, summary offset start, CRC.
    let footer_len = 1 + 8 + 20;
    let Some(footer_at) = bytes.len().checked_sub(magic + footer_len) else {
        return Vec::new();
    };
    if !bytes.ends_with(mcap::MAGIC) || bytes[footer_at] != op::FOOTER {
        return Vec::new();
    }
    let mut f = Fields::new(&bytes[footer_at + 9..]);
    let Some(start) = f.u64().and_then(|s| usize::try_from(s).ok()) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    let mut pos = start;
    while pos < footer_at {
        let Some((opcode, body)) = frame_at(bytes, pos) else {
            break;
        };
        if opcode == op::CHUNK_INDEX {
            // Message start and end times, then the chunk's offset.
            let mut f = Fields::new(&bytes[body.clone()]);
            if let Some(offset) = f.take(16).and_then(|_| f.u64()).and_then(|o| usize::try_from(o).ok()) {
                out.push(offset);
            }
        }
        pos = body.end;
    }
    out.sort_unstable();
    out
}

impl Recording {
    /// Reads `path` (see the module docs).
    ///
    /// # Errors
    /// See [`ReadError`]: the file cannot be read, is not a gantry recording, comes
    /// from a newer gantry, or holds nothing to replay.
    pub fn open(path: impl AsRef<Path>) -> Result<Recording, ReadError> {
        let path = path.as_ref();
        let bytes = std::fs::read(path).map_err(|source| ReadError::Io {
            path: path.to_owned(),
            source,
        })?;
        Self::from_bytes(bytes, path)
    }

    /// Reads a recording held in memory; `path` only names it in messages.
    ///
    /// # Errors
    /// As [`Recording::open`], I/O aside.
    pub fn from_bytes(bytes: Vec<u8>, path: &Path) -> Result<Recording, ReadError> {
        if !bytes.starts_with(mcap::MAGIC) {
            return Err(ReadError::NotMcap { path: path.to_owned() });
        }
        let mut rec = Recording {
            path: path.to_owned(),
            bytes: Vec::new(),
            profile: String::new(),
            metadata: BTreeMap::new(),
            attachments: Vec::new(),
            frames: Vec::new(),
            frame_ids: HashMap::new(),
            tf: Vec::new(),
            tf_static: Vec::new(),
            joints: Vec::new(),
            graphs: BTreeMap::new(),
            logs: Vec::new(),
            images: BTreeMap::new(),
            chunks: Vec::new(),
            channels: HashMap::new(),
            schemas: HashMap::new(),
            start_ns: u64::MAX,
            end_ns: 0,
            messages: 0,
            complete: false,
            lost: Vec::new(),
            warnings: Vec::new(),
            undecodable: BTreeMap::new(),
        };
        let mut gantry_seen = false;
        let mut resync: Option<Vec<usize>> = None;
        let mut pos = mcap::MAGIC.len();
        while pos < bytes.len() {
            let Some((opcode, body)) = frame_at(&bytes, pos) else {
                // Either the file was cut inside this record, or the bytes are damaged
                // here. The summary (if the file's end is intact) knows where the next
                // chunk starts.
                let offsets = resync.get_or_insert_with(|| summary_chunk_offsets(&bytes));
                match offsets.iter().find(|&&o| o > pos) {
                    Some(&next) => {
                        rec.warnings.push(format!(
                            "bytes {pos} to {next} are damaged (not an MCAP record); reading on from the next chunk"
                        ));
                        pos = next;
                        continue;
                    }
                    None => break,
                }
            };
            let record = pos..body.end;
            let body_bytes = &bytes[body.clone()];
            match opcode {
                op::HEADER => {
                    if let Some(p) = Fields::new(body_bytes).string() {
                        p.clone_into(&mut rec.profile);
                    }
                }
                op::FOOTER => {
                    rec.complete = true;
                    break;
                }
                op::METADATA => {
                    let mut f = Fields::new(body_bytes);
                    match (f.string(), f.string_map()) {
                        (Some(METADATA_NAME), Some(map)) => {
                            check_version(&map, path)?;
                            gantry_seen = true;
                            rec.metadata = map;
                        }
                        (Some(_), Some(_)) => {}
                        _ => rec
                            .warnings
                            .push(format!("the metadata record at byte {pos} is damaged; skipped")),
                    }
                }
                op::ATTACHMENT => match parse_attachment(body_bytes) {
                    Some(a) => rec.attachments.push(a),
                    None => rec
                        .warnings
                        .push(format!("the attachment at byte {pos} is damaged; skipped")),
                },
                op::CHUNK => rec.chunk(&bytes, record, body.clone()),
                op::SCHEMA | op::CHANNEL | op::MESSAGE => {
                    // Records outside chunks (an unchunked writer).
                    let data_at = body.start;
                    rec.inner_record(opcode, body_bytes, ImageSource::File(data_at));
                }
                _ => {}
            }
            pos = body.end;
        }
        if !gantry_seen {
            let reason = if rec.profile == "ros2" || rec.profile.is_empty() {
                "it has no `gantry` metadata record".to_owned()
            } else {
                format!(
                    "its profile is `{}` and it has no `gantry` metadata record",
                    rec.profile
                )
            };
            return Err(ReadError::NotGantry {
                path: path.to_owned(),
                reason,
            });
        }
        if !rec.complete {
            let t = if rec.messages > 0 {
                format!(", {:.3} s into the run", rec.end_ns as f64 * 1e-9)
            } else {
                String::new()
            };
            rec.warnings.push(format!(
                "the file was cut short (no summary or footer: the recording did not end properly); it is read up to its last complete chunk{t}"
            ));
        }
        for (topic, (n, first)) in &rec.undecodable {
            rec.warnings.push(format!(
                "{n} message(s) on {topic} could not be decoded and are skipped (first: {first})"
            ));
        }
        if rec.tf.is_empty() && rec.tf_static.is_empty() {
            let mut reason = "it holds no poses (no /tf or /tf_static message)".to_owned();
            if !rec.warnings.is_empty() {
                reason.push_str(": ");
                reason.push_str(&rec.warnings.join("; "));
            }
            return Err(ReadError::Unreadable {
                path: path.to_owned(),
                reason,
            });
        }
        // A writer keeps each channel's messages in time order; chunks written out of
        // order (or a file stitched together) are not, so sort once here.
        rec.tf.sort_by_key(|e| e.time_ns);
        rec.tf_static.sort_by_key(|e| e.time_ns);
        rec.joints.sort_by_key(|e| e.time_ns);
        rec.logs.sort_by_key(|e| e.time_ns);
        for s in rec.graphs.values_mut() {
            s.sort_by_key(|e| e.0);
        }
        for s in rec.images.values_mut() {
            s.sort_by_key(|e| e.0);
        }
        rec.bytes = bytes;
        Ok(rec)
    }

    /// Reads one chunk record (`record`: its bytes in the file, `body` its body's),
    /// or notes the time range it held as lost.
    fn chunk(&mut self, bytes: &[u8], record: Range<usize>, body: Range<usize>) {
        let mut f = Fields::new(&bytes[body]);
        let header = (|| Some((f.u64()?, f.u64()?, f.u64()?, f.u32()?, f.string()?, f.bytes64()?)))();
        let Some((start, end, uncompressed, _crc, compression, data)) = header else {
            self.warnings.push(format!(
                "the chunk at byte {} is damaged (bad header); its messages are lost",
                record.start
            ));
            return;
        };
        let lost = |why: String, rec: &mut Recording| {
            rec.lost.push((start, end));
            rec.warnings.push(format!(
                "the chunk at byte {} is damaged ({why}): the messages from {:.3} s to {:.3} s are lost",
                record.start,
                start as f64 * 1e-9,
                end as f64 * 1e-9
            ));
        };
        let most = MAX_CHUNK_BYTES.min(data.len().saturating_mul(MAX_CHUNK_RATIO).saturating_add(4096));
        if usize::try_from(uncompressed).map_or(true, |u| u > most) {
            lost(
                format!("it claims {uncompressed} bytes uncompressed from {} bytes", data.len()),
                self,
            );
            return;
        }
        if !matches!(compression, "" | "zstd") {
            lost(format!("compression `{compression}` is not supported"), self);
            return;
        }
        let index = u32::try_from(self.chunks.len()).unwrap_or(u32::MAX);
        self.chunks.push(record.clone());
        let result = for_each_chunk_record(&bytes[record.clone()], |opcode, data| {
            self.inner_record(opcode, data, ImageSource::Chunk(index));
        });
        if let Err(e) = result {
            lost(e.to_string(), self);
        }
    }

    /// A schema, channel or message record (in a chunk or not).
    fn inner_record(&mut self, opcode: u8, body: &[u8], source: ImageSource) {
        let mut f = Fields::new(body);
        match opcode {
            op::SCHEMA => {
                if let (Some(id), Some(name)) = (f.u16(), f.string()) {
                    self.schemas.insert(id, name.to_owned());
                }
            }
            op::CHANNEL => {
                let (Some(id), Some(schema_id), Some(topic), Some(encoding)) =
                    (f.u16(), f.u16(), f.string(), f.string())
                else {
                    return;
                };
                let schema = self.schemas.get(&schema_id).map_or("", String::as_str);
                let kind = channel_kind(topic, schema, encoding);
                self.channels.insert(
                    id,
                    ChannelInfo {
                        topic: topic.to_owned(),
                        kind,
                    },
                );
            }
            op::MESSAGE => {
                let (Some(channel), Some(sequence), Some(log_time), Some(_publish)) =
                    (f.u16(), f.u32(), f.u64(), f.u64())
                else {
                    return;
                };
                let data_offset = f.pos;
                let data = f.rest();
                self.start_ns = self.start_ns.min(log_time);
                self.end_ns = self.end_ns.max(log_time);
                self.messages += 1;
                let at = match source {
                    ImageSource::Chunk(chunk) => ImageAt::Chunk {
                        chunk,
                        channel,
                        sequence,
                    },
                    ImageSource::File(body_at) => {
                        let s = body_at + data_offset;
                        ImageAt::File(s..s + data.len())
                    }
                };
                self.message(channel, log_time, data, at);
            }
            _ => {}
        }
    }

    /// One message on `channel` at `time_ns`.
    fn message(&mut self, channel: u16, time_ns: u64, data: &[u8], at: ImageAt) {
        let Some(info) = self.channels.get(&channel) else {
            return;
        };
        let result = match info.kind {
            Kind::Tf | Kind::TfStatic => decode::tf_message(data).map(|ts| {
                let transforms = ts
                    .iter()
                    .map(|t| FramePose {
                        child: intern(&mut self.frames, &mut self.frame_ids, t.child_frame_id),
                        parent: intern(&mut self.frames, &mut self.frame_ids, t.frame_id),
                        pose: t.pose,
                    })
                    .collect();
                let entry = TfEntry { time_ns, transforms };
                if info.kind == Kind::Tf {
                    self.tf.push(entry);
                } else {
                    self.tf_static.push(entry);
                }
            }),
            Kind::Joints => decode::joint_state(data).map(|js| {
                let names = js
                    .name
                    .iter()
                    .map(|n| intern(&mut self.frames, &mut self.frame_ids, n))
                    .collect();
                self.joints.push(JointSample {
                    time_ns,
                    names,
                    position: js.position,
                    velocity: js.velocity,
                    effort: js.effort,
                });
            }),
            Kind::Log => decode::log(data).map(|l| {
                self.logs.push(LogLine {
                    time_ns,
                    stamp_ns: stamp_ns(l.stamp),
                    level: l.level,
                    name: l.name.to_owned(),
                    msg: l.msg.to_owned(),
                });
            }),
            Kind::Graph => decode::float64(data).map(|v| {
                self.graphs.entry(info.topic.clone()).or_default().push((time_ns, v));
            }),
            Kind::Image => decode::image(data).map(|_| {
                self.images.entry(info.topic.clone()).or_default().push((time_ns, at));
            }),
            Kind::Other => Ok(()),
        };
        if let Err(e) = result {
            let topic = info.topic.clone();
            let entry = self.undecodable.entry(topic).or_insert((0, e.to_string()));
            entry.0 += 1;
        }
    }

    /// The file's path, as given to [`Recording::open`].
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The `gantry` metadata record: `gantry_version`, `command_line`, `scene`, `dt`...
    pub fn metadata(&self) -> &BTreeMap<String, String> {
        &self.metadata
    }

    /// The attached files (the scene's files as they were at the start).
    pub fn attachments(&self) -> &[AttachedFile] {
        &self.attachments
    }

    /// The first message's time, ns.
    pub fn start_ns(&self) -> u64 {
        self.start_ns.min(self.end_ns)
    }

    /// The last message's time, ns.
    pub fn end_ns(&self) -> u64 {
        self.end_ns
    }

    /// Messages read.
    pub fn message_count(&self) -> u64 {
        self.messages
    }

    /// Whether the file ended properly (summary and footer).
    pub fn is_complete(&self) -> bool {
        self.complete
    }

    /// The byte ranges of the file's chunk records, in file order (to locate damage,
    /// or cut a file between chunks).
    pub fn chunk_ranges(&self) -> &[Range<usize>] {
        &self.chunks
    }

    /// Time ranges (ns, inclusive) of damaged chunks whose messages are lost.
    pub fn lost(&self) -> &[(u64, u64)] {
        &self.lost
    }

    /// What was wrong with the file but did not stop it from being read: cut short,
    /// damaged chunks (with the time lost), messages that did not decode.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Every frame id met in the recording, by [`FrameId`].
    pub fn frames(&self) -> &[String] {
        &self.frames
    }

    /// A frame's id (object path without the leading `/`, or `world`).
    pub fn frame_name(&self, id: FrameId) -> &str {
        self.frames.get(id.0 as usize).map_or("", String::as_str)
    }

    /// The [`FrameId`] of a frame id.
    pub fn frame_id(&self, name: &str) -> Option<FrameId> {
        self.frame_ids.get(name).copied()
    }

    /// Times (ns) of the snapshots, one per `/tf` message: the frames a replay steps
    /// through.
    pub fn snapshot_times(&self) -> impl ExactSizeIterator<Item = u64> + '_ {
        self.tf.iter().map(|e| e.time_ns)
    }

    /// Every frame's pose in its parent's frame at `t_ns`: the latest `/tf_static` at
    /// or before it, overlaid with the latest `/tf` at or before it. Static frames come
    /// first, then the moving ones in recorded order (parents before children within
    /// each set; a static frame may hang from a moving one). Empty before the first
    /// snapshot.
    pub fn tree_at(&self, t_ns: u64) -> Vec<FramePose> {
        let mut out: Vec<FramePose> = latest(&self.tf_static, t_ns, |e| e.time_ns)
            .map(|e| e.transforms.to_vec())
            .unwrap_or_default();
        if let Some(d) = latest(&self.tf, t_ns, |e| e.time_ns) {
            if out.is_empty() {
                return d.transforms.to_vec();
            }
            let mut at: HashMap<FrameId, usize> = out.iter().enumerate().map(|(i, f)| (f.child, i)).collect();
            for f in d.transforms.iter() {
                match at.get(&f.child) {
                    Some(&i) => out[i] = *f,
                    None => {
                        at.insert(f.child, out.len());
                        out.push(*f);
                    }
                }
            }
        }
        out
    }

    /// The latest `/joint_states` at or before `t_ns`.
    pub fn joints_at(&self, t_ns: u64) -> Option<&JointSample> {
        latest(&self.joints, t_ns, |e| e.time_ns)
    }

    /// Every graph stream (`/graph/<graph>/<stream>`): `(log time ns, value)` in time
    /// order.
    pub fn graphs(&self) -> &BTreeMap<String, Vec<(u64, f64)>> {
        &self.graphs
    }

    /// Every `/rosout` line, in time order.
    pub fn logs(&self) -> &[LogLine] {
        &self.logs
    }

    /// The `/rosout` lines logged at or before `t_ns`.
    pub fn logs_until(&self, t_ns: u64) -> &[LogLine] {
        &self.logs[..self.logs.partition_point(|l| l.time_ns <= t_ns)]
    }

    /// Topics of the recorded images (`sensor_msgs/msg/Image`).
    pub fn image_topics(&self) -> impl Iterator<Item = &str> {
        self.images.keys().map(String::as_str)
    }

    /// The latest image on `topic` at or before `t_ns`, decoded from the file.
    pub fn image_at(&self, topic: &str, t_ns: u64) -> Option<ImageFrame> {
        let list = self.images.get(topic)?;
        let (time_ns, at) = latest(list, t_ns, |e| e.0)?;
        let decode_one = |data: &[u8]| {
            decode::image(data).ok().map(|i| ImageFrame {
                time_ns: *time_ns,
                frame_id: i.frame_id.to_owned(),
                width: i.width,
                height: i.height,
                encoding: i.encoding.to_owned(),
                step: i.step,
                data: i.data.to_vec(),
            })
        };
        match at {
            ImageAt::File(r) => decode_one(self.bytes.get(r.clone())?),
            ImageAt::Chunk {
                chunk,
                channel,
                sequence,
            } => {
                let record = self.chunks.get(*chunk as usize)?.clone();
                let mut found = None;
                // The chunk decompressed once when the file was opened: it does again.
                let _ = for_each_chunk_record(&self.bytes[record], |opcode, body| {
                    if found.is_some() || opcode != op::MESSAGE {
                        return;
                    }
                    let mut f = Fields::new(body);
                    if f.u16() == Some(*channel) && f.u32() == Some(*sequence) && f.u64() == Some(*time_ns) {
                        let _publish = f.u64();
                        found = decode_one(f.rest());
                    }
                });
                found
            }
        }
    }
}

/// Where the messages being read come from, for [`ImageAt`].
#[derive(Debug, Clone, Copy)]
enum ImageSource {
    /// The chunk with this index in [`Recording::chunks`].
    Chunk(u32),
    /// Outside chunks: the record body starts at this byte of the file.
    File(usize),
}

/// Refuses a `gantry` metadata record of a newer format.
fn check_version(map: &BTreeMap<String, String>, path: &Path) -> Result<(), ReadError> {
    let Some(v) = map.get("format_version") else {
        return Ok(());
    };
    match v.trim().parse::<u32>() {
        Ok(n) if n <= FORMAT_VERSION => Ok(()),
        _ => Err(ReadError::Newer {
            path: path.to_owned(),
            found: v.clone(),
            known: FORMAT_VERSION,
            writer: map
                .get("gantry_version")
                .map_or_else(|| "version unknown".to_owned(), |g| format!("gantry {g}")),
            ours: env!("CARGO_PKG_VERSION"),
        }),
    }
}

/// An attachment record's body: times, name, media type, data, CRC (checked when not 0).
fn parse_attachment(body: &[u8]) -> Option<AttachedFile> {
    let mut f = Fields::new(body);
    let _log_time = f.u64()?;
    let _create_time = f.u64()?;
    let name = f.string()?;
    let media_type = f.string()?;
    let data = f.bytes64()?;
    let crc_at = f.pos;
    let crc = f.u32()?;
    if crc != 0 && crc32fast_hash(&body[..crc_at]) != crc {
        return None;
    }
    Some(AttachedFile {
        name: name.to_owned(),
        media_type: media_type.to_owned(),
        data: data.to_vec(),
    })
}

/// CRC-32 (IEEE), as MCAP uses; the table is built once per call (attachments are few).
fn crc32fast_hash(bytes: &[u8]) -> u32 {
    let mut table = [0u32; 256];
    for (i, slot) in table.iter_mut().enumerate() {
        let mut c = i as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 { 0xEDB8_8320 ^ (c >> 1) } else { c >> 1 };
        }
        *slot = c;
    }
    let mut crc = !0u32;
    for &b in bytes {
        crc = table[((crc ^ u32::from(b)) & 0xff) as usize] ^ (crc >> 8);
    }
    !crc
}

/// Calls `f(opcode, body)` for each record inside one chunk record (`record`: the
/// whole record, opcode and length included). The chunk is decompressed and its CRC
/// checked before any record is handed out, so a damaged chunk yields nothing.
fn for_each_chunk_record(record: &[u8], mut f: impl FnMut(u8, &[u8])) -> Result<(), mcap::McapError> {
    // An uncompressed chunk is read here: the `mcap` crate's linear reader trusts the
    // lengths of the records inside one (an overlong record made it subtract past zero,
    // found by the `recording` fuzz target), and there is nothing to decompress.
    if let Some(records) = uncompressed_chunk_records(record) {
        let records = records?;
        let mut r = Fields::new(records);
        while r.pos < records.len() {
            let (Some(op), Some(body)) = (r.take(1), r.bytes64()) else {
                return Err(mcap::McapError::UnexpectedEoc);
            };
            f(op[0], body);
        }
        return Ok(());
    }
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_skip_start_magic(true)
            .with_skip_end_magic(true)
            .with_validate_chunk_crcs(true)
            .with_prevalidate_chunk_crcs(true)
            .with_record_length_limit(MAX_CHUNK_BYTES),
    );
    let mut input = record;
    while let Some(event) = reader.next_event() {
        match event? {
            LinearReadEvent::ReadRequest(need) => {
                let n = need.min(input.len());
                reader.insert(n).copy_from_slice(&input[..n]);
                reader.notify_read(n);
                input = &input[n..];
            }
            LinearReadEvent::Record { opcode, data } => f(opcode, data),
        }
    }
    Ok(())
}

/// The records of an uncompressed chunk record (`record`: opcode and length
/// included), their CRC checked when it is not 0; `None` for a compressed chunk, which
/// the `mcap` crate decompresses.
fn uncompressed_chunk_records(record: &[u8]) -> Option<Result<&[u8], mcap::McapError>> {
    /// The chunk's compression and records, `None` when the record is too short.
    fn parts(record: &[u8]) -> Option<(u32, &str, &[u8])> {
        let mut f = Fields::new(record);
        let _opcode = f.take(1)?;
        let mut c = Fields::new(f.bytes64()?);
        let (_start, _end, _size) = (c.u64()?, c.u64()?, c.u64()?);
        let crc = c.u32()?;
        let compression = c.string()?;
        Some((crc, compression, c.bytes64()?))
    }
    let Some((crc, compression, records)) = parts(record) else {
        return Some(Err(mcap::McapError::UnexpectedEoc));
    };
    if !compression.is_empty() {
        return None;
    }
    let calculated = crc32fast_hash(records);
    if crc != 0 && calculated != crc {
        return Some(Err(mcap::McapError::BadChunkCrc { saved: crc, calculated }));
    }
    Some(Ok(records))
}

/// What a channel carries, from its topic, schema name and encoding.
fn channel_kind(topic: &str, schema: &str, encoding: &str) -> Kind {
    if encoding != "cdr" {
        return Kind::Other;
    }
    // The schema decides when it is known; a channel whose schema record was lost with
    // a damaged chunk is recognised by its topic.
    let is = |name: &str| schema.is_empty() || schema == name;
    match topic {
        "/tf" if is("tf2_msgs/msg/TFMessage") => Kind::Tf,
        "/tf_static" if is("tf2_msgs/msg/TFMessage") => Kind::TfStatic,
        "/joint_states" if is("sensor_msgs/msg/JointState") => Kind::Joints,
        "/rosout" if is("rcl_interfaces/msg/Log") => Kind::Log,
        t if t.starts_with("/graph/") && is("std_msgs/msg/Float64") => Kind::Graph,
        _ if schema == "sensor_msgs/msg/Image" => Kind::Image,
        _ => Kind::Other,
    }
}

/// The frame number of `name`, added if new.
fn intern(frames: &mut Vec<String>, ids: &mut HashMap<String, FrameId>, name: &str) -> FrameId {
    if let Some(&id) = ids.get(name) {
        return id;
    }
    let id = FrameId(u32::try_from(frames.len()).unwrap_or(u32::MAX));
    frames.push(name.to_owned());
    ids.insert(name.to_owned(), id);
    id
}

/// The last element of `list` (sorted by `time`) at or before `t`.
fn latest<T>(list: &[T], t: u64, time: impl Fn(&T) -> u64) -> Option<&T> {
    let n = list.partition_point(|e| time(e) <= t);
    n.checked_sub(1).and_then(|i| list.get(i))
}

/// A message stamp in nanoseconds (negative times count as 0).
fn stamp_ns(t: gantry_protocol::ros::typed::Time) -> u64 {
    u64::try_from(t.sec).unwrap_or(0) * 1_000_000_000 + u64::from(t.nanosec)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Found by the `recording` fuzz target: an uncompressed chunk whose inner record
    /// claims more bytes than the chunk holds made the `mcap` crate's reader subtract
    /// past zero (a panic in debug builds). The chunk is now read here and counted as
    /// damaged.
    #[test]
    fn an_uncompressed_chunk_whose_record_overruns_it_is_damage_not_a_panic() {
        let bytes = include_bytes!("../../../fuzz/seeds/recording/uncompressed-chunk-overrun.mcap");
        match Recording::from_bytes(bytes.to_vec(), Path::new("overrun.mcap")) {
            Ok(rec) => assert!(
                !rec.warnings().is_empty() || !rec.lost().is_empty(),
                "the damage is reported"
            ),
            Err(e) => assert!(!e.to_string().is_empty()),
        }
    }
}
