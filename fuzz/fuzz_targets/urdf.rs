//! URDF importer: a bare `.urdf` (any bytes) loads or fails with an error, never
//! panics, and every model it returns keeps the resolver's invariants. Its mesh
//! references can reach the in-memory meshes (`package://meshes/cube.obj`).
#![no_main]

mod common;

use std::path::Path;

use gantry_scene::scene::{EmbeddedFiles, LoadOptions, load_scene};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let path = EmbeddedFiles::path("assets/robots/fuzz/fuzz.urdf");
    let files = common::MemFiles::new(Some((path.clone(), data)));
    let opts = LoadOptions {
        package_paths: vec![Path::new(EmbeddedFiles::ROOT).join("assets")],
        // The last byte picks the base: fixed (the default) or free.
        free_base: data.last().is_some_and(|b| b & 1 == 1),
    };
    if let Ok(model) = load_scene(&files, &path, &opts) {
        common::check_model(&model);
    }
});
