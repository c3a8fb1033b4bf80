//! Drawing objects (`sim.addDrawingObject`): points, lines, line strips and triangles
//! that scripts draw into the scene, kept in the world for the viewer and the API.

/// Every drawing object of the scene.
#[derive(Debug, Clone, Default)]
pub struct Drawings {}
