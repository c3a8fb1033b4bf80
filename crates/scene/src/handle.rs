//! Object handles, the leaf every floor of sim-core names objects with.

/// An object handle: CoppeliaSim's integer handle, stable for the scene's life (removed
/// objects' handles are never reused).
pub type Handle = i64;
