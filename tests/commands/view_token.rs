//! `raywave view`'s access token and addresses: the page opens with the token in its URL and
//! keeps it as a cookie, scripts send it as a bearer token, every request without it is refused,
//! a token in the wrong place is a 400, and an address other than loopback is served only with
//! a token and a warning. Every route of the router (its table read from src/view/routes.rs),
//! every asset and every image is refused without the token and with a wrong one.

use crate::common;

use common::view::ViewServer;
use std::time::Duration;

const T: &str = "abcdefghijklmnop-1234";

fn error_of(r: &common::view::HttpReply) -> String {
    assert_eq!(r.header("content-type"), Some("application/json"));
    r.json()["error"]
        .as_str()
        .expect("an error message")
        .to_string()
}

#[test]
fn the_page_takes_the_token_once_and_keeps_it_in_a_cookie() {
    let server = ViewServer::start(&["--size", "16", "8"]);
    let token = server.token.clone().expect("a generated token in the URL");
    assert_eq!(token.len(), 48, "{}", server.url());
    assert!(token.bytes().all(|b| b.is_ascii_hexdigit()));
    let port = server.port;

    // Nothing is served without the token: page, assets, API.
    for path in [
        "/",
        "/index.html",
        "/assets/app.mjs",
        "/api/scene",
        "/api/render/1",
    ] {
        let r = server.request_without_token("GET", path, &[], b"");
        assert_eq!(r.status, 403, "{path}");
        assert!(error_of(&r).contains("needs its access token"), "{path}");
    }
    let r = server.request_without_token("POST", "/api/render", &[], b"{}");
    assert_eq!(r.status, 403);
    assert_eq!(
        server.get("/api/render/1").status,
        404,
        "no job was started"
    );

    // The first load: the token in the URL, answered with the cookie.
    let page = server.request_without_token("GET", &format!("/?token={token}"), &[], b"");
    assert_eq!(page.status, 200, "{}", page.text());
    let cookie = page.header("set-cookie").expect("Set-Cookie");
    for part in [
        format!("raywave_token_{port}={token}"),
        "HttpOnly".into(),
        "SameSite=Strict".into(),
        "Path=/".into(),
    ] {
        assert!(cookie.contains(&part), "{cookie} lacks {part}");
    }
    assert_eq!(page.header("referrer-policy"), Some("no-referrer"));
    // Later requests carry the cookie alone.
    let jar = format!("theme=dark; raywave_token_{port}={token}");
    for path in ["/", "/assets/app.mjs", "/api/scene"] {
        let r = server.request_without_token("GET", path, &[("Cookie", &jar)], b"");
        assert_eq!(r.status, 200, "{path}: {}", r.text());
        assert_eq!(
            r.header("set-cookie"),
            None,
            "{path}: set once, on the first load"
        );
    }
    let r = server.request_without_token(
        "POST",
        "/api/render",
        &[
            ("Cookie", &jar),
            ("Origin", &format!("http://127.0.0.1:{port}")),
        ],
        b"{}",
    );
    assert_eq!(r.status, 200, "{}", r.text());
}

/// A refused request: path, headers, status, a part of the message.
type Case<'a> = (&'a str, Vec<(&'a str, &'a str)>, u16, &'a str);

#[test]
fn wrong_and_misplaced_tokens_are_refused() {
    let server = ViewServer::start(&["--size", "16", "8"]);
    let token = server.token.clone().unwrap();
    let port = server.port;
    let other_port = format!("raywave_token_{}={token}", port + 1);
    let wrong_cookie = format!("raywave_token_{port}=0123456789abcdef0123");
    let bearer_in_query = format!("/api/scene?token={token}");
    let cases: Vec<Case> = vec![
        (
            "/?token=0123456789abcdef0123",
            vec![],
            403,
            "wrong access token",
        ),
        (
            "/api/scene",
            vec![("Authorization", "Bearer 0123456789abcdef0123")],
            403,
            "wrong access token",
        ),
        (
            "/api/scene",
            vec![("Cookie", &wrong_cookie)],
            403,
            "wrong access token",
        ),
        // Another server's cookie (another port) is not this one's.
        (
            "/api/scene",
            vec![("Cookie", &other_port)],
            403,
            "needs its access token",
        ),
        // In a URL other than the page's, the token would end up in logs.
        (
            &bearer_in_query,
            vec![],
            400,
            "belongs only in the page's URL",
        ),
        (
            "/api/scene",
            vec![("Authorization", &token)],
            400,
            "expected `Authorization: Bearer TOKEN`",
        ),
        (
            "/api/scene",
            vec![("Authorization", "Basic dXNlcjpwYXNz")],
            400,
            "expected `Authorization: Bearer TOKEN`",
        ),
        (
            "/api/scene",
            vec![("Authorization", "Bearer")],
            400,
            "expected `Authorization: Bearer TOKEN`",
        ),
    ];
    for (path, headers, status, message) in cases {
        let r = server.request_without_token("GET", path, &headers, b"");
        assert_eq!(r.status, status, "{path} {headers:?}: {}", r.text());
        let error = error_of(&r);
        assert!(
            error.contains(message),
            "{path}: {error:?} lacks {message:?}"
        );
        assert!(
            !error.contains(&token),
            "{path}: the error repeats the token"
        );
    }
    // And the server goes on serving.
    assert_eq!(server.get("/api/scene").status, 200);
}

#[test]
fn a_token_can_be_fixed_by_flag_or_variable_and_checked() {
    let server = ViewServer::start(&["--size", "16", "8", "--token", T]);
    assert_eq!(server.token.as_deref(), Some(T));
    assert_eq!(server.get("/api/scene").status, 200);
    drop(server);
    let server = ViewServer::start_with(&["--size", "16", "8"], &[("RAYWAVE_VIEW_TOKEN", T)]);
    assert_eq!(server.token.as_deref(), Some(T));
    let r = server.request_without_token(
        "GET",
        "/api/scene",
        &[("Authorization", &format!("Bearer {T}"))],
        b"",
    );
    assert_eq!(r.status, 200);
    drop(server);

    // --help does not show the variable's value.
    let out = std::process::Command::new(crate::common::bin::exe())
        .args(["view", "--help"])
        .env("RAYWAVE_VIEW_TOKEN", T)
        .output()
        .unwrap();
    let help = String::from_utf8_lossy(&out.stdout);
    assert!(help.contains("RAYWAVE_VIEW_TOKEN"), "{help}");
    assert!(!help.contains(T), "--help shows the token: {help}");
}

#[test]
fn bad_tokens_and_unsafe_binds_are_refused_at_start_with_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&[&str], &str); 6] = [
        (&["--token", "short"], "16 to 256"),
        (&["--token", "spaces are not allowed here"], "only letters"),
        (&["--bind", "0.0.0.0", "--no-token"], "needs its token"),
        (&["--bind", "::", "--no-token"], "needs its token"),
        (&["--bind", "example.org"], "invalid IP address"),
        (&["--token", T, "--no-token"], "cannot be used with"),
    ];
    for (args, message) in cases {
        let mut all = vec!["view"];
        all.extend_from_slice(args);
        let out = common::bin::raywave(dir.path(), &all);
        let err = common::bin::stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(message), "{args:?}: {err:?} lacks {message:?}");
    }
}

#[test]
fn every_interface_is_served_only_with_the_token_and_a_warning() {
    let server = ViewServer::start(&["--size", "16", "8", "--bind", "0.0.0.0"]);
    assert!(server.token.is_some());
    // A LAN name is fine once the server is not loopback-only; the token still decides.
    let lan = format!("raywave-lab.local:{}", server.port);
    assert_eq!(
        server
            .request("GET", "/api/scene", &[("Host", &lan)], b"")
            .status,
        200
    );
    assert_eq!(
        server
            .request_without_token("GET", "/api/scene", &[("Host", &lan)], b"")
            .status,
        403
    );
    let (status, stderr) = server.stop(libc::SIGTERM, Duration::from_secs(10));
    assert_eq!(status.code(), Some(143), "{stderr}");
    assert!(
        stderr.contains("warning: --bind 0.0.0.0: serving on every interface"),
        "{stderr}"
    );
}

#[test]
fn an_ssh_tunnel_on_another_port_is_served() {
    // ssh -L 9999:localhost:PORT: the browser names localhost:9999, its page's origin too.
    let server = ViewServer::start(&["--size", "16", "8"]);
    let headers = [
        ("Host", "localhost:9999"),
        ("Origin", "http://localhost:9999"),
    ];
    let r = server.request("POST", "/api/render", &headers, b"{}");
    assert_eq!(r.status, 200, "{}", r.text());
    // But a page of another origin through the same tunnel is not.
    let headers = [
        ("Host", "localhost:9999"),
        ("Origin", "http://localhost:8888"),
    ];
    assert_eq!(
        server
            .request("POST", "/api/render", &headers, b"{}")
            .status,
        403
    );
}

#[test]
fn no_token_serves_loopback_openly() {
    let server = ViewServer::start(&["--size", "16", "8", "--no-token"]);
    assert_eq!(server.token, None, "{}", server.url());
    let r = server.request_without_token("GET", "/api/scene", &[], b"");
    assert_eq!(r.status, 200);
}

/// One arm of the routing table in src/view/routes.rs: its alternatives (each a list of
/// segments, `Some(literal)` or `None` for a segment the arm binds), the methods it serves, and
/// its text for messages.
struct Route {
    alternatives: Vec<Vec<Option<String>>>,
    methods: &'static [&'static str],
    text: String,
}

/// The routing table, read from the router's source: every arm of `match segments.as_slice()`
/// in `route`, up to the fallback. Reading it here (rather than listing the routes by hand) is
/// what makes a route added there a route this file requests; a pattern it cannot read fails
/// the test, naming it.
fn routing_table() -> Vec<Route> {
    let source = include_str!(concat!(env!("RAYWAVE_REPO"), "/src/view/routes.rs"));
    let (_, table) = source.split_once("match segments.as_slice() {").expect(
        "src/view/routes.rs: no `match segments.as_slice()` in `route`: update routing_table()",
    );
    let (table, _) = table
        .split_once("\n        _ =>")
        .expect("src/view/routes.rs: no `_ =>` fallback after the routes: update routing_table()");
    let mut arms: Vec<(String, String)> = Vec::new();
    for line in table.lines() {
        let trimmed = line.trim();
        match trimmed.split_once("=>") {
            Some((pattern, body)) if trimmed.starts_with('[') => {
                arms.push((pattern.trim().to_string(), body.to_string()))
            }
            _ => {
                if let Some((_, body)) = arms.last_mut() {
                    body.push_str(trimmed);
                }
            }
        }
    }
    let segment = |s: &str, text: &str| -> Option<String> {
        let s = s.trim();
        if let Some(literal) = s.strip_prefix('"').and_then(|s| s.strip_suffix('"')) {
            return Some(literal.to_string());
        }
        assert!(
            !s.is_empty() && s != "_" && s.bytes().all(|b| b.is_ascii_lowercase() || b == b'_'),
            "routes.rs: segment `{s}` of `{text}` is neither a literal nor a binding: teach routing_table() to read it"
        );
        None
    };
    arms.into_iter()
        .map(|(text, body)| {
            let alternatives = text
                .split('|')
                .map(|alt| {
                    let inner = alt
                        .trim()
                        .strip_prefix('[')
                        .and_then(|a| a.strip_suffix(']'))
                        .unwrap_or_else(|| panic!("routes.rs: cannot read the pattern `{text}`"));
                    inner.split(',').map(|s| segment(s, &text)).collect()
                })
                .collect();
            let (get, post) = (body.contains("get("), body.contains("post()"));
            let methods: &'static [&'static str] = match (get, post) {
                (true, false) => &["GET", "HEAD"],
                (false, true) => &["POST"],
                _ => panic!(
                    "routes.rs: `{text}` calls neither get(..) nor post() alone: which method does it serve?"
                ),
            };
            Route {
                alternatives,
                methods,
                text,
            }
        })
        .collect()
}

/// Whether the path of `url` (its query left out) is one of `route`'s, segment by segment as
/// the router splits it.
fn matches(route: &Route, url: &str) -> bool {
    let path = url.split('?').next().unwrap_or(url);
    let segments: Vec<&str> = path.split('/').skip(1).collect();
    route.alternatives.iter().any(|alt| {
        alt.len() == segments.len()
            && alt
                .iter()
                .zip(&segments)
                .all(|(want, got)| want.as_deref().is_none_or(|w| w == *got))
    })
}

/// A reply's body for a message: JSON as it is, anything else by its type and length.
fn shown(r: &common::view::HttpReply) -> String {
    match r.header("content-type") {
        Some("application/json") => r.text(),
        other => format!("{} bytes of {}", r.body.len(), other.unwrap_or("no type")),
    }
}

/// Every string in `v` that is a URL of the API (a comparison names its images so).
fn api_urls(v: &serde_json::Value, out: &mut Vec<String>) {
    match v {
        serde_json::Value::String(s) if s.starts_with("/api/") => out.push(s.clone()),
        serde_json::Value::Array(a) => a.iter().for_each(|v| api_urls(v, out)),
        serde_json::Value::Object(o) => o.values().for_each(|v| api_urls(v, out)),
        _ => {}
    }
}

/// The status of a raw reply (a HEAD reply has a Content-Length and no body, which
/// `parse_reply` takes for a short body).
fn status_of(raw: &[u8]) -> u16 {
    let line = String::from_utf8_lossy(raw);
    line.split(' ')
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no status line in {line:?}"))
}

/// A request to refuse: target, headers, a part of the message.
type Try<'a> = (String, Vec<(&'a str, &'a str)>, &'a str);

#[test]
fn every_route_refuses_a_missing_or_wrong_token() {
    let server = ViewServer::start(&["--size", "16", "8", "--bounces", "0"]);
    let token = server.token.clone().expect("a token");
    let port = server.port;
    let wrong = "0123456789abcdef0123";
    assert_ne!(token, wrong);

    // Every URL the server serves: the page, each file under assets/ (the directory listed, so
    // a new file is covered), the API, and every image, as the server's own answers name them.
    let mut urls: Vec<String> = vec!["/".into(), "/index.html".into(), "/api/scene".into()];
    let assets = concat!(env!("RAYWAVE_REPO"), "/src/view/assets");
    let mut files: Vec<String> = std::fs::read_dir(assets)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|name| name != "index.html")
        .collect();
    files.sort();
    assert!(files.len() >= 10, "{files:?}");
    urls.extend(files.iter().map(|f| format!("/assets/{f}")));
    let (job, status) = server.render("{}", Duration::from_secs(60));
    urls.push("/api/render".into());
    urls.push(format!("/api/render/{job}"));
    let levels = status["levels"].as_array().expect("levels").len();
    assert_eq!(
        levels,
        status["sizes"].as_array().unwrap().len(),
        "{status}"
    );
    urls.extend((0..levels).map(|k| format!("/api/render/{job}/{k}.png")));
    urls.push(format!("/api/pixel?job={job}&x=1&y=1"));
    let compare = server.post(
        "/api/compare",
        r#"{"samplers": ["random", "sobol"], "n": 2, "seeds": 2, "size": 8, "reference_samples": 16}"#,
    );
    assert_eq!(compare.status, 200, "{}", compare.text());
    urls.push("/api/compare".into());
    let before = urls.len();
    api_urls(&compare.json(), &mut urls);
    assert!(urls.len() - before >= 6, "{}", compare.text());

    // Each URL is one route's, and each route of the table has a URL here.
    let table = routing_table();
    assert!(
        table.len() >= 9,
        "{} routes read from routes.rs",
        table.len()
    );
    let mut requests: Vec<(&str, &str)> = Vec::new();
    for url in &urls {
        let route = table
            .iter()
            .find(|r| matches(r, url))
            .unwrap_or_else(|| panic!("{url} is none of routes.rs's routes"));
        requests.extend(route.methods.iter().map(|m| (*m, url.as_str())));
    }
    for route in &table {
        assert!(
            urls.iter().any(|u| matches(route, u)),
            "routes.rs serves `{}`, which this test requests nowhere: add a URL for it",
            route.text
        );
    }
    // With the token each GET is served: every URL above is a live one.
    for (method, url) in &requests {
        if *method == "GET" {
            let r = server.get(url);
            assert_eq!(r.status, 200, "GET {url} with the token: {}", shown(&r));
        }
    }
    // And paths that are no route: refused before they are looked up.
    requests.extend([
        ("GET", "/no/such/page"),
        ("GET", "/api/nope"),
        ("GET", "/x.png"),
    ]);
    let wrong_bearer = format!("Bearer {wrong}");
    let wrong_cookie = format!("raywave_token_{port}={wrong}");
    let mut refused = 0;
    for (method, url) in &requests {
        let mut tries: Vec<Try> = vec![
            (url.to_string(), vec![], "needs its access token"),
            (
                url.to_string(),
                vec![("Authorization", &wrong_bearer)],
                "wrong access token",
            ),
            (
                url.to_string(),
                vec![("Cookie", &wrong_cookie)],
                "wrong access token",
            ),
        ];
        // The page is the one path that takes the token in its query.
        if matches!(*url, "/" | "/index.html") {
            tries.push((format!("{url}?token={wrong}"), vec![], "wrong access token"));
        }
        for (target, headers, message) in tries {
            let body: &[u8] = if *method == "POST" { b"{}" } else { b"" };
            let what = format!("{method} {target} {headers:?}");
            if *method == "HEAD" {
                let mut head = format!(
                    "HEAD {target} HTTP/1.1\r\nConnection: close\r\nHost: 127.0.0.1:{port}\r\n"
                );
                for (n, v) in &headers {
                    head += &format!("{n}: {v}\r\n");
                }
                head += "\r\n";
                assert_eq!(status_of(&server.raw(head.as_bytes())), 403, "{what}");
            } else {
                let r = server.request_without_token(method, &target, &headers, body);
                assert_eq!(r.status, 403, "{what}: {}", shown(&r));
                let error = error_of(&r);
                assert!(
                    error.contains(message),
                    "{what}: {error:?} lacks {message:?}"
                );
            }
            refused += 1;
        }
    }
    assert!(refused > 100, "{refused} requests refused");
    // Nothing the refused POSTs asked for was started: the last job is still the test's own.
    let r = server.get(&format!("/api/render/{}", job + 1));
    assert_eq!(r.status, 404, "a refused POST started a job: {}", r.text());
}
