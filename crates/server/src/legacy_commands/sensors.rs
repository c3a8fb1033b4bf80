//! The sensor commands: vision sensor images and depth, and the three sensors' read
//! functions, each with the reply layout the client library expects.

use gantry_sim_core::Value;

use super::layout::CommandError;
use super::layout::{Arg, as_i32, numbers, pad3, put_count, put_f32s};
use super::session::Ctx;

/// `simxGetVisionSensorImage`: the resolution (two integers), then the pixels, RGB or
/// grey as CoppeliaSim computes it (the mean of the three channels).
pub(super) async fn image(cx: &mut Ctx<'_>, rgb: bool) -> Result<Vec<u8>, CommandError> {
    let r = cx.call("getVisionSensorImg", vec![Arg::Id.read(cx.cmd)?]).await?;
    let (Some(Value::Bytes(img)), Some(res)) = (r.first(), r.get(1)) else {
        return Err(CommandError::NoImage);
    };
    let mut out = resolution(res)?;
    if rgb {
        out.extend_from_slice(img);
    } else {
        out.extend(
            img.chunks_exact(3)
                .map(|p| ((u16::from(p[0]) + u16::from(p[1]) + u16::from(p[2])) / 3) as u8),
        );
    }
    Ok(out)
}

/// `simxSetVisionSensorImage`: the pixels are the whole argument; a grey one is spread
/// to the three channels.
pub(super) async fn set_image(cx: &mut Ctx<'_>, rgb: bool) -> Result<Vec<u8>, CommandError> {
    let img = if rgb {
        cx.cmd.data.clone()
    } else {
        cx.cmd.data.iter().flat_map(|&g| [g, g, g]).collect()
    };
    cx.call("setVisionSensorImg", vec![Arg::Id.read(cx.cmd)?, Value::Bytes(img)])
        .await?;
    Ok(Vec::new())
}

/// `simxGetVisionSensorDepthBuffer`: the resolution, then the depth buffer's bytes.
pub(super) async fn depth_buffer(cx: &mut Ctx<'_>) -> Result<Vec<u8>, CommandError> {
    let r = cx.call("getVisionSensorDepth", vec![Arg::Id.read(cx.cmd)?]).await?;
    let (Some(Value::Bytes(depth)), Some(res)) = (r.first(), r.get(1)) else {
        return Err(CommandError::NoDepthBuffer);
    };
    let mut out = resolution(res)?;
    out.extend_from_slice(depth);
    Ok(out)
}

/// A resolution result as two integers (0 for a missing one).
fn resolution(res: &Value) -> Result<Vec<u8>, CommandError> {
    let res = numbers(Some(res))?;
    let mut out = as_i32(res.first()).unwrap_or(0).to_le_bytes().to_vec();
    out.extend_from_slice(&as_i32(res.get(1)).unwrap_or(0).to_le_bytes());
    Ok(out)
}

/// `simxReadVisionSensor`: a detection byte, the packet count, each packet's length,
/// then the packets' floats. A sensor that has not run yet is an error.
pub(super) async fn read_vision(cx: &mut Ctx<'_>) -> Result<Vec<u8>, CommandError> {
    let r = cx.call("readVisionSensor", vec![Arg::Id.read(cx.cmd)?]).await?;
    let detected = as_i32(r.first()).unwrap_or(-1);
    if detected < 0 {
        return Err(CommandError::NoVisionResult);
    }
    let packets: Vec<Vec<Value>> = r
        .get(1..)
        .unwrap_or_default()
        .iter()
        .map(|p| numbers(Some(p)))
        .collect::<Result<_, _>>()?;
    let mut out = vec![u8::from(detected > 0)];
    put_count(&mut out, packets.len());
    for p in &packets {
        put_count(&mut out, p.len());
    }
    for p in &packets {
        put_f32s(&mut out, p)?;
    }
    Ok(out)
}

/// `simxReadProximitySensor`: a detection byte, the detected point (three floats), the
/// detected object's handle (-1 for none) and the surface normal (three floats).
pub(super) async fn read_proximity(cx: &mut Ctx<'_>) -> Result<Vec<u8>, CommandError> {
    let r = cx.call("readProximitySensor", vec![Arg::Id.read(cx.cmd)?]).await?;
    let detected = as_i32(r.first()).unwrap_or(0);
    let point = r.get(2).map(|p| numbers(Some(p))).transpose()?.unwrap_or_default();
    let normal = r.get(4).map(|p| numbers(Some(p))).transpose()?.unwrap_or_default();
    let mut out = vec![u8::from(detected > 0)];
    put_f32s(&mut out, &pad3(point))?;
    out.extend_from_slice(&as_i32(r.get(3)).unwrap_or(-1).to_le_bytes());
    put_f32s(&mut out, &pad3(normal))?;
    Ok(out)
}

/// `simxReadForceSensor`: the state byte, then force and torque (three floats each).
pub(super) async fn read_force(cx: &mut Ctx<'_>) -> Result<Vec<u8>, CommandError> {
    let r = cx.call("readForceSensor", vec![Arg::Id.read(cx.cmd)?]).await?;
    let mut out = vec![as_i32(r.first()).unwrap_or(0).clamp(0, 255) as u8];
    put_f32s(&mut out, &pad3(numbers(r.get(1)).unwrap_or_default()))?;
    put_f32s(&mut out, &pad3(numbers(r.get(2)).unwrap_or_default()))?;
    Ok(out)
}
