//! `raywave view`'s render jobs over HTTP: a newer job stops the running one within about a
//! tile, the superseded job's pixels are refused with 410 naming the job to ask instead, and
//! render starts past the rate limit get 429 with `Retry-After` while the server goes on.
//!
//! Times are never compared with a constant: the superseded render's stop is compared with the
//! time its own previous level took, which the server reports, so a slow or busy machine slows
//! both sides alike.

use crate::common;

use common::view::{HttpReply, ViewServer};
use serde_json::Value;
use std::time::{Duration, Instant};

const LIMIT: Duration = Duration::from_secs(60);

/// A render of a few seconds: 1024² at 4 samples a pixel, 256 soft-shadow points per hit; 1024
/// tiles at full size.
const BIG: &str =
    r#"{"width": 1024, "height": 1024, "aa": 4, "shadows": "soft", "shadow_samples": 256}"#;

/// A render of a few milliseconds.
const TINY: &str = r#"{"width": 16, "height": 16, "shadows": "hard"}"#;

/// The rate limit as docs/VIEWER.md states it: 20 starts at once, 20 a second after that.
const BURST: f64 = 20.0;
const RATE: f64 = 20.0;

fn start_job(server: &ViewServer, settings: &str) -> u64 {
    let r = server.post("/api/render", settings);
    assert_eq!(r.status, 200, "{}", r.text());
    r.json()["job"].as_u64().expect("a job id")
}

/// Polls job `job` until `done` holds for its status; panics after [`LIMIT`].
fn wait_for(server: &ViewServer, job: u64, done: impl Fn(&Value) -> bool) -> Value {
    let start = Instant::now();
    loop {
        let status = server.get(&format!("/api/render/{job}")).json();
        if done(&status) {
            return status;
        }
        assert!(start.elapsed() < LIMIT, "job {job} stuck: {status}");
        std::thread::sleep(Duration::from_millis(5));
    }
}

fn levels(status: &Value) -> usize {
    status["levels"].as_array().map_or(0, Vec::len)
}

#[test]
fn a_superseded_render_stops_within_a_tile_and_the_newer_one_finishes() {
    let server = ViewServer::start(&["--size", "64", "64"]);
    let big = start_job(&server, BIG);
    // Wait until it renders its last level: 1/8, 1/4 and 1/2 are done, their seconds known.
    let running = wait_for(&server, big, |s| {
        levels(s) == 3 || !matches!(s["state"].as_str(), Some("running" | "queued"))
    });
    assert_eq!(running["state"], "running", "{running}");
    let half = running["levels"][2]["rays"]["total"]["seconds"]
        .as_f64()
        .unwrap();
    let asked = Instant::now();
    let tiny = start_job(&server, TINY);
    let stopped = wait_for(&server, big, |s| s["state"] != "running");
    let took = asked.elapsed().as_secs_f64();
    // The full level has four times the half level's pixels: left to finish, it takes about
    // 4 × `half` more. Stopped at the next tile (1/1024 of it, per thread), it takes a small
    // part of one `half`.
    assert!(
        took < half,
        "the superseded job stopped {took:.3} s after the newer one was asked for, not well \
         within the {half:.3} s its 1/2 level took ({stopped})"
    );
    assert_eq!(stopped["state"], "superseded", "{stopped}");
    assert_eq!(
        levels(&stopped),
        3,
        "the last level was never finished: {stopped}"
    );
    let finished = wait_for(&server, tiny, |s| {
        !matches!(s["state"].as_str(), Some("running" | "queued"))
    });
    assert_eq!(finished["state"], "done", "{finished}");

    // Its pixels are gone: 410, naming the job that took its place.
    let r = server.get(&format!("/api/pixel?job={big}&x=512&y=512"));
    let start: String = r.text().chars().take(300).collect();
    assert_eq!(r.status, 410, "{start}");
    assert_eq!(r.header("content-type"), Some("application/json"));
    assert_eq!(
        r.json()["error"],
        format!(
            "job {big} was superseded by job {tiny} before its image was finished: ask for job \
             {tiny}'s pixels"
        )
    );
    assert_eq!(
        server.get(&format!("/api/pixel?job={tiny}&x=8&y=8")).status,
        200
    );
}

#[test]
fn a_burst_of_render_starts_is_limited_with_retry_after_and_the_server_goes_on() {
    let server = ViewServer::start(&["--size", "16", "16", "--shadows", "hard"]);
    let start = Instant::now();
    // 1,000 starts from four clients at once.
    let replies: Vec<HttpReply> = std::thread::scope(|s| {
        let clients: Vec<_> = (0..4)
            .map(|_| {
                s.spawn(|| {
                    (0..250)
                        .map(|_| server.post("/api/render", TINY))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        clients
            .into_iter()
            .flat_map(|c| c.join().unwrap())
            .collect()
    });
    let seconds = start.elapsed().as_secs_f64();
    let admitted = replies.iter().filter(|r| r.status == 200).count();
    let mut retry = 0;
    for r in replies.iter().filter(|r| r.status != 200) {
        assert_eq!(r.status, 429, "{}", r.text());
        assert_eq!(r.header("content-type"), Some("application/json"));
        let after: u32 = r
            .header("retry-after")
            .and_then(|s| s.parse().ok())
            .unwrap_or_else(|| panic!("no Retry-After in seconds: {:?}", r.headers));
        assert!(after >= 1, "Retry-After: {after}");
        retry = retry.max(after);
        let json = r.json();
        assert_eq!(json["status"], 429);
        let error = json["error"].as_str().unwrap();
        assert!(
            error.contains("too many renders started: at most 20 at once and 20 a second"),
            "{error}"
        );
    }
    // The whole burst within the bucket's arithmetic: the burst, plus the refill while it ran.
    let most = (BURST + RATE * seconds).floor() as usize + 1;
    assert!(
        (BURST as usize..=most).contains(&admitted),
        "{admitted} of 1000 starts admitted in {seconds:.2} s, expected 20..={most}"
    );
    assert!(admitted < 1000, "no start was refused");

    // Still serving; after Retry-After a render is admitted again and finishes.
    assert_eq!(server.get("/api/scene").status, 200);
    std::thread::sleep(Duration::from_secs(retry.into()));
    let (_, status) = server.render(TINY, LIMIT);
    assert_eq!(status["state"], "done");
}

#[test]
fn renders_at_twice_the_pages_pace_are_never_limited() {
    let server = ViewServer::start(&["--size", "16", "16", "--shadows", "hard"]);
    // 30 starts at 10 a second: more than the burst, so the refill has to carry the last ten.
    for i in 0..30 {
        let r = server.post("/api/render", TINY);
        assert_eq!(r.status, 200, "start {i}: {}", r.text());
        std::thread::sleep(Duration::from_millis(100));
    }
}
