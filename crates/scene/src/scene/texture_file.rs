//! Texture files beside a TOML scene: the image as PNG (RGBA, rows from the top) and
//! fixed texture coordinates as text, one `u v` line per triangle corner. `gantry
//! convert` writes them ([`super::write_scene`]) and the loader reads them back, to the
//! bit: f32 values are written as the shortest decimal that reads back the same.

/// The largest texture side read from a file, pixels (CoppeliaSim's own limit).
pub const MAX_TEXTURE_SIDE: u32 = 4096;
/// Most coordinates (numbers) in one file: 6 per triangle of a mesh of 16 M triangles.
pub const MAX_COORDINATES: usize = 96 << 20;

/// Encodes an RGBA image as PNG.
///
/// # Errors
/// A buffer that is not 4 bytes a pixel.
pub fn encode_png([w, h]: [u32; 2], rgba: &[u8]) -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, w, h);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
    writer.write_image_data(rgba).map_err(|e| e.to_string())?;
    writer.finish().map_err(|e| e.to_string())?;
    Ok(out)
}

/// Decodes a PNG image to RGBA (grey and palette images expanded, 16-bit channels
/// reduced to 8).
///
/// # Errors
/// Not a PNG, corrupt, or a side of 0 or over [`MAX_TEXTURE_SIDE`] (refused before the
/// pixels are decoded).
pub fn decode_png(bytes: &[u8]) -> Result<([u32; 2], Vec<u8>), String> {
    let mut decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder.read_info().map_err(|e| format!("not a readable PNG: {e}"))?;
    let (w, h) = (reader.info().width, reader.info().height);
    if w == 0 || h == 0 || w > MAX_TEXTURE_SIDE || h > MAX_TEXTURE_SIDE {
        return Err(format!(
            "a {w} x {h} image: a texture's sides must be 1 to {MAX_TEXTURE_SIDE} pixels"
        ));
    }
    let mut buf = vec![0; reader.output_buffer_size()];
    let frame = reader
        .next_frame(&mut buf)
        .map_err(|e| format!("not a readable PNG: {e}"))?;
    buf.truncate(frame.buffer_size());
    let rgba = match frame.color_type {
        png::ColorType::Rgba => buf,
        png::ColorType::Rgb => buf.chunks_exact(3).flat_map(|p| [p[0], p[1], p[2], 255]).collect(),
        png::ColorType::Grayscale => buf.iter().flat_map(|&g| [g, g, g, 255]).collect(),
        png::ColorType::GrayscaleAlpha => buf.chunks_exact(2).flat_map(|p| [p[0], p[0], p[0], p[1]]).collect(),
        png::ColorType::Indexed => return Err("an indexed PNG that did not expand".into()),
    };
    Ok(([w, h], rgba))
}

/// Coordinates as text: one `u v` line per corner.
pub fn write_coordinates(coordinates: &[f32]) -> String {
    let mut out = String::with_capacity(coordinates.len() * 10);
    for uv in coordinates.chunks(2) {
        let line: Vec<String> = uv.iter().map(f32::to_string).collect();
        out.push_str(&line.join(" "));
        out.push('\n');
    }
    out
}

/// Reads [`write_coordinates`]'s text back.
///
/// # Errors
/// A line that is not two finite numbers, or more than [`MAX_COORDINATES`] numbers.
pub fn read_coordinates(text: &str) -> Result<Vec<f32>, String> {
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let values: Vec<f32> = line
            .split_whitespace()
            .map(|v| v.parse::<f32>().ok().filter(|v| v.is_finite()))
            .collect::<Option<_>>()
            .filter(|v: &Vec<f32>| v.len() == 2)
            .ok_or_else(|| format!("line {}: expected two finite numbers `u v`, got '{line}'", n + 1))?;
        if out.len() + 2 > MAX_COORDINATES {
            return Err(format!("more than {MAX_COORDINATES} coordinates"));
        }
        out.extend(values);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_and_coordinates_round_trip() {
        let rgba: Vec<u8> = (0..3 * 2 * 4).map(|i| (i * 37 % 256) as u8).collect();
        let png = encode_png([3, 2], &rgba).unwrap();
        assert_eq!(decode_png(&png).unwrap(), ([3, 2], rgba));
        assert!(decode_png(b"not a png").is_err());
        assert!(encode_png([3, 2], &[0; 5]).is_err());

        let coords = [0.1f32, 0.515_72, 1.0 / 3.0, -2.5e-8, 7.0, 0.0];
        assert_eq!(read_coordinates(&write_coordinates(&coords)).unwrap(), coords);
        assert!(read_coordinates("0.5\n").is_err());
        assert!(read_coordinates("0.5 NaN\n").is_err());
        assert!(read_coordinates("0.5 x\n").is_err());
    }
}
