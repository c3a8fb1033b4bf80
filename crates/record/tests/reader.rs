//! The reader (gantry-mcap) against files the recorder's writer produced: read back
//! exactly, cut short, damaged, foreign, and from a newer gantry.

use std::collections::BTreeMap;
use std::io::{Cursor, Seek, SeekFrom, Write};
use std::path::Path;
use std::sync::{Arc, Mutex};

use gantry_record::format::WORLD_FRAME;
use gantry_record::reader::METADATA_NAME;
use gantry_record::writer::McapSink;
use gantry_record::{AttachedFile, ReadError, Recording};
use gantry_ros::msg::{self, Time, TransformStamped};
use gantry_ros::{Sampler, Snapshot};
use gantry_sim_core::Sim;
use gantry_sim_core::scene::{LoadOptions, load_bundled};

/// A `Write + Seek` whose bytes the test keeps after the writer is dropped.
#[derive(Clone, Default)]
struct SharedBuf(Arc<Mutex<Cursor<Vec<u8>>>>);

impl SharedBuf {
    fn bytes(&self) -> Vec<u8> {
        self.0.lock().expect("not poisoned").get_ref().clone()
    }
}

impl Write for SharedBuf {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0.lock().expect("not poisoned").write(buf)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

impl Seek for SharedBuf {
    fn seek(&mut self, pos: SeekFrom) -> std::io::Result<u64> {
        self.0.lock().expect("not poisoned").seek(pos)
    }
}

fn gantry_metadata(extra: &[(&str, &str)]) -> BTreeMap<String, String> {
    let mut m: BTreeMap<String, String> = [
        ("gantry_version", "0.1.0"),
        ("scene", "showroom"),
        ("scene_file", "(bundled showroom)"),
        ("dt", "0.05"),
        ("substeps", "4"),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_owned(), v.to_owned()))
    .collect();
    for (k, v) in extra {
        m.insert((*k).to_owned(), (*v).to_owned());
    }
    m
}

/// The showroom stepped without scripts for `steps` steps, every snapshot recorded;
/// returns the file and the snapshots written.
fn record_showroom(steps: usize, metadata: &BTreeMap<String, String>) -> (Vec<u8>, Vec<Snapshot>) {
    let model = load_bundled("showroom", &LoadOptions::default())
        .expect("bundled")
        .expect("loads");
    let mut sim = Sim::new(&model);
    let buf = SharedBuf::default();
    let mut sink = McapSink::new(buf.clone()).expect("header");
    sink.metadata(metadata).expect("metadata");
    sink.attach(&AttachedFile {
        name: "showroom.toml".into(),
        media_type: "application/toml".into(),
        data: b"# the scene".to_vec(),
    })
    .expect("attachment");
    let mut sampler = Sampler::new(None);
    let mut written = Vec::new();
    for i in 0..=steps {
        if i > 0 {
            sim.step();
        }
        let s = sampler.sample(&sim).expect("a snapshot per step");
        sink.snapshot(&s).expect("written");
        written.push(s);
    }
    sink.finish().expect("finished");
    drop(sink);
    (buf.bytes(), written)
}

/// What the snapshot says every frame's parent-relative pose is, sorted by frame id (the
/// writer splits them between `/tf_static` and `/tf`).
fn expected_tree(s: &Snapshot) -> Vec<(String, String, [f64; 7])> {
    let name = |h: i64| s.frames[usize::try_from(h).expect("handle")].clone();
    let mut out: Vec<_> = s
        .poses
        .iter()
        .map(|p| (name(p.handle), p.parent.map_or(WORLD_FRAME.to_owned(), name), p.pose))
        .collect();
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

/// The reader's tree at `t`, sorted by frame id.
fn tree_names(rec: &Recording, t: u64) -> Vec<(String, String, [f64; 7])> {
    let mut out: Vec<_> = rec
        .tree_at(t)
        .iter()
        .map(|f| {
            (
                rec.frame_name(f.child).to_owned(),
                rec.frame_name(f.parent).to_owned(),
                f.pose,
            )
        })
        .collect();
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

fn open(bytes: &[u8]) -> Result<Recording, ReadError> {
    Recording::from_bytes(bytes.to_vec(), Path::new("test.mcap"))
}

/// One showroom recording shared by the tests (1800 steps: four zstd chunks of snapshots).
fn showroom_file() -> &'static (Vec<u8>, Vec<Snapshot>) {
    static FILE: std::sync::OnceLock<(Vec<u8>, Vec<Snapshot>)> = std::sync::OnceLock::new();
    FILE.get_or_init(|| record_showroom(1800, &gantry_metadata(&[("format_version", "1")])))
}

#[test]
fn a_recording_reads_back_exactly() {
    let (bytes, written) = showroom_file();
    let rec = open(bytes).expect("reads");
    assert!(rec.is_complete());
    assert!(rec.warnings().is_empty(), "{:?}", rec.warnings());
    assert!(
        rec.chunk_ranges().len() >= 2,
        "several chunks: {}",
        rec.chunk_ranges().len()
    );
    assert_eq!(rec.metadata()["dt"], "0.05");
    assert_eq!(rec.attachments().len(), 1);
    assert_eq!(rec.attachments()[0].data, b"# the scene");
    assert_eq!(rec.snapshot_times().len(), written.len());
    assert_eq!(rec.start_ns(), written[0].log_time_ns);
    assert_eq!(rec.end_ns(), written.last().expect("some").log_time_ns);
    for s in written {
        assert_eq!(
            tree_names(&rec, s.log_time_ns),
            expected_tree(s),
            "at {} ns",
            s.log_time_ns
        );
        // Between two snapshots the earlier one holds.
        assert_eq!(tree_names(&rec, s.log_time_ns + 1), expected_tree(s));
        let joints = rec.joints_at(s.log_time_ns).expect("joint states");
        assert_eq!(joints.time_ns, s.log_time_ns);
        let names: Vec<&str> = joints.names.iter().map(|&n| rec.frame_name(n)).collect();
        let want: Vec<&str> = s.joints.iter().map(|j| s.frames[j.handle as usize].as_str()).collect();
        assert_eq!(names, want);
        let pos: Vec<f64> = s.joints.iter().map(|j| j.position).collect();
        assert_eq!(joints.position, pos);
    }
    assert!(rec.tree_at(written[0].log_time_ns.saturating_sub(1)).is_empty() || written[0].log_time_ns == 0);
}

#[test]
fn graphs_logs_and_tf_static_are_read_and_overlaid() {
    // A hand-made file: /tf_static with two frames, /tf moving one of them, a graph
    // stream, log lines and a topic the reader does not know.
    let buf = SharedBuf::default();
    let mut w = mcap::WriteOptions::new()
        .profile("ros2")
        .create(buf.clone())
        .expect("writer");
    w.write_metadata(&mcap::records::Metadata {
        name: METADATA_NAME.into(),
        metadata: gantry_metadata(&[]),
    })
    .expect("metadata");
    let schema = |w: &mut mcap::Writer<SharedBuf>, ty: &gantry_record::schema::MessageType| {
        w.add_schema(ty.name, "ros2msg", ty.schema_text().as_bytes())
            .expect("schema")
    };
    let tf_schema = schema(&mut w, &gantry_record::schema::TF_MESSAGE);
    let f64_schema = schema(&mut w, &gantry_record::schema::FLOAT64);
    let log_schema = schema(&mut w, &gantry_record::schema::LOG);
    let none = BTreeMap::new();
    let tf = w.add_channel(tf_schema, "/tf", "cdr", &none).expect("channel");
    let tf_static = w.add_channel(tf_schema, "/tf_static", "cdr", &none).expect("channel");
    let graph = w
        .add_channel(f64_schema, "/graph/g/speed", "cdr", &none)
        .expect("channel");
    let rosout = w.add_channel(log_schema, "/rosout", "cdr", &none).expect("channel");
    let other = w.add_channel(0, "/gantry/input", "cdr", &none).expect("channel");
    let t = |frame_id: &'static str, child: &'static str, x: f64| TransformStamped {
        stamp: Time::default(),
        frame_id,
        child_frame_id: child,
        translation: [x, 0.0, 0.0],
        rotation: [0.0, 0.0, 0.0, 1.0],
    };
    let put = |w: &mut mcap::Writer<SharedBuf>, channel: u16, time: u64, data: &[u8]| {
        w.write_to_known_channel(
            &mcap::records::MessageHeader {
                channel_id: channel,
                sequence: 0,
                log_time: time,
                publish_time: time,
            },
            data,
        )
        .expect("message");
    };
    put(
        &mut w,
        tf_static,
        0,
        &msg::tf_message(&[t("world", "base", 1.0), t("base", "lidar", 0.5)]),
    );
    put(&mut w, tf, 0, &msg::tf_message(&[t("world", "rover", 0.0)]));
    put(&mut w, graph, 10, &msg::float64(2.5));
    put(
        &mut w,
        rosout,
        20,
        &msg::log(Time::default(), msg::LogLevel::Info, "s", "hello"),
    );
    put(&mut w, other, 25, b"not CDR at all");
    put(
        &mut w,
        tf,
        50,
        &msg::tf_message(&[t("world", "rover", 2.0), t("base", "lidar", 0.7)]),
    );
    put(&mut w, tf_static, 60, &msg::tf_message(&[t("world", "base", 3.0)]));
    put(&mut w, graph, 70, &msg::float64(-1.0));
    w.finish().expect("finished");
    drop(w);
    let rec = open(&buf.bytes()).expect("reads");
    assert!(rec.warnings().is_empty(), "{:?}", rec.warnings());
    let x = |t: u64, frame: &str| {
        let id = rec.frame_id(frame).expect("frame");
        rec.tree_at(t).iter().find(|f| f.child == id).map(|f| f.pose[0])
    };
    assert_eq!(
        (x(0, "base"), x(0, "lidar"), x(0, "rover")),
        (Some(1.0), Some(0.5), Some(0.0))
    );
    // /tf overrides the static lidar from 50 on; the static set changes at 60.
    assert_eq!(
        (x(55, "base"), x(55, "lidar"), x(55, "rover")),
        (Some(1.0), Some(0.7), Some(2.0))
    );
    assert_eq!((x(60, "base"), x(60, "lidar")), (Some(3.0), Some(0.7)));
    assert_eq!(rec.graphs()["/graph/g/speed"], vec![(10, 2.5), (70, -1.0)]);
    assert_eq!(rec.logs_until(19).len(), 0);
    let logs = rec.logs_until(20);
    assert_eq!((logs.len(), logs[0].msg.as_str(), logs[0].level), (1, "hello", 20));
    assert_eq!((rec.start_ns(), rec.end_ns()), (0, 70));
}

#[test]
fn a_file_cut_anywhere_reads_its_complete_chunks_or_says_it_cannot() {
    let (bytes, written) = showroom_file();
    let full = open(bytes).expect("reads");
    // The first chunk holds only the schemas and channels (the writer closes it to
    // write the metadata outside chunks); the first cut that reads is the end of the
    // first chunk with a snapshot.
    let first_chunk_end = full
        .chunk_ranges()
        .iter()
        .map(|c| c.end)
        .find(|&e| open(&bytes[..e]).is_ok())
        .expect("a chunk with a snapshot");
    assert!(full.chunk_ranges().len() >= 4, "chunks: {}", full.chunk_ranges().len());
    let mut cuts = vec![
        bytes.len() - 1,
        bytes.len() - 40,
        full.chunk_ranges()[1].start + 100,
        full.chunk_ranges()[1].start,
        first_chunk_end,
        first_chunk_end - 1,
        full.chunk_ranges()[0].start,
        200,
        8,
    ];
    cuts.extend((1..20).map(|k| bytes.len() * k / 20));
    for cut in cuts {
        match open(&bytes[..cut]) {
            Ok(rec) => {
                assert!(cut >= first_chunk_end, "cut at {cut}: nothing complete to read");
                if cut < bytes.len() - 30 {
                    assert!(!rec.is_complete(), "cut at {cut}");
                    assert!(
                        rec.warnings().iter().any(|w| w.contains("cut short")),
                        "cut at {cut}: {:?}",
                        rec.warnings()
                    );
                }
                let n = rec.snapshot_times().len();
                assert!(n > 0 && n <= written.len(), "cut at {cut}: {n}");
                for s in &written[..n] {
                    assert_eq!(tree_names(&rec, s.log_time_ns), expected_tree(s), "cut at {cut}");
                }
            }
            Err(e) => {
                assert!(cut < first_chunk_end, "cut at {cut}: {e}");
                let text = e.to_string();
                assert!(
                    matches!(e, ReadError::Unreadable { .. } | ReadError::NotGantry { .. }),
                    "cut at {cut}: {text}"
                );
            }
        }
    }
}

#[test]
fn a_damaged_chunk_loses_its_time_range_and_the_rest_reads() {
    let (bytes, written) = showroom_file();
    let full = open(bytes).expect("reads");
    // A chunk in the middle: neither the first snapshot's nor the last one's.
    let chunk = full.chunk_ranges()[full.chunk_ranges().len() - 2].clone();
    // The chunk record: opcode, length, then its header: start and end times, then the
    // uncompressed size, whose top byte set claims petabytes.
    let size_top_byte = chunk.start + 9 + 16 + 7;
    for (what, at) in [
        ("data", chunk.start + (chunk.end - chunk.start) / 2),
        ("header", chunk.start + 3),
        ("size", size_top_byte),
    ] {
        let mut damaged = bytes.clone();
        damaged[at] ^= 0x5a;
        let rec = open(&damaged).unwrap_or_else(|e| panic!("{what}: {e}"));
        assert!(
            rec.warnings().iter().any(|w| w.contains("damaged")),
            "{what}: {:?}",
            rec.warnings()
        );
        // The first chunk's snapshots are intact, and so are the last chunk's.
        let first = &written[0];
        let last = written.last().expect("some");
        assert_eq!(tree_names(&rec, first.log_time_ns), expected_tree(first), "{what}");
        assert_eq!(tree_names(&rec, last.log_time_ns), expected_tree(last), "{what}");
        assert!(rec.snapshot_times().len() < written.len(), "{what}");
        if what == "size" {
            assert!(
                rec.warnings().iter().any(|w| w.contains("claims")),
                "{:?}",
                rec.warnings()
            );
        }
        if what != "header" {
            assert_eq!(rec.lost().len(), 1, "{what}");
            let (from, to) = rec.lost()[0];
            let text = rec.warnings().join("\n");
            assert!(text.contains(&format!("{:.3} s", from as f64 * 1e-9)), "{text}");
            assert!(text.contains(&format!("{:.3} s", to as f64 * 1e-9)), "{text}");
            assert!(text.contains("lost"), "{text}");
        }
    }
}

#[test]
fn foreign_files_are_refused_with_a_clear_error() {
    // Random bytes, with and without MCAP's magic in front; a JSON file; nothing.
    let mut x = 0x2545_f491_4f6c_dd1du64;
    let random: Vec<u8> = (0..4096)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x as u8
        })
        .collect();
    for bytes in [random.clone(), br#"{"tf": [1, 2, 3]}"#.to_vec(), Vec::new()] {
        let e = open(&bytes).expect_err("refused");
        assert!(matches!(e, ReadError::NotMcap { .. }), "{e}");
        assert!(e.to_string().contains("is not an MCAP file"), "{e}");
    }
    let mut with_magic = mcap::MAGIC.to_vec();
    with_magic.extend(&random);
    let e = open(&with_magic).expect_err("refused");
    assert!(matches!(e, ReadError::NotGantry { .. }), "{e}");

    // A valid MCAP file of another profile, without gantry's metadata.
    let buf = SharedBuf::default();
    let mut w = mcap::WriteOptions::new()
        .profile("ros1")
        .create(buf.clone())
        .expect("writer");
    let ch = w.add_channel(0, "/chatter", "json", &BTreeMap::new()).expect("channel");
    w.write_to_known_channel(
        &mcap::records::MessageHeader {
            channel_id: ch,
            sequence: 0,
            log_time: 1,
            publish_time: 1,
        },
        b"{}",
    )
    .expect("message");
    w.finish().expect("finished");
    drop(w);
    let e = open(&buf.bytes()).expect_err("refused");
    let text = e.to_string();
    assert!(matches!(e, ReadError::NotGantry { .. }), "{text}");
    assert!(
        text.contains("profile is `ros1`") && text.contains("not a gantry recording"),
        "{text}"
    );
}

#[test]
fn a_recording_from_a_newer_gantry_is_refused_naming_both_versions() {
    let (bytes, _) = record_showroom(
        2,
        &gantry_metadata(&[("format_version", "2"), ("gantry_version", "9.0.0")]),
    );
    let e = open(&bytes).expect_err("refused");
    let text = e.to_string();
    assert!(matches!(e, ReadError::Newer { .. }), "{text}");
    assert!(text.contains("version 2") && text.contains("up to 1"), "{text}");
    assert!(text.contains("gantry 9.0.0") && text.contains("newer gantry"), "{text}");
    // No format_version: version 1.
    let (bytes, _) = record_showroom(2, &gantry_metadata(&[]));
    assert!(open(&bytes).is_ok());
}

#[test]
fn mutated_recordings_read_or_fail_cleanly() {
    // A small recording, damaged a few thousand ways (bytes flipped, ranges zeroed or
    // duplicated, cut): every one reads or fails with an error; none panics. The fuzz
    // target does the same, unguided by the file's structure, at length.
    let (bytes, _) = record_showroom(20, &gantry_metadata(&[]));
    let mut x = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = |n: usize| {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x % n as u64) as usize
    };
    let mut read = 0;
    for i in 0..3000 {
        let mut b = bytes.clone();
        match i % 4 {
            0 => {
                for _ in 0..1 + next(8) {
                    let at = next(b.len());
                    b[at] ^= 1 << next(8);
                }
            }
            1 => {
                let at = next(b.len());
                let n = next(64).min(b.len() - at);
                b[at..at + n].fill(0xff);
            }
            2 => {
                let at = next(b.len());
                let n = next(256).min(b.len() - at);
                let piece = b[at..at + n].to_vec();
                let to = next(b.len());
                b.splice(to..to, piece);
            }
            _ => b.truncate(next(b.len())),
        }
        if let Ok(rec) = open(&b) {
            read += 1;
            let (start, end) = (rec.start_ns(), rec.end_ns());
            let _ = rec.tree_at(start + (end - start) / 2);
            let _ = rec.joints_at(end);
            let _ = rec.logs_until(end);
        }
    }
    assert!(read > 0, "some damage leaves a readable recording");
}
