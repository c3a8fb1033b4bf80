//! Textures: `sim.createTexture`, `sim.setShapeTexture`, `sim.applyTexture`,
//! `sim.getShapeTextureId` and `sim.getTextureId`.
//!
//! Texture objects live in the world ([`crate::world::Textures`]): RGBA images, ids
//! never reused, the store bounded. What is set reads back exactly (ids, mapping,
//! options, coordinates, pixels). Vision sensors draw them (`crate::vision`'s
//! rasteriser: mapping, scaling, texture frame, repeat, interpolation and decal as set
//! here), and so does the browser viewer, with the same coordinates.

use std::f64::consts::PI;
use std::path::Path;
use std::sync::Arc;

use super::image_file::{MAX_SIDE, confined, read_image};
use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::math::{self, Pose, Vec3};
use crate::scene::{Geometry, ShapeModel};
use crate::sim::Sim;
use crate::world::{Handle, MAX_TEXTURE_SIDE, ObjectKind, ShapeTexture, TextureMapping, World};

/// The `sim.*` constants of this file, with CoppeliaSim's values.
pub const CONSTANTS: &[(&str, i64)] = &[
    ("texturemap_plane", 0),
    ("texturemap_cylinder", 1),
    ("texturemap_sphere", 2),
    ("texturemap_cube", 3),
];

/// The texture functions.
pub const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "applyTexture",
        call: ApiFn::World(apply_texture),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "createTexture",
        call: ApiFn::Sim(create_texture),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "getShapeTextureId",
        call: ApiFn::World(get_shape_texture_id),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getTextureId",
        call: ApiFn::World(get_texture_id),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setShapeTexture",
        call: ApiFn::World(set_shape_texture),
        cost: Cost::Quick,
    },
];

/// `sim.applyTexture` option bit: the image has 4 bytes a pixel (RGBA), not 3.
const APPLY_RGBA: i64 = 16;
/// `sim.applyTexture` option bit: mirror the image left to right.
const APPLY_FLIP_H: i64 = 32;
/// `sim.applyTexture` option bit: mirror the image top to bottom.
const APPLY_FLIP_V: i64 = 64;
/// Thickness of the plane `sim.createTexture` makes, m (0.1 mm, as a primitive plane).
const PLANE_THICKNESS: f64 = 1e-4;

/// `sim.createTexture(fileName, options, planeSizes=nil, scalingUV=nil, xy_g=nil,
/// fixedResolution=0, resolution=nil)` → `shapeHandle, textureId, resolution`: reads a
/// PNG or JPEG image into a new texture object (named after the file) and makes a
/// static, non-respondable plane wearing it. `planeSizes` (m) defaults to 1 m along the
/// image's longer side, keeping its aspect; `scalingUV` (the texture's size on the
/// plane, m) to the plane's size; `xy_g` places the texture (x, y, m, and a turn about
/// z, rad). With `fixedResolution` non-zero the image is resampled (nearest pixel) to
/// `resolution`. `options` are kept as `sim.setShapeTexture`'s.
fn create_texture(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let filename = a.str(0)?;
    let options = a.int(1)?;
    let sizes = opt_floats::<2>(a, 2)?;
    let scaling = opt_floats::<2>(a, 3)?;
    let xy_g = opt_floats::<3>(a, 4)?.unwrap_or([0.0; 3]);
    let fixed = match a.get(5) {
        Value::Nil => false,
        Value::Bool(b) => *b,
        _ => a.int(5)? != 0,
    };
    let path = confined(sim, filename, "read")?;
    let ([w, h], mut rgba) = read_image(&path, if fixed { MAX_SIDE } else { MAX_TEXTURE_SIDE })?;
    let mut resolution = [w, h];
    if fixed {
        let [rw, rh] = opt_floats::<2>(a, 6)?
            .ok_or_else(|| SimError::bad_argument("argument 7: a fixed resolution needs {width, height}"))?;
        let side = |x: f64| {
            (x.fract() == 0.0 && (1.0..=f64::from(MAX_TEXTURE_SIDE)).contains(&x))
                .then_some(x as u32)
                .ok_or_else(|| {
                    SimError::bad_argument(format!(
                        "argument 7: each side of the resolution is an integer from 1 to {MAX_TEXTURE_SIDE}, got {x}"
                    ))
                })
        };
        resolution = [side(rw)?, side(rh)?];
        rgba = resample(&rgba, [w, h], resolution);
    }
    let sizes = match sizes {
        Some(s) => s,
        None => {
            let long = f64::from(w.max(h));
            [f64::from(w) / long, f64::from(h) / long]
        }
    };
    if sizes.iter().any(|&s| !(s.is_finite() && s > 0.0)) {
        return Err(SimError::bad_argument(format!(
            "argument 3: the plane's sizes must be positive, got {sizes:?}"
        )));
    }
    let name = Path::new(filename)
        .file_stem()
        .map_or_else(|| "texture".to_owned(), |s| s.to_string_lossy().into_owned());
    let id = sim.world.add_texture(&name, resolution, rgba)?;
    let plane = ShapeModel {
        respondable: false,
        dynamic: false,
        ..ShapeModel::single(
            Geometry::Box {
                half_extents: [sizes[0] / 2.0, sizes[1] / 2.0, PLANE_THICKNESS / 2.0],
            },
            [1.0, 1.0, 1.0],
        )
    };
    let shape = sim
        .world
        .add_object("Plane", ObjectKind::Shape(Box::new(plane)), None, Pose::identity())?;
    sim.world.set_shape_texture(
        shape,
        Some(ShapeTexture {
            id,
            mapping: TextureMapping::Plane,
            options,
            uv_scaling: scaling.unwrap_or(sizes),
            position: [xy_g[0], xy_g[1], 0.0],
            orientation: [0.0, 0.0, xy_g[2]],
            coordinates: None,
        }),
    )?;
    Ok(vec![
        Value::Int(shape),
        Value::Int(id),
        Value::Array(resolution.iter().map(|&r| Value::Int(i64::from(r))).collect()),
    ])
}

/// Argument `i` as N numbers, `None` when nil.
fn opt_floats<const N: usize>(a: &Args<'_>, i: usize) -> Result<Option<[f64; N]>, SimError> {
    match a.get(i) {
        Value::Nil => Ok(None),
        _ => a.floats::<N>(i).map(Some),
    }
}

/// An RGBA image resampled to `to` pixels, each taking the nearest source pixel.
fn resample(rgba: &[u8], [w, h]: [u32; 2], [tw, th]: [u32; 2]) -> Vec<u8> {
    let mut out = Vec::with_capacity(tw as usize * th as usize * 4);
    for y in 0..th {
        let sy = (u64::from(y) * u64::from(h) / u64::from(th)) as usize;
        for x in 0..tw {
            let sx = (u64::from(x) * u64::from(w) / u64::from(tw)) as usize;
            let at = (sy * w as usize + sx) * 4;
            out.extend_from_slice(&rgba[at..at + 4]);
        }
    }
    out
}

/// `sim.getShapeTextureId(shapeHandle)` → the id of the texture the shape wears, -1
/// for none.
fn get_shape_texture_id(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let t = w.shape_texture(a.handle(0)?)?;
    Ok(vec![Value::Int(t.map_or(-1, |t| t.id))])
}

/// `sim.getTextureId(textureName)` → `textureId, resolution`: the first texture object
/// of that name (a file's stem for `sim.createTexture`), or -1 and nil when there is
/// none.
fn get_texture_id(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let name = a.str(0)?;
    Ok(match w.textures().find(name) {
        Some(id) => {
            let [rw, rh] = w.textures().get(id)?.resolution;
            vec![
                Value::Int(id),
                Value::Array(vec![Value::Int(i64::from(rw)), Value::Int(i64::from(rh))]),
            ]
        }
        None => vec![Value::Int(-1), Value::Nil],
    })
}

/// `sim.setShapeTexture(shapeHandle, textureId, mappingMode, options, uvScaling,
/// position=nil, orientation=nil)`: puts texture `textureId` on the shape (-1 takes it
/// off), laid by `mappingMode` (`sim.texturemap_*`) with `uvScaling` (the texture's size
/// on the shape, m) from the texture frame at `position` (m) and `orientation` (Euler
/// angles, rad) in the shape frame. `options`: 1 no interpolation, 2 decal, 4 repeat
/// along u, 8 along v (clamped to the edges without).
fn set_shape_texture(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let id = a.int(1)?;
    if id == -1 {
        w.set_shape_texture(h, None)?;
        return Ok(Vec::new());
    }
    let mapping = TextureMapping::from_code(a.int(2)?)?;
    let options = a.int(3)?;
    let uv_scaling = a.floats::<2>(4)?;
    if uv_scaling.iter().any(|&s| !(s.is_finite() && s > 0.0)) {
        return Err(SimError::bad_argument(format!(
            "argument 5: the u and v scaling must be positive, got {uv_scaling:?}"
        )));
    }
    w.set_shape_texture(
        h,
        Some(ShapeTexture {
            id,
            mapping,
            options,
            uv_scaling,
            position: opt_floats::<3>(a, 5)?.unwrap_or([0.0; 3]),
            orientation: opt_floats::<3>(a, 6)?.unwrap_or([0.0; 3]),
            coordinates: None,
        }),
    )?;
    Ok(Vec::new())
}

/// `sim.applyTexture(shapeHandle, textureCoordinates, texture, textureResolution,
/// options)` → the id of the new texture object: puts an image (3 bytes a pixel, 4 with
/// option bit 4; rows from the top) on the shape with explicit coordinates, u and v for
/// each corner of each triangle of `sim.getShapeMesh` (6 numbers a triangle). Option
/// bits 5 and 6 mirror the image left to right and top to bottom; bits 0 and 1 (no
/// interpolation, decal) are kept, as `sim.setShapeTexture`'s.
fn apply_texture(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let coordinates = a.numbers(1)?;
    let image = a.bytes(2)?;
    let [rw, rh] = a.floats::<2>(3)?;
    let options = a.int(4)?;
    let side = |x: f64| {
        (x.fract() == 0.0 && (1.0..=f64::from(MAX_TEXTURE_SIDE)).contains(&x))
            .then_some(x as u32)
            .ok_or_else(|| {
                SimError::bad_argument(format!(
                    "argument 4: each side of the resolution is an integer from 1 to {MAX_TEXTURE_SIDE}, got {x}"
                ))
            })
    };
    let (tw, th) = (side(rw)?, side(rh)?);
    let bpp = if options & APPLY_RGBA != 0 { 4 } else { 3 };
    let expected = tw as usize * th as usize * bpp;
    if image.len() != expected {
        return Err(SimError::bad_argument(format!(
            "argument 3: a {tw} x {th} image of {bpp} bytes a pixel has {expected} bytes, got {}",
            image.len()
        )));
    }
    let (flip_h, flip_v) = (options & APPLY_FLIP_H != 0, options & APPLY_FLIP_V != 0);
    let mut rgba = Vec::with_capacity(tw as usize * th as usize * 4);
    for y in 0..th as usize {
        let sy = if flip_v { th as usize - 1 - y } else { y };
        for x in 0..tw as usize {
            let sx = if flip_h { tw as usize - 1 - x } else { x };
            let p = &image[(sy * tw as usize + sx) * bpp..][..bpp];
            rgba.extend_from_slice(&[p[0], p[1], p[2], if bpp == 4 { p[3] } else { 255 }]);
        }
    }
    // Checked against the mesh before the image is stored, so a refused call leaves no
    // texture object behind.
    let triangles = w.shape_mesh(h)?.indices.len();
    if coordinates.len() != triangles * 6 || coordinates.iter().any(|c| !c.is_finite()) {
        return Err(SimError::bad_argument(format!(
            "argument 2: shape {h} has {triangles} triangles: {} finite texture coordinates (u, v per corner) are needed, got {}",
            triangles * 6,
            coordinates.len()
        )));
    }
    let id = w.add_texture("applied", [tw, th], rgba)?;
    w.set_shape_texture(
        h,
        Some(ShapeTexture {
            id,
            mapping: TextureMapping::Coordinates,
            options: options & 0xF,
            uv_scaling: [1.0, 1.0],
            position: [0.0; 3],
            orientation: [0.0; 3],
            coordinates: Some(Arc::new(coordinates.iter().map(|&c| c as f32).collect())),
        }),
    )?;
    Ok(vec![Value::Int(id)])
}

/// The texture coordinates of shape `h` wearing `t`: u, v for each corner of each
/// triangle of its mesh. Explicit coordinates are given back as set; projections are
/// computed from the corners in the texture frame, scaled by `uv_scaling` and centred
/// (u = x / su + 0.5 for a plane; angle around z and height for a cylinder; longitude
/// and latitude for a sphere; for a cube, the plane across the axis nearest each
/// triangle's normal).
pub(super) fn coordinates(w: &World, h: Handle, t: &ShapeTexture) -> Result<Vec<f32>, SimError> {
    if let Some(c) = &t.coordinates {
        return Ok(c.to_vec());
    }
    let mesh = w.shape_mesh(h)?;
    let frame = math::pose_from_euler(t.position, t.orientation).inverse();
    let [su, sv] = t.uv_scaling;
    let normals = mesh.face_normals();
    let mut out = Vec::with_capacity(mesh.indices.len() * 6);
    for (tri, n) in mesh.indices.iter().zip(normals) {
        let n = frame.rotation * Vec3::from(n);
        for &i in tri {
            let p = frame * nalgebra::Point3::from(Vec3::from(mesh.vertices[i as usize]));
            let (u, v) = match t.mapping {
                TextureMapping::Plane | TextureMapping::Coordinates => (p.x / su + 0.5, p.y / sv + 0.5),
                TextureMapping::Cylinder => (p.y.atan2(p.x) / (2.0 * PI) + 0.5, p.z / sv + 0.5),
                TextureMapping::Sphere => (p.y.atan2(p.x) / (2.0 * PI) + 0.5, p.z.atan2(p.x.hypot(p.y)) / PI + 0.5),
                TextureMapping::Cube => {
                    let a = n.abs();
                    if a.z >= a.x && a.z >= a.y {
                        (p.x / su + 0.5, p.y / sv + 0.5)
                    } else if a.x >= a.y {
                        (p.y / su + 0.5, p.z / sv + 0.5)
                    } else {
                        (p.x / su + 0.5, p.z / sv + 0.5)
                    }
                }
            };
            out.extend([u as f32, v as f32]);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resampling_takes_the_nearest_pixel() {
        // 2 x 1: red, blue → 4 x 2.
        let src = [255, 0, 0, 255, 0, 0, 255, 255];
        let out = resample(&src, [2, 1], [4, 2]);
        assert_eq!(out.len(), 32);
        assert_eq!(&out[0..4], &src[0..4]);
        assert_eq!(&out[8..12], &src[4..8]);
        assert_eq!(&out[16..20], &src[0..4]);
    }
}
