//! Commands against a stand-in simulation thread that records what the registry was
//! asked and answers from a table, so each layout is checked byte for byte without a
//! scene or a socket.

use std::sync::mpsc::Receiver;
use std::sync::{Arc, Mutex};

use gantry_engine::ClientId;
use gantry_protocol::legacy_remote_api::{Command, CommandId};
use gantry_sim_core::Value;

use super::{Outcome, Session, execute};
use crate::sim_thread::{Request, SimHandle, channel};

/// The registry calls made, as `name(args)`.
type Calls = Arc<Mutex<Vec<String>>>;

/// A simulation thread whose registry answers `answer(function)`, the function named as
/// it resolved (`sim.getJointPosition`).
fn stand_in(answer: fn(&str) -> Vec<Value>) -> (SimHandle, Calls) {
    let (sim, rx) = channel();
    let calls = Calls::default();
    let log = calls.clone();
    std::thread::spawn(move || serve(&rx, answer, &log));
    (sim, calls)
}

fn serve(rx: &Receiver<Request>, answer: fn(&str) -> Vec<Value>, calls: &Calls) {
    while let Ok(req) = rx.recv() {
        if let Request::Call { target, args, reply } = req {
            let name = target.qualified();
            calls.lock().expect("not poisoned").push(format!("{name}{args:?}"));
            let _ = reply.send(Ok(answer(&name)));
        }
    }
}

fn command(code: i32, id: CommandId, data: Vec<u8>) -> Command {
    Command {
        code,
        opmode: 0,
        delay_or_split: 0,
        id,
        data,
        status: 0,
        sim_time_ms: 0,
    }
}

fn run(sim: &SimHandle, cmd: &Command) -> Outcome {
    let rt = tokio::runtime::Builder::new_current_thread()
        .build()
        .expect("a runtime");
    rt.block_on(execute(sim, &mut Session::new(ClientId(1)), cmd))
}

fn f32s(xs: &[f32]) -> Vec<u8> {
    xs.iter().flat_map(|x| x.to_le_bytes()).collect()
}

#[test]
fn a_row_reads_its_arguments_and_encodes_the_result() {
    let (sim, calls) = stand_in(|_| vec![Value::floats(&[0.5, -1.0, 2.0])]);
    // simxGetObjectPosition (4.x): the object and the frame in the identity.
    let out = run(&sim, &command(0x200e, CommandId::IntInt(7, -1), Vec::new()));
    assert!(out.ok);
    assert_eq!(out.data, f32s(&[0.5, -1.0, 2.0]));
    // simxSetObjectPosition: the frame and the position in the arguments.
    let data = [3i32.to_le_bytes().to_vec(), f32s(&[1.0, 2.0, 3.0])].concat();
    assert!(run(&sim, &command(0x101b, CommandId::Int(7), data)).ok);
    assert_eq!(
        *calls.lock().expect("not poisoned"),
        [
            "sim.getObjectPosition[Int(7), Int(-1)]",
            "sim.setObjectPosition[Int(7), Int(3), Array([Float(1.0), Float(2.0), Float(3.0)])]",
        ]
    );
}

#[test]
fn short_arguments_and_unknown_codes_fail_with_the_reason_kept() {
    let (sim, calls) = stand_in(|_| Vec::new());
    let rt = tokio::runtime::Builder::new_current_thread()
        .build()
        .expect("a runtime");
    let mut session = Session::new(ClientId(1));
    let set_joint = command(0x1002, CommandId::Int(7), vec![0, 0]);
    assert!(!rt.block_on(execute(&sim, &mut session, &set_joint)).ok);
    assert!(
        !rt.block_on(execute(
            &sim,
            &mut session,
            &command(0x7777, CommandId::None, Vec::new())
        ))
        .ok
    );
    assert!(
        calls.lock().expect("not poisoned").is_empty(),
        "nothing reached the registry"
    );
    let errors = rt.block_on(execute(
        &sim,
        &mut session,
        &command(0x0004, CommandId::None, Vec::new()),
    ));
    let mut expected = 2i32.to_le_bytes().to_vec();
    expected.extend_from_slice(b"arguments too short: no float at byte 0\0");
    expected.extend_from_slice(
        b"command 0x7777 is not served by gantry's legacy remote API (see docs/legacy-remote-api.md)\0",
    );
    assert!(errors.ok);
    assert_eq!(
        String::from_utf8_lossy(&errors.data),
        String::from_utf8_lossy(&expected)
    );
}

#[test]
fn get_and_clear_string_signal_clears_it_and_ends_its_stream() {
    let (sim, calls) = stand_in(|name| match name {
        "sim.getStringSignal" => vec![Value::Bytes(b"hi".to_vec())],
        _ => Vec::new(),
    });
    let out = run(&sim, &command(0x3017, CommandId::Str(b"s".to_vec()), Vec::new()));
    assert!(out.ok && out.ends_stream);
    assert_eq!(out.data, b"hi");
    assert_eq!(
        *calls.lock().expect("not poisoned"),
        ["sim.getStringSignal[Str(\"s\")]", "sim.clearStringSignal[Str(\"s\")]"]
    );
}

#[test]
fn an_unset_string_stream_is_nothing_new_but_an_unset_signal_is_an_error() {
    let (sim, _) = stand_in(|_| vec![Value::Nil]);
    let stream = run(&sim, &command(0x3018, CommandId::Str(b"s".to_vec()), Vec::new()));
    assert!(stream.ok && stream.data.is_empty());
    assert!(!run(&sim, &command(0x3012, CommandId::Str(b"s".to_vec()), Vec::new())).ok);
}

#[test]
fn a_grey_image_is_the_mean_of_the_channels() {
    let (sim, _) = stand_in(|_| {
        vec![
            Value::Bytes(vec![30, 60, 90, 255, 255, 255]),
            Value::Array(vec![Value::Int(2), Value::Int(1)]),
        ]
    });
    let out = run(&sim, &command(0x1003, CommandId::Int(4), Vec::new()));
    let mut expected = 2i32.to_le_bytes().to_vec();
    expected.extend_from_slice(&1i32.to_le_bytes());
    expected.extend_from_slice(&[60, 255]);
    assert_eq!(out.data, expected);
}

/// A command cut short fails with the offset where its data ended, in the words
/// `simxGetLastErrors` has always returned.
#[test]
fn short_arguments_name_the_byte_where_they_end() {
    use super::layout::{CommandError, Data};
    let d = Data(&[1, 2, 3]);
    assert!(matches!(d.i32(0), Err(CommandError::NoInteger(0))));
    assert!(matches!(d.f32s(0, 2), Err(CommandError::NoFloat(0))));
    assert_eq!(
        d.f32(4).unwrap_err().to_string(),
        "arguments too short: no float at byte 4"
    );
    assert_eq!(
        d.string(1).unwrap_err().to_string(),
        "arguments too short: no string at byte 1"
    );
}
