//! `raywave view` in a real browser: headless Chromium (WebGL through SwiftShader) driven by
//! chromedriver over WebDriver. The page loads, the progressive render arrives level by level,
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

use common::view::ViewServer;
use fantoccini::actions::{InputSource, MOUSE_BUTTON_LEFT, MouseActions, PointerAction};
use fantoccini::{Client, ClientBuilder, Locator};
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

async fn connect(driver: &Driver, chromium: &Path, profile: &Path) -> Client {
    let mut caps = serde_json::Map::new();
    caps.insert(
        "goog:chromeOptions".into(),
        serde_json::json!({
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
        }),
    );
    ClientBuilder::new(hyper_util::client::legacy::connect::HttpConnector::new())
        .capabilities(caps)
        .connect(&format!("http://127.0.0.1:{}", driver.port))
        .await
        .expect("a WebDriver session")
}

/// Waits until `css`'s attribute `name` satisfies `ok`, and returns it.
async fn wait_attr(c: &Client, css: &str, name: &str, ok: impl Fn(&str) -> bool) -> String {
    let start = Instant::now();
    let mut last = None;
    while start.elapsed() < WAIT {
        if let Ok(el) = c.find(Locator::Css(css)).await {
            last = el.attr(name).await.ok().flatten();
            if last.as_deref().is_some_and(&ok) {
                return last.unwrap_or_default();
            }
        }
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    let error = match c.find(Locator::Css("#error")).await {
        Ok(e) => e.text().await.unwrap_or_default(),
        Err(_) => String::new(),
    };
    panic!("{css}[{name}] is {last:?} after {WAIT:?}; the page's error line: {error:?}");
}

/// Waits for the job after `previous` to be rendered at every level; returns its id.
async fn wait_render(c: &Client, previous: u64) -> u64 {
    let job = wait_attr(c, "#render", "data-job", |v| {
        v.parse::<u64>().is_ok_and(|j| j > previous)
    })
    .await;
    wait_attr(c, "#render", "data-state", |v| v == "done").await;
    let levels = wait_attr(c, "#render", "data-levels", |v| v != "0").await;
    wait_attr(c, "#render", "data-level", |v| v == levels).await;
    job.parse().unwrap_or_default()
}

async fn click_centre_and_count(c: &Client, expected: usize) {
    // The render is shown 512 CSS pixels wide for a 64-pixel image, 8 per pixel: half a pixel
    // right of and below its centre is the middle of pixel (32, 32).
    let element = c.find(Locator::Css("#render")).await.unwrap();
    let click = MouseActions::new("mouse".into())
        .then(PointerAction::MoveToElement {
            element,
            duration: None,
            x: 4.0,
            y: 4.0,
        })
        .then(PointerAction::Down {
            button: MOUSE_BUTTON_LEFT,
        })
        .then(PointerAction::Up {
            button: MOUSE_BUTTON_LEFT,
        });
    c.perform_actions(click).await.unwrap();
    let n = expected.to_string();
    wait_attr(c, "#tree", "data-segments", |v| v == n).await;
    assert_eq!(
        wait_attr(c, "#tree", "data-x", |v| !v.is_empty()).await,
        "32"
    );
    assert_eq!(
        wait_attr(c, "#tree", "data-y", |v| !v.is_empty()).await,
        "32"
    );
    // The 3D view drew them.
    wait_attr(c, "#view3d", "data-segments", |v| v == n).await;
}

async fn set_value(c: &Client, name: &str, value: &str) {
    c.execute(
        "const el = document.querySelector(arguments[0]); el.value = arguments[1];",
        vec![name.into(), value.into()],
    )
    .await
    .unwrap();
}

async fn drive(c: &Client, url: &str, screenshot: Option<PathBuf>) {
    c.goto(url).await.unwrap();
    assert_eq!(c.title().await.unwrap(), "raywave view");
    let webgl = wait_attr(c, "#view3d", "data-webgl", |v| !v.is_empty()).await;
    assert_eq!(webgl, "ok", "WebGL is not available in this browser");

    // The progressive render: 64×64 comes as 8, 16, 32 and 64 pixels wide.
    let job = wait_render(c, 0).await;
    assert_eq!(
        wait_attr(c, "#render", "data-levels", |v| !v.is_empty()).await,
        "4"
    );
    let natural = c
        .execute(
            "return document.getElementById('render').naturalWidth;",
            vec![],
        )
        .await
        .unwrap();
    assert_eq!(natural, 64);
    // Rays per second, one row per level.
    let rows = c
        .find_all(Locator::Css("#stats tbody tr"))
        .await
        .unwrap()
        .len();
    assert_eq!(rows, 4);

    click_centre_and_count(c, 2).await;

    // A changed setting renders again: 4 soft-shadow points per light.
    set_value(c, "#settings [name=shadows]", "soft").await;
    set_value(c, "#settings [name=shadow_samples]", "4").await;
    c.execute(
        "document.getElementById('settings').dispatchEvent(new Event('change'));",
        vec![],
    )
    .await
    .unwrap();
    wait_render(c, job).await;
    click_centre_and_count(c, 5).await;

    // The comparison: the reference, two renders and two heat maps, all loaded.
    set_value(c, "#compare-form [name=size]", "16").await;
    set_value(c, "#compare-form [name=seeds]", "2").await;
    c.find(Locator::Css("#compare-run"))
        .await
        .unwrap()
        .click()
        .await
        .unwrap();
    wait_attr(c, "#compare-result", "data-images", |v| v == "5").await;
    let sizes = c
        .execute(
            "return [...document.querySelectorAll('#compare-result img')].map(i => i.naturalWidth);",
            vec![],
        )
        .await
        .unwrap();
    assert_eq!(sizes, serde_json::json!([16, 16, 16, 16, 16]));

    if let Some(path) = screenshot {
        // The ray tree and the comparison in view.
        c.execute(
            "document.getElementById('tree-panel').scrollIntoView();",
            vec![],
        )
        .await
        .unwrap();
        let png = c.screenshot().await.unwrap();
        std::fs::write(&path, png).unwrap();
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
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .unwrap();
    runtime.block_on(async {
        let client = connect(&driver, &chromium, profile.path()).await;
        drive(&client, &server.url(), screenshot).await;
        client.close().await.unwrap();
    });
    eprintln!("browser test: {:.1} s", start.elapsed().as_secs_f64());
}
