//! `raywave view` in a real browser: headless Chromium (WebGL through SwiftShader) driven by
//! chromedriver over WebDriver (the W3C protocol's JSON over plain HTTP, sent with ureq). The page loads, the progressive render arrives level by level,
//! a click on a known pixel draws that pixel's ray tree in the 3D view, a changed setting
//! renders again, and the comparison mode shows its images.
//!
//! Needs Debian's `chromium` and `chromium-driver` (`.ci/run` installs them). Without them the
//! test prints SKIPPED and passes, unless CI is set: then it fails.
//!
//! The expected tree sizes come from the scene: the built-in Cornell box has one area light,
//! and the centre of the image looks at the back wall, which faces the light. With no bounces,
//! its tree is the camera ray and one shadow ray per light point: 1 + 1 with hard shadows,
//! 1 + 4 with 4 soft-shadow points.
//!
//! RAYWAVE_VIEW_SCREENSHOT=FILE.png saves a screenshot of the page at the end.

use crate::common;

use base64::Engine as _;
use common::view::ViewServer;
use serde_json::{Value, json};
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// How long any one thing may take to appear on the page.
const WAIT: Duration = Duration::from_secs(45);

fn find(names: &[&str]) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    names.iter().find_map(|name| {
        std::env::split_paths(&path)
            .map(|dir| dir.join(name))
            .find(|p| p.is_file())
    })
}

/// chromedriver on a free port; killed when dropped.
struct Driver {
    child: Child,
    port: u16,
}

impl Driver {
    fn start(binary: &Path) -> Driver {
        let port = TcpListener::bind(("127.0.0.1", 0))
            .and_then(|l| l.local_addr())
            .expect("a free port")
            .port();
        // Its own process group, so that dropping it ends the browsers it started too.
        use std::os::unix::process::CommandExt;
        let child = Command::new(binary)
            .arg(format!("--port={port}"))
            .process_group(0)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("start chromedriver");
        let start = Instant::now();
        while std::net::TcpStream::connect(("127.0.0.1", port)).is_err() {
            assert!(
                start.elapsed() < Duration::from_secs(20),
                "chromedriver did not listen on port {port}"
            );
            std::thread::sleep(Duration::from_millis(50));
        }
        Driver { child, port }
    }
}

impl Drop for Driver {
    fn drop(&mut self) {
        // SAFETY: kill(2) on the process group of our own child.
        unsafe { libc::kill(-(self.child.id() as i32), libc::SIGKILL) };
        let _ = self.child.wait();
    }
}

/// The W3C WebDriver protocol's key for an element reference.
const ELEMENT: &str = "element-6066-11e4-a52e-4f735466cecf";

/// One WebDriver session with chromedriver on loopback: each command is a JSON request over
/// plain HTTP (ureq), its answer the reply's `value`. Only the commands this test uses.
struct Session {
    agent: ureq::Agent,
    url: String,
}

impl Session {
    fn new(driver: &Driver, chromium: &Path, profile: &Path) -> Session {
        let agent: ureq::Agent = ureq::Agent::config_builder()
            .http_status_as_error(false)
            .timeout_global(Some(Duration::from_secs(120)))
            .build()
            .into();
        let mut session = Session {
            agent,
            url: format!("http://127.0.0.1:{}", driver.port),
        };
        let capabilities = json!({"alwaysMatch": {"goog:chromeOptions": {
            "binary": chromium,
            "args": [
                "--headless=new", "--no-sandbox",
                // WebGL without a GPU.
                "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
                "--disable-quic", "--no-first-run", "--disable-background-networking",
                "--disable-component-update", "--disable-sync", "--disable-dev-shm-usage",
                "--window-size=1400,1300",
                format!("--user-data-dir={}", profile.display()),
            ],
        }}});
        let created = session
            .command(
                "POST",
                "/session",
                Some(json!({"capabilities": capabilities})),
            )
            .expect("a WebDriver session");
        let id = created["sessionId"].as_str().expect("a session id");
        session.url = format!("{}/session/{id}", session.url);
        session
    }

    /// Sends one command; its `value`, or the WebDriver error as text.
    fn command(&self, method: &str, path: &str, body: Option<Value>) -> Result<Value, String> {
        let url = format!("{}{path}", self.url);
        let reply = match (method, body) {
            ("GET", _) => self.agent.get(&url).call(),
            ("DELETE", _) => self.agent.delete(&url).call(),
            (_, body) => self.agent.post(&url).send_json(body.unwrap_or(json!({}))),
        };
        let mut reply = reply.map_err(|e| format!("{method} {path}: {e}"))?;
        let ok = reply.status().is_success();
        let json: Value = reply
            .body_mut()
            .read_json()
            .map_err(|e| format!("{method} {path}: {e}"))?;
        let value = json["value"].clone();
        if ok {
            Ok(value)
        } else {
            Err(format!("{method} {path}: {value}"))
        }
    }

    fn run(&self, method: &str, path: &str, body: Option<Value>) -> Value {
        self.command(method, path, body)
            .unwrap_or_else(|e| panic!("{e}"))
    }

    fn goto(&self, url: &str) {
        self.run("POST", "/url", Some(json!({"url": url})));
    }

    fn title(&self) -> String {
        self.run("GET", "/title", None)
            .as_str()
            .unwrap_or_default()
            .to_string()
    }

    /// The first element `css` selects, if any.
    fn find(&self, css: &str) -> Option<String> {
        let found = self.command(
            "POST",
            "/element",
            Some(json!({"using": "css selector", "value": css})),
        );
        found
            .ok()
            .and_then(|v| v[ELEMENT].as_str().map(String::from))
    }

    fn find_all(&self, css: &str) -> usize {
        let found = self.run(
            "POST",
            "/elements",
            Some(json!({"using": "css selector", "value": css})),
        );
        found.as_array().map_or(0, Vec::len)
    }

    fn attr(&self, element: &str, name: &str) -> Option<String> {
        let value = self.command("GET", &format!("/element/{element}/attribute/{name}"), None);
        value.ok().and_then(|v| v.as_str().map(String::from))
    }

    fn text(&self, element: &str) -> String {
        let value = self.command("GET", &format!("/element/{element}/text"), None);
        value
            .ok()
            .and_then(|v| v.as_str().map(String::from))
            .unwrap_or_default()
    }

    fn click(&self, element: &str) {
        self.run("POST", &format!("/element/{element}/click"), None);
    }

    /// A left click `x`, `y` CSS pixels from the centre of `element`.
    fn click_at(&self, element: &str, x: i64, y: i64) {
        let pointer = json!({"type": "pointer", "id": "mouse", "parameters": {"pointerType": "mouse"},
        "actions": [
            {"type": "pointerMove", "origin": {ELEMENT: element}, "x": x, "y": y, "duration": 0},
            {"type": "pointerDown", "button": 0},
            {"type": "pointerUp", "button": 0},
        ]});
        self.run("POST", "/actions", Some(json!({"actions": [pointer]})));
    }

    fn execute(&self, script: &str, args: Vec<Value>) -> Value {
        self.run(
            "POST",
            "/execute/sync",
            Some(json!({"script": script, "args": args})),
        )
    }

    fn screenshot(&self) -> Vec<u8> {
        let text = self.run("GET", "/screenshot", None);
        base64::engine::general_purpose::STANDARD
            .decode(text.as_str().unwrap_or_default())
            .expect("a base64 screenshot")
    }

    fn close(self) {
        self.run("DELETE", "", None);
    }
}

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
        std::thread::sleep(Duration::from_millis(50));
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

fn click_centre_and_count(c: &Session, expected: usize) {
    // The render is shown 512 CSS pixels wide for a 64-pixel image, 8 per pixel: half a pixel
    // right of and below its centre is the middle of pixel (32, 32).
    let element = c.find("#render").expect("the render");
    c.click_at(&element, 4, 4);
    let n = expected.to_string();
    wait_attr(c, "#tree", "data-segments", |v| v == n);
    assert_eq!(wait_attr(c, "#tree", "data-x", |v| !v.is_empty()), "32");
    assert_eq!(wait_attr(c, "#tree", "data-y", |v| !v.is_empty()), "32");
    // The 3D view drew them.
    wait_attr(c, "#view3d", "data-segments", |v| v == n);
}

fn set_value(c: &Session, name: &str, value: &str) {
    c.execute(
        "const el = document.querySelector(arguments[0]); el.value = arguments[1];",
        vec![name.into(), value.into()],
    );
}

fn drive(c: &Session, url: &str, screenshot: Option<PathBuf>) {
    c.goto(url);
    assert_eq!(c.title(), "raywave view");
    let webgl = wait_attr(c, "#view3d", "data-webgl", |v| !v.is_empty());
    assert_eq!(webgl, "ok", "WebGL is not available in this browser");

    // The progressive render: 64×64 comes as 8, 16, 32 and 64 pixels wide.
    let job = wait_render(c, 0);
    assert_eq!(
        wait_attr(c, "#render", "data-levels", |v| !v.is_empty()),
        "4"
    );
    let natural = c.execute(
        "return document.getElementById('render').naturalWidth;",
        vec![],
    );
    assert_eq!(natural, 64);
    // Rays per second, one row per level.
    assert_eq!(c.find_all("#stats tbody tr"), 4);

    click_centre_and_count(c, 2);

    // A changed setting renders again: 4 soft-shadow points per light.
    set_value(c, "#settings [name=shadows]", "soft");
    set_value(c, "#settings [name=shadow_samples]", "4");
    c.execute(
        "document.getElementById('settings').dispatchEvent(new Event('change'));",
        vec![],
    );
    wait_render(c, job);
    click_centre_and_count(c, 5);

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

    if let Some(path) = screenshot {
        // The ray tree and the comparison in view.
        c.execute(
            "document.getElementById('tree-panel').scrollIntoView();",
            vec![],
        );
        std::fs::write(&path, c.screenshot()).unwrap();
        eprintln!("screenshot: {}", path.display());
    }
}

#[test]
fn the_page_renders_traces_and_compares_in_chromium() {
    let (Some(chromium), Some(chromedriver)) = (
        find(&["chromium", "chromium-browser"]),
        find(&["chromedriver"]),
    ) else {
        if std::env::var_os("CI").is_some() {
            panic!("CI is set but chromium or chromedriver is missing (.ci/run installs them)");
        }
        println!("SKIPPED: chromium or chromedriver is not installed");
        return;
    };
    let start = Instant::now();
    let server = ViewServer::start(&["--size", "64", "64", "--bounces", "0", "--shadows", "hard"]);
    let driver = Driver::start(&chromedriver);
    let profile = tempfile::tempdir().unwrap();
    let screenshot = std::env::var_os("RAYWAVE_VIEW_SCREENSHOT").map(PathBuf::from);
    let session = Session::new(&driver, &chromium, profile.path());
    drive(&session, &server.url(), screenshot);
    session.close();
    eprintln!("browser test: {:.1} s", start.elapsed().as_secs_f64());
}
