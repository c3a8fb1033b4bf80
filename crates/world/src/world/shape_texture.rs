//! The world's texture operations: the texture objects it keeps and the textures its
//! shapes wear (the store itself is `texture.rs`, which the world holds).

use super::object::Handle;
use super::texture::{ShapeTexture, Textures};
use super::world::World;
use crate::error::SimError;

impl World {
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
            self.textures.on_shapes.remove(&h);
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
        Ok(())
    }
}
