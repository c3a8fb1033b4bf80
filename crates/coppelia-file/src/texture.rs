//! Textures: the top-level texture objects (`TEX`) and the texture property a mesh leaf
//! wears (`Toj`, in the mesh part of a `Gst`/`Geo` node).
//!
//! A `TEX` stream holds `Ipa` (i32 id, i32 width, i32 height), `Gon` (name), `Bst` (u8,
//! bit 0: the image has an alpha byte) and `Img` (the pixels, 3 or 4 bytes each, rows
//! as CoppeliaSim keeps them: the first row is the bottom of the picture, where the v
//! texture coordinate is 0). Ids count up from 2 180 000 [seen: 2180009 and 2180010 in
//! PyRep's `test_scene.ttt`].
//!
//! A `Toj` stream holds `Bst` (u8: bit 0 interpolate, bit 1 decal, bit 2 repeat along u,
//! bit 3 along v), `Bs2` (the same without the decal bit, which moved to `Apm`), `Tob`
//! or `_ob` (i32 texture id, i32 mapping mode, then the u and v scaling as f32 or f64),
//! `Trc` or `_rc` (the texture frame in the mesh frame: quaternion w, x, y, z, then
//! position, f32 or f64), `Ftc` (fixed texture coordinates: f32 u, v per triangle corner,
//! empty when the mapping projects them) and `Apm` (i32 apply mode: 0 modulate, 1 decal,
//! 2 add). A `Tob` id below 2 000 000 names a vision sensor (its image is the texture),
//! not a texture object. [Tags and layouts verified on the 147 `TEX` objects and 400-odd
//! `Toj` streams of the public files; every `Ftc` there holds 6 numbers per triangle.]

use std::sync::Arc;

use crate::chunk::{At, Chunk, Chunks};
use crate::error::ReadError;
use crate::field::{Fields, is_double};
use crate::pose::Pose;

/// The largest texture side, pixels (CoppeliaSim refuses larger images too).
pub const MAX_TEXTURE_SIDE: u32 = 4096;
/// Most texture objects in one file.
pub const MAX_TEXTURES: usize = 1 << 12;

/// One texture object.
#[derive(Debug, Clone, PartialEq)]
pub struct Texture {
    /// Its id, which shapes' [`TextureProperty::texture`] name.
    pub id: i32,
    /// Its name (`Gon`), e.g. `importedTexture`.
    pub name: String,
    /// Width and height, pixels.
    pub resolution: [u32; 2],
    /// 4 bytes a pixel (alpha 255 where the file has none), rows bottom first, as stored.
    pub rgba: Vec<u8>,
}

/// How a texture is laid on a mesh (CoppeliaSim's `sim.texturemap_*`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TextureMapping {
    /// Projected along the texture frame's z axis (0).
    Plane,
    /// Wrapped around its z axis (1).
    Cylinder,
    /// Wrapped around its origin (2).
    Sphere,
    /// Each triangle projected along the axis nearest its normal (3).
    Cube,
    /// A value this reader does not know.
    Other(i32),
}

impl TextureMapping {
    fn from_code(code: i32) -> Self {
        match code {
            0 => TextureMapping::Plane,
            1 => TextureMapping::Cylinder,
            2 => TextureMapping::Sphere,
            3 => TextureMapping::Cube,
            other => TextureMapping::Other(other),
        }
    }
}

/// The texture a mesh leaf wears.
#[derive(Debug, Clone, PartialEq)]
pub struct TextureProperty {
    /// The texture object's id ([`Texture::id`]), or a vision sensor's handle (see
    /// [`TextureProperty::from_vision_sensor`]).
    pub texture: i32,
    /// How coordinates are projected when [`TextureProperty::coordinates`] is `None`.
    pub mapping: TextureMapping,
    /// The texture's size on the mesh along u and v, m, for the projections.
    pub scaling: [f64; 2],
    /// The texture frame in the leaf's vertex frame.
    pub frame: Pose,
    /// Fixed coordinates: u, v per triangle corner, in the order of the leaf's indices
    /// (6 per triangle); checked to fit the mesh.
    pub coordinates: Option<Arc<[f32]>>,
    /// Colours are interpolated between texels.
    pub interpolate: bool,
    /// 0 modulate (texture times colour), 1 decal, 2 add.
    pub apply_mode: i32,
    /// Repeats along u.
    pub repeat_u: bool,
    /// Repeats along v.
    pub repeat_v: bool,
}

impl TextureProperty {
    /// Whether the texture is a vision sensor's image rather than a texture object
    /// (CoppeliaSim numbers texture objects from 2 000 000 up, scene objects below).
    pub fn from_vision_sensor(&self) -> bool {
        self.texture < 2_000_000
    }
}

/// Reads a `TEX` chunk.
///
/// # Errors
/// A malformed stream, a missing `Ipa`, a side of 0 or above [`MAX_TEXTURE_SIDE`], or an
/// `Img` whose length is not width x height x 3 (or 4 with the alpha bit).
pub fn read_texture(c: &Chunk, top: &At) -> Result<Texture, ReadError> {
    let at = top.child(c.tag, c.offset);
    let (chunks, _) = Chunks::new(c.payload, &at).part(false)?;
    let mut ipa = None;
    let mut name = String::new();
    let mut alpha = false;
    let mut img: Option<&Chunk> = None;
    for c in &chunks {
        let mut f = Fields::new(c, &at);
        match &c.tag {
            b"Ipa" => ipa = Some((f.i32()?, f.i32()?, f.i32()?)),
            b"Gon" => name = f.string()?,
            b"Bst" => alpha = f.u8()? & 0x01 != 0,
            b"Img" => img = Some(c),
            _ => {}
        }
    }
    let Some((id, w, h)) = ipa else {
        return Err(at.value_error("texture has no Ipa (id and size)"));
    };
    let side = |v: i32| {
        u32::try_from(v)
            .ok()
            .filter(|s| (1..=MAX_TEXTURE_SIDE).contains(s))
            .ok_or_else(|| {
                at.value_error(format!(
                    "texture {id} is {w} x {h} pixels: each side must be 1 to {MAX_TEXTURE_SIDE}"
                ))
            })
    };
    let resolution = [side(w)?, side(h)?];
    let pixels = resolution[0] as usize * resolution[1] as usize;
    let bpp = if alpha { 4 } else { 3 };
    let Some(img) = img else {
        return Err(at.value_error(format!("texture {id} has no Img")));
    };
    if img.payload.len() != pixels * bpp {
        return Err(at.child(img.tag, img.offset).value_error(format!(
            "a {w} x {h} image of {bpp} bytes a pixel has {} bytes, got {}",
            pixels * bpp,
            img.payload.len()
        )));
    }
    let rgba = if alpha {
        img.payload.to_vec()
    } else {
        let mut out = Vec::with_capacity(pixels * 4);
        for p in img.payload.chunks_exact(3) {
            out.extend_from_slice(&[p[0], p[1], p[2], 255]);
        }
        out
    };
    Ok(Texture {
        id,
        name,
        resolution,
        rgba,
    })
}

/// Reads a `Toj` chunk of a mesh with `corners` triangle corners (indices). Fixed
/// coordinates that do not fit the mesh are dropped, as CoppeliaSim drops the texture
/// then; the projection stays.
///
/// # Errors
/// A malformed stream or a field shorter than its layout.
pub fn read_property(c: &Chunk, parent: &At, corners: usize) -> Result<Option<TextureProperty>, ReadError> {
    let at = parent.child(c.tag, c.offset);
    at.check_depth()?;
    let (chunks, _) = Chunks::new(c.payload, &at).part(false)?;
    let mut out = TextureProperty {
        texture: -1,
        mapping: TextureMapping::Plane,
        scaling: [1.0, 1.0],
        frame: Pose::IDENTITY,
        coordinates: None,
        interpolate: false,
        apply_mode: 0,
        repeat_u: false,
        repeat_v: false,
    };
    let mut has_id = false;
    let mut decal = false;
    let mut has_apply_mode = false;
    for c in &chunks {
        let mut f = Fields::new(c, &at);
        match &c.tag {
            b"Bst" | b"Bs2" => {
                let bits = f.u8()?;
                out.interpolate = bits & 0x01 != 0;
                out.repeat_u = bits & 0x04 != 0;
                out.repeat_v = bits & 0x08 != 0;
                if &c.tag == b"Bst" {
                    decal = bits & 0x02 != 0;
                }
            }
            b"Tob" | b"_ob" => {
                out.texture = f.i32()?;
                out.mapping = TextureMapping::from_code(f.i32()?);
                out.scaling = f.reals::<2>(is_double(c.tag))?;
                has_id = true;
            }
            b"Trc" | b"_rc" => {
                let v = f.reals::<7>(is_double(c.tag))?;
                out.frame = Pose {
                    position: [v[4], v[5], v[6]],
                    rotation: [v[0], v[1], v[2], v[3]],
                };
            }
            // Coordinates that do not fit the mesh (or none) leave the projection.
            b"Ftc" if !c.payload.is_empty() && c.payload.len() == corners * 8 => {
                let coords: Vec<f32> = c
                    .payload
                    .chunks_exact(4)
                    .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                    .collect();
                out.coordinates = Some(coords.into());
            }
            b"Apm" => {
                out.apply_mode = f.i32()?;
                has_apply_mode = true;
            }
            _ => {}
        }
    }
    if !has_apply_mode && decal {
        out.apply_mode = 1;
    }
    Ok(has_id.then_some(out))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::{Payload, Stream};

    fn chunk<'a>(tag: &[u8; 3], payload: &'a [u8]) -> Chunk<'a> {
        Chunk {
            tag: *tag,
            payload,
            offset: 0,
        }
    }

    #[test]
    fn reads_rgb_and_rgba_textures_and_refuses_bad_sizes() {
        let top = At::top();
        let tex = |w: i32, h: i32, bst: u8, img: &[u8]| {
            Stream::new()
                .chunk("Ipa", &Payload::new().i32(2_180_001).i32(w).i32(h).done())
                .chunk("Gon", &Payload::new().str("wood").done())
                .chunk("Bst", &[bst])
                .chunk("Img", img)
                .marker("EOO")
                .bytes()
        };
        let rgb = tex(2, 1, 0, &[1, 2, 3, 4, 5, 6]);
        let t = read_texture(&chunk(b"TEX", &rgb), &top).unwrap();
        assert_eq!((t.id, t.name.as_str(), t.resolution), (2_180_001, "wood", [2, 1]));
        assert_eq!(t.rgba, [1, 2, 3, 255, 4, 5, 6, 255]);
        let rgba = tex(1, 1, 1, &[9, 8, 7, 6]);
        assert_eq!(read_texture(&chunk(b"TEX", &rgba), &top).unwrap().rgba, [9, 8, 7, 6]);
        // Wrong byte count, zero and absurd sides (refused before any allocation).
        for bad in [
            tex(2, 2, 0, &[0; 6]),
            tex(0, 1, 0, &[]),
            tex(100_000, 100_000, 1, &[0; 4]),
        ] {
            let err = read_texture(&chunk(b"TEX", &bad), &top).unwrap_err();
            assert!(err.to_string().contains("TEX"), "{err}");
        }
    }

    #[test]
    fn reads_a_texture_property_in_both_precisions() {
        let top = At::top();
        let coords: Vec<f32> = (0..6).map(|i| i as f32 / 8.0).collect();
        let single = Stream::new()
            .chunk("Bst", &[0x0f])
            .chunk("Bs2", &[0x0d])
            .chunk("Tob", &Payload::new().i32(2_180_009).i32(3).f32s(&[0.5, 0.25]).done())
            .chunk("Trc", &Payload::new().f32s(&[1.0, 0.0, 0.0, 0.0, 0.1, 0.2, 0.3]).done())
            .chunk("Ftc", &Payload::new().f32s(&coords).done())
            .chunk("Apm", &Payload::new().i32(2).done())
            .marker("EOO")
            .bytes();
        let p = read_property(&chunk(b"Toj", &single), &top, 3).unwrap().unwrap();
        assert_eq!(p.texture, 2_180_009);
        assert!(!p.from_vision_sensor());
        assert_eq!((p.mapping, p.scaling), (TextureMapping::Cube, [0.5, 0.25]));
        assert!((p.frame.position[2] - 0.3).abs() < 1e-6 && p.frame.rotation[0] == 1.0);
        assert_eq!(p.coordinates.as_deref(), Some(&coords[..]));
        assert!(p.interpolate && p.repeat_u && p.repeat_v);
        assert_eq!(p.apply_mode, 2);
        // The coordinates of another mesh size are dropped; the link stays.
        let p = read_property(&chunk(b"Toj", &single), &top, 6).unwrap().unwrap();
        assert!(p.coordinates.is_none());

        // f64 variants; an old file with the decal bit and no Apm.
        let double = Stream::new()
            .chunk("Bst", &[0x02])
            .chunk("_ob", &Payload::new().i32(90).i32(0).f64s(&[0.1, 0.1]).done())
            .chunk(
                "_rc",
                &Payload::new().f64s(&[1.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0]).done(),
            )
            .chunk("Ftc", &[])
            .marker("EOO")
            .bytes();
        let p = read_property(&chunk(b"Toj", &double), &top, 3).unwrap().unwrap();
        assert!(p.from_vision_sensor());
        assert_eq!(
            (p.scaling, p.apply_mode, p.coordinates.is_none()),
            ([0.1, 0.1], 1, true)
        );
        assert_eq!(p.frame.position, [0.0, 0.0, -1.0]);

        // A cut field is an error; a stream without Tob is no texture.
        let cut = Stream::new().chunk("Tob", &[1, 2]).marker("EOO").bytes();
        assert!(read_property(&chunk(b"Toj", &cut), &top, 3).is_err());
        let none = Stream::new()
            .chunk("Apm", &Payload::new().i32(0).done())
            .marker("EOO")
            .bytes();
        assert_eq!(read_property(&chunk(b"Toj", &none), &top, 3).unwrap(), None);
    }
}
