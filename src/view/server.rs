//! The HTTP server: tiny_http on 127.0.0.1, a few worker threads taking requests, the routing
//! table, and a clean stop on SIGINT or SIGTERM (the workers finish the request in hand, the
//! listener closes, `serve` returns).
//!
//! ```text
//! GET  /                              the page          GET /assets/NAME   its scripts and style
//! GET  /api/scene                     geometry, camera, settings, choices
//! POST /api/render                    settings -> a progressive job (supersedes the last)
//! GET  /api/render/{job}              status, levels, rays/s by kind
//! GET  /api/render/{job}/{level}.png  one level's image
//! GET  /api/pixel?job=J&x=X&y=Y       the pixel's ray tree (x, y from the top-left)
//! POST /api/compare                   two samplers against the converged reference
//! GET  /api/compare/{id}/{name}.png   its images
//! ```

use super::api::{self, State};
use super::assets;
use super::http::{ApiError, Reply, read_body};
use anyhow::{Context, Result};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// Request-handling threads: enough that a slow comparison does not hold up the page's polls.
pub(crate) const WORKERS: usize = 4;

/// A bound server.
pub(crate) struct Server {
    http: Arc<tiny_http::Server>,
    /// The port it listens on.
    pub port: u16,
}

impl Server {
    /// Listens on 127.0.0.1:`port` (0: a free port the system chooses).
    pub(crate) fn bind(port: u16) -> Result<Server> {
        let addr = format!("127.0.0.1:{port}");
        let http = tiny_http::Server::http(&addr)
            .map_err(|e| anyhow::anyhow!("{e}"))
            .with_context(|| format!("cannot listen on {addr}"))?;
        let port = http
            .server_addr()
            .to_ip()
            .map(|a| a.port())
            .context("the server has no IP address")?;
        Ok(Server {
            http: Arc::new(http),
            port,
        })
    }

    /// Serves until SIGINT or SIGTERM; returns the signal's name.
    pub(crate) fn serve(self, state: Arc<State>) -> Result<&'static str> {
        use signal_hook::consts::{SIGINT, SIGTERM};
        let stop = Arc::new(AtomicBool::new(false));
        let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM])
            .context("cannot install the signal handler")?;
        let handle = signals.handle();
        let workers: Vec<_> = (0..WORKERS)
            .map(|i| {
                let (http, stop, state) = (self.http.clone(), stop.clone(), state.clone());
                std::thread::Builder::new()
                    .name(format!("http-{i}"))
                    .spawn(move || worker(&http, &stop, &state))
                    .context("cannot start the server's threads")
            })
            .collect::<Result<_>>()?;
        let signal = signals.forever().next();
        handle.close();
        stop.store(true, Ordering::Relaxed);
        for w in workers {
            let _ = w.join();
        }
        Ok(match signal {
            Some(SIGTERM) => "SIGTERM",
            _ => "SIGINT",
        })
    }
}

fn worker(http: &tiny_http::Server, stop: &AtomicBool, state: &State) {
    while !stop.load(Ordering::Relaxed) {
        match http.recv_timeout(Duration::from_millis(100)) {
            Ok(Some(request)) => respond(request, state),
            Ok(None) => {}
            Err(e) => {
                eprintln!("warning: cannot receive a request: {e}");
                std::thread::sleep(Duration::from_millis(100));
            }
        }
    }
}

/// Answers one request; a panic in a handler becomes a 500, not a dead worker.
fn respond(mut request: tiny_http::Request, state: &State) {
    let method = request.method().as_str().to_string();
    let url = request.url().to_string();
    let declared = request.body_length();
    let header = |name: &'static str| {
        request
            .headers()
            .iter()
            .find(|h| h.field.equiv(name))
            .map(|h| h.value.as_str().to_string())
    };
    let (host, origin) = (header("Host"), header("Origin"));
    let reply = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        route(
            &method,
            &url,
            [host.as_deref(), origin.as_deref()],
            declared,
            request.as_reader(),
            state,
        )
        .unwrap_or_else(Reply::from)
    }))
    .unwrap_or_else(|_| {
        Reply::from(ApiError::status(
            500,
            "internal error while answering this request (see the server's log)",
        ))
    });
    let mut response = tiny_http::Response::from_data(reply.body).with_status_code(reply.status);
    let mut add = |name: &str, value: &str| {
        if let Ok(h) = tiny_http::Header::from_bytes(name.as_bytes(), value.as_bytes()) {
            response.add_header(h);
        }
    };
    add("Content-Type", reply.content_type);
    add(
        "Cache-Control",
        if reply.cacheable {
            "max-age=60"
        } else {
            "no-store"
        },
    );
    add("X-Content-Type-Options", "nosniff");
    if let Some(allow) = reply.allow {
        add("Allow", allow);
    }
    if let Some(seconds) = reply.retry_after {
        add("Retry-After", &seconds.to_string());
    }
    // A client that hung up is not our error.
    let _ = request.respond(response);
}

/// The routing table.
fn route(
    method: &str,
    url: &str,
    [host, origin]: [Option<&str>; 2],
    declared: Option<usize>,
    body: &mut dyn std::io::Read,
    state: &State,
) -> Result<Reply, ApiError> {
    check_host(host, state.port)?;
    check_origin(origin, state.port)?;
    let (path, query) = url.split_once('?').unwrap_or((url, ""));
    let segments: Vec<&str> = path.split('/').skip(1).collect();
    let get = |allow: &'static str| {
        if method == "GET" || method == "HEAD" {
            Ok(())
        } else {
            Err(ApiError::method(method, path, allow))
        }
    };
    let post = || {
        if method == "POST" {
            Ok(())
        } else {
            Err(ApiError::method(method, path, "POST"))
        }
    };
    match segments.as_slice() {
        [""] | ["index.html"] => {
            get("GET")?;
            assets::page()
        }
        ["assets", name] => {
            get("GET")?;
            assets::asset(name)
        }
        ["api", "scene"] => {
            get("GET")?;
            Ok(api::scene(state))
        }
        ["api", "render"] => {
            post()?;
            api::render(state, &read_body(declared, body)?)
        }
        ["api", "render", job] => {
            get("GET")?;
            api::render_status(state, job)
        }
        ["api", "render", job, level] => {
            get("GET")?;
            api::render_png(state, job, level)
        }
        ["api", "pixel"] => {
            get("GET")?;
            api::pixel(state, query)
        }
        ["api", "compare"] => {
            post()?;
            api::compare(state, &read_body(declared, body)?)
        }
        ["api", "compare", id, name] => {
            get("GET")?;
            api::compare_png(state, id, name)
        }
        _ => Err(ApiError::not_found(format!(
            "no such path: {} (the page is at /, the API under /api/)",
            crate::render::quote::quote(path)
        ))),
    }
}

/// Refuses requests addressed to another host name: a page elsewhere that resolves its own name
/// to 127.0.0.1 (DNS rebinding) must not reach the API.
fn check_host(host: Option<&str>, port: u16) -> Result<(), ApiError> {
    let ok = host.is_some_and(|h| {
        let name = h.strip_suffix(&format!(":{port}")).unwrap_or(h);
        matches!(name, "127.0.0.1" | "localhost" | "[::1]")
    });
    if ok {
        Ok(())
    } else {
        Err(ApiError::status(
            421,
            format!(
                "unexpected Host `{}`: this server answers only to 127.0.0.1:{port} and localhost:{port}",
                crate::render::quote::quote(host.unwrap_or(""))
            ),
        ))
    }
}

/// Refuses requests that a page from another origin sent (browsers name the page's origin on
/// every POST): such a page could otherwise start renders here.
fn check_origin(origin: Option<&str>, port: u16) -> Result<(), ApiError> {
    let Some(origin) = origin else {
        return Ok(());
    };
    let ours = ["127.0.0.1", "localhost", "[::1]"]
        .iter()
        .any(|h| origin == format!("http://{h}:{port}"));
    if ours {
        Ok(())
    } else {
        Err(ApiError::status(
            403,
            format!(
                "requests from `{}` are refused: only the page at http://127.0.0.1:{port}/ may call this API",
                crate::render::quote::quote(origin)
            ),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_local_host_names_are_served() {
        assert!(check_host(Some("127.0.0.1:8080"), 8080).is_ok());
        assert!(check_host(Some("localhost:8080"), 8080).is_ok());
        assert!(check_host(Some("localhost"), 8080).is_ok());
        assert_eq!(
            check_host(Some("evil.example:8080"), 8080)
                .unwrap_err()
                .status,
            421
        );
        assert_eq!(check_host(None, 8080).unwrap_err().status, 421);
        assert!(check_origin(None, 8080).is_ok());
        assert!(check_origin(Some("http://127.0.0.1:8080"), 8080).is_ok());
        assert_eq!(
            check_origin(Some("http://127.0.0.1:9090"), 8080)
                .unwrap_err()
                .status,
            403
        );
        assert_eq!(
            check_origin(Some("https://evil.example"), 8080)
                .unwrap_err()
                .status,
            403
        );
    }
}
