//! `raywave view` under load and abuse, on loopback, bounded in count and time: 200 clients at
//! once, a slowloris client, 10,000 requests one after another, and a connection limit that
//! answers 503; during each, a normal `GET /api/scene` from another client must be answered
//! within a second. The server's threads and resident memory are read from /proc before and
//! after the 10,000 requests, and must come back to where they were.
//!
//! Each test prints its figures (`cargo test --release --test commands view_load --
//! --nocapture`); docs/VIEWER.md quotes them. Only the probe's one-second bound and the limits
//! are asserted: the machine is shared, and speed belongs to benchmarks.

use crate::common;

use common::view::{ViewServer, parse_reply, send};
use std::io::{Read, Write};
use std::net::TcpStream;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// The longest a normal request may wait while the server is under load.
const PROBE_LIMIT: Duration = Duration::from_secs(1);

/// A client that sends `GET /api/scene` every 50 ms until stopped, and keeps the worst latency.
struct Probe {
    stop: Arc<AtomicBool>,
    thread: JoinHandle<(Duration, usize)>,
}

impl Probe {
    fn start(server: &ViewServer) -> Probe {
        let stop = Arc::new(AtomicBool::new(false));
        let (port, bearer) = (server.port, bearer(server));
        let flag = stop.clone();
        let thread = std::thread::spawn(move || {
            let (mut worst, mut count) = (Duration::ZERO, 0);
            while !flag.load(Ordering::Relaxed) {
                let start = Instant::now();
                let r = get(port, "/api/scene", &bearer);
                worst = worst.max(start.elapsed());
                assert_eq!(r.status, 200, "the probe was refused: {}", r.text());
                count += 1;
                std::thread::sleep(Duration::from_millis(50));
            }
            (worst, count)
        });
        Probe { stop, thread }
    }

    /// Stops; the worst latency, after checking it against the limit.
    fn finish(self, during: &str) -> Duration {
        self.stop.store(true, Ordering::Relaxed);
        let (worst, count) = self.thread.join().expect("the probe failed");
        assert!(count > 0, "no probe request during {during}");
        assert!(
            worst < PROBE_LIMIT,
            "during {during}, a GET /api/scene took {worst:?} (limit {PROBE_LIMIT:?})"
        );
        worst
    }
}

fn bearer(server: &ViewServer) -> String {
    format!("Bearer {}", server.token.as_deref().expect("a token"))
}

/// One GET with the token, on a connection of its own.
fn get(port: u16, path: &str, bearer: &str) -> common::view::HttpReply {
    send(port, "GET", path, &[("Authorization", bearer)], b"")
}

/// A line of /proc/PID/status, as a number (the first word after the name).
fn proc_status(pid: u32, name: &str) -> u64 {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).expect("/proc");
    status
        .lines()
        .find_map(|l| l.strip_prefix(name))
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no {name} in /proc/{pid}/status"))
}

#[test]
fn two_hundred_clients_at_once_are_all_served() {
    let server = ViewServer::start(&["--size", "32", "16"]);
    let probe = Probe::start(&server);
    let (port, bearer) = (server.port, bearer(&server));
    let gate = Arc::new(std::sync::Barrier::new(200));
    let start = Instant::now();
    let clients: Vec<_> = (0..200)
        .map(|i| {
            let (gate, bearer) = (gate.clone(), bearer.clone());
            std::thread::spawn(move || {
                gate.wait();
                let path = ["/api/scene", "/assets/gl.mjs", "/"][i % 3];
                // A 503 asks to come back after Retry-After seconds; nothing else may fail.
                for _ in 0..5 {
                    let r = get(port, path, &bearer);
                    match r.status {
                        200 => return 0,
                        503 => {
                            let wait: u64 = r
                                .header("retry-after")
                                .expect("Retry-After")
                                .parse()
                                .unwrap();
                            std::thread::sleep(Duration::from_secs(wait));
                        }
                        s => panic!("{path}: {s} {}", r.text()),
                    }
                }
                panic!("{path}: still refused after 5 tries");
            })
        })
        .collect();
    for c in clients {
        c.join().expect("a client failed");
    }
    let seconds = start.elapsed().as_secs_f64();
    let worst = probe.finish("200 concurrent clients");
    println!("view load: 200 concurrent clients served in {seconds:.2} s; probe worst {worst:?}");
}

#[test]
fn a_slowloris_client_is_cut_off_and_holds_up_nobody() {
    let server = ViewServer::start(&["--size", "32", "16"]);
    let probe = Probe::start(&server);
    let port = server.port;
    let start = Instant::now();
    let slow = std::thread::spawn(move || {
        let mut s = TcpStream::connect(("127.0.0.1", port)).unwrap();
        s.set_read_timeout(Some(Duration::from_secs(30))).unwrap();
        // One byte of the head a second, as long as the server takes them.
        for b in b"GET /api/scene HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: "
            .iter()
            .cycle()
        {
            if s.write_all(&[*b]).is_err() {
                break;
            }
            // A reply ends the trickle.
            s.set_nonblocking(true).unwrap();
            let mut peek = [0u8; 1];
            let answered = matches!(s.peek(&mut peek), Ok(n) if n > 0);
            s.set_nonblocking(false).unwrap();
            if answered || start.elapsed() > Duration::from_secs(20) {
                break;
            }
            std::thread::sleep(Duration::from_secs(1));
        }
        let mut raw = Vec::new();
        let _ = s.read_to_end(&mut raw);
        (parse_reply(&raw), start.elapsed())
    });
    let (reply, cut_after) = slow.join().unwrap();
    let worst = probe.finish("a slowloris client");
    assert_eq!(reply.status, 408, "{}", reply.text());
    assert!(
        reply.json()["error"]
            .as_str()
            .unwrap()
            .contains("within 5 s")
    );
    // Cut at the 5-second request deadline (plus the trickle's one-second step), not held.
    assert!(
        cut_after < Duration::from_secs(8),
        "the slow client was held {cut_after:?}"
    );
    println!("view load: slowloris cut off after {cut_after:?} with 408; probe worst {worst:?}");
}

#[test]
fn ten_thousand_requests_leave_threads_and_memory_where_they_were() {
    let server = ViewServer::start(&["--size", "32", "16"]);
    let (job, _) = server.render("{}", Duration::from_secs(60));
    let (port, bearer, pid) = (server.port, bearer(&server), server.child.id());
    let paths = [
        "/api/scene".to_string(),
        format!("/api/render/{job}"),
        format!("/api/render/{job}/1.png"),
        "/assets/app.mjs".to_string(),
        "/api/nope".to_string(),
    ];
    // Warm up: the allocator's arenas and the first replies' buffers.
    for path in paths.iter().cycle().take(200) {
        get(port, path, &bearer);
    }
    std::thread::sleep(Duration::from_millis(300));
    let (threads_before, rss_before) = (proc_status(pid, "Threads:"), proc_status(pid, "VmRSS:"));
    let probe = Probe::start(&server);
    let start = Instant::now();
    for (i, path) in paths.iter().cycle().take(10_000).enumerate() {
        let r = get(port, path, &bearer);
        let expected = if path == "/api/nope" { 404 } else { 200 };
        assert_eq!(r.status, expected, "request {i}, {path}: {}", r.text());
    }
    let seconds = start.elapsed().as_secs_f64();
    let worst = probe.finish("10,000 sequential requests");
    // The last connections' threads end within their lingering close.
    std::thread::sleep(Duration::from_millis(500));
    let (threads_after, rss_after) = (proc_status(pid, "Threads:"), proc_status(pid, "VmRSS:"));
    println!(
        "view load: 10,000 sequential requests in {seconds:.2} s ({:.0} requests/s); probe worst {worst:?}; \
         threads {threads_before} -> {threads_after}; RSS {:.1} -> {:.1} MiB",
        10_000.0 / seconds,
        rss_before as f64 / 1024.0,
        rss_after as f64 / 1024.0
    );
    assert!(
        threads_after <= threads_before,
        "threads grew from {threads_before} to {threads_after}"
    );
    // Bounded: a leak of even 1 KiB a request would be 10 MiB.
    assert!(
        rss_after < rss_before + 8 * 1024,
        "resident memory grew from {rss_before} KiB to {rss_after} KiB"
    );
}

#[test]
fn connections_over_the_limit_get_503_with_retry_after() {
    let server = ViewServer::start(&["--size", "32", "16", "--max-connections", "4"]);
    // Four clients that connect and say nothing hold every place (until the request deadline).
    let idle: Vec<TcpStream> = (0..4)
        .map(|_| TcpStream::connect(("127.0.0.1", server.port)).unwrap())
        .collect();
    std::thread::sleep(Duration::from_millis(200));
    let r = server.get("/api/scene");
    assert_eq!(r.status, 503, "{}", r.text());
    assert_eq!(r.header("retry-after"), Some("1"));
    assert!(
        r.json()["error"]
            .as_str()
            .unwrap()
            .contains("limit of 4 open connections")
    );
    // Their places come back when they leave.
    drop(idle);
    std::thread::sleep(Duration::from_millis(300));
    assert_eq!(server.get("/api/scene").status, 200);
}

#[test]
fn oversized_and_malformed_requests_get_their_4xx() {
    let server = ViewServer::start(&["--size", "32", "16"]);
    let bearer = bearer(&server);
    let many: String = (0..65).map(|i| format!("X-{i}: 1\r\n")).collect();
    let long = format!("X-Long: {}\r\n", "a".repeat(20_000));
    let cases: [(String, u16, &str); 5] = [
        (
            format!("GET /api/scene HTTP/1.1\r\n{many}\r\n"),
            431,
            "too many request headers",
        ),
        (
            format!("GET /api/scene HTTP/1.1\r\n{long}\r\n"),
            431,
            "request head too large",
        ),
        (
            format!(
                "POST /api/render HTTP/1.1\r\nAuthorization: {bearer}\r\nTransfer-Encoding: chunked\r\n\r\n2\r\n{{}}\r\n0\r\n\r\n"
            ),
            411,
            "Content-Length",
        ),
        (
            "\x16\x03\x01\x02\x00 not http\r\n\r\n".to_string(),
            400,
            "malformed HTTP request",
        ),
        (
            format!(
                "POST /api/render HTTP/1.1\r\nAuthorization: {bearer}\r\nContent-Length: 999999\r\n\r\n{{}}"
            ),
            413,
            "too large",
        ),
    ];
    for (request, status, message) in cases {
        let r = parse_reply(&server.raw(request.as_bytes()));
        let what = &request[..request.len().min(40)];
        assert_eq!(r.status, status, "{what:?}: {}", r.text());
        let json = r.json();
        assert!(
            json["error"].as_str().unwrap().contains(message),
            "{what:?}: {json}"
        );
    }
    assert_eq!(server.get("/api/scene").status, 200);
}

#[test]
fn a_stop_finishes_the_requests_in_hand() {
    let server = ViewServer::start(&["--size", "32", "16"]);
    let (port, bearer) = (server.port, bearer(&server));
    // A request whose body comes a second after its head: the signal arrives in between, and
    // the request is still read and answered whole.
    let client = std::thread::spawn(move || {
        let mut s = TcpStream::connect(("127.0.0.1", port)).unwrap();
        let head = format!(
            "POST /api/render HTTP/1.1\r\nHost: 127.0.0.1\r\nAuthorization: {bearer}\r\nContent-Length: 2\r\n\r\n"
        );
        s.write_all(head.as_bytes()).unwrap();
        std::thread::sleep(Duration::from_secs(1));
        let body_sent = Instant::now();
        s.write_all(b"{}").unwrap();
        let mut raw = Vec::new();
        s.read_to_end(&mut raw).unwrap();
        (parse_reply(&raw), body_sent)
    });
    std::thread::sleep(Duration::from_millis(300));
    let signalled = Instant::now();
    let (status, stderr) = server.stop(libc::SIGINT, Duration::from_secs(30));
    let (reply, body_sent) = client.join().unwrap();
    assert!(body_sent > signalled, "the body went before the signal");
    assert_eq!(reply.status, 200, "{}", reply.text());
    assert!(reply.json()["job"].is_u64());
    assert_eq!(status.code(), Some(130), "{stderr}");
}
