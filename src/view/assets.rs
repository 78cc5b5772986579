//! The page and its files, compiled into the binary: nothing is fetched at run time, and the
//! viewer works without a network.

use super::http::{ApiError, Reply};

/// The page's ES modules (`<script type="module">`): the DOM glue (app, gl, compare) and the
/// logic it imports, which node's test runner imports too (tests/js/).
macro_rules! module {
    ($name:literal) => {
        (
            concat!($name, ".mjs"),
            "text/javascript; charset=utf-8",
            include_str!(concat!("assets/", $name, ".mjs")),
        )
    };
}

/// (name, content type, bytes) of every file under /assets/.
const ASSETS: [(&str, &str, &str); 11] = [
    (
        "style.css",
        "text/css; charset=utf-8",
        include_str!("assets/style.css"),
    ),
    module!("app"),
    module!("gl"),
    module!("compare"),
    module!("orbit"),
    module!("math"),
    module!("tree"),
    module!("settings"),
    module!("token"),
    module!("render"),
    module!("debounce"),
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

#[cfg(test)]
mod tests {
    use super::ASSETS;

    /// Every file in assets/ is served, and every module a module imports is one of them: a
    /// file left out of [`ASSETS`] would be a 404 and a blank page.
    #[test]
    fn every_file_and_every_import_is_served() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/src/view/assets");
        let names: Vec<&str> = ASSETS.iter().map(|a| a.0).collect();
        for entry in std::fs::read_dir(dir).unwrap() {
            let name = entry.unwrap().file_name().into_string().unwrap();
            assert!(
                name == "index.html" || names.contains(&name.as_str()),
                "{name} is not in ASSETS"
            );
        }
        for (name, _, text) in ASSETS {
            for import in text.split("from './").skip(1) {
                let target = import.split('\'').next().unwrap_or_default();
                assert!(
                    names.contains(&target),
                    "{name} imports {target}, not served"
                );
            }
        }
    }
}
