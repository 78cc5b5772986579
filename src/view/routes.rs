//! The routing table, behind three checks every request passes first: the `Host` it names (on
//! a loopback address, a local name: DNS rebinding cannot reach the API), the `Origin` a browser
//! names (this server's own page only), and the access token (token.rs).
//!
//! ```text
//! GET  /                              the page          GET /assets/NAME   its scripts and style
//! GET  /api/scene                     geometry, camera, settings, choices
//! POST /api/render                    settings -> a progressive job (supersedes the last)
//! GET  /api/render/{job}              status, levels, rays/s by kind
//! GET  /api/render/{job}/{level}.png  one level's image (N.cost.png: its cost-map overlay)
//! GET  /api/pixel?job=J&x=X&y=Y       the pixel's ray tree (x, y from the top-left)
//! POST /api/compare                   two samplers against the converged reference
//! GET  /api/compare/{id}/{name}.png   its images
//! ```

use super::api::{self, State};
use super::assets;
use super::connection::Request;
use super::http::{ApiError, Reply};
use super::token::Access;
use crate::render::quote::quote;

/// Who may reach the routes.
#[derive(Debug)]
pub(crate) struct Gate {
    /// The token, or none (`--no-token`).
    pub access: Access,
    /// Whether the server listens on a loopback address only: then a request must name a
    /// local host.
    pub loopback: bool,
    /// The port served (it names the token's cookie).
    pub port: u16,
}

/// Answers `request`: the checks, then the handler. Errors become their JSON reply.
pub(crate) fn answer(request: &Request, state: &State, gate: &Gate) -> Reply {
    let (path, query) = request.path_and_query();
    check(request, gate)
        .and_then(|cookie| {
            let mut reply = route(request, path, query, state)?;
            if let Some(cookie) = cookie.filter(|_| reply.status == 200) {
                reply.headers.push(("Set-Cookie", cookie));
            }
            Ok(reply)
        })
        .unwrap_or_else(Reply::from)
}

/// The Host, Origin and token checks; the cookie to set when the page came with the token.
fn check(request: &Request, gate: &Gate) -> Result<Option<String>, ApiError> {
    let host = request.one("host")?;
    check_host(host, gate)?;
    check_origin(request.one("origin")?, host.unwrap_or(""))?;
    gate.access.check(request, gate.port)
}

/// The routing table: each arm checks the method with `get()` or `post()`, then calls its
/// handler. tests/commands/view_token.rs reads the arms from this source.
fn route(request: &Request, path: &str, query: &str, state: &State) -> Result<Reply, ApiError> {
    let method = request.method.as_str();
    let segments: Vec<&str> = path.split('/').skip(1).collect();
    // GET allows HEAD.
    let allow = |allowed: &'static str| match (allowed, method) {
        ("GET", "GET" | "HEAD") | ("POST", "POST") => Ok(()),
        _ => Err(ApiError::method(method, path, allowed)),
    };
    let (get, post) = (|| allow("GET"), || allow("POST"));
    let body = &request.body;
    match segments.as_slice() {
        [""] | ["index.html"] => get().and_then(|()| assets::page()),
        ["assets", name] => get().and_then(|()| assets::asset(name)),
        ["api", "scene"] => get().map(|()| api::scene(state)),
        ["api", "render"] => post().and_then(|()| api::render(state, body)),
        ["api", "render", job] => get().and_then(|()| api::render_status(state, job)),
        ["api", "render", job, level] => get().and_then(|()| api::render_png(state, job, level)),
        ["api", "pixel"] => get().and_then(|()| api::pixel(state, query)),
        ["api", "compare"] => post().and_then(|()| api::compare(state, body)),
        ["api", "compare", id, name] => get().and_then(|()| api::compare_png(state, id, name)),
        _ => Err(ApiError::not_found(format!(
            "no such path: {} (the page is at /, the API under /api/)",
            quote(path)
        ))),
    }
}

/// A `Host` value without its port: `localhost:8080` -> `localhost`, `[::1]:80` -> `[::1]`.
fn host_name(host: &str) -> &str {
    match host.rsplit_once(':') {
        Some((name, port))
            if !name.is_empty()
                && !port.is_empty()
                && port.bytes().all(|b| b.is_ascii_digit())
                && (!name.contains(':') || name.ends_with(']')) =>
        {
            name
        }
        _ => host,
    }
}

/// On a loopback address, refuses requests addressed to another host name: a page elsewhere
/// that resolves its own name to 127.0.0.1 (DNS rebinding) must not reach the API. Any port is
/// accepted, for SSH tunnels that forward another local port. On other addresses the token
/// alone decides.
fn check_host(host: Option<&str>, gate: &Gate) -> Result<(), ApiError> {
    let Some(host) = host else {
        return Err(ApiError::bad(
            "no Host header: HTTP/1.1 requests must name the host",
        ));
    };
    let name = host_name(host);
    let local = name.eq_ignore_ascii_case("localhost") || matches!(name, "127.0.0.1" | "[::1]");
    if !gate.loopback || local {
        return Ok(());
    }
    Err(ApiError::status(
        421,
        format!(
            "unexpected Host `{}`: this server listens on loopback and answers only to 127.0.0.1, localhost and [::1]",
            quote(host)
        ),
    ))
}

/// Refuses requests that a page from another origin sent (browsers name the page's origin on
/// every POST): such a page could otherwise start renders here. Our own page's origin is the
/// host it was loaded from, whatever port a tunnel gives it.
fn check_origin(origin: Option<&str>, host: &str) -> Result<(), ApiError> {
    let Some(origin) = origin else {
        return Ok(());
    };
    if origin.eq_ignore_ascii_case(&format!("http://{host}")) {
        return Ok(());
    }
    Err(ApiError::status(
        403,
        format!(
            "requests from `{}` are refused: only this server's own page (http://{}) may call this API",
            quote(origin),
            quote(host)
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gate(loopback: bool) -> Gate {
        Gate {
            access: Access::Open,
            loopback,
            port: 8080,
        }
    }

    #[test]
    fn on_loopback_only_local_host_names_are_served() {
        let g = gate(true);
        for ok in [
            "127.0.0.1:8080",
            "localhost:8080",
            "localhost",
            "LOCALHOST:9999",
            "[::1]:8080",
        ] {
            assert!(check_host(Some(ok), &g).is_ok(), "{ok}");
        }
        for bad in ["evil.example:8080", "127.0.0.1.evil.example", "[::2]:80"] {
            assert_eq!(check_host(Some(bad), &g).unwrap_err().status, 421, "{bad}");
        }
        assert_eq!(check_host(None, &g).unwrap_err().status, 400);
        assert!(check_host(Some("raywave.lab:8080"), &gate(false)).is_ok());
    }

    #[test]
    fn only_our_own_origin_may_call() {
        assert!(check_origin(None, "127.0.0.1:8080").is_ok());
        assert!(check_origin(Some("http://127.0.0.1:8080"), "127.0.0.1:8080").is_ok());
        assert!(check_origin(Some("http://localhost:9999"), "localhost:9999").is_ok());
        for bad in ["http://127.0.0.1:9090", "https://evil.example", "null"] {
            assert_eq!(
                check_origin(Some(bad), "127.0.0.1:8080")
                    .unwrap_err()
                    .status,
                403,
                "{bad}"
            );
        }
    }

    #[test]
    fn host_names_lose_only_their_port() {
        assert_eq!(host_name("localhost:80"), "localhost");
        assert_eq!(host_name("[::1]:80"), "[::1]");
        assert_eq!(host_name("[::1]"), "[::1]");
        assert_eq!(host_name("::1"), "::1");
        assert_eq!(host_name("a:"), "a:");
    }
}
