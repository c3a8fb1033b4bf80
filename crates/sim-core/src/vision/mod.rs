//! Vision sensors: CPU rendering of RGB and depth images, and CoppeliaSim's
//! `simVision` work-image operations.
