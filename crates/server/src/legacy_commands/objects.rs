//! The commands on the scene and its objects that need more than one registry call
//! or a layout of their own: loading scenes and models, finding objects, the
//! selection, parenting and velocities.

use std::path::PathBuf;

use gantry_sim_core::Value;
use tokio::sync::oneshot;

use super::layout::CommandError;
use super::layout::{Arg, Data, as_i32, floats_reply, id_str, int_reply, numbers, pad3, put_count};
use super::session::Ctx;
use crate::sim_thread::{Request, SendError};

/// `simxCloseScene`: the empty scene, and a new scene id for the client to notice.
pub(super) async fn close_scene(cx: &mut Ctx<'_>) -> Result<Vec<u8>, CommandError> {
    replace_scene(cx, None).await?;
    Ok(Vec::new())
}

/// `simxLoadScene`: a file named by the command that the server can read (bit 0 of the
/// first argument byte would mean a file sent by the client, which gantry refuses).
pub(super) async fn load_scene(cx: &mut Ctx<'_>) -> Result<Vec<u8>, CommandError> {
    if client_side_file(cx) {
        return Err(CommandError::ClientFile("simxLoadScene"));
    }
    replace_scene(cx, Some(PathBuf::from(id_str(cx.cmd)))).await?;
    Ok(Vec::new())
}

/// `simxLoadModel`: `sim.loadModel` on a file the server can read; replies the model's
/// handle.
pub(super) async fn load_model(cx: &mut Ctx<'_>) -> Result<Vec<u8>, CommandError> {
    if client_side_file(cx) {
        return Err(CommandError::ClientFile("simxLoadModel"));
    }
    int_reply(cx.call("loadModel", vec![Value::Str(id_str(cx.cmd))]).await?.first())
}

fn client_side_file(cx: &Ctx<'_>) -> bool {
    cx.cmd.data.first().is_some_and(|&o| o & 1 != 0)
}

async fn replace_scene(cx: &mut Ctx<'_>, path: Option<PathBuf>) -> Result<(), CommandError> {
    let (reply, rx) = oneshot::channel();
    cx.sim.send(Request::LoadScene { path, reply })?;
    rx.await.map_err(|_| SendError::Closed)??;
    cx.session.scene_id = cx.session.scene_id.wrapping_add(1);
    Ok(())
}

/// `simxGetObjectHandle`: the 4.0-4.2 lookup by name (`name#n`, `@silentError` as in
/// CoppeliaSim); an object that does not exist is an error, not -1.
pub(super) async fn object_handle(cx: &mut Ctx<'_>) -> Result<Vec<u8>, CommandError> {
    let name = id_str(cx.cmd);
    let r = cx.call("getObjectHandle", vec![Value::Str(name.clone())]).await?;
    match as_i32(r.first()) {
        Some(x) if x >= 0 => Ok(x.to_le_bytes().to_vec()),
        _ => Err(CommandError::NoObject(name)),
    }
}

/// `simxGetObjects`: `sim.getObjects(index, type)` until it answers -1, as the server
/// does; replies the count, then the handles.
pub(super) async fn objects(cx: &mut Ctx<'_>) -> Result<Vec<u8>, CommandError> {
    let kind = Arg::Id.read(cx.cmd)?;
    let mut handles = Vec::new();
    for i in 0..100_000i64 {
        let r = cx.call("getObjects", vec![Value::Int(i), kind.clone()]).await?;
        match as_i32(r.first()) {
            Some(x) if x >= 0 => handles.push(x),
            _ => break,
        }
    }
    let mut out = Vec::new();
    put_count(&mut out, handles.len());
    handles.iter().for_each(|x| out.extend_from_slice(&x.to_le_bytes()));
    Ok(out)
}

/// `simxGetObjectSelection`: the count, then the handles.
pub(super) async fn selection(cx: &mut Ctx<'_>) -> Result<Vec<u8>, CommandError> {
    let sel = cx.call("getObjectSel", vec![]).await?;
    let handles = numbers(sel.first())?;
    let mut out = Vec::new();
    put_count(&mut out, handles.len());
    for v in &handles {
        out.extend_from_slice(&as_i32(Some(v)).unwrap_or(-1).to_le_bytes());
    }
    Ok(out)
}

/// `simxSetObjectSelection`: the arguments are the handles, without a count.
pub(super) async fn set_selection(cx: &mut Ctx<'_>) -> Result<Vec<u8>, CommandError> {
    let d = Data(&cx.cmd.data);
    let handles = (0..cx.cmd.data.len() / 4)
        .map(|i| d.i32(4 * i).map(|x| Value::Int(i64::from(x))))
        .collect::<Result<Vec<_>, _>>()?;
    cx.call("setObjectSel", vec![Value::Array(handles)]).await?;
    Ok(Vec::new())
}

/// `simxSetObjectParent`: the parent's handle, then one byte saying whether the object
/// keeps its world pose (true when the client sent no such byte).
pub(super) async fn set_parent(cx: &mut Ctx<'_>) -> Result<Vec<u8>, CommandError> {
    let object = Arg::Id.read(cx.cmd)?;
    let parent = Arg::I32(0).read(cx.cmd)?;
    let keep = Value::Bool(cx.cmd.data.get(4).copied().unwrap_or(1) != 0);
    cx.call("setObjectParent", vec![object, parent, keep]).await?;
    Ok(Vec::new())
}

/// `simxGetObjectVelocity`: linear then angular velocity, three floats each.
pub(super) async fn velocity(cx: &mut Ctx<'_>) -> Result<Vec<u8>, CommandError> {
    let r = cx.call("getObjectVelocity", vec![Arg::Id.read(cx.cmd)?]).await?;
    let mut out = floats_reply(&pad3(numbers(r.first())?))?;
    out.extend(floats_reply(&pad3(numbers(r.get(1))?))?);
    Ok(out)
}
