//! The recorder against a real simulation (the bundled showroom, stepped without
//! scripts): a file it writes reads back with the `mcap` crate's reader, and a failing
//! disk stops the recording, not the simulation.

use std::io::{Cursor, Seek, SeekFrom, Write};

use gantry_record::{RecordError, RecordParams, Recorder};
use gantry_sim_core::Sim;
use gantry_sim_core::scene::{LoadOptions, load_bundled};
use gantry_test_support::TempDir;

fn showroom() -> Sim {
    let model = load_bundled("showroom", &LoadOptions::default())
        .expect("bundled")
        .expect("loads");
    Sim::new(&model)
}

#[test]
fn a_recording_reads_back_indexed_with_every_channel_and_message() {
    let dir = TempDir::new("record");
    let path = dir.path().join("ok.mcap");
    let mut sim = showroom();
    let mut rec = Recorder::create(RecordParams {
        path: path.clone(),
        metadata: [("dt".to_owned(), "0.05".to_owned())].into(),
        attachments: vec![gantry_record::AttachedFile {
            name: "scene.toml".into(),
            media_type: "application/toml".into(),
            data: b"# scene".to_vec(),
        }],
        ..RecordParams::default()
    })
    .expect("recording starts");
    rec.record(&sim);
    for _ in 0..20 {
        sim.step();
        rec.record(&sim);
    }
    let report = rec.finish(Some(&sim), std::collections::BTreeMap::new());
    assert_eq!(report.error, None);
    assert_eq!(report.snapshots, 21);
    assert_eq!(report.dropped, 0, "a queue of 64 batches holds 21 snapshots");
    let bytes = std::fs::read(&path).expect("file");
    let summary = mcap::Summary::read(&bytes).expect("reads").expect("has a summary");
    assert!(!summary.chunk_indexes.is_empty(), "chunks are indexed");
    let stats = summary.stats.expect("statistics");
    assert_eq!(stats.message_count, report.messages);
    assert_eq!(stats.attachment_count, 1);
    assert_eq!(
        stats.metadata_count, 2,
        "`gantry` at the start, `gantry_end` at the end"
    );
    let topics: Vec<&str> = summary.channels.values().map(|c| c.topic.as_str()).collect();
    for t in ["/tf", "/joint_states", "/rosout"] {
        assert!(topics.contains(&t), "{t} in {topics:?}");
    }
    let mut tf = 0;
    let mut last = 0;
    for m in mcap::MessageStream::new(&bytes).expect("stream") {
        let m = m.expect("message");
        assert!(m.log_time >= last, "log times never go back");
        last = m.log_time;
        assert_eq!(m.channel.message_encoding, "cdr");
        assert_eq!(&m.data[..4], &[0, 1, 0, 0], "little-endian CDR");
        if m.channel.topic == "/tf" {
            tf += 1;
        }
    }
    assert_eq!(tf, 21, "one /tf message per snapshot");
}

#[test]
fn a_folder_that_does_not_exist_is_refused_before_the_run_naming_the_file() {
    let dir = TempDir::new("record");
    let path = dir.path().join("missing-folder").join("run.mcap");
    let err = match Recorder::create(RecordParams {
        path: path.clone(),
        ..RecordParams::default()
    }) {
        Err(e) => e,
        Ok(_) => panic!("a file in a missing folder cannot be created"),
    };
    assert!(matches!(err, RecordError::Create { .. }), "{err:?}");
    let text = err.to_string();
    assert!(text.contains(&path.display().to_string()), "{text}");
    assert!(text.contains("cannot record to"), "{text}");
}

/// A disk that fills up after `room` bytes.
struct FillingDisk {
    inner: Cursor<Vec<u8>>,
    room: usize,
}

impl Write for FillingDisk {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let left = self.room.saturating_sub(self.inner.get_ref().len());
        if left == 0 {
            return Err(std::io::Error::new(
                std::io::ErrorKind::StorageFull,
                "No space left on device",
            ));
        }
        let n = buf.len().min(left);
        self.inner.write(&buf[..n])
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

impl Seek for FillingDisk {
    fn seek(&mut self, pos: SeekFrom) -> std::io::Result<u64> {
        self.inner.seek(pos)
    }
}

#[test]
fn a_full_disk_stops_the_recording_and_the_simulation_goes_on() {
    let mut sim = showroom();
    let disk = FillingDisk {
        inner: Cursor::new(Vec::new()),
        room: 64 * 1024,
    };
    let mut rec = Recorder::with_writer(
        disk,
        RecordParams {
            path: "full-disk.mcap".into(),
            ..RecordParams::default()
        },
    )
    .expect("the header fits");
    // Enough steps for more than 64 KiB of chunks: the disk fills during the run.
    let steps = 600;
    for _ in 0..steps {
        sim.step();
        rec.record(&sim);
    }
    assert_eq!(sim.world.steps(), steps, "every step was taken");
    let report = rec.finish(Some(&sim), std::collections::BTreeMap::new());
    let error = report.error.expect("the write error is reported");
    assert!(error.contains("No space left on device"), "{error}");
    assert!(report.snapshots > 0);
}
