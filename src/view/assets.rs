//! The page and its files, compiled into the binary: nothing is fetched at run time, and the
//! viewer works without a network.

use super::http::{ApiError, Reply};

/// (name, content type, bytes) of every file under /assets/.
const ASSETS: [(&str, &str, &str); 4] = [
    (
        "style.css",
        "text/css; charset=utf-8",
        include_str!("assets/style.css"),
    ),
    (
        "gl.js",
        "text/javascript; charset=utf-8",
        include_str!("assets/gl.js"),
    ),
    (
        "app.js",
        "text/javascript; charset=utf-8",
        include_str!("assets/app.js"),
    ),
    (
        "compare.js",
        "text/javascript; charset=utf-8",
        include_str!("assets/compare.js"),
    ),
];

/// `GET /`.
pub(crate) fn page() -> Result<Reply, ApiError> {
    Ok(Reply::bytes(
        "text/html; charset=utf-8",
        include_str!("assets/index.html").as_bytes().to_vec(),
    ))
}

/// `GET /assets/{name}`.
pub(crate) fn asset(name: &str) -> Result<Reply, ApiError> {
    ASSETS
        .iter()
        .find(|(n, _, _)| *n == name)
        .map(|(_, content_type, text)| Reply {
            cacheable: true,
            ..Reply::bytes(content_type, text.as_bytes().to_vec())
        })
        .ok_or_else(|| {
            ApiError::not_found(format!(
                "no asset `{}`: expected one of {}",
                crate::render::quote::quote(name),
                ASSETS.map(|a| a.0).join(", ")
            ))
        })
}
