//! The world's texture operations: the texture objects it keeps, the textures its
//! shapes wear, and loading a scene's textures (the store itself is `texture.rs`,
//! which the world holds).

use std::sync::Arc;

use super::object::Handle;
use super::texture::{ShapeTexture, TextureMapping, Textures};
use super::world::World;
use crate::error::SimError;
use crate::scene::{ObjectModelKind, SceneModel, VisualTexture};

impl World {
    /// Adds the textures of `model` to the store and puts them on its shapes; `map` gives
    /// a model object's handle here. A shape keeps one texture (the world's store holds
    /// one per shape): that of its first textured part, with the fixed coordinates of
    /// all its parts when every part wears the same texture with fixed coordinates, and
    /// else projected by that part's mapping. What cannot be kept is returned as warnings.
    pub(super) fn load_textures(&mut self, model: &SceneModel, map: impl Fn(usize) -> Handle) -> Vec<String> {
        let mut warnings = Vec::new();
        let mut ids = Vec::with_capacity(model.textures.len());
        for t in &model.textures {
            match self.textures.add(&t.name, t.resolution, t.rgba.to_vec()) {
                Ok(id) => ids.push(Some(id)),
                Err(e) => {
                    warnings.push(format!("texture '{}' not loaded: {e}", t.name));
                    ids.push(None);
                }
            }
        }
        for (i, o) in model.objects.iter().enumerate() {
            let ObjectModelKind::Shape(shape) = &o.kind else {
                continue;
            };
            let textured: Vec<&VisualTexture> = shape.visuals.iter().filter_map(|v| v.texture.as_ref()).collect();
            let Some(first) = textured.first() else { continue };
            let Some(id) = ids.get(first.texture).copied().flatten() else {
                continue;
            };
            let whole = textured.len() == shape.visuals.len()
                && textured
                    .iter()
                    .all(|t| t.texture == first.texture && t.coordinates.is_some());
            if !whole && shape.visuals.len() > 1 {
                warnings.push(format!(
                    "{}: its parts' textures are kept as one, projected ({} of {} parts textured)",
                    o.alias,
                    textured.len(),
                    shape.visuals.len()
                ));
            }
            let coordinates = whole.then(|| {
                Arc::new(
                    textured
                        .iter()
                        .flat_map(|t| t.coordinates.iter().flat_map(|c| c.iter().copied()))
                        .collect::<Vec<f32>>(),
                )
            });
            let frame = first.frame;
            let texture = ShapeTexture {
                id,
                mapping: match first.mapping {
                    1 => TextureMapping::Cylinder,
                    2 => TextureMapping::Sphere,
                    3 => TextureMapping::Cube,
                    _ if coordinates.is_some() => TextureMapping::Coordinates,
                    _ => TextureMapping::Plane,
                },
                options: first.options,
                uv_scaling: first.scaling,
                position: frame.translation.vector.into(),
                orientation: crate::math::euler_from_quat(&frame.rotation),
                coordinates,
            };
            let h = map(i);
            if let Err(e) = self.set_shape_texture(h, Some(texture.clone())) {
                // Fixed coordinates made for the file's triangles do not fit a primitive
                // gantry meshes its own way: project instead.
                let projected = ShapeTexture {
                    mapping: if texture.mapping == TextureMapping::Coordinates {
                        TextureMapping::Plane
                    } else {
                        texture.mapping
                    },
                    coordinates: None,
                    ..texture
                };
                warnings.push(format!("{}: texture coordinates not kept ({e}); projected", o.alias));
                if let Err(e) = self.set_shape_texture(h, Some(projected)) {
                    warnings.push(format!("{}: texture not kept: {e}", o.alias));
                }
            }
        }
        warnings
    }

    /// The world's texture objects.
    pub fn textures(&self) -> &Textures {
        &self.textures
    }

    /// Adds a texture object (see [`Textures::add`]) and returns its id.
    ///
    /// # Errors
    /// As [`Textures::add`].
    pub fn add_texture(&mut self, name: &str, resolution: [u32; 2], rgba: Vec<u8>) -> Result<i64, SimError> {
        self.textures.add(name, resolution, rgba)
    }

    /// The texture shape `h` wears, if any.
    ///
    /// # Errors
    /// No such object, or not a shape.
    pub fn shape_texture(&self, h: Handle) -> Result<Option<&ShapeTexture>, SimError> {
        self.shape(h)?;
        Ok(self.textures.on_shapes.get(&h))
    }

    /// Puts a texture on shape `h`, or takes it off with `None`. Explicit coordinates must
    /// be 6 finite numbers per triangle of the shape's mesh.
    ///
    /// # Errors
    /// No such object, not a shape, no such texture, non-finite placement values, or
    /// coordinates that do not fit the mesh.
    pub fn set_shape_texture(&mut self, h: Handle, texture: Option<ShapeTexture>) -> Result<(), SimError> {
        self.shape(h)?;
        let Some(t) = texture else {
            if self.textures.on_shapes.remove(&h).is_some() {
                self.textures.revision += 1;
                // The viewer's scene description shows textures.
                self.bump();
            }
            return Ok(());
        };
        self.textures.get(t.id)?;
        let placement = t.uv_scaling.iter().chain(&t.position).chain(&t.orientation);
        if placement.into_iter().any(|v| !v.is_finite()) {
            return Err(SimError::bad_argument(
                "the texture's scaling, position and orientation must be finite",
            ));
        }
        if let Some(c) = &t.coordinates {
            let triangles = self.shape_mesh(h)?.indices.len();
            if c.len() != triangles * 6 || c.iter().any(|v| !v.is_finite()) {
                return Err(SimError::bad_argument(format!(
                    "the shape has {triangles} triangles: the texture needs {} finite coordinates (u, v per corner), got {}",
                    triangles * 6,
                    c.len()
                )));
            }
        }
        self.textures.on_shapes.insert(h, t);
        self.textures.revision += 1;
        self.bump();
        Ok(())
    }
}
