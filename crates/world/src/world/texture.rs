//! Texture objects and the textures shapes wear (`sim.createTexture`,
//! `sim.setShapeTexture`, `sim.applyTexture`, `sim.getShapeTextureId`,
//! `sim.getTextureId`).
//!
//! A texture is an RGBA image kept with the world under an id that is never reused, as
//! CoppeliaSim's texture objects are; a shape refers to one by id together with how it
//! is laid on the shape (a projection, or explicit coordinates per triangle corner).
//! The store is bounded ([`MAX_TEXTURE_SIDE`], [`MAX_TEXTURE_BYTES`]) because its images
//! come from files and scripts.
//!
//! A scene's textures (CoppeliaSim files' texture objects, TOML scenes' PNG files) are
//! added at load ([`World::load_textures`]).
//!
//! Vision sensors draw the textures shapes wear (`crate::vision`'s rasteriser, which
//! notices a change of texture by [`Textures::revision`]), and so does the browser
//! viewer, from the coordinates `crate::vision::textured_parts` gives (a change of
//! texture changes the scene revision, so the page reloads the scene).

use std::collections::BTreeMap;
use std::sync::Arc;

use super::object::Handle;
use crate::error::SimError;

/// The largest texture side, pixels (CoppeliaSim's own limit for textures is 4096).
pub const MAX_TEXTURE_SIDE: u32 = 4096;
/// The most image bytes the store holds over all its textures (64 textures of 1024 x 1024
/// RGBA): a script creating textures in a loop is refused rather than exhausting memory.
pub const MAX_TEXTURE_BYTES: usize = 256 << 20;

/// One texture object: an RGBA image, rows from the top.
#[derive(Debug, Clone)]
pub struct Texture {
    /// The name `sim.getTextureId` finds it by (the image file's stem, or "texture").
    pub name: String,
    /// Width and height, pixels.
    pub resolution: [u32; 2],
    /// 4 bytes a pixel, `resolution[0] * resolution[1] * 4` of them.
    pub rgba: Arc<Vec<u8>>,
}

/// How a texture is laid on a shape (`sim.texturemap_*`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TextureMapping {
    /// Projected along the texture frame's z axis.
    Plane,
    /// Wrapped around the texture frame's z axis.
    Cylinder,
    /// Wrapped around the texture frame's origin.
    Sphere,
    /// Each triangle projected along the axis its normal is closest to.
    Cube,
    /// Explicit coordinates per triangle corner (`sim.applyTexture`).
    Coordinates,
}

impl TextureMapping {
    /// The mapping of a `sim.texturemap_*` value (0 to 3).
    ///
    /// # Errors
    /// Any other value.
    pub fn from_code(code: i64) -> Result<Self, SimError> {
        Ok(match code {
            0 => TextureMapping::Plane,
            1 => TextureMapping::Cylinder,
            2 => TextureMapping::Sphere,
            3 => TextureMapping::Cube,
            _ => {
                return Err(SimError::bad_argument(format!(
                    "texture mapping mode {code} is not one of sim.texturemap_plane (0), _cylinder (1), _sphere (2), _cube (3)"
                )));
            }
        })
    }

    /// The `sim.texturemap_*` value; explicit coordinates count as a plane mapping, as
    /// CoppeliaSim reports them.
    pub fn code(self) -> i64 {
        match self {
            TextureMapping::Plane | TextureMapping::Coordinates => 0,
            TextureMapping::Cylinder => 1,
            TextureMapping::Sphere => 2,
            TextureMapping::Cube => 3,
        }
    }
}

/// The texture a shape wears.
#[derive(Debug, Clone, PartialEq)]
pub struct ShapeTexture {
    /// The texture object's id.
    pub id: i64,
    /// How it is laid on the shape.
    pub mapping: TextureMapping,
    /// `sim.setShapeTexture`'s options bits as given (1: no interpolation, 2: decal,
    /// 4: repeat along u, 8: repeat along v).
    pub options: i64,
    /// Scaling along u and v (texture size on the shape, m, for projections).
    pub uv_scaling: [f64; 2],
    /// The texture frame relative to the shape frame: position, m, and Euler angles, rad.
    pub position: [f64; 3],
    /// See `position`.
    pub orientation: [f64; 3],
    /// For [`TextureMapping::Coordinates`]: u, v per triangle corner of the shape's mesh
    /// (`sim.getShapeMesh` order), 6 numbers a triangle.
    pub coordinates: Option<Arc<Vec<f32>>>,
}

/// The texture objects of a world and the textures its shapes wear.
#[derive(Debug, Clone, Default)]
pub struct Textures {
    /// By id: ids are indices, never reused (textures are not deleted).
    items: Vec<Texture>,
    /// Bytes held by `items`.
    bytes: usize,
    /// By shape handle. Handles are never reused, so an entry of a removed shape is
    /// unreachable and harmless.
    pub(super) on_shapes: BTreeMap<Handle, ShapeTexture>,
    /// Counts the changes to `on_shapes`, so a renderer caching what shapes wear knows
    /// when to look again (texture objects themselves never change).
    pub(super) revision: u64,
}

impl Textures {
    /// Adds a texture and returns its id.
    ///
    /// # Errors
    /// A side of 0 or over [`MAX_TEXTURE_SIDE`], a buffer that is not 4 bytes a pixel, or
    /// a store that would exceed [`MAX_TEXTURE_BYTES`].
    pub fn add(&mut self, name: &str, resolution: [u32; 2], rgba: Vec<u8>) -> Result<i64, SimError> {
        let [w, h] = resolution;
        if w == 0 || h == 0 || w > MAX_TEXTURE_SIDE || h > MAX_TEXTURE_SIDE {
            return Err(SimError::bad_argument(format!(
                "a texture of {w} x {h} pixels: each side must be 1 to {MAX_TEXTURE_SIDE}"
            )));
        }
        let expected = w as usize * h as usize * 4;
        if rgba.len() != expected {
            return Err(SimError::bad_argument(format!(
                "a {w} x {h} RGBA texture has {expected} bytes, got {}",
                rgba.len()
            )));
        }
        if self.bytes + expected > MAX_TEXTURE_BYTES {
            return Err(SimError::refused(format!(
                "the textures would hold over {} MiB of images; gantry keeps at most that",
                MAX_TEXTURE_BYTES >> 20
            )));
        }
        self.bytes += expected;
        self.items.push(Texture {
            name: name.to_owned(),
            resolution,
            rgba: Arc::new(rgba),
        });
        Ok(self.items.len() as i64 - 1)
    }

    /// The texture `id`.
    ///
    /// # Errors
    /// No texture has that id.
    pub fn get(&self, id: i64) -> Result<&Texture, SimError> {
        usize::try_from(id)
            .ok()
            .and_then(|i| self.items.get(i))
            .ok_or_else(|| SimError::NoSuchItem(format!("texture {id} does not exist")))
    }

    /// A number that changes whenever a shape's texture is put on, taken off or moved.
    pub fn revision(&self) -> u64 {
        self.revision
    }

    /// The id of the first texture named `name`.
    pub fn find(&self, name: &str) -> Option<i64> {
        self.items.iter().position(|t| t.name == name).map(|i| i as i64)
    }
}

#[cfg(test)]
mod tests {
    use super::super::world::World;
    use super::*;
    use crate::scene::{ObjectModelKind, VisualTexture};

    #[test]
    fn ids_are_stable_and_the_store_is_bounded() {
        let mut t = Textures::default();
        assert_eq!(t.add("a", [2, 1], vec![0; 8]), Ok(0));
        assert_eq!(t.add("b", [1, 1], vec![7; 4]), Ok(1));
        assert_eq!(t.get(1).map(|x| x.rgba[0]), Ok(7));
        assert_eq!(t.find("a"), Some(0));
        assert_eq!(t.find("c"), None);
        assert!(t.get(2).is_err() && t.get(-1).is_err());
        // Wrong byte count, absurd sides.
        assert!(t.add("c", [2, 2], vec![0; 12]).is_err());
        assert!(t.add("c", [MAX_TEXTURE_SIDE + 1, 1], Vec::new()).is_err());
        assert!(t.add("c", [0, 5], Vec::new()).is_err());
        // The total is bounded.
        t.bytes = MAX_TEXTURE_BYTES - 4;
        assert!(matches!(t.add("d", [1, 2], vec![0; 8]), Err(SimError::Refused(_))));
        assert_eq!(t.add("d", [1, 1], vec![0; 4]), Ok(2));
    }

    /// A scene with `shapes` (each a list of box parts, each with an optional texture)
    /// and one 1 x 2 texture.
    fn textured_world(shapes: Vec<Vec<Option<VisualTexture>>>) -> World {
        use crate::math::Pose;
        use crate::scene::{
            EmbeddedFiles, Geometry, LoadOptions, ObjectModel, ShapeModel, TextureModel, VisualModel, load_scene_text,
        };
        let mut model = load_scene_text(
            &EmbeddedFiles::default(),
            "",
            std::path::Path::new("/empty.toml"),
            &LoadOptions::default(),
        )
        .expect("an empty scene loads");
        model.textures.push(TextureModel {
            name: "wood".into(),
            resolution: [1, 2],
            rgba: Arc::new(vec![1, 2, 3, 4, 5, 6, 7, 8]),
        });
        let cube = Geometry::Box { half_extents: [0.1; 3] };
        for (k, parts) in shapes.into_iter().enumerate() {
            let mut shape = ShapeModel::single(cube.clone(), [0.5; 3]);
            shape.visuals = parts
                .into_iter()
                .map(|texture| VisualModel {
                    geometry: cube.clone(),
                    local: Pose::identity(),
                    color: [0.5; 3],
                    texture,
                })
                .collect();
            model.objects.push(ObjectModel {
                alias: format!("s{k}"),
                parent: None,
                local: Pose::identity(),
                model_base: false,
                extension: String::new(),
                layer: 1,
                kind: ObjectModelKind::Shape(shape),
            });
        }
        World::new(&model)
    }

    fn textured(coordinates: Option<Vec<f32>>) -> Option<VisualTexture> {
        Some(VisualTexture {
            texture: 0,
            mapping: 0,
            options: 12,
            scaling: [0.5, 0.25],
            frame: crate::math::Pose::identity(),
            coordinates: coordinates.map(Arc::new),
        })
    }

    #[test]
    fn a_scenes_textures_reach_the_store_and_its_shapes() {
        // A cube is 12 triangles: 72 coordinates.
        let coords = |v: f32| Some(vec![v; 72]);
        let w = textured_world(vec![
            // Two parts with coordinates: one texture with both parts' coordinates.
            vec![textured(coords(0.25)), textured(coords(0.75))],
            // Coordinates that do not fit the mesh: projected instead, warned.
            vec![textured(Some(vec![0.5; 6]))],
            // One part of two textured, by projection: kept, warned.
            vec![textured(None), None],
            // No texture.
            vec![None],
        ]);
        let id = w.textures().find("wood").expect("the texture is in the store");
        assert_eq!(w.textures().get(id).map(|t| t.resolution), Ok([1, 2]));
        let handle = |name: &str| {
            (0..w.len() as Handle)
                .find(|&h| w.object(h).is_ok_and(|o| o.alias == name))
                .expect(name)
        };
        let both = w.shape_texture(handle("s0")).unwrap().expect("textured");
        assert_eq!(
            (both.id, both.mapping, both.options),
            (id, TextureMapping::Coordinates, 12)
        );
        let c = both.coordinates.as_ref().expect("fixed coordinates");
        assert_eq!((c.len(), c[0], c[143]), (144, 0.25, 0.75));
        let bad = w.shape_texture(handle("s1")).unwrap().expect("still textured");
        assert_eq!(
            (bad.mapping, bad.coordinates.is_none(), bad.uv_scaling),
            (TextureMapping::Plane, true, [0.5, 0.25])
        );
        assert!(
            w.warnings()
                .iter()
                .any(|m| m.contains("s1: texture coordinates not kept")),
            "{:?}",
            w.warnings()
        );
        assert!(w.shape_texture(handle("s2")).unwrap().is_some());
        assert!(w.warnings().iter().any(|m| m.contains("s2: its parts' textures")));
        assert!(w.shape_texture(handle("s3")).unwrap().is_none());
    }

    #[test]
    fn mapping_codes_round_trip() {
        for code in 0..4 {
            assert_eq!(TextureMapping::from_code(code).map(TextureMapping::code), Ok(code));
        }
        assert!(TextureMapping::from_code(4).is_err());
    }
}
