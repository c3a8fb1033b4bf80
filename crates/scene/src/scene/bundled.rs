//! The scenes compiled into gantry, so that `gantry` and `gantry.Client("bubble_rob")`
//! run from any directory: the showroom, the two seed scenes and the laser scanners,
//! with every file they reference.

use super::{EmbeddedFiles, Files, LoadError, LoadOptions, SceneModel, load_scene};

/// Bundled scenes by name, with their path relative to the repository root.
pub const BUNDLED_SCENES: &[(&str, &str)] = &[
    ("showroom", "assets/scenes/showroom.toml"),
    ("bubble_rob", "assets/scenes/bubble_rob.toml"),
    ("fk_arm", "assets/scenes/fk_arm.toml"),
    ("scanners", "assets/scenes/scanners.toml"),
];

/// Every file the bundled scenes reference, by path relative to the repository root.
pub fn bundled_files() -> EmbeddedFiles {
    EmbeddedFiles::new(&[
        (
            "assets/scenes/showroom.toml",
            include_bytes!("../../../../assets/scenes/showroom.toml"),
        ),
        (
            "assets/scenes/bubble_rob.toml",
            include_bytes!("../../../../assets/scenes/bubble_rob.toml"),
        ),
        (
            "assets/scenes/fk_arm.toml",
            include_bytes!("../../../../assets/scenes/fk_arm.toml"),
        ),
        (
            "assets/scenes/scanners.toml",
            include_bytes!("../../../../assets/scenes/scanners.toml"),
        ),
        (
            "assets/robots/arm6/arm6.urdf",
            include_bytes!("../../../../assets/robots/arm6/arm6.urdf"),
        ),
        (
            "scripts/bubble_rob.lua",
            include_bytes!("../../../../scripts/bubble_rob.lua"),
        ),
        (
            "scripts/fk_server.lua",
            include_bytes!("../../../../scripts/fk_server.lua"),
        ),
        (
            "scripts/edge_detect.lua",
            include_bytes!("../../../../scripts/edge_detect.lua"),
        ),
        ("scripts/hokuyo.lua", include_bytes!("../../../../scripts/hokuyo.lua")),
        (
            "scripts/hokuyo_sensor.lua",
            include_bytes!("../../../../scripts/hokuyo_sensor.lua"),
        ),
        (
            "scripts/velodyne.lua",
            include_bytes!("../../../../scripts/velodyne.lua"),
        ),
        (
            "scripts/velodyne_sensor.lua",
            include_bytes!("../../../../scripts/velodyne_sensor.lua"),
        ),
    ])
}

/// Loads the bundled scene `name`; `None` when there is no such scene.
pub fn load_bundled(name: &str, opts: &LoadOptions) -> Option<Result<SceneModel, LoadError>> {
    let (_, path) = BUNDLED_SCENES.iter().find(|(n, _)| *n == name)?;
    let files = bundled_files();
    Some(load_scene(&files as &dyn Files, &EmbeddedFiles::path(path), opts))
}
