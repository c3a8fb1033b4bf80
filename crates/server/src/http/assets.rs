//! The page's files, embedded in the binary at build time (`crates/server/web/`), so
//! the viewer works offline and from a single executable.
//!
//! The script is plain JavaScript ES modules (`web/js/`, entry `main.js`; no framework,
//! no build step). Each module is served at its own path under `/js/`, so that the
//! browser resolves their relative `import`s; [`ASSETS`] lists every file, and a path
//! not listed falls through to the router's 404.

use axum::Router;
use axum::http::header;
use axum::response::{IntoResponse, Response};
use axum::routing::get;

const HTML: &str = "text/html; charset=utf-8";
const JS: &str = "text/javascript; charset=utf-8";
const CSS: &str = "text/css; charset=utf-8";

/// One file of the page.
pub(super) struct Asset {
    /// Where it is served.
    pub(super) path: &'static str,
    content_type: &'static str,
    body: &'static str,
}

/// A module of the viewer's script, by its path under `web/js/`.
macro_rules! module {
    ($path:literal) => {
        Asset {
            path: concat!("/js/", $path),
            content_type: JS,
            body: include_str!(concat!("../../web/js/", $path)),
        }
    };
}

/// Every file of the page, by the path it is served at.
pub(super) const ASSETS: &[Asset] = &[
    Asset {
        path: "/",
        content_type: HTML,
        body: include_str!("../../web/index.html"),
    },
    Asset {
        path: "/style.css",
        content_type: CSS,
        body: include_str!("../../web/style.css"),
    },
    module!("main.js"),
    module!("state.js"),
    module!("net.js"),
    module!("dom.js"),
    module!("math.js"),
    module!("geometry.js"),
    module!("gl.js"),
    module!("scene.js"),
    module!("camera.js"),
    module!("input.js"),
    module!("render.js"),
    module!("picking.js"),
    module!("panels/simulation.js"),
    module!("panels/debug.js"),
    module!("panels/selection.js"),
    module!("panels/joints.js"),
    module!("panels/ik.js"),
    module!("panels/scripts.js"),
    module!("panels/custom_ui.js"),
    module!("panels/graphs.js"),
    module!("panels/vision.js"),
    module!("panels/replay.js"),
    module!("panels/ros2.js"),
];

impl Asset {
    /// The file, `no-cache`: the browser revalidates, so a rebuilt gantry never serves
    /// a stale page.
    fn response(&self) -> Response {
        (
            [
                (header::CONTENT_TYPE, self.content_type),
                (header::CACHE_CONTROL, "no-cache"),
            ],
            self.body,
        )
            .into_response()
    }
}

/// `router` with a route for each of [`ASSETS`].
pub(super) fn routes<S: Clone + Send + Sync + 'static>(router: Router<S>) -> Router<S> {
    ASSETS.iter().fold(router, |router, asset| {
        router.route(asset.path, get(move || async move { asset.response() }))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The path a module's `import` names, resolved against the importing module's.
    fn resolve(from: &str, spec: &str) -> String {
        let mut parts: Vec<&str> = from.split('/').collect();
        parts.pop();
        for part in spec.split('/') {
            match part {
                "." => {}
                ".." => {
                    parts.pop();
                }
                p => parts.push(p),
            }
        }
        parts.join("/")
    }

    fn served(path: &str) -> bool {
        ASSETS.iter().any(|a| a.path == path)
    }

    #[test]
    fn every_import_is_served() {
        for asset in ASSETS.iter().filter(|a| a.content_type == JS) {
            for line in asset.body.lines().filter(|l| l.starts_with("import ")) {
                let spec = line
                    .split('\'')
                    .nth(1)
                    .unwrap_or_else(|| panic!("{}: unquoted import: {line}", asset.path));
                let path = resolve(asset.path, spec);
                assert!(served(&path), "{} imports {path}, which is not served", asset.path);
            }
        }
        let index = ASSETS.iter().find(|a| a.path == "/").map_or("", |a| a.body);
        assert!(index.contains(r#"<script type="module" src="js/main.js">"#));
    }

    #[test]
    fn every_module_in_the_source_tree_is_served() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("web/js");
        let mut dirs = vec![root.clone()];
        while let Some(dir) = dirs.pop() {
            for entry in std::fs::read_dir(&dir).expect("web/js is readable") {
                let path = entry.expect("a directory entry").path();
                if path.is_dir() {
                    dirs.push(path);
                } else {
                    let rel = path.strip_prefix(&root).expect("under web/js");
                    let served_at = format!("/js/{}", rel.to_string_lossy().replace('\\', "/"));
                    assert!(served(&served_at), "{served_at} is not in ASSETS");
                }
            }
        }
    }
}
