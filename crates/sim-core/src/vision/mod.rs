//! Vision sensors: CPU rendering of RGB and depth images, and CoppeliaSim's
//! `simVision` work-image operations.

/// Rendered images and work images of every vision sensor, by handle.
#[derive(Debug, Clone, Default)]
pub struct VisionStates {}
