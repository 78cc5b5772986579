//! WebDriver for the browser test: chromedriver on a free port and one session with headless
//! Chromium, each command the W3C protocol's JSON over plain HTTP (ureq). Only the commands
//! view_browser uses.

use base64::Engine as _;
use serde_json::{Value, json};
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// The first of `names` found on PATH.
pub(crate) fn find(names: &[&str]) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    names.iter().find_map(|name| {
        std::env::split_paths(&path)
            .map(|dir| dir.join(name))
            .find(|p| p.is_file())
    })
}

/// chromedriver on a free port; killed when dropped.
pub(crate) struct Driver {
    child: Child,
    port: u16,
}

impl Driver {
    pub(crate) fn start(binary: &Path) -> Driver {
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
pub(crate) const ELEMENT: &str = "element-6066-11e4-a52e-4f735466cecf";

/// One WebDriver session with chromedriver on loopback: each command is a JSON request over
/// plain HTTP (ureq), its answer the reply's `value`. Only the commands this test uses.
pub(crate) struct Session {
    agent: ureq::Agent,
    url: String,
}

impl Session {
    pub(crate) fn new(driver: &Driver, chromium: &Path, profile: &Path) -> Session {
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
    pub(crate) fn command(
        &self,
        method: &str,
        path: &str,
        body: Option<Value>,
    ) -> Result<Value, String> {
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

    pub(crate) fn run(&self, method: &str, path: &str, body: Option<Value>) -> Value {
        self.command(method, path, body)
            .unwrap_or_else(|e| panic!("{e}"))
    }

    pub(crate) fn goto(&self, url: &str) {
        self.run("POST", "/url", Some(json!({"url": url})));
    }

    pub(crate) fn title(&self) -> String {
        self.run("GET", "/title", None)
            .as_str()
            .unwrap_or_default()
            .to_string()
    }

    /// The first element `css` selects, if any.
    pub(crate) fn find(&self, css: &str) -> Option<String> {
        let found = self.command(
            "POST",
            "/element",
            Some(json!({"using": "css selector", "value": css})),
        );
        found
            .ok()
            .and_then(|v| v[ELEMENT].as_str().map(String::from))
    }

    pub(crate) fn find_all(&self, css: &str) -> usize {
        let found = self.run(
            "POST",
            "/elements",
            Some(json!({"using": "css selector", "value": css})),
        );
        found.as_array().map_or(0, Vec::len)
    }

    pub(crate) fn attr(&self, element: &str, name: &str) -> Option<String> {
        let value = self.command("GET", &format!("/element/{element}/attribute/{name}"), None);
        value.ok().and_then(|v| v.as_str().map(String::from))
    }

    pub(crate) fn text(&self, element: &str) -> String {
        let value = self.command("GET", &format!("/element/{element}/text"), None);
        value
            .ok()
            .and_then(|v| v.as_str().map(String::from))
            .unwrap_or_default()
    }

    pub(crate) fn click(&self, element: &str) {
        self.run("POST", &format!("/element/{element}/click"), None);
    }

    /// A left click `x`, `y` CSS pixels from the centre of `element`.
    pub(crate) fn click_at(&self, element: &str, x: i64, y: i64) {
        let pointer = json!({"type": "pointer", "id": "mouse", "parameters": {"pointerType": "mouse"},
        "actions": [
            {"type": "pointerMove", "origin": {ELEMENT: element}, "x": x, "y": y, "duration": 0},
            {"type": "pointerDown", "button": 0},
            {"type": "pointerUp", "button": 0},
        ]});
        self.run("POST", "/actions", Some(json!({"actions": [pointer]})));
    }

    /// Pointer actions of the mouse, in order (WebDriver's `pointerMove`, `pointerDown`,
    /// `pointerUp`, `pause`).
    pub(crate) fn pointer(&self, actions: Vec<Value>) {
        let pointer = json!({"type": "pointer", "id": "mouse", "parameters": {"pointerType": "mouse"},
            "actions": actions});
        self.run("POST", "/actions", Some(json!({"actions": [pointer]})));
        self.run("DELETE", "/actions", None);
    }

    /// Moves the mouse `x`, `y` CSS pixels from the centre of `element`.
    pub(crate) fn move_to(&self, element: &str, x: i64, y: i64) {
        self.pointer(vec![
            json!({"type": "pointerMove", "origin": {ELEMENT: element}, "x": x, "y": y, "duration": 0}),
        ]);
    }

    /// Presses and releases `key` (a character, or a WebDriver code such as "\u{E00C}",
    /// Escape) on whatever has the focus.
    pub(crate) fn key(&self, key: &str) {
        let keys = json!({"type": "key", "id": "keyboard", "actions": [
            {"type": "keyDown", "value": key}, {"type": "keyUp", "value": key}]});
        self.run("POST", "/actions", Some(json!({"actions": [keys]})));
        self.run("DELETE", "/actions", None);
    }

    pub(crate) fn execute(&self, script: &str, args: Vec<Value>) -> Value {
        self.run(
            "POST",
            "/execute/sync",
            Some(json!({"script": script, "args": args})),
        )
    }

    pub(crate) fn screenshot(&self) -> Vec<u8> {
        let text = self.run("GET", "/screenshot", None);
        base64::engine::general_purpose::STANDARD
            .decode(text.as_str().unwrap_or_default())
            .expect("a base64 screenshot")
    }

    pub(crate) fn close(self) {
        self.run("DELETE", "", None);
    }
}
