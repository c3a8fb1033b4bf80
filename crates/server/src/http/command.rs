//! What a viewer page may ask over its WebSocket: JSON text messages, parsed here
//! without any I/O so every malformed input can be tested.
//!
//! ```json
//! {"id": 7, "op": "control", "action": "start"}        // start, pause, stop, step
//! {"id": 8, "op": "packet", "text": "<FK#J1=0.5>"}     // as the text channel would
//! {"id": 9, "op": "ui", "ui": 1000, "widget": 1, "value": 30}   // simUI.interact
//! {"id": 10, "op": "reload", "script": 0}              // index in the scripts panel
//! {"id": 11, "op": "debug", "action": "continue"}      // with --debug: continue, step_over, step_in, step_out, pause
//! {"op": "key", "key": 2007, "mods": 0}                // a key pressed in the 3D view, for sim.getSimulatorMessage
//! {"op": "select", "handles": [12]}                    // the user picked an object: sim.getObjectSel
//! {"op": "mask", "sensor": 15}                         // draw this vision sensor's segmentation mask
//! {"op": "replay", "action": "seek", "time": 12.5}      // gantry replay only: play, pause, seek (s),
//!                                                      // step (frames: +-N snapshots), speed (0.25-4)
//! ```
//!
//! `id` is optional and echoed in the reply. Anything else gets an error reply; the
//! connection stays open.

use gantry_sim_core::Value;
use serde::Deserialize;

use gantry_sim_core::sim::Control;

use crate::sim_thread::LoopControl;

/// Longest text message accepted, bytes (the WebSocket layer refuses longer frames too).
pub const MAX_MESSAGE: usize = 16 * 1024;
/// Longest packet, as the text channel's default line limit.
pub const MAX_PACKET: usize = 4096;

/// A parsed message.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct ClientMessage {
    /// Echoed in the reply, so the page can match replies to requests.
    #[serde(default)]
    pub id: Option<u64>,
    /// What to do.
    #[serde(flatten)]
    pub command: Command,
}

/// The commands.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(tag = "op", rename_all = "snake_case")]
pub enum Command {
    /// Start, pause, stop or single-step the simulation.
    Control {
        /// Which control.
        action: ControlAction,
    },
    /// A text packet (`<FK#J1=..>`), delivered exactly as the TCP text channel does.
    Packet {
        /// The packet.
        text: String,
    },
    /// The user acted on a custom UI widget: `simUI.interact(ui, widget, value)`.
    Ui {
        /// UI handle.
        ui: i64,
        /// Widget id (0 = the window's close button).
        widget: i64,
        /// The new value (number, text, boolean or null, depending on the widget).
        #[serde(default)]
        value: serde_json::Value,
    },
    /// Reload a script from its file.
    Reload {
        /// Index in the scripts list the page received.
        script: usize,
    },
    /// Resume or step a script stopped in the debugger (`gantry run --debug`).
    Debug {
        /// What to do.
        action: DebugAction,
    },
    /// The user picked objects in the view (an empty list: clicked on nothing); what
    /// `sim.getObjectSel` returns.
    Select {
        /// The picked objects' handles.
        handles: Vec<i64>,
    },
    /// A key pressed in the 3D view: a `sim.message_keypress` for
    /// `sim.getSimulatorMessage` (CoppeliaSim's key codes: characters by their code,
    /// arrows 2007-2010).
    Key {
        /// The key's code.
        key: i64,
        /// Bit 0 ctrl, bit 1 shift.
        #[serde(default)]
        mods: i64,
    },
    /// Draw a vision sensor's segmentation mask from now on, for the vision panel
    /// (as `sim.getVisionSensorMask` turns it on; the images do not change).
    Mask {
        /// The vision sensor's handle.
        sensor: i64,
    },
    /// The replay's timeline (`gantry replay` only; a live run refuses it).
    Replay {
        /// What to do.
        action: ReplayAction,
        /// For `seek`: the time to show, s (log time of the recording).
        #[serde(default)]
        time: Option<f64>,
        /// For `speed`: replay seconds per wall-clock second, 0.25 to 4.
        #[serde(default)]
        speed: Option<f64>,
        /// For `step`: snapshots to move, negative back (default 1).
        #[serde(default)]
        frames: Option<i64>,
    },
}

/// The timeline controls of a replay.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ReplayAction {
    /// Play from the current time at the current speed.
    Play,
    /// Stop the clock where it is.
    Pause,
    /// Show the state at `time`.
    Seek,
    /// Move `frames` snapshots forward (or back), pausing.
    Step,
    /// Change the speed.
    Speed,
}

/// Slowest replay speed, replay seconds per wall-clock second.
pub const MIN_REPLAY_SPEED: f64 = 0.25;
/// Fastest replay speed.
pub const MAX_REPLAY_SPEED: f64 = 4.0;
/// Most snapshots one `step` moves.
pub const MAX_REPLAY_STEP: i64 = 100_000;

/// Largest key code accepted: the Unicode range (CoppeliaSim's special keys are below).
pub const MAX_KEY_CODE: i64 = 0x10_FFFF;

/// The debugger buttons of the page's "paused in SCRIPT:LINE" banner.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DebugAction {
    /// Resume.
    Continue,
    /// Next line (over calls).
    StepOver,
    /// Next line, into calls.
    StepIn,
    /// Until the function returns.
    StepOut,
    /// Stop at the next script line.
    Pause,
}

impl From<DebugAction> for gantry_lua::DebugRequest {
    fn from(a: DebugAction) -> Self {
        match a {
            DebugAction::Continue => Self::Continue,
            DebugAction::StepOver => Self::StepOver,
            DebugAction::StepIn => Self::StepIn,
            DebugAction::StepOut => Self::StepOut,
            DebugAction::Pause => Self::Pause,
        }
    }
}

/// The simulation controls the page offers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ControlAction {
    /// Start or resume.
    Start,
    /// Pause.
    Pause,
    /// Stop (cleanup, initial scene restored).
    Stop,
    /// One step.
    Step,
}

impl From<ControlAction> for LoopControl {
    fn from(a: ControlAction) -> Self {
        match a {
            ControlAction::Start => LoopControl::Control(Control::Start),
            ControlAction::Pause => LoopControl::Control(Control::Pause),
            ControlAction::Stop => LoopControl::Control(Control::Stop),
            ControlAction::Step => LoopControl::Step,
        }
    }
}

/// Why a message was refused. The message goes back to the page.
#[derive(Debug, thiserror::Error)]
pub enum CommandError {
    /// Over [`MAX_MESSAGE`] bytes.
    #[error("message longer than {MAX_MESSAGE} bytes")]
    TooLong,
    /// Not JSON, or not one of the commands.
    #[error(
        "bad message: {0} (expected {{\"op\": \"control\"|\"packet\"|\"ui\"|\"reload\"|\"debug\"|\"key\"|\"select\"|\"replay\", ...}})"
    )]
    Json(#[from] serde_json::Error),
    /// A packet over [`MAX_PACKET`] bytes.
    #[error("packet longer than {MAX_PACKET} bytes")]
    PacketTooLong,
    /// A widget value that is an array or object.
    #[error("a widget value must be a number, text, boolean or null")]
    BadValue,
    /// A key code or modifier outside the ranges.
    #[error("a key code is 1..=1114111 and its modifiers 0..=3")]
    BadKey,
    /// A replay command without its argument, or with one out of range.
    #[error(
        "a replay seek needs a finite \"time\" (s), a speed a \"speed\" from 0.25 to 4, a step a non-zero \"frames\" of at most 100000"
    )]
    BadReplay,
}

/// Parses and checks one text message.
///
/// # Errors
/// See [`CommandError`].
pub fn parse(text: &str) -> Result<ClientMessage, CommandError> {
    if text.len() > MAX_MESSAGE {
        return Err(CommandError::TooLong);
    }
    let msg: ClientMessage = serde_json::from_str(text)?;
    match &msg.command {
        Command::Packet { text } if text.len() > MAX_PACKET => Err(CommandError::PacketTooLong),
        Command::Ui { value, .. } if value.is_array() || value.is_object() => Err(CommandError::BadValue),
        Command::Key { key, mods } if !(1..=MAX_KEY_CODE).contains(key) || !(0..=3).contains(mods) => {
            Err(CommandError::BadKey)
        }
        Command::Replay {
            action,
            time,
            speed,
            frames,
        } => {
            let ok = match action {
                ReplayAction::Play | ReplayAction::Pause => true,
                ReplayAction::Seek => time.is_some_and(f64::is_finite),
                ReplayAction::Speed => speed.is_some_and(|s| (MIN_REPLAY_SPEED..=MAX_REPLAY_SPEED).contains(&s)),
                ReplayAction::Step => frames.is_none_or(|n| n != 0 && n.abs() <= MAX_REPLAY_STEP),
            };
            if ok { Ok(msg) } else { Err(CommandError::BadReplay) }
        }
        _ => Ok(msg),
    }
}

/// A widget value as the simulation's value type (integers stay integers, as simUI
/// passes slider positions).
pub fn ui_value(v: &serde_json::Value) -> Value {
    match v {
        serde_json::Value::Bool(b) => Value::Bool(*b),
        serde_json::Value::Number(n) => match n.as_i64() {
            Some(i) => Value::Int(i),
            None => Value::Float(n.as_f64().unwrap_or(0.0)),
        },
        serde_json::Value::String(s) => Value::Str(s.clone()),
        _ => Value::Nil,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mask_requests_name_a_sensor() {
        let m = parse(r#"{"id":3,"op":"mask","sensor":15}"#).unwrap();
        assert_eq!((m.id, m.command), (Some(3), Command::Mask { sensor: 15 }));
        assert!(parse(r#"{"op":"mask"}"#).is_err());
        assert!(parse(r#"{"op":"mask","sensor":"cam"}"#).is_err());
    }

    #[test]
    fn keys_parse_within_their_ranges() {
        let m = parse(r#"{"op":"key","key":2007,"mods":2}"#).unwrap();
        assert_eq!(m.command, Command::Key { key: 2007, mods: 2 });
        let m = parse(r#"{"op":"key","key":97}"#).unwrap();
        assert_eq!(m.command, Command::Key { key: 97, mods: 0 });
        for bad in [
            r#"{"op":"key","key":0}"#,
            r#"{"op":"key","key":-5}"#,
            r#"{"op":"key","key":1114112}"#,
            r#"{"op":"key","key":97,"mods":4}"#,
        ] {
            assert!(matches!(parse(bad), Err(CommandError::BadKey)), "{bad}");
        }
        assert!(matches!(parse(r#"{"op":"key","key":"a"}"#), Err(CommandError::Json(_))));
    }

    #[test]
    fn commands_parse() {
        let m = parse(r#"{"id":3,"op":"control","action":"step"}"#).unwrap();
        assert_eq!(m.id, Some(3));
        assert_eq!(
            m.command,
            Command::Control {
                action: ControlAction::Step
            }
        );
        let m = parse(r#"{"op":"packet","text":"<FK#J1=0.5>"}"#).unwrap();
        assert_eq!(m.id, None);
        assert!(matches!(m.command, Command::Packet { text } if text == "<FK#J1=0.5>"));
        let m = parse(r#"{"op":"ui","ui":1000,"widget":1,"value":30}"#).unwrap();
        let Command::Ui { ui, widget, value } = m.command else {
            panic!("not ui")
        };
        assert_eq!((ui, widget, ui_value(&value)), (1000, 1, Value::Int(30)));
        let m = parse(r#"{"op":"ui","ui":1000,"widget":2}"#).unwrap();
        assert!(matches!(
            m.command,
            Command::Ui {
                value: serde_json::Value::Null,
                ..
            }
        ));
        assert!(matches!(
            parse(r#"{"op":"reload","script":2}"#).unwrap().command,
            Command::Reload { script: 2 }
        ));
        assert_eq!(
            parse(r#"{"op":"debug","action":"step_out"}"#).unwrap().command,
            Command::Debug {
                action: DebugAction::StepOut
            }
        );
    }

    #[test]
    fn bad_messages_are_errors_not_panics() {
        for bad in [
            "",
            "not json",
            "[]",
            "{}",
            r#"{"op":"nope"}"#,
            r#"{"op":"control","action":"explode"}"#,
            r#"{"op":"control"}"#,
            r#"{"op":"reload","script":-1}"#,
            r#"{"op":"debug","action":"jump"}"#,
            r#"{"op":"ui","ui":"x","widget":1}"#,
            r#"{"op":"ui","ui":1,"widget":1,"value":[1,2]}"#,
            r#"{"id":-5,"op":"control","action":"start"}"#,
        ] {
            assert!(parse(bad).is_err(), "{bad:?} parsed");
        }
        let long = format!(r#"{{"op":"packet","text":"{}"}}"#, "x".repeat(MAX_PACKET + 1));
        assert!(matches!(parse(&long), Err(CommandError::PacketTooLong)));
        assert!(matches!(
            parse(&" ".repeat(MAX_MESSAGE + 1)),
            Err(CommandError::TooLong)
        ));
    }

    #[test]
    fn replay_commands_parse_with_their_arguments_in_range() {
        let m = parse(r#"{"id":1,"op":"replay","action":"seek","time":12.5}"#).unwrap();
        assert_eq!(
            m.command,
            Command::Replay {
                action: ReplayAction::Seek,
                time: Some(12.5),
                speed: None,
                frames: None
            }
        );
        for ok in [
            r#"{"op":"replay","action":"play"}"#,
            r#"{"op":"replay","action":"pause"}"#,
            r#"{"op":"replay","action":"step"}"#,
            r#"{"op":"replay","action":"step","frames":-1}"#,
            r#"{"op":"replay","action":"speed","speed":0.25}"#,
            r#"{"op":"replay","action":"speed","speed":4}"#,
        ] {
            assert!(parse(ok).is_ok(), "{ok}");
        }
        for bad in [
            r#"{"op":"replay","action":"seek"}"#,
            r#"{"op":"replay","action":"speed","speed":8}"#,
            r#"{"op":"replay","action":"speed"}"#,
            r#"{"op":"replay","action":"step","frames":0}"#,
            r#"{"op":"replay","action":"step","frames":1000000}"#,
        ] {
            assert!(matches!(parse(bad), Err(CommandError::BadReplay)), "{bad}");
        }
        assert!(matches!(
            parse(r#"{"op":"replay","action":"rewind"}"#),
            Err(CommandError::Json(_))
        ));
    }

    #[test]
    fn values_convert() {
        assert_eq!(ui_value(&serde_json::json!(2.5)), Value::Float(2.5));
        assert_eq!(ui_value(&serde_json::json!("a")), Value::Str("a".into()));
        assert_eq!(ui_value(&serde_json::json!(true)), Value::Bool(true));
        assert_eq!(ui_value(&serde_json::json!(null)), Value::Nil);
    }
}
