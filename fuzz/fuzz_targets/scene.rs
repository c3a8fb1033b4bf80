//! Scene resolver: TOML text → resolved model (`load_scene_text`) never panics, whatever
//! the text, and every model it returns keeps the resolver's invariants. Files come from
//! memory (the shipped robot, scripts and two tiny meshes), never from the disk.
#![no_main]

mod common;

use std::path::Path;

use gantry_scene::scene::{EmbeddedFiles, LoadOptions, load_scene_text};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let files = common::MemFiles::new(None);
    // In assets/scenes/, so the shipped scenes' relative references resolve.
    let path = EmbeddedFiles::path("assets/scenes/fuzz.toml");
    let opts = LoadOptions {
        package_paths: vec![Path::new(EmbeddedFiles::ROOT).join("assets")],
        free_base: false,
    };
    if let Ok(model) = load_scene_text(&files, text, &path, &opts) {
        common::check_model(&model);
    }
});
