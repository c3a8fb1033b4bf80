//! The textured parts of a shape for the browser viewer: the triangles and texture
//! coordinates vision sensors draw ([`super::raster`]), so that the page shows a texture
//! where the sensors see it.

use crate::error::SimError;
use crate::world::{Handle, ObjectKind, World};

/// One visual part of a textured shape, as vision sensors draw it: its triangles (three
/// corners each, in the part's frame, m) and each corner's u, v.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TexturedPart {
    /// Three corners per triangle.
    pub positions: Vec<[f32; 3]>,
    /// u, v per corner, parallel to `positions`.
    pub uvs: Vec<[f32; 2]>,
}

/// The parts of shape `h` (one per visual, in order) with the coordinates of the texture
/// it wears, for a viewer to draw them as vision sensors do; `None` for a shape without
/// a texture.
///
/// # Errors
/// No such object, or not a shape.
pub fn textured_parts(world: &World, h: Handle) -> Result<Option<Vec<TexturedPart>>, SimError> {
    let Some(worn) = world.shape_texture(h)? else {
        return Ok(None);
    };
    let (Ok(texture), Ok(ObjectKind::Shape(shape))) = (world.textures().get(worn.id), world.object(h).map(|o| &o.kind))
    else {
        return Ok(None);
    };
    let parts = super::raster::textured_visuals(shape, worn, texture)
        .iter()
        .map(|v| {
            let (mesh, texture) = v.parts();
            let mut part = TexturedPart::default();
            let mut k = 0;
            for chunk in &mesh.chunks {
                let positions = mesh.chunk_positions(chunk);
                for tri in mesh.chunk_triangles(chunk) {
                    let uv = texture.and_then(|t| t.uvs.get(k)).copied().unwrap_or_default();
                    for (c, &i) in tri.iter().enumerate() {
                        part.positions
                            .push(positions.get(i as usize).copied().unwrap_or_default());
                        part.uvs.push(uv[c]);
                    }
                    k += 1;
                }
            }
            part
        })
        .collect();
    Ok(Some(parts))
}
