//! `raywave view` in a real browser: headless Chromium (WebGL through SwiftShader) driven by
//! chromedriver over WebDriver (webdriver.rs). On the built-in lab box: the page opens with the
//! 3D view framed on the scene and the render camera; the progressive render arrives level by
//! level, with its progress; the render canvas equals `raywave render`'s PNG pixel for pixel
//! for three settings (pixels.rs); a click, or `t` over the render, draws that pixel's ray tree
//! and `Escape` clears it; `r` renders again; a bad setting is refused with a message; an orbit
//! with "re-render as I orbit" renders from the 3D camera once the hand stops; the comparison
//! mode shows its images.
//!
//! Needs Debian's `chromium` and `chromium-driver` (`.ci/run` installs them). Without them the
//! test prints SKIPPED and passes, unless CI is set: then it fails.
//!
//! The expected tree sizes come from the scene: the built-in Cornell box has one area light,
//! and the centre of the image looks at the back wall, which faces the light. With no bounces,
//! its tree is the camera ray and one shadow ray per light point: 1 + 1 with hard shadows,
//! 1 + 4 with 4 soft-shadow points.
//!
//! RAYWAVE_VIEW_SCREENSHOT=FILE.png saves a screenshot of the page with a render and a ray tree
//! (a relative path is from the package root; docs/images/viewer.png is made so).

mod pixels;
mod webdriver;

use crate::common;
use crate::common::skip::skip_or_fail;
use common::view::ViewServer;
use serde_json::{Value, json};
use std::path::PathBuf;
use std::time::{Duration, Instant};
use webdriver::{Driver, ELEMENT, Session, find};

/// How long any one thing may take to appear on the page.
const WAIT: Duration = Duration::from_secs(45);
/// WebDriver's code of the Escape key.
const ESCAPE: &str = "\u{E00C}";

/// Waits until `css`'s attribute `name` satisfies `ok`, and returns it.
fn wait_attr(c: &Session, css: &str, name: &str, ok: impl Fn(&str) -> bool) -> String {
    let start = Instant::now();
    let mut last = None;
    while start.elapsed() < WAIT {
        if let Some(el) = c.find(css) {
            last = c.attr(&el, name);
            if last.as_deref().is_some_and(&ok) {
                return last.unwrap_or_default();
            }
        }
        std::thread::sleep(Duration::from_millis(30));
    }
    let error = c.find("#error").map(|e| c.text(&e)).unwrap_or_default();
    panic!("{css}[{name}] is {last:?} after {WAIT:?}; the page's error line: {error:?}");
}

/// Waits for the job after `previous` to be rendered at every level; returns its id.
fn wait_render(c: &Session, previous: u64) -> u64 {
    let job = wait_attr(c, "#render", "data-job", |v| {
        v.parse::<u64>().is_ok_and(|j| j > previous)
    });
    wait_attr(c, "#render", "data-state", |v| v == "done");
    let levels = wait_attr(c, "#render", "data-levels", |v| v != "0");
    wait_attr(c, "#render", "data-level", |v| v == levels);
    job.parse().unwrap_or_default()
}

fn text_of(c: &Session, css: &str) -> String {
    c.text(&c.find(css).unwrap_or_else(|| panic!("no {css}")))
}

/// Waits for the tree of pixel (x, y) with `expected` segments (any count when None), in the
/// table and in the 3D view.
fn wait_tree(c: &Session, x: u32, y: u32, expected: Option<usize>) {
    // The pixel first: a tree of another pixel still on screen has its own count.
    wait_attr(c, "#tree", "data-x", |v| v == x.to_string());
    wait_attr(c, "#tree", "data-y", |v| v == y.to_string());
    let n = expected.map(|n| n.to_string());
    let fits = |v: &str| n.as_deref().map_or(!v.is_empty() && v != "0", |n| v == n);
    let count = wait_attr(c, "#tree", "data-segments", fits);
    let title = c
        .find("#tree-title")
        .map(|e| c.text(&e))
        .unwrap_or_default();
    assert_eq!(
        c.find_all("#segments tbody tr").to_string(),
        count,
        "table rows against data-segments; the tree's title: {title}"
    );
    wait_attr(c, "#view3d", "data-segments", |v| v == count);
}

// The render is shown 512 CSS pixels wide for a 64-pixel image, 8 per pixel: (4, 4) from its
// centre is the middle of pixel (32, 32).
fn click_centre_and_count(c: &Session, expected: usize) {
    c.click_at(&c.find("#render").expect("the render"), 4, 4);
    wait_tree(c, 32, 32, Some(expected));
}

fn set_value(c: &Session, css: &str, value: &str) {
    c.execute(
        "const el = document.querySelector(arguments[0]); el.value = arguments[1];",
        vec![css.into(), value.into()],
    );
}

/// Sets the settings form's fields and sends the change, as a user's edit does.
fn set_settings(c: &Session, fields: &[(&str, &str)]) {
    for (name, value) in fields {
        set_value(c, &format!("#settings [name={name}]"), value);
    }
    c.execute(
        "document.getElementById('settings').dispatchEvent(new Event('change'));
         document.activeElement.blur();",
        vec![],
    );
}

/// The 3D view opened framed: every corner of the scene's bounds and of the render camera's
/// frame (the server's) projects inside the canvas, and together they fill it, centred.
fn assert_fitted(c: &Session, server: &ViewServer, job: u64) {
    let scene = server.get("/api/scene").json();
    let [lo, hi] = [0, 1].map(|k| scene["scene"]["bounds"][k].clone());
    let mut points = Vec::new();
    for k in 0..8 {
        let pick = |axis: usize| if k >> axis & 1 == 1 { &hi } else { &lo }[axis].clone();
        points.push(json!([pick(0), pick(1), pick(2)]));
    }
    let status = server.get(&format!("/api/render/{job}")).json();
    let frame = &status["frame"];
    points.push(frame["eye"].clone());
    points.extend(
        frame["corners"]
            .as_array()
            .expect("corners")
            .iter()
            .cloned(),
    );
    // The page's own frame of the scene camera is the server's.
    let page_frame = c.execute(
        "const s = window.raywave.app.sceneCamera; return window.raywave.renderFrame(s, 64, 64);",
        vec![],
    );
    let flat = |v: &Value| -> Vec<f64> {
        let mut out = v["eye"].as_array().unwrap().to_vec();
        out.extend(
            v["corners"]
                .as_array()
                .unwrap()
                .iter()
                .flat_map(|c| c.as_array().unwrap().clone()),
        );
        out.iter().map(|x| x.as_f64().unwrap()).collect()
    };
    for (a, b) in flat(&page_frame).iter().zip(flat(frame)) {
        assert!(
            (a - b).abs() < 1e-5,
            "the page's frame {page_frame} is not the server's {frame}"
        );
    }
    let projected = c.execute(
        "return window.raywave.app.view.project(arguments[0]);",
        vec![Value::Array(points.clone())],
    );
    let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
    for (p, q) in points
        .iter()
        .zip(projected.as_array().expect("projected points"))
    {
        let [x, y, w] = ["x", "y", "w"].map(|k| q[k].as_f64().unwrap_or(f64::NAN));
        assert!(
            w > 0.0 && x.abs() <= 1.0 && y.abs() <= 1.0,
            "{p} is off the 3D view: {q}"
        );
        for (k, v) in [x, y].into_iter().enumerate() {
            lo[k] = lo[k].min(v);
            hi[k] = hi[k].max(v);
        }
    }
    let (centre, half) = (
        [0, 1].map(|k| (lo[k] + hi[k]) / 2.0),
        [0, 1].map(|k| (hi[k] - lo[k]) / 2.0),
    );
    assert!(
        centre.iter().all(|m| m.abs() < 0.1) && half.iter().any(|h| *h > 0.8),
        "the scene and the camera are not framed: centre {centre:?}, half extent {half:?}"
    );
}

/// The progress line and bar of a finished job: the server's work units of its last level.
fn assert_progress(c: &Session, server: &ViewServer, job: u64) {
    let status = server.get(&format!("/api/render/{job}")).json();
    let [done, total] = [0, 1].map(|k| status["progress"][k].as_u64().expect("progress"));
    assert!(total > 0 && done == total, "{status}");
    assert_eq!(
        text_of(c, "#progress-text"),
        format!("level 4 of 4: {done}/{total} tiles")
    );
    let width = c.execute(
        "return document.getElementById('progress-bar').style.width;",
        vec![],
    );
    assert_eq!(width, "100%");
}

fn drive(c: &Session, server: &ViewServer, screenshot: Option<PathBuf>) {
    c.goto(&server.url());
    assert_eq!(c.title(), "raywave view");
    let webgl = wait_attr(c, "#view3d", "data-webgl", |v| !v.is_empty());
    assert_eq!(webgl, "ok", "WebGL is not available in this browser");
    // The token is out of the address bar once the page has it.
    let href = c.execute("return location.href;", vec![]);
    assert!(
        !href.as_str().unwrap_or_default().contains("token="),
        "{href}"
    );
    // The keys are listed.
    assert_eq!(
        text_of(c, "#keys")
            .lines()
            .map(|l| l.split(' ').next().unwrap_or_default())
            .collect::<Vec<_>>(),
        ["r", "t", "Escape"]
    );

    // The progressive render: 64×64 comes as 8, 16, 32 and 64 pixels wide, into a canvas of
    // each level's size.
    let job = wait_render(c, 0);
    assert_eq!(
        wait_attr(c, "#render", "data-levels", |v| !v.is_empty()),
        "4"
    );
    let canvas = c.execute(
        "const r = document.getElementById('render'); return [r.width, r.height];",
        vec![],
    );
    assert_eq!(canvas, json!([64, 64]));
    assert_eq!(c.find_all("#stats tbody tr"), 4);
    assert_progress(c, server, job);
    assert_fitted(c, server, job);
    pixels::assert_canvas_is_cli_render(c, &["--bounces", "0", "--shadows", "hard"]);

    // A click, then the keys: Escape clears, t traces under the pointer, r renders again.
    click_centre_and_count(c, 2);
    c.key(ESCAPE);
    wait_attr(c, "#tree", "data-segments", |v| v == "0");
    wait_attr(c, "#view3d", "data-segments", |v| v == "0");
    let render = c.find("#render").expect("the render");
    c.move_to(&render, 4 + 8 * 4, 4 - 8 * 2);
    c.key("t");
    wait_tree(c, 36, 30, Some(2));
    c.key("r");
    let job = wait_render(c, job);

    // A bad setting is refused with a message, and nothing is rendered.
    set_settings(c, &[("width", "0")]);
    wait_attr(c, "#settings [name=width]", "aria-invalid", |_| true);
    assert_eq!(text_of(c, "#error"), "width must be in 1..=2048, found 0");
    set_settings(c, &[("width", "64")]);

    // Soft shadows, stratified: 4 points per light.
    set_settings(
        c,
        &[
            ("shadows", "soft"),
            ("shadow_samples", "4"),
            ("sampler", "stratified"),
        ],
    );
    let job = wait_render(c, job);
    pixels::assert_canvas_is_cli_render(
        c,
        &[
            "--bounces",
            "0",
            "--shadows",
            "soft",
            "--shadow-samples",
            "4",
            "--sampler",
            "stratified",
        ],
    );
    click_centre_and_count(c, 5);

    // Two bounces; t over the middle mirror sphere, pixel (32, 48), shows its reflections.
    set_settings(c, &[("bounces", "2")]);
    let job = wait_render(c, job);
    pixels::assert_canvas_is_cli_render(
        c,
        &[
            "--bounces",
            "2",
            "--shadows",
            "soft",
            "--shadow-samples",
            "4",
            "--sampler",
            "stratified",
        ],
    );
    c.move_to(&render, 4, 4 + 8 * 16);
    c.key("t");
    wait_tree(c, 32, 48, None);
    let kinds = c.execute("return [...document.querySelectorAll('#segments tbody tr td:nth-child(3)')].map(t => t.textContent);", vec![]);
    assert!(
        kinds
            .as_array()
            .is_some_and(|k| k.contains(&json!("reflection"))),
        "{kinds}"
    );
    // The cost-map overlay: the shadow rays' work laid over the render, whose own pixels are
    // still the command line's; off again, and the overlay goes.
    set_settings(c, &[("cost_map", "shadow"), ("cost_measure", "tests")]);
    let job = wait_render(c, job);
    let levels = wait_attr(c, "#render", "data-levels", |v| v != "0");
    wait_attr(c, "#cost-overlay", "data-level", |v| v == levels);
    let cost = text_of(c, "#cost-text");
    assert!(
        cost.starts_with("cost map, shadow rays: primitives tested per pixel"),
        "{cost}"
    );
    // The overlay image loaded (it may still be on its way when the level is drawn).
    let start = Instant::now();
    let loaded = loop {
        let size = c.execute(
            "const o = document.getElementById('cost-overlay');
             return o.complete && !o.hidden ? [o.naturalWidth, o.naturalHeight] : null;",
            vec![],
        );
        if !size.is_null() || start.elapsed() > WAIT {
            break size;
        }
        std::thread::sleep(Duration::from_millis(30));
    };
    assert_eq!(loaded, json!([64, 64]), "the overlay is the full-size map");
    pixels::assert_canvas_is_cli_render(
        c,
        &[
            "--bounces",
            "2",
            "--shadows",
            "soft",
            "--shadow-samples",
            "4",
            "--sampler",
            "stratified",
        ],
    );
    set_settings(c, &[("cost_map", "off")]);
    let job = wait_render(c, job);
    wait_attr(c, "#cost-overlay", "data-level", |v| v == "0");
    assert_eq!(
        c.execute(
            "return document.getElementById('cost-overlay').hidden;",
            vec![]
        ),
        json!(true)
    );
    if let Some(path) = screenshot {
        let tmp = path.with_extension("png.tmp");
        std::fs::write(&tmp, c.screenshot()).unwrap();
        std::fs::rename(&tmp, &path).unwrap();
        eprintln!("screenshot: {}", path.display());
    }

    // Re-render as I orbit: one drag of several moves is one render, from the 3D camera. A
    // render the settings above started late (each field's change may start one) lands first,
    // so that the drag's is the only new one.
    std::thread::sleep(Duration::from_millis(500));
    wait_attr(c, "#render", "data-state", |v| v == "done");
    let job: u64 = wait_attr(c, "#render", "data-job", |v| v.parse::<u64>().is_ok())
        .parse()
        .unwrap_or(job);
    c.click(&c.find("#follow").expect("the orbit option"));
    let view = c.find("#view3d").expect("the 3D view");
    let mut drag = vec![
        json!({"type": "pointerMove", "origin": {ELEMENT: view.as_str()}, "x": 0, "y": 0, "duration": 0}),
        json!({"type": "pointerDown", "button": 0}),
    ];
    for k in 1..=5 {
        drag.push(
            json!({"type": "pointerMove", "origin": "pointer", "x": 12, "y": 3, "duration": 0}),
        );
        drag.push(json!({"type": "pause", "duration": 30 + k}));
    }
    drag.push(json!({"type": "pointerUp", "button": 0}));
    c.pointer(drag);
    let orbit_job = wait_render(c, job);
    assert_eq!(orbit_job, job + 1, "one render for one drag");
    let camera = &server.get(&format!("/api/render/{orbit_job}")).json()["settings"]["camera"];
    let view_camera = c.execute("return window.raywave.app.view.camera();", vec![]);
    for key in ["position", "look_at"] {
        for k in 0..3 {
            let (a, b) = (
                camera[key][k].as_f64().unwrap(),
                view_camera[key][k].as_f64().unwrap(),
            );
            assert!(
                (a - b).abs() < 1e-4,
                "{key}: the job's camera {camera} is not the view's {view_camera}"
            );
        }
    }
    assert_ne!(
        camera["position"],
        json!([0.0, 0.0, 8.0]),
        "the scene camera, not the view's"
    );
    // Nothing more once the hand has stopped.
    std::thread::sleep(Duration::from_millis(400));
    assert_eq!(
        wait_attr(c, "#render", "data-job", |_| true),
        orbit_job.to_string()
    );

    // The comparison: the reference, two renders, two heat maps and the spectra, all loaded.
    set_value(c, "#compare-form [name=size]", "16");
    set_value(c, "#compare-form [name=seeds]", "2");
    c.click(&c.find("#compare-run").expect("the compare button"));
    wait_attr(c, "#compare-result", "data-images", |v| v == "6");
    let sizes = c.execute(
        "return [...document.querySelectorAll('#compare-result img')].map(i => i.naturalWidth);",
        vec![],
    );
    assert_eq!(sizes, json!([16, 16, 16, 16, 16, 640]));
}

#[test]
fn the_page_renders_traces_and_compares_in_chromium() {
    let (Some(chromium), Some(chromedriver)) = (
        find(&["chromium", "chromium-browser"]),
        find(&["chromedriver"]),
    ) else {
        return skip_or_fail("chromium or chromedriver is missing (.ci/run installs them)");
    };
    let start = Instant::now();
    let server = ViewServer::start(&["--size", "64", "64", "--bounces", "0", "--shadows", "hard"]);
    let driver = Driver::start(&chromedriver);
    let profile = tempfile::tempdir().unwrap();
    let screenshot = std::env::var_os("RAYWAVE_VIEW_SCREENSHOT").map(PathBuf::from);
    let session = Session::new(&driver, &chromium, profile.path());
    drive(&session, &server, screenshot);
    session.close();
    eprintln!("browser test: {:.1} s", start.elapsed().as_secs_f64());
}
