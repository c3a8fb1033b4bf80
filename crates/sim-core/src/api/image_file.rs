//! `sim.saveImage` and `sim.loadImage`: images as PNG (and, read, JPEG) files or buffers, confined like
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
pub(super) const MAX_SIDE: u32 = 16_384;

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

/// `sim.loadImage(options, filename)` → `image, resolution`: a PNG or JPEG file's
/// pixels, 3 bytes each (RGB), or 4 (RGBA) with option bit 0; grey and palette images
/// are expanded, 16-bit channels reduced to 8.
fn load_image(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let options = a.int(0)?;
    let filename = a.str(1)?;
    let path = confined(sim, filename, "read")?;
    let ([w, h], rgba) = read_image(&path, MAX_SIDE)?;
    let pixels = if options & RGBA != 0 {
        rgba
    } else {
        rgba.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect()
    };
    Ok(vec![
        Value::Bytes(pixels),
        Value::Array(vec![Value::Int(i64::from(w)), Value::Int(i64::from(h))]),
    ])
}

/// A PNG or JPEG file (told apart by their first bytes) as RGBA pixels, rows from the
/// top, and its resolution; images over `max_side` pixels a side are refused before
/// their pixels are decoded.
///
/// # Errors
/// A file that cannot be read, is neither PNG nor JPEG, is broken, or is too large.
pub(super) fn read_image(path: &Path, max_side: u32) -> Result<([u32; 2], Vec<u8>), SimError> {
    let bytes = std::fs::read(path).map_err(|e| SimError::refused(format!("cannot read '{}': {e}", path.display())))?;
    let bad = |e: &dyn std::fmt::Display| {
        SimError::bad_argument(format!(
            "'{}' is not a PNG or JPEG image gantry can read: {e}",
            path.display()
        ))
    };
    let too_big = |w: u32, h: u32| {
        if w > max_side || h > max_side || w == 0 || h == 0 {
            Err(bad(&format!("{w} x {h} pixels; gantry takes 1 to {max_side} a side")))
        } else {
            Ok(())
        }
    };
    if bytes.starts_with(&[0xFF, 0xD8]) {
        let mut decoder = jpeg_decoder::Decoder::new(bytes.as_slice());
        decoder.read_info().map_err(|e| bad(&e))?;
        let info = decoder.info().ok_or_else(|| bad(&"no image header"))?;
        let (w, h) = (u32::from(info.width), u32::from(info.height));
        too_big(w, h)?;
        let pixels = decoder.decode().map_err(|e| bad(&e))?;
        let rgba: Vec<u8> = match info.pixel_format {
            jpeg_decoder::PixelFormat::RGB24 => pixels.chunks_exact(3).flat_map(|p| [p[0], p[1], p[2], 255]).collect(),
            jpeg_decoder::PixelFormat::L8 => pixels.iter().flat_map(|&g| [g, g, g, 255]).collect(),
            // Big-endian 16-bit grey: its high byte.
            jpeg_decoder::PixelFormat::L16 => pixels.chunks_exact(2).flat_map(|p| [p[0], p[0], p[0], 255]).collect(),
            jpeg_decoder::PixelFormat::CMYK32 => pixels
                .chunks_exact(4)
                .flat_map(|p| {
                    let k = u16::from(255 - p[3]);
                    let c = |x: u8| ((u16::from(255 - x) * k) / 255) as u8;
                    [c(p[0]), c(p[1]), c(p[2]), 255]
                })
                .collect(),
        };
        if rgba.len() != w as usize * h as usize * 4 {
            return Err(bad(&"the decoded pixels do not fill the image"));
        }
        return Ok(([w, h], rgba));
    }
    let mut decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder.read_info().map_err(|e| bad(&e))?;
    let (w, h) = (reader.info().width, reader.info().height);
    too_big(w, h)?;
    let mut buf = vec![0; reader.output_buffer_size()];
    let frame = reader.next_frame(&mut buf).map_err(|e| bad(&e))?;
    buf.truncate(frame.buffer_size());
    let rgba: Vec<u8> = match frame.color_type {
        png::ColorType::Rgba => buf,
        png::ColorType::Rgb => buf.chunks_exact(3).flat_map(|p| [p[0], p[1], p[2], 255]).collect(),
        png::ColorType::Grayscale => buf.iter().flat_map(|&g| [g, g, g, 255]).collect(),
        png::ColorType::GrayscaleAlpha => buf.chunks_exact(2).flat_map(|p| [p[0], p[0], p[0], p[1]]).collect(),
        png::ColorType::Indexed => return Err(bad(&"an indexed image that did not expand")),
    };
    Ok(([w, h], rgba))
}

/// `filename` resolved in the scene's folder, where the API may read and write files.
pub(super) fn confined(sim: &Sim, filename: &str, verb: &str) -> Result<std::path::PathBuf, SimError> {
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
