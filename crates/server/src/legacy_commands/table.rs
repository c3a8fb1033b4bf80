//! Every `simx` command gantry serves, one row per command code: the client library's
//! `simx_cmd_*` name and the typed command it runs. Most rows are a single registry call
//! written as data (function, where each argument comes from, how the first result is
//! encoded); a command that needs more (several calls, a layout of its own, session
//! state) is a [`Simx`] variant whose function is named on its doc line.

use super::layout::{Arg, CommandError, Reply};
use super::session::{Ctx, Outcome, ok};
use super::{objects, script_call, sensors, signals};

/// What one command code does.
#[derive(Clone, Copy, Debug)]
pub(super) enum Simx {
    /// One registry call: its arguments read in order, its first result encoded.
    Call {
        function: &'static str,
        args: &'static [Arg],
        reply: Reply,
    },
    /// Enter (true) or leave synchronous stepping: [`Ctx::set_synchronous`].
    Synchronous(bool),
    /// One step in synchronous mode, answered once done: [`Ctx::synchronous_trigger`].
    SynchronousTrigger,
    /// Start, pause or stop the simulation: [`Ctx::control_simulation`].
    ControlSimulation,
    /// The errors kept since the last call: [`Ctx::take_errors`].
    GetLastErrors,
    /// Close the connection after this reply: [`Ctx::kill`].
    KillConnection,
    /// Load the empty scene: [`objects::close_scene`].
    CloseScene,
    /// Load a scene file the server can read: [`objects::load_scene`].
    LoadScene,
    /// Load a model file the server can read: [`objects::load_model`].
    LoadModel,
    /// The object named by the command: [`objects::object_handle`].
    GetObjectHandle,
    /// Objects of a type, by index: [`objects::objects`].
    GetObjects,
    /// The selected objects: [`objects::selection`].
    GetObjectSelection,
    /// Replace the selection: [`objects::set_selection`].
    SetObjectSelection,
    /// Reparent, keeping the world pose or not: [`objects::set_parent`].
    SetObjectParent,
    /// Linear and angular velocity: [`objects::velocity`].
    GetObjectVelocity,
    /// A vision sensor's image, colour or grey: [`sensors::image`].
    GetVisionSensorImage { rgb: bool },
    /// Replace a vision sensor's image, colour or grey: [`sensors::set_image`].
    SetVisionSensorImage { rgb: bool },
    /// A vision sensor's depth buffer: [`sensors::depth_buffer`].
    GetVisionSensorDepthBuffer,
    /// A vision sensor's detection and packets: [`sensors::read_vision`].
    ReadVisionSensor,
    /// A proximity sensor's detection: [`sensors::read_proximity`].
    ReadProximitySensor,
    /// A force sensor's force and torque: [`sensors::read_force`].
    ReadForceSensor,
    /// A number signal, an error when unset: [`signals::number`].
    GetNumberSignal {
        function: &'static str,
        kind: &'static str,
        reply: Reply,
    },
    /// A string signal, read as CoppeliaSim's three commands do: [`signals::string`].
    GetStringSignal(signals::Read),
    /// Set or append to a string signal: [`signals::set_string`].
    SetStringSignal { append: bool },
    /// A function of an object's script: [`script_call::call_script_function`].
    CallScriptFunction,
}

impl Simx {
    /// Runs the command for `cx`'s client.
    pub(super) async fn run(self, cx: &mut Ctx<'_>) -> Result<Outcome, CommandError> {
        let data = match self {
            Simx::Call { function, args, reply } => {
                let args = args.iter().map(|a| a.read(cx.cmd)).collect::<Result<_, _>>()?;
                reply.encode(&cx.call(function, args).await?)?
            }
            Simx::Synchronous(enable) => cx.set_synchronous(enable).await?,
            Simx::SynchronousTrigger => cx.synchronous_trigger().await?,
            Simx::ControlSimulation => cx.control_simulation().await?,
            Simx::GetLastErrors => cx.take_errors(),
            Simx::KillConnection => cx.kill(),
            Simx::CloseScene => objects::close_scene(cx).await?,
            Simx::LoadScene => objects::load_scene(cx).await?,
            Simx::LoadModel => objects::load_model(cx).await?,
            Simx::GetObjectHandle => objects::object_handle(cx).await?,
            Simx::GetObjects => objects::objects(cx).await?,
            Simx::GetObjectSelection => objects::selection(cx).await?,
            Simx::SetObjectSelection => objects::set_selection(cx).await?,
            Simx::SetObjectParent => objects::set_parent(cx).await?,
            Simx::GetObjectVelocity => objects::velocity(cx).await?,
            Simx::GetVisionSensorImage { rgb } => sensors::image(cx, rgb).await?,
            Simx::SetVisionSensorImage { rgb } => sensors::set_image(cx, rgb).await?,
            Simx::GetVisionSensorDepthBuffer => sensors::depth_buffer(cx).await?,
            Simx::ReadVisionSensor => sensors::read_vision(cx).await?,
            Simx::ReadProximitySensor => sensors::read_proximity(cx).await?,
            Simx::ReadForceSensor => sensors::read_force(cx).await?,
            Simx::GetNumberSignal { function, kind, reply } => signals::number(cx, function, kind, reply).await?,
            Simx::GetStringSignal(read) => return signals::string(cx, read).await,
            Simx::SetStringSignal { append } => signals::set_string(cx, append).await?,
            Simx::CallScriptFunction => script_call::call_script_function(cx).await?,
        };
        Ok(ok(data))
    }
}

/// One row of [`COMMANDS`].
pub(super) struct Entry {
    /// The command code (`simx_cmd_*`).
    pub(super) code: i32,
    /// The client library's name for the code, for logs.
    pub(super) name: &'static str,
    /// What it does.
    pub(super) command: Simx,
}

const fn row(code: i32, name: &'static str, command: Simx) -> Entry {
    Entry { code, name, command }
}

const fn call(function: &'static str, args: &'static [Arg], reply: Reply) -> Simx {
    Simx::Call { function, args, reply }
}

use Arg::{F32, F32s, Flag, I32, Id, Id2, IdStr, Text};

/// Every command served, by code. A code not here fails with a message naming it.
#[rustfmt::skip]
pub(super) const COMMANDS: &[Entry] = &[
    // Connection and simulation control.
    row(0x0001, "simx_cmd_synchronous_enable", Simx::Synchronous(true)),
    row(0x0002, "simx_cmd_synchronous_disable", Simx::Synchronous(false)),
    row(0x0003, "simx_cmd_synchronous_next", Simx::SynchronousTrigger),
    row(0x0004, "simx_cmd_get_last_errors", Simx::GetLastErrors),
    row(0x0005, "simx_cmd_close_scene", Simx::CloseScene),
    row(0x0006, "simx_cmd_get_object_selection", Simx::GetObjectSelection),
    row(0x0009, "simx_cmd_create_dummy", call("createDummy", &[F32(0)], Reply::Int)),
    row(0x000a, "simx_cmd_kill_connection", Simx::KillConnection),
    // Commands identified by one integer (mostly an object handle).
    row(0x1001, "simx_cmd_get_joint_position", call("getJointPosition", &[Id], Reply::Float)),
    row(0x1002, "simx_cmd_set_joint_position", call("setJointPosition", &[Id, F32(0)], Reply::Empty)),
    row(0x1003, "simx_cmd_get_vision_sensor_image_bw", Simx::GetVisionSensorImage { rgb: false }),
    row(0x1004, "simx_cmd_get_vision_sensor_image_rgb", Simx::GetVisionSensorImage { rgb: true }),
    row(0x1005, "simx_cmd_set_vision_sensor_image_bw", Simx::SetVisionSensorImage { rgb: false }),
    row(0x1006, "simx_cmd_set_vision_sensor_image_rgb", Simx::SetVisionSensorImage { rgb: true }),
    row(0x1007, "simx_cmd_start_pause_stop_simulation", Simx::ControlSimulation),
    row(0x1008, "simx_cmd_set_joint_target_velocity", call("setJointTargetVelocity", &[Id, F32(0)], Reply::Empty)),
    row(0x1009, "simx_cmd_read_proximity_sensor", Simx::ReadProximitySensor),
    row(0x100c, "simx_cmd_set_joint_target_position", call("setJointTargetPosition", &[Id, F32(0)], Reply::Empty)),
    row(0x100d, "simx_cmd_get_joint_force", call("getJointForce", &[Id], Reply::Float)),
    row(0x100e, "simx_cmd_set_joint_force", call("setJointMaxForce", &[Id, F32(0)], Reply::Empty)),
    row(0x100f, "simx_cmd_read_force_sensor", Simx::ReadForceSensor),
    row(0x1011, "simx_cmd_read_vision_sensor", Simx::ReadVisionSensor),
    row(0x1012, "simx_cmd_get_object_parent", call("getObjectParent", &[Id], Reply::Int)),
    row(0x1014, "simx_cmd_aux_console_close", call("auxiliaryConsoleClose", &[Id], Reply::Empty)),
    row(0x1015, "simx_cmd_aux_console_print", call("auxiliaryConsolePrint", &[Id, Text], Reply::Empty)),
    row(0x1016, "simx_cmd_aux_console_show", call("auxiliaryConsoleShow", &[Id, Flag(0)], Reply::Empty)),
    row(0x1017, "simx_cmd_get_vision_sensor_depth_buffer", Simx::GetVisionSensorDepthBuffer),
    // The oldest clients put the reference frame in the arguments (0x1018, 0x1019), later
    // ones in the command's identity (0x200d, 0x200e), so that two frames can stream
    // side by side.
    row(0x1018, "simx_cmd_get_object_orientation", call("getObjectOrientation", &[Id, I32(0)], Reply::Floats)),
    row(0x1019, "simx_cmd_get_object_position", call("getObjectPosition", &[Id, I32(0)], Reply::Floats)),
    row(0x101a, "simx_cmd_set_object_orientation", call("setObjectOrientation", &[Id, I32(0), F32s(4, 3)], Reply::Empty)),
    row(0x101b, "simx_cmd_set_object_position", call("setObjectPosition", &[Id, I32(0), F32s(4, 3)], Reply::Empty)),
    row(0x101c, "simx_cmd_set_object_parent", Simx::SetObjectParent),
    row(0x101f, "simx_cmd_get_boolean_parameter", call("getBoolParam", &[Id], Reply::Bool)),
    row(0x1020, "simx_cmd_set_boolean_parameter", call("setBoolParam", &[Id, Flag(0)], Reply::Empty)),
    row(0x1021, "simx_cmd_get_integer_parameter", call("getInt32Param", &[Id], Reply::Int)),
    row(0x1022, "simx_cmd_set_integer_parameter", call("setInt32Param", &[Id, I32(0)], Reply::Empty)),
    row(0x1023, "simx_cmd_get_floating_parameter", call("getFloatParam", &[Id], Reply::Float)),
    row(0x1024, "simx_cmd_set_floating_parameter", call("setFloatParam", &[Id, F32(0)], Reply::Empty)),
    row(0x1028, "simx_cmd_remove_object", call("removeObject", &[Id], Reply::Empty)),
    row(0x102a, "simx_cmd_get_objects", Simx::GetObjects),
    row(0x102f, "simx_cmd_set_object_selection", Simx::SetObjectSelection),
    row(0x1036, "simx_cmd_get_object_velocity", Simx::GetObjectVelocity),
    row(0x1038, "simx_cmd_get_joint_max_force", call("getJointMaxForce", &[Id], Reply::Float)),
    row(0x1801, "simx_cmd_set_object_quaternion", call("setObjectQuaternion", &[Id, I32(0), F32s(4, 4)], Reply::Empty)),
    // Commands identified by two integers (an object and a parameter, frame or object).
    row(0x2007, "simx_cmd_get_object_float_parameter", call("getObjectFloatParam", &[Id, Id2], Reply::Float)),
    row(0x2008, "simx_cmd_get_object_int_parameter", call("getObjectInt32Param", &[Id, Id2], Reply::Int)),
    row(0x2009, "simx_cmd_set_object_float_parameter", call("setObjectFloatParam", &[Id, Id2, F32(0)], Reply::Empty)),
    row(0x200a, "simx_cmd_set_object_int_parameter", call("setObjectInt32Param", &[Id, Id2, I32(0)], Reply::Empty)),
    row(0x200b, "simx_cmd_get_object_child", call("getObjectChild", &[Id, Id2], Reply::Int)),
    row(0x200d, "simx_cmd_get_object_orientation2", call("getObjectOrientation", &[Id, Id2], Reply::Floats)),
    row(0x200e, "simx_cmd_get_object_position2", call("getObjectPosition", &[Id, Id2], Reply::Floats)),
    row(0x200f, "simx_cmd_check_collision", call("checkCollision", &[Id, Id2], Reply::Int)),
    row(0x2801, "simx_cmd_get_object_quaternion", call("getObjectQuaternion", &[Id, Id2], Reply::Floats)),
    // Commands identified by a string (a name).
    row(0x3001, "simx_cmd_get_object_handle", Simx::GetObjectHandle),
    row(0x3002, "simx_cmd_load_scene", Simx::LoadScene),
    row(0x3003, "simx_cmd_load_model", Simx::LoadModel),
    row(0x3008, "simx_cmd_add_statusbar_message", call("addStatusbarMessage", &[IdStr], Reply::Empty)),
    row(0x3009, "simx_cmd_aux_console_open", call("auxiliaryConsoleOpen", &[IdStr, I32(0), I32(4)], Reply::Int)),
    row(0x300d, "simx_cmd_clear_float_signal", call("clearFloatSignal", &[IdStr], Reply::Empty)),
    row(0x300e, "simx_cmd_clear_integer_signal", call("clearInt32Signal", &[IdStr], Reply::Empty)),
    row(0x300f, "simx_cmd_clear_string_signal", call("clearStringSignal", &[IdStr], Reply::Empty)),
    row(0x3010, "simx_cmd_get_float_signal", Simx::GetNumberSignal { function: "getFloatSignal", kind: "float", reply: Reply::Float }),
    row(0x3011, "simx_cmd_get_integer_signal", Simx::GetNumberSignal { function: "getInt32Signal", kind: "integer", reply: Reply::Int }),
    row(0x3012, "simx_cmd_get_string_signal", Simx::GetStringSignal(signals::Read::Get)),
    row(0x3013, "simx_cmd_set_float_signal", call("setFloatSignal", &[IdStr, F32(0)], Reply::Empty)),
    row(0x3014, "simx_cmd_set_integer_signal", call("setInt32Signal", &[IdStr, I32(0)], Reply::Empty)),
    row(0x3015, "simx_cmd_set_string_signal", Simx::SetStringSignal { append: false }),
    row(0x3016, "simx_cmd_append_string_signal", Simx::SetStringSignal { append: true }),
    row(0x3017, "simx_cmd_get_and_clear_string_signal", Simx::GetStringSignal(signals::Read::GetAndClear)),
    row(0x3018, "simx_cmd_read_string_stream", Simx::GetStringSignal(signals::Read::Stream)),
    // Commands identified by an integer and two strings.
    row(0x3401, "simx_cmd_call_script_function", Simx::CallScriptFunction),
];

/// The row for a command code.
pub(super) fn find(code: i32) -> Option<&'static Entry> {
    COMMANDS.iter().find(|e| e.code == code)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_code_has_one_row() {
        for (i, e) in COMMANDS.iter().enumerate() {
            assert!(
                COMMANDS[i + 1..].iter().all(|other| other.code != e.code),
                "0x{:04x} ({}) has two rows",
                e.code,
                e.name
            );
            assert_eq!(find(e.code).map(|f| f.name), Some(e.name));
        }
    }

    /// Kept in code order so that a reader finds a code where the client library's
    /// header has it.
    #[test]
    fn rows_are_in_code_order() {
        for pair in COMMANDS.windows(2) {
            assert!(pair[0].code < pair[1].code, "{} before {}", pair[0].name, pair[1].name);
        }
    }
}
