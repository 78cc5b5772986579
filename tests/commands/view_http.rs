//! `raywave view` over HTTP: the binary on a free port, every endpoint answered, every kind of
//! bad request refused with its 4xx and a message naming the problem, and a clean stop on
//! SIGINT and SIGTERM.
//!
//! The expected values come from the scene and the request, not from the server: the built-in
//! Cornell box has one area light (the face at z = 1), and the centre of the image looks at the
//! back wall, so with hard shadows and no bounces its tree is one camera ray and one shadow ray.

use crate::common;

use common::view::{ViewServer, png_size};
use std::time::Duration;

const LIMIT: Duration = Duration::from_secs(60);

#[test]
fn every_endpoint_answers() {
    let server = ViewServer::start(&["--size", "32", "16", "--bounces", "0", "--shadows", "hard"]);

    let page = server.get("/");
    assert_eq!(page.status, 200);
    assert!(
        page.header("content-type")
            .unwrap()
            .starts_with("text/html")
    );
    assert!(page.text().contains("<title>raywave view</title>"));
    // The page loads app.mjs as a module; it imports the others.
    assert!(
        page.text()
            .contains(r#"<script type="module" src="/assets/app.mjs">"#)
    );
    let app = server.get("/assets/app.mjs").text();
    for asset in [
        "app", "gl", "compare", "orbit", "math", "tree", "settings", "token", "render", "debounce",
    ] {
        let r = server.get(&format!("/assets/{asset}.mjs"));
        assert_eq!(r.status, 200, "{asset}");
        assert!(
            r.header("content-type")
                .unwrap()
                .starts_with("text/javascript")
        );
        assert!(
            r.text().contains("export ") || asset == "app",
            "{asset} is a module"
        );
    }
    assert!(
        app.contains("from './gl.mjs'"),
        "app.mjs imports the others"
    );
    assert_eq!(server.get("/assets/style.css").status, 200);

    let scene = server.get("/api/scene").json();
    // 6 quads of the box = 12 triangles, 3 spheres, 1 light with 4 corners.
    assert_eq!(
        scene["scene"]["positions"].as_array().unwrap().len(),
        12 * 9
    );
    assert_eq!(scene["scene"]["spheres"].as_array().unwrap().len(), 3);
    assert_eq!(scene["scene"]["lights"][0].as_array().unwrap().len(), 4);
    assert_eq!(scene["settings"]["width"], 32);
    assert_eq!(scene["settings"]["shadows"], "hard");
    assert_eq!(
        scene["palette"]["reflection"],
        serde_json::json!([255, 40, 40])
    );

    let (job, status) = server.render("{}", LIMIT);
    // Levels at 1/8, 1/4, 1/2 and 1 of 32×16, coarse to fine.
    assert_eq!(
        status["sizes"],
        serde_json::json!([[4, 2], [8, 4], [16, 8], [32, 16]])
    );
    let levels = status["levels"].as_array().unwrap();
    assert_eq!(levels.len(), 4);
    for (level, (w, h)) in levels.iter().zip([(4u64, 2u64), (8, 4), (16, 8), (32, 16)]) {
        // One camera ray per pixel; at most one shadow ray per camera hit (one light, hard
        // shadows), and some: the middle of the image is the back wall.
        let rays = &level["rays"];
        assert_eq!(rays["camera"]["rays"], w * h);
        let shadow = rays["shadow"]["rays"].as_u64().unwrap();
        assert!(shadow > 0 && shadow <= w * h, "{level}");
        assert_eq!(rays["reflection"]["rays"], 0);
        assert!(rays["total"]["rays_per_second"].as_f64().unwrap() > 0.0);
    }
    for (k, size) in [(0, (4, 2)), (3, (32, 16))] {
        let png = server.get(&format!("/api/render/{job}/{k}.png"));
        assert_eq!(png.status, 200);
        assert_eq!(png.header("content-type"), Some("image/png"));
        assert_eq!(png_size(&png.body), size);
    }

    let tree = server.get(&format!("/api/pixel?job={job}&x=16&y=8"));
    assert_eq!(tree.status, 200, "{}", tree.text());
    let tree = tree.json();
    assert_eq!(tree["pixel"]["x"], 16);
    assert_eq!(tree["pixel"]["y"], 8);
    let kinds: Vec<&str> = tree["segments"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["kind"].as_str().unwrap())
        .collect();
    assert_eq!(kinds, ["camera", "shadow"]);
    assert_eq!(tree["check"]["agrees"], true, "{}", tree["check"]);

    let compare = server.post(
        "/api/compare",
        r#"{"samplers": ["random", "sobol"], "n": 2, "seeds": 2, "size": 16, "reference_samples": 64}"#,
    );
    assert_eq!(compare.status, 200, "{}", compare.text());
    let compare = compare.json();
    assert_eq!(compare["sides"][0]["sampler"], "random");
    assert_eq!(compare["sides"][1]["sampler"], "sobol");
    // The longer side is 16, the aspect ratio the render's (2:1).
    assert_eq!(
        (compare["width"].clone(), compare["height"].clone()),
        (16.into(), 8.into())
    );
    for url in [
        compare["reference"].as_str().unwrap(),
        compare["sides"][0]["image"].as_str().unwrap(),
        compare["sides"][1]["heat"].as_str().unwrap(),
    ] {
        let png = server.get(url);
        assert_eq!(png.status, 200, "{url}");
        assert_eq!(png_size(&png.body), (16, 8), "{url}");
    }
    for side in compare["sides"].as_array().unwrap() {
        let mse = &side["mse"];
        assert!(mse["mean"].as_f64().unwrap() > 0.0, "{side}");
        assert!(mse["se"].as_f64().unwrap() >= 0.0, "{side}");
        // Where the error sits: a spectrum of 32 rings and the low band's share.
        let p = &side["perceived"];
        assert_eq!(p["spectrum"].as_array().unwrap().len(), 32, "{side}");
        assert!(
            p["low_band_share"].as_f64().is_some_and(f64::is_finite),
            "{side}"
        );
    }
    let spectrum = compare["spectrum"].as_str().unwrap();
    let png = server.get(spectrum);
    assert_eq!(png.status, 200, "{spectrum}");
    assert_eq!(png_size(&png.body), (640, 400), "{spectrum}");
}

#[test]
fn the_cost_map_overlay_is_each_levels_map_and_leaves_the_image_as_it_is() {
    let server = ViewServer::start(&["--size", "32", "16", "--bounces", "0", "--shadows", "hard"]);
    let (plain, _) = server.render("{}", LIMIT);
    let (job, status) = server.render(r#"{"cost_map": "camera", "cost_measure": "tests"}"#, LIMIT);
    assert_eq!(status["settings"]["cost_map"], "camera");
    let levels = status["levels"].as_array().unwrap();
    for (k, (level, size)) in levels
        .iter()
        .zip([(4, 2), (8, 4), (16, 8), (32, 16)])
        .enumerate()
    {
        // The built-in box has no BVH: every camera ray tests its 12 triangles and 3 spheres.
        let cost = &level["cost"];
        assert_eq!(cost["kind"], "camera", "{level}");
        assert_eq!(cost["measure"], "tests");
        assert_eq!(cost["per_ray"], 15.0);
        assert_eq!(
            (cost["largest"].as_f64(), cost["high"].as_f64()),
            (Some(15.0), Some(16.0))
        );
        let png = server.get(&format!("/api/render/{job}/{k}.cost.png"));
        assert_eq!(png.status, 200, "{}", png.text());
        assert_eq!(png.header("content-type"), Some("image/png"));
        assert_eq!(png_size(&png.body), size);
        // The counted render's image is the uncounted one's, byte for byte.
        let counted = server.get(&format!("/api/render/{job}/{k}.png")).body;
        assert!(
            counted == server.get(&format!("/api/render/{plain}/{k}.png")).body,
            "level {k}"
        );
    }
    let none = server.get(&format!("/api/render/{plain}/0.cost.png"));
    assert_eq!(none.status, 404);
    assert!(none.text().contains("has no cost map"), "{}", none.text());
    assert!(server.get(&format!("/api/render/{plain}")).json()["levels"][0]["cost"].is_null());
}

/// A bad request: method, path, extra headers, body, the status and a part of the message.
type Case<'a> = (
    &'a str,
    String,
    Vec<(&'a str, &'a str)>,
    &'a [u8],
    u16,
    &'a str,
);

#[test]
fn bad_requests_get_their_4xx_and_a_message() {
    let server = ViewServer::start(&["--size", "32", "16", "--bounces", "0"]);
    let (job, _) = server.render("{}", LIMIT);
    let big = vec![b' '; 70_000];
    let pixel = |q: &str| format!("/api/pixel?{q}");
    let cases: Vec<Case> = vec![
        ("GET", "/nope".into(), vec![], b"", 404, "no such path"),
        ("GET", "/assets/nope.js".into(), vec![], b"", 404, "no asset"),
        ("DELETE", "/api/scene".into(), vec![], b"", 405, "DELETE is not allowed"),
        ("GET", "/api/render".into(), vec![], b"", 405, "expected POST"),
        ("PUT", "/api/compare".into(), vec![], b"", 405, "expected POST"),
        ("POST", "/api/render".into(), vec![], b"{", 400, "settings:"),
        ("POST", "/api/render".into(), vec![], br#"{"width": 0}"#, 400, "width must be in 1..=2048"),
        ("POST", "/api/render".into(), vec![], br#"{"bounces": 65}"#, 400, "bounces must be in 0..=64"),
        ("POST", "/api/render".into(), vec![], br#"{"sampler": "best"}"#, 400, "unknown variant `best`"),
        ("POST", "/api/render".into(), vec![], br#"{"colour": 1}"#, 400, "unknown field `colour`"),
        ("POST", "/api/render".into(), vec![], br#"{"width": "wide"}"#, 400, "invalid type"),
        (
            "POST",
            "/api/render".into(),
            vec![],
            br#"{"camera": {"position": [0,0,1], "look_at": [0,0,1], "up": [0,1,0], "fov_degrees": 30}}"#,
            400,
            "same point",
        ),
        (
            "POST",
            "/api/render".into(),
            vec![],
            br#"{"cost_map": "all", "engine": "reference"}"#,
            400,
            "cost_map counts the wavefront engine's traversal",
        ),
        ("POST", "/api/render".into(), vec![], &big, 413, "too large"),
        ("POST", "/api/compare".into(), vec![], br#"{"seeds": 1}"#, 400, "seeds must be in 2..=16"),
        ("POST", "/api/compare".into(), vec![], &big, 413, "too large"),
        ("GET", "/api/render/abc".into(), vec![], b"", 400, "expected a job number"),
        ("GET", "/api/render/999".into(), vec![], b"", 404, "no render job 999"),
        ("GET", format!("/api/render/{job}/9.png"), vec![], b"", 404, "not 9"),
        ("GET", format!("/api/render/{job}/1.gif"), vec![], b"", 400, "expected a level"),
        ("GET", format!("/api/render/{job}/x.cost.png"), vec![], b"", 400, "N.cost.png"),
        ("GET", pixel(&format!("job={job}&x=32&y=0")), vec![], b"", 400, "outside the 32×16 image"),
        ("GET", pixel(&format!("job={job}&x=0&y=16")), vec![], b"", 400, "outside the 32×16 image"),
        ("GET", pixel(&format!("job={job}&x=-1&y=0")), vec![], b"", 400, "expected a whole number, found `-1`"),
        ("GET", pixel(&format!("job={job}&x=1")), vec![], b"", 400, "missing query parameter `y`"),
        ("GET", pixel("x=1&y=1"), vec![], b"", 400, "missing query parameter `job`"),
        ("GET", pixel(&format!("job={job}&x=1&y=1&z=2")), vec![], b"", 400, "unknown query parameter `z`"),
        ("GET", pixel(&format!("job={job}&x=1&x=2&y=1")), vec![], b"", 400, "given twice"),
        ("GET", pixel("job=999&x=1&y=1"), vec![], b"", 404, "no render job 999"),
        ("GET", "/api/compare/1/nope.png".into(), vec![], b"", 404, "no image"),
        ("GET", "/api/compare/x/a.png".into(), vec![], b"", 400, "expected a comparison number"),
        ("GET", "/api/scene".into(), vec![("Host", "evil.example")], b"", 421, "unexpected Host"),
        ("POST", "/api/render".into(), vec![("Origin", "http://evil.example")], b"{}", 403, "are refused"),
        // Both checks come before routing: the page, an asset and the other verbs refuse alike.
        ("GET", "/".into(), vec![("Host", "evil.example")], b"", 421, "unexpected Host"),
        ("POST", "/api/render".into(), vec![("Host", "evil.example")], b"{}", 421, "unexpected Host"),
        ("GET", "/api/scene".into(), vec![("Origin", "http://evil.example")], b"", 403, "are refused"),
        ("GET", "/assets/app.mjs".into(), vec![("Origin", "http://evil.example")], b"", 403, "are refused"),
    ];
    for (method, path, headers, body, status, message) in cases {
        let r = server.request(method, &path, &headers, body);
        let what = format!("{method} {path} ({} bytes)", body.len());
        assert_eq!(r.status, status, "{what}: {}", r.text());
        assert_eq!(r.header("content-type"), Some("application/json"), "{what}");
        let json = r.json();
        let error = json["error"]
            .as_str()
            .unwrap_or_else(|| panic!("{what}: {json}"));
        assert!(
            error.contains(message),
            "{what}: {error:?} lacks {message:?}"
        );
        if status == 405 {
            assert!(r.header("allow").is_some(), "{what}: no Allow header");
        }
    }
    // A tree too large to show: 64 aa × 65 depths × (1 + 4096 points) segments at most.
    let r = server.post(
        "/api/render",
        r#"{"width": 2, "height": 2, "aa": 64, "bounces": 64, "shadows": "soft", "shadow_samples": 4096}"#,
    );
    let huge = r.json()["job"].as_u64().unwrap();
    let r = server.get(&format!("/api/pixel?job={huge}&x=0&y=0"));
    assert_eq!(r.status, 400, "{}", r.text());
    assert!(
        r.json()["error"]
            .as_str()
            .unwrap()
            .contains(&format!("{} segments", 64 * 65 * 4097))
    );
    // Still serving, and the job is unharmed.
    assert_eq!(server.get("/api/scene").status, 200);
    assert_eq!(server.get(&format!("/api/render/{job}/3.png")).status, 200);
}

#[test]
fn sigint_and_sigterm_stop_it_cleanly_even_mid_render() {
    for (signal, name) in [(libc::SIGINT, "SIGINT"), (libc::SIGTERM, "SIGTERM")] {
        let server = ViewServer::start(&["--size", "64", "64"]);
        let port = server.port;
        // A render that is still going when the signal arrives.
        let r = server.post(
            "/api/render",
            r#"{"width": 1024, "height": 1024, "shadows": "soft", "shadow_samples": 256}"#,
        );
        assert_eq!(r.status, 200, "{}", r.text());
        let (status, stderr) = server.stop(signal, Duration::from_secs(10));
        assert_eq!(status.code(), Some(128 + signal), "{name}: {stderr}");
        assert!(stderr.contains(&format!("stopped by {name}")), "{stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
        // The port is free again.
        std::net::TcpListener::bind(("127.0.0.1", port))
            .unwrap_or_else(|e| panic!("{name}: port {port} still taken: {e}"));
    }
}

#[test]
fn a_busy_port_and_an_oversized_image_are_refused_before_serving() {
    let taken = std::net::TcpListener::bind(("127.0.0.1", 0)).unwrap();
    let port = taken.local_addr().unwrap().port().to_string();
    let dir = tempfile::tempdir().unwrap();
    let out = common::bin::raywave(dir.path(), &["view", "--port", &port]);
    assert_eq!(out.status.code(), Some(1));
    let err = common::bin::stderr(&out);
    assert!(
        err.contains(&format!("cannot listen on 127.0.0.1:{port}")),
        "{err}"
    );

    let out = common::bin::raywave(dir.path(), &["view", "--size", "4096", "16"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(common::bin::stderr(&out).contains("at most 2048"));
}
