//! Vision sensors (`sim.*Vision*`) and the `simVision.*` work-image functions.
//!
//! Images cross the API as CoppeliaSim's buffers (see [`crate::vision`] for the
//! rendering model): bytes, row-major, **bottom row first**, RGB 3 bytes per pixel
//! (greyscale 1, RGBA 4), depth as packed little-endian `f32`s. Every image function
//! takes an optional portion, `pos = {x, y}` (column from the left, row from the
//! bottom) and `size = {w, h}`; a size component of 0 extends to the image edge, so
//! the defaults `{0, 0}`, `{0, 0}` mean the whole image. Functions returning an image
//! also return the portion's `{width, height}`.

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::sim::Sim;
use crate::vision::{self, SensorImage, VisionResult};
use crate::world::Handle;

/// `sim.handle_all`.
const HANDLE_ALL: Handle = -2;
/// `sim.handle_all_except_explicit`.
const HANDLE_ALL_EXCEPT_EXPLICIT: Handle = -3;
/// `sim.handle_self`: the object of the calling script.
const HANDLE_SELF: Handle = -4;

/// The `sim.*` vision functions this file implements, in alphabetical order.
pub(super) const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        // CoppeliaSim 4.0-4.5's byte image.
        name: "getVisionSensorCharImage",
        call: ApiFn::Sim(get_vision_sensor_char_image),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "getVisionSensorDepth",
        call: ApiFn::Sim(get_vision_sensor_depth),
        cost: Cost::Long,
    },
    ApiFunction {
        // V-REP 3 to CoppeliaSim 4.5's depth as a table.
        name: "getVisionSensorDepthBuffer",
        call: ApiFn::Sim(get_vision_sensor_depth_buffer),
        cost: Cost::Long,
    },
    ApiFunction {
        // CoppeliaSim 4.0-4.5's float image.
        name: "getVisionSensorImage",
        call: ApiFn::Sim(get_vision_sensor_image),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "getVisionSensorImg",
        call: ApiFn::Sim(get_vision_sensor_img),
        cost: Cost::Long,
    },
    ApiFunction {
        // gantry's own: the segmentation mask.
        name: "getVisionSensorMask",
        call: ApiFn::Sim(get_vision_sensor_mask),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "getVisionSensorRes",
        call: ApiFn::Sim(get_vision_sensor_res),
        cost: Cost::Long,
    },
    ApiFunction {
        // CoppeliaSim 4.1's name of getVisionSensorRes.
        name: "getVisionSensorResolution",
        call: ApiFn::Sim(get_vision_sensor_res),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "handleVisionSensor",
        call: ApiFn::Sim(handle_vision_sensor),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "readVisionSensor",
        call: ApiFn::Sim(read_vision_sensor),
        cost: Cost::Long,
    },
    ApiFunction {
        // CoppeliaSim 4.0-4.5's byte image setter.
        name: "setVisionSensorCharImage",
        call: ApiFn::Sim(set_vision_sensor_char_image),
        cost: Cost::Long,
    },
    ApiFunction {
        // V-REP 3 to CoppeliaSim 4.5's float image setter.
        name: "setVisionSensorImage",
        call: ApiFn::Sim(set_vision_sensor_image),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "setVisionSensorImg",
        call: ApiFn::Sim(set_vision_sensor_img),
        cost: Cost::Long,
    },
];

/// The `simVision.*` functions, in alphabetical order.
pub(super) const SIM_VISION_FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "blobDetectionOnWorkImg",
        call: ApiFn::Sim(blob_detection_on_work_img),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "edgeDetectionOnWorkImg",
        call: ApiFn::Sim(edge_detection_on_work_img),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "handleSpherical",
        call: ApiFn::Sim(super::vision_spherical::handle_spherical),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "horizontalFlipWorkImg",
        call: ApiFn::Sim(horizontal_flip_work_img),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "selectiveColorOnWorkImg",
        call: ApiFn::Sim(selective_color_on_work_img),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "sensorDepthMapToWorkImg",
        call: ApiFn::Sim(sensor_depth_map_to_work_img),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "sensorImgToWorkImg",
        call: ApiFn::Sim(sensor_img_to_work_img),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "sharpenWorkImg",
        call: ApiFn::Sim(sharpen_work_img),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "uniformImgToWorkImg",
        call: ApiFn::Sim(uniform_img_to_work_img),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "verticalFlipWorkImg",
        call: ApiFn::Sim(vertical_flip_work_img),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "workImgToSensorImg",
        call: ApiFn::Sim(work_img_to_sensor_img),
        cost: Cost::Long,
    },
];

/// A rectangle of an image, in pixels: columns `x..x + w`, rows `y..y + h` (row 0 at
/// the bottom).
#[derive(Debug, Clone, Copy)]
struct Portion {
    x: usize,
    y: usize,
    w: usize,
    h: usize,
}

impl Portion {
    /// Pixel indices of the portion, one range per row, bottom row first. Images are
    /// copied row by row: a remote client fetching the whole 256 x 256 image paid
    /// 0.1-0.2 ms for a loop over pixels.
    fn rows(self, image_width: usize) -> impl Iterator<Item = std::ops::Range<usize>> {
        (self.y..self.y + self.h).map(move |row| row * image_width + self.x..row * image_width + self.x + self.w)
    }

    fn size_value(self) -> Value {
        Value::Array(vec![Value::Int(self.w as i64), Value::Int(self.h as i64)])
    }
}

/// Argument `i` as `{a, b}` of non-negative integers; `{0, 0}` when absent.
fn int_pair(a: &Args<'_>, i: usize) -> Result<[usize; 2], SimError> {
    let bad = || {
        SimError::bad_argument(format!(
            "argument {}: expected a table of 2 non-negative integers",
            i + 1
        ))
    };
    match a.get(i) {
        Value::Nil => Ok([0, 0]),
        Value::Array(items) if items.len() >= 2 => {
            let get = |k: usize| items[k].as_i64().and_then(|v| usize::try_from(v).ok()).ok_or_else(bad);
            Ok([get(0)?, get(1)?])
        }
        _ => Err(bad()),
    }
}

/// The portion named by arguments `pos_i` and `pos_i + 1` of an image of `res`.
fn portion(a: &Args<'_>, pos_i: usize, res: [u32; 2]) -> Result<Portion, SimError> {
    let pos = int_pair(a, pos_i)?;
    let size = int_pair(a, pos_i + 1)?;
    let res = res.map(|v| v as usize);
    let mut out = [0usize; 2];
    for k in 0..2 {
        let extent = if size[k] == 0 {
            res[k].saturating_sub(pos[k])
        } else {
            size[k]
        };
        if pos[k] >= res[k] || extent > res[k] - pos[k] {
            return Err(SimError::bad_argument(format!(
                "arguments {} and {}: portion at {{{}, {}}} of size {{{}, {}}} exceeds the {}x{} image",
                pos_i + 1,
                pos_i + 2,
                pos[0],
                pos[1],
                size[0],
                size[1],
                res[0],
                res[1]
            )));
        }
        out[k] = extent;
    }
    Ok(Portion {
        x: pos[0],
        y: pos[1],
        w: out[0],
        h: out[1],
    })
}

/// Argument `i` as a sensor handle, `sim.handle_self` meaning the calling script's object.
pub(super) fn sensor_handle(ctx: &CallContext<'_>, a: &Args<'_>, i: usize) -> Result<Handle, SimError> {
    self_or(ctx, a.handle(i)?)
}

/// `sim.handle_self` as the calling script's object; other handles as they are.
pub(super) fn self_or(ctx: &CallContext<'_>, h: Handle) -> Result<Handle, SimError> {
    match h {
        HANDLE_SELF => ctx
            .script_object
            .ok_or_else(|| SimError::bad_argument("sim.handle_self: the caller is not a script attached to an object")),
        h => Ok(h),
    }
}

/// `sim.readVisionSensor`'s and `sim.handleVisionSensor`'s values: the trigger state
/// (0/1) then the packets, or just -1 before the sensor was handled.
fn result_values(result: Option<&VisionResult>) -> Ret {
    match result {
        Some(r) => std::iter::once(Value::Int(i64::from(r.trigger)))
            .chain(r.packets.iter().map(|p| Value::floats(p)))
            .collect(),
        None => vec![Value::Int(-1)],
    }
}

/// `sim.handleVisionSensor(h)` → `detectionCount, packet1, packet2, ...`: renders now.
/// Packet 1 holds the 15 default values (min, max, average of intensity, R, G, B,
/// depth); `detectionCount` is 0 until a `sysCall_vision` callback triggers.
/// `sim.handle_all` / `sim.handle_all_except_explicit` render every (non-explicit)
/// sensor and return only the count of triggered sensors, 0.
pub(super) fn handle_vision_sensor(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    if h == HANDLE_ALL || h == HANDLE_ALL_EXCEPT_EXPLICIT {
        vision::handle_all_vision_sensors(&sim.world, &mut sim.vision, h == HANDLE_ALL_EXCEPT_EXPLICIT)?;
        return Ok(vec![Value::Int(0)]);
    }
    vision::handle_vision_sensor(&sim.world, &mut sim.vision, h)?;
    Ok(result_values(sim.vision.image(h).and_then(SensorImage::result)))
}

/// `sim.readVisionSensor(h)` → `result, packet1, packet2, ...` of the last handling;
/// `result` is -1 (and alone) if the sensor was never handled.
pub(super) fn read_vision_sensor(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let s = vision::read(&sim.world, &mut sim.vision, h)?;
    Ok(result_values(s.result()))
}

/// `sim.getVisionSensorRes(h)` → `{width, height}` in pixels.
pub(super) fn get_vision_sensor_res(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let (m, _) = vision::sensor_model(&sim.world, h)?;
    Ok(vec![Value::Array(vec![
        Value::Int(i64::from(m.resolution[0])),
        Value::Int(i64::from(m.resolution[1])),
    ])])
}

/// `sim.getVisionSensorImg(h, options=0, rgbaCutOff=0, pos={0,0}, size={0,0})` →
/// `bytes, {width, height}`. Options bit 0: greyscale, 1 byte per pixel, the mean of
/// R, G, B; otherwise RGB. Bit 1, or a `rgbaCutOff` other than 0: one more byte per
/// pixel, alpha (RGBA, or greyscale + alpha), as `sim.setVisionSensorImg` takes it:
/// with a cut-off, 255 where the normalised depth is below `rgbaCutOff` and 0
/// elsewhere; without one, 255 (the sensor's image is opaque). Other option bits are
/// ignored.
pub(super) fn get_vision_sensor_img(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let options = a.opt_int(1, 0)?;
    let cutoff = a.opt_f64(2, 0.0)?;
    if !cutoff.is_finite() {
        return Err(SimError::bad_argument(format!(
            "argument 3: rgbaCutOff must be finite, got {cutoff}"
        )));
    }
    // Arguments are checked against the model before reading, so a bad call renders nothing.
    let (&model, _) = vision::sensor_model(&sim.world, h)?;
    let p = portion(a, 3, model.resolution)?;
    let width = model.resolution[0] as usize;
    let s = vision::read(&sim.world, &mut sim.vision, h)?;
    let (rgb, depth) = (s.rgb(), s.depth());
    let grey = options & 1 != 0;
    let alpha = options & 2 != 0 || cutoff != 0.0;
    let bpp = usize::from(if grey { 1u8 } else { 3 }) + usize::from(alpha);
    let alpha_of = |d: f32| {
        if cutoff == 0.0 || f64::from(d) < cutoff { 255 } else { 0 }
    };
    let mut out = Vec::with_capacity(p.w * p.h * bpp);
    // The portion lies within the image (checked by `portion`), and so do its rows.
    for row in p.rows(width) {
        let (Some(px), Some(d)) = (rgb.get(3 * row.start..3 * row.end), depth.get(row)) else {
            continue;
        };
        if !grey && !alpha {
            // The common case, RGB as stored: one copy per row, not three bytes at a time.
            out.extend_from_slice(px);
            continue;
        }
        for (c, &dv) in px.chunks_exact(3).zip(d) {
            if grey {
                // Integer mean, rounded, of three bytes: at most 255.
                out.push(((u16::from(c[0]) + u16::from(c[1]) + u16::from(c[2]) + 1) / 3) as u8);
            } else {
                out.extend_from_slice(c);
            }
            if alpha {
                out.push(alpha_of(dv));
            }
        }
    }
    Ok(vec![Value::Bytes(out), p.size_value()])
}

/// `sim.getVisionSensorDepth(h, options=0, pos={0,0}, size={0,0})` → `bytes, {width,
/// height}`: one little-endian `f32` per pixel, the planar depth normalised to 0..1
/// between the clipping planes (1 where nothing is seen); options bit 0: in metres
/// instead (`near + d * (far - near)`).
pub(super) fn get_vision_sensor_depth(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let options = a.opt_int(1, 0)?;
    let (&model, _) = vision::sensor_model(&sim.world, h)?;
    let p = portion(a, 2, model.resolution)?;
    let width = model.resolution[0] as usize;
    let s = vision::read(&sim.world, &mut sim.vision, h)?;
    let metres = options & 1 != 0;
    let (near, far) = (model.near as f32, model.far as f32);
    let mut out = vec![0; 4 * p.w * p.h];
    for (row, bytes) in p.rows(width).zip(out.chunks_exact_mut(4 * p.w)) {
        let Some(ds) = s.depth().get(row) else {
            continue;
        };
        // Written in place, four bytes per float, so that the loop compiles to vector
        // stores (a push per float was a third of reading a 128 x 128 map).
        for (b, &d) in bytes.chunks_exact_mut(4).zip(ds) {
            let v = if metres { near + d * (far - near) } else { d };
            b.copy_from_slice(&v.to_le_bytes());
        }
    }
    Ok(vec![Value::Bytes(out), p.size_value()])
}

/// `sim.getVisionSensorMask(h, pos={0,0}, size={0,0})` → `bytes, {width, height}`
/// (gantry's own): the segmentation mask, one little-endian `i32` per pixel, bottom
/// row first, the handle of the shape seen there or -1 where nothing is (unpack with
/// `sim.unpackInt32Table`). The mask comes from the same render as the RGB and depth
/// images; the first call renders the sensor (again) with a mask (see
/// [`vision::read_mask`]), later renders draw one each time. CoppeliaSim's way, a
/// sensor in `sim.rendermode_colorcoded`, gives the same handles as colours.
fn get_vision_sensor_mask(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let (&model, _) = vision::sensor_model(&sim.world, h)?;
    let p = portion(a, 1, model.resolution)?;
    let width = model.resolution[0] as usize;
    let s = vision::read_mask(&sim.world, &mut sim.vision, h)?;
    let mask = s.mask().unwrap_or_default();
    // 0xff bytes are -1, nothing seen: what a sensor without a mask (an image written by
    // `sim.setVisionSensorImg`) reads.
    let mut out = vec![0xff; 4 * p.w * p.h];
    for (row, bytes) in p.rows(width).zip(out.chunks_exact_mut(4 * p.w)) {
        for (b, &id) in bytes.chunks_exact_mut(4).zip(mask.get(row).unwrap_or_default()) {
            b.copy_from_slice(&id.to_le_bytes());
        }
    }
    Ok(vec![Value::Bytes(out), p.size_value()])
}

/// `sim.setVisionSensorImg(h, image, options=0, pos={0,0}, size={0,0})`: writes RGB
/// bytes (options bit 0: greyscale, 1 byte per pixel copied to R, G and B; bit 1: one
/// more byte per pixel, alpha, which the sensor's opaque image drops) into the sensor
/// image, bottom row first. The length must match the portion exactly. The
/// written image is what readers get until the sensor renders again.
pub(super) fn set_vision_sensor_img(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let data = a.bytes(1)?;
    let options = a.opt_int(2, 0)?;
    let (&model, _) = vision::sensor_model(&sim.world, h)?;
    let p = portion(a, 3, model.resolution)?;
    let colour = if options & 1 != 0 { 1 } else { 3 };
    let bpp = colour + usize::from(options & 2 != 0);
    let expected = p.w * p.h * bpp;
    if data.len() != expected {
        return Err(SimError::bad_argument(format!(
            "argument 2: expected {expected} bytes ({}x{} pixels, {bpp} per pixel), got {}",
            p.w,
            p.h,
            data.len()
        )));
    }
    let width = model.resolution[0] as usize;
    let rgb = vision::write(&sim.world, &mut sim.vision, h)?.rgb_mut();
    for (row, src) in p.rows(width).zip(data.chunks_exact(bpp * p.w)) {
        let Some(dst) = rgb.get_mut(3 * row.start..3 * row.end) else {
            continue;
        };
        for (d, px) in dst.chunks_exact_mut(3).zip(src.chunks_exact(bpp)) {
            if colour == 1 {
                d.fill(px[0]);
            } else {
                d.copy_from_slice(&px[..3]);
            }
        }
    }
    Ok(Vec::new())
}

/// `simVision.sensorImgToWorkImg(h)`: the sensor image (rendered first if stale, as
/// any reader) becomes the work image, as floats 0..1.
fn sensor_img_to_work_img(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = sensor_handle(ctx, a, 0)?;
    vision::read(&sim.world, &mut sim.vision, h)?.rgb_to_work();
    Ok(Vec::new())
}

/// `simVision.sensorDepthMapToWorkImg(h)`: the normalised depth map becomes the work
/// image, as grey levels (near = black, far = white).
fn sensor_depth_map_to_work_img(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = sensor_handle(ctx, a, 0)?;
    vision::read(&sim.world, &mut sim.vision, h)?.depth_to_work();
    Ok(Vec::new())
}

/// `simVision.uniformImgToWorkImg(h, {r, g, b})`: a work image of one colour (0..1).
fn uniform_img_to_work_img(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = sensor_handle(ctx, a, 0)?;
    let color = a.floats::<3>(1)?.map(|c| c as f32);
    vision::state(&sim.world, &mut sim.vision, h)?.uniform_work(color);
    Ok(Vec::new())
}

/// `simVision.workImgToSensorImg(h, removeBuffer=true)`: the work image, clamped to
/// 0..1, becomes the sensor image (what `sim.getVisionSensorImg` then returns); the
/// work image is dropped unless `removeBuffer` is false.
fn work_img_to_sensor_img(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = sensor_handle(ctx, a, 0)?;
    let remove = a.opt_bool(1, true)?;
    vision::work_to_sensor(&sim.world, &mut sim.vision, h, remove)?;
    Ok(Vec::new())
}

/// `simVision.edgeDetectionOnWorkImg(h, threshold)`: CoppeliaSim's edge filter (a 3x3
/// Laplacian, -3 around and 24 in the centre, per channel), then white where the mean
/// of R, G, B exceeds `threshold` and black elsewhere.
fn edge_detection_on_work_img(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = sensor_handle(ctx, a, 0)?;
    let threshold = a.finite(1)? as f32;
    vision::work(&sim.world, &mut sim.vision, h)?.edge_detection(threshold);
    Ok(Vec::new())
}

/// `simVision.sharpenWorkImg(h)`.
fn sharpen_work_img(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = sensor_handle(ctx, a, 0)?;
    vision::work(&sim.world, &mut sim.vision, h)?.sharpen();
    Ok(Vec::new())
}

/// `simVision.horizontalFlipWorkImg(h)`: mirrors the work image left to right.
fn horizontal_flip_work_img(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = sensor_handle(ctx, a, 0)?;
    vision::work(&sim.world, &mut sim.vision, h)?.flip_horizontal();
    Ok(Vec::new())
}

/// `simVision.verticalFlipWorkImg(h)`: mirrors the work image top to bottom.
fn vertical_flip_work_img(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = sensor_handle(ctx, a, 0)?;
    vision::work(&sim.world, &mut sim.vision, h)?.flip_vertical();
    Ok(Vec::new())
}

/// `simVision.selectiveColorOnWorkImg(h, color, colorTolerance, rgb, keep,
/// removedPartToBuffer1)`: with `keep`, pixels whose colour is not within
/// `colorTolerance` of `color` (per component, in RGB when `rgb` is true, else in HSL
/// with the hue wrapping around) turn black; without `keep`, those within do. With
/// `removedPartToBuffer1`, the removed pixels are copied to buffer 1 and the others are
/// black there.
fn selective_color_on_work_img(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = sensor_handle(ctx, a, 0)?;
    let color = a.floats::<3>(1)?.map(|c| c as f32);
    let tolerance = a.floats::<3>(2)?.map(|c| c as f32);
    let (rgb, keep, to_buffer1) = (a.bool(3)?, a.bool(4)?, a.bool(5)?);
    let mut work = vision::work(&sim.world, &mut sim.vision, h)?;
    if to_buffer1 {
        work.selective_color_to_buffer1(color, tolerance, rgb, keep);
    } else {
        work.selective_color(color, tolerance, rgb, keep);
    }
    Ok(Vec::new())
}

/// `simVision.blobDetectionOnWorkImg(h, threshold, minBlobSize, modifyWorkImage,
/// overlayColor)` → `trigger, packedPacket`: finds the 8-connected blobs of pixels whose
/// mean of R, G, B is at least `threshold`. Blobs smaller than `minBlobSize` (a
/// fraction of the image's pixels) are left out and blacked out in the work image.
/// `modifyWorkImage` paints the background black and each blob in its own colour;
/// a given `overlayColor` ({r, g, b}) draws each blob's rectangle. `trigger` is always
/// false. The packet is packed floats: blob count, 6, then per blob its size (fraction
/// of the pixels), orientation (radians), centre x and y, width and height (fractions
/// of the image's width and height; y from the bottom).
fn blob_detection_on_work_img(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = sensor_handle(ctx, a, 0)?;
    let threshold = a.finite(1)? as f32;
    let min_size = a.finite(2)?;
    let recolor = a.bool(3)?;
    let overlay = match a.get(4) {
        Value::Nil => None,
        _ => Some(a.floats::<3>(4)?.map(|c| c as f32)),
    };
    let packet = vision::work(&sim.world, &mut sim.vision, h)?.blob_detection(threshold, min_size, recolor, overlay);
    let bytes = packet.iter().flat_map(|v| v.to_le_bytes()).collect();
    Ok(vec![Value::Bool(false), Value::Bytes(bytes)])
}

/// `sim.handleflag_greyscale`, or-ed into the sensor handle of the 4.x image getters.
const HANDLEFLAG_GREYSCALE: Handle = 0x0040_0000;

/// The 4.x getters' `(handle [| handleflag_greyscale], posX, posY, sizeX, sizeY)` as
/// `getVisionSensorImg`'s arguments `(handle, options, rgbaCutOff, pos, size)`, and the
/// plain sensor handle.
fn legacy_img_args(a: &Args<'_>, cutoff: f64) -> Result<(Handle, Vec<Value>), SimError> {
    let raw = a.handle(0)?;
    let grey = raw >= 0 && raw & HANDLEFLAG_GREYSCALE != 0;
    let h = if grey { raw & !HANDLEFLAG_GREYSCALE } else { raw };
    let mut xy = [0i64; 4];
    for (k, v) in xy.iter_mut().enumerate() {
        *v = a.opt_int(k + 1, 0)?;
        if *v < 0 {
            return Err(SimError::bad_argument(format!(
                "argument {}: expected a non-negative integer, got {v}",
                k + 2
            )));
        }
    }
    let pair = |x: i64, y: i64| Value::Array(vec![Value::Int(x), Value::Int(y)]);
    let args = vec![
        Value::Int(h),
        Value::Int(i64::from(grey)),
        Value::Float(cutoff),
        pair(xy[0], xy[1]),
        pair(xy[2], xy[3]),
    ];
    Ok((h, args))
}

/// The bytes of a `getVisionSensorImg` reply.
fn reply_bytes(mut reply: Ret) -> Vec<u8> {
    match reply.drain(..).next() {
        Some(Value::Bytes(b)) => b,
        _ => Vec::new(),
    }
}

/// `sim.getVisionSensorCharImage(h, posX=0, posY=0, sizeX=0, sizeY=0, rgbaCutOff=0)` →
/// `bytes, resX, resY` (CoppeliaSim 4.0-4.5): `getVisionSensorImg` with the portion as
/// four integers. `h | sim.handleflag_greyscale` gives 1 byte per pixel; a non-zero
/// `rgbaCutOff` gives RGBA. `resX, resY` are the sensor's full resolution, not the
/// portion's, as CoppeliaSim returns them.
fn get_vision_sensor_char_image(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let cutoff = a.opt_f64(5, 0.0)?;
    let (h, args) = legacy_img_args(a, cutoff)?;
    let bytes = reply_bytes(get_vision_sensor_img(sim, ctx, &Args::new(&args))?);
    let (m, _) = vision::sensor_model(&sim.world, h)?;
    Ok(vec![
        Value::Bytes(bytes),
        Value::Int(i64::from(m.resolution[0])),
        Value::Int(i64::from(m.resolution[1])),
    ])
}

/// `sim.setVisionSensorCharImage(h, image)` → 1 (CoppeliaSim 4.0-4.5): writes a whole
/// image of RGB bytes, or of 1 byte per pixel with `h | sim.handleflag_greyscale`, as
/// `setVisionSensorImg` does (bottom row first; the length must match the resolution).
/// The pairing of `getVisionSensorCharImage` on one sensor with this on another copies
/// an image between sensors, as CoppeliaSim's synchronous image transmission example
/// does.
fn set_vision_sensor_char_image(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let raw = a.handle(0)?;
    let grey = raw >= 0 && raw & HANDLEFLAG_GREYSCALE != 0;
    let h = if grey { raw & !HANDLEFLAG_GREYSCALE } else { raw };
    let args = [
        Value::Int(h),
        Value::Bytes(a.bytes(1)?.to_vec()),
        Value::Int(i64::from(grey)),
    ];
    set_vision_sensor_img(sim, ctx, &Args::new(&args))?;
    Ok(vec![Value::Int(1)])
}

/// `sim.setVisionSensorImage(h [| sim.handleflag_greyscale], image)` → 1: the image as
/// floats 0..1 (a table, or packed single floats as a string), RGB per pixel or one
/// grey value per pixel with the flag, bottom row first: [`set_vision_sensor_img`] with
/// each value scaled to 0..255.
fn set_vision_sensor_image(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let raw = a.handle(0)?;
    let grey = raw >= 0 && raw & HANDLEFLAG_GREYSCALE != 0;
    let h = if grey { raw & !HANDLEFLAG_GREYSCALE } else { raw };
    let to_byte = |v: f64| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
    let bytes: Vec<u8> = match a.get(1) {
        Value::Array(items) => items
            .iter()
            .enumerate()
            .map(|(k, v)| match v.as_f64() {
                Some(f) if f.is_finite() => Ok(to_byte(f)),
                _ => Err(SimError::bad_argument(format!(
                    "argument 2: element {} must be a finite number",
                    k + 1
                ))),
            })
            .collect::<Result<_, _>>()?,
        Value::Str(_) | Value::Bytes(_) => {
            let packed = a.bytes(1)?;
            if packed.len() % 4 != 0 {
                return Err(SimError::bad_argument(format!(
                    "argument 2: packed floats need a multiple of 4 bytes, got {}",
                    packed.len()
                )));
            }
            packed
                .chunks_exact(4)
                .map(|c| to_byte(f64::from(f32::from_le_bytes([c[0], c[1], c[2], c[3]]))))
                .collect()
        }
        other => {
            return Err(SimError::bad_argument(format!(
                "argument 2: expected a table of numbers or packed floats, got {}",
                other.type_name()
            )));
        }
    };
    let args = [Value::Int(h), Value::Bytes(bytes), Value::Int(i64::from(grey))];
    set_vision_sensor_img(sim, ctx, &Args::new(&args))?;
    Ok(vec![Value::Int(1)])
}

/// `sim.handleflag_depthbuffermeters`, or-ed into the sensor handle of
/// `sim.getVisionSensorDepthBuffer`.
const HANDLEFLAG_DEPTH_METRES: Handle = 0x0080_0000;

/// `sim.getVisionSensorDepthBuffer(h [| handleflag_depthbuffermeters], posX=0, posY=0,
/// sizeX=0, sizeY=0)` → a table of depths (V-REP 3 to CoppeliaSim 4.5), bottom row
/// first: from 0 at the near plane to 1 at the far one, or in metres with the flag.
/// `sim.getVisionSensorDepth` with the portion as four integers, unpacked.
fn get_vision_sensor_depth_buffer(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let raw = a.handle(0)?;
    let metres = raw >= 0 && raw & HANDLEFLAG_DEPTH_METRES != 0;
    let h = if metres { raw & !HANDLEFLAG_DEPTH_METRES } else { raw };
    let mut xy = [0i64; 4];
    for (k, v) in xy.iter_mut().enumerate() {
        *v = a.opt_int(k + 1, 0)?;
    }
    let pair = |x: i64, y: i64| Value::Array(vec![Value::Int(x), Value::Int(y)]);
    let args = [
        Value::Int(h),
        Value::Int(i64::from(metres)),
        pair(xy[0], xy[1]),
        pair(xy[2], xy[3]),
    ];
    let bytes = reply_bytes(get_vision_sensor_depth(sim, ctx, &Args::new(&args))?);
    let depths = bytes
        .chunks_exact(4)
        .map(|c| Value::Float(f64::from(f32::from_le_bytes([c[0], c[1], c[2], c[3]]))))
        .collect();
    Ok(vec![Value::Array(depths)])
}

/// `sim.getVisionSensorImage(h, posX=0, posY=0, sizeX=0, sizeY=0, returnType=0)` → the
/// image as numbers 0..1 (CoppeliaSim 4.0-4.5): R, G, B per pixel (one value with
/// `h | sim.handleflag_greyscale`), bottom row first. `returnType` 1 packs them as
/// little-endian `f32` bytes instead of a table. Values are the byte image divided by
/// 255, so they take the 256 levels of `getVisionSensorImg`.
fn get_vision_sensor_image(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let packed = match a.opt_int(5, 0)? {
        0 => false,
        1 => true,
        other => {
            return Err(SimError::bad_argument(format!(
                "argument 6: returnType must be 0 (table) or 1 (packed floats), got {other}"
            )));
        }
    };
    let (_, args) = legacy_img_args(a, 0.0)?;
    let bytes = reply_bytes(get_vision_sensor_img(sim, ctx, &Args::new(&args))?);
    let values = bytes.iter().map(|&b| f32::from(b) / 255.0);
    Ok(vec![if packed {
        Value::Bytes(values.flat_map(f32::to_le_bytes).collect())
    } else {
        Value::Array(values.map(|v| Value::Float(f64::from(v))).collect())
    }])
}
