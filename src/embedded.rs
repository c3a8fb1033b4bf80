//! The default scene, compiled into the binary so `gantry` runs from any directory.

use gantry_sim_core::scene::EmbeddedFiles;

/// The embedded scene's path (a virtual path under [`EmbeddedFiles::ROOT`]).
pub const SHOWROOM: &str = "assets/scenes/showroom.toml";

/// Every file the embedded scenes reference, by path relative to the repository root.
pub fn files() -> EmbeddedFiles {
    EmbeddedFiles::new(&[
        (
            "assets/scenes/showroom.toml",
            include_bytes!("../assets/scenes/showroom.toml"),
        ),
        (
            "assets/scenes/bubble_rob.toml",
            include_bytes!("../assets/scenes/bubble_rob.toml"),
        ),
        (
            "assets/scenes/fk_arm.toml",
            include_bytes!("../assets/scenes/fk_arm.toml"),
        ),
        (
            "assets/robots/arm6/arm6.urdf",
            include_bytes!("../assets/robots/arm6/arm6.urdf"),
        ),
        ("scripts/bubble_rob.lua", include_bytes!("../scripts/bubble_rob.lua")),
        ("scripts/fk_server.lua", include_bytes!("../scripts/fk_server.lua")),
        ("scripts/edge_detect.lua", include_bytes!("../scripts/edge_detect.lua")),
    ])
}
