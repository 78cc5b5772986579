//! `raywave view`'s access token and addresses: the page opens with the token in its URL and
//! keeps it as a cookie, scripts send it as a bearer token, every request without it is refused,
//! a token in the wrong place is a 400, and an address other than loopback is served only with
//! a token and a warning.

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
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_raywave"))
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
