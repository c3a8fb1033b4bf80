//! The page's files, embedded in the binary at build time (`crates/server/web/`), so
//! the viewer works offline and from a single executable.

use axum::http::header;
use axum::response::IntoResponse;

/// The page.
const INDEX_HTML: &str = include_str!("../../web/index.html");
/// The WebGL2 viewer and panels, plain JavaScript (no framework, no build step).
const APP_JS: &str = include_str!("../../web/app.js");
/// The page's styles.
const STYLE_CSS: &str = include_str!("../../web/style.css");

/// `no-cache`: the browser revalidates, so a rebuilt gantry never serves a stale page.
fn asset(content_type: &'static str, body: &'static str) -> impl IntoResponse {
    (
        [
            (header::CONTENT_TYPE, content_type),
            (header::CACHE_CONTROL, "no-cache"),
        ],
        body,
    )
}

pub(super) async fn index() -> impl IntoResponse {
    asset("text/html; charset=utf-8", INDEX_HTML)
}

pub(super) async fn app_js() -> impl IntoResponse {
    asset("text/javascript; charset=utf-8", APP_JS)
}

pub(super) async fn style_css() -> impl IntoResponse {
    asset("text/css; charset=utf-8", STYLE_CSS)
}
