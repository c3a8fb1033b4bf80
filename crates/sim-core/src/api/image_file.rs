//! `sim.saveImage` and `sim.loadImage`: images as PNG files or buffers, confined like
//! every file the API writes to the scene's folder ([`crate::graph::ExportScope`]).
//!
//! Rows go in buffer order: the first row of the buffer is the top of the file. A
//! vision sensor's image starts with its bottom row, so it comes out upside down, as it
//! does in CoppeliaSim; flip it first with `sim.transformImage(img, res, 4)`.

use std::path::Path;

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::sim::Sim;

/// The image file functions.
pub const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "loadImage",
        call: ApiFn::Sim(load_image),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "saveImage",
        call: ApiFn::Sim(save_image),
        cost: Cost::Quick,
    },
];

/// `options` bit of both functions: 4 bytes a pixel (RGBA) instead of 3 (RGB).
const RGBA: i64 = 1;
/// `options` bit of `sim.saveImage`: 1 byte a pixel (grey).
const GREY: i64 = 2;
/// The largest image either function handles, pixels a side (a 16 k x 16 k RGBA image
/// is 1 GiB: beyond what a script should hold in one string).
const MAX_SIDE: u32 = 16_384;

/// `sim.saveImage(image, resolution, options, filename, quality)`: writes the image
/// (3 bytes a pixel, 4 with option bit 0, 1 with bit 1) as a PNG file, or, when
/// `filename` is only an extension (`'.png'`), returns the encoded file as a buffer.
/// PNG is lossless: `quality` is accepted and ignored. gantry encodes PNG only; other
/// extensions (`.jpg`, `.bmp`) are refused with that advice.
fn save_image(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let image = a.bytes(0)?;
    let [w, h] = resolution(a, 1)?;
    let options = a.int(2)?;
    let filename = a.str(3)?;
    a.opt_int(4, -1)?;
    let (bpp, colour) = match (options & RGBA != 0, options & GREY != 0) {
        (false, false) => (3, png::ColorType::Rgb),
        (true, false) => (4, png::ColorType::Rgba),
        (false, true) => (1, png::ColorType::Grayscale),
        (true, true) => (2, png::ColorType::GrayscaleAlpha),
    };
    let expected = w as usize * h as usize * bpp;
    if image.len() != expected {
        return Err(SimError::bad_argument(format!(
            "argument 1: a {w} x {h} image of {bpp} bytes a pixel has {expected} bytes, got {}",
            image.len()
        )));
    }
    let extension = Path::new(filename)
        .extension()
        .or_else(|| filename.strip_prefix('.').map(std::ffi::OsStr::new))
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    if extension.as_deref() != Some("png") {
        return Err(SimError::bad_argument(format!(
            "argument 4: gantry writes PNG images only (lossless); name the file '.png', not '{filename}'"
        )));
    }
    let mut encoded = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut encoded, w, h);
        encoder.set_color(colour);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder
            .write_header()
            .map_err(|e| SimError::refused(format!("cannot encode the image: {e}")))?;
        writer
            .write_image_data(&image)
            .map_err(|e| SimError::refused(format!("cannot encode the image: {e}")))?;
    }
    if filename.starts_with('.') && Path::new(filename).file_stem().is_none_or(|s| s == filename) {
        return Ok(vec![Value::Bytes(encoded)]);
    }
    let path = confined(sim, filename, "write")?;
    std::fs::write(&path, &encoded)
        .map_err(|e| SimError::refused(format!("cannot write '{}': {e}", path.display())))?;
    Ok(vec![Value::Nil])
}

/// `sim.loadImage(options, filename)` → `image, resolution`: a PNG file's pixels, 3
/// bytes each (RGB), or 4 (RGBA) with option bit 0; grey and palette images are
/// expanded, 16-bit channels reduced to 8.
fn load_image(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let options = a.int(0)?;
    let filename = a.str(1)?;
    let path = confined(sim, filename, "read")?;
    let file =
        std::fs::File::open(&path).map_err(|e| SimError::refused(format!("cannot read '{}': {e}", path.display())))?;
    let bad = |e: &dyn std::fmt::Display| {
        SimError::bad_argument(format!("'{}' is not a PNG image gantry can read: {e}", path.display()))
    };
    let mut decoder = png::Decoder::new(std::io::BufReader::new(file));
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder.read_info().map_err(|e| bad(&e))?;
    let (w, h) = (reader.info().width, reader.info().height);
    if w > MAX_SIDE || h > MAX_SIDE {
        return Err(bad(&format!("{w} x {h} pixels, over gantry's {MAX_SIDE} a side")));
    }
    let mut buf = vec![0; reader.output_buffer_size()];
    let frame = reader.next_frame(&mut buf).map_err(|e| bad(&e))?;
    buf.truncate(frame.buffer_size());
    let want_alpha = options & RGBA != 0;
    let pixels: Vec<u8> = match frame.color_type {
        png::ColorType::Rgb if !want_alpha => buf,
        png::ColorType::Rgba if want_alpha => buf,
        png::ColorType::Rgb => buf.chunks_exact(3).flat_map(|p| [p[0], p[1], p[2], 255]).collect(),
        png::ColorType::Rgba => buf.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect(),
        png::ColorType::Grayscale => buf
            .iter()
            .flat_map(|&g| if want_alpha { vec![g, g, g, 255] } else { vec![g, g, g] })
            .collect(),
        png::ColorType::GrayscaleAlpha => buf
            .chunks_exact(2)
            .flat_map(|p| {
                if want_alpha {
                    vec![p[0], p[0], p[0], p[1]]
                } else {
                    vec![p[0], p[0], p[0]]
                }
            })
            .collect(),
        png::ColorType::Indexed => return Err(bad(&"an indexed image that did not expand")),
    };
    Ok(vec![
        Value::Bytes(pixels),
        Value::Array(vec![Value::Int(i64::from(w)), Value::Int(i64::from(h))]),
    ])
}

/// `filename` resolved in the scene's folder, where the API may read and write files.
fn confined(sim: &Sim, filename: &str, verb: &str) -> Result<std::path::PathBuf, SimError> {
    let path = Path::new(filename);
    let dir = path.parent().unwrap_or(Path::new(""));
    let name = path
        .file_name()
        .ok_or_else(|| SimError::bad_argument(format!("'{filename}' names no file")))?;
    let dir = sim
        .graphs
        .export_scope()
        .resolve(dir)
        .map_err(|e| SimError::refused(format!("cannot {verb} '{filename}': {e}")))?;
    Ok(dir.join(name))
}

/// Argument `i`, `{width, height}`: positive integers up to [`MAX_SIDE`].
fn resolution(a: &Args<'_>, i: usize) -> Result<[u32; 2], SimError> {
    let bad = || {
        SimError::bad_argument(format!(
            "argument {}: expected {{width, height}}, two integers from 1 to {MAX_SIDE}",
            i + 1
        ))
    };
    let Value::Array(items) = a.get(i) else {
        return Err(bad());
    };
    let dim = |v: Option<&Value>| {
        v.and_then(Value::as_i64)
            .and_then(|n| u32::try_from(n).ok())
            .filter(|n| (1..=MAX_SIDE).contains(n))
            .ok_or_else(bad)
    };
    Ok([dim(items.first())?, dim(items.get(1))?])
}
