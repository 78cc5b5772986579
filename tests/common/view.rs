//! `raywave view` for the tests: the server started on a free port, plain HTTP/1.1 requests to
//! it over a socket (so a test can send exactly the malformed request it means), with the
//! access token it printed or without it, and stopping it with a signal.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

/// A running `raywave view`.
pub struct ViewServer {
    /// The process.
    pub child: Child,
    /// Its port on 127.0.0.1.
    pub port: u16,
    /// The access token in the URL it printed (None with `--no-token`).
    pub token: Option<String>,
    /// The URL it printed, token included.
    pub printed_url: String,
}

/// One reply.
#[derive(Debug)]
pub struct HttpReply {
    /// Status code.
    pub status: u16,
    /// Header lines, names lower-cased.
    pub headers: Vec<(String, String)>,
    /// Body.
    pub body: Vec<u8>,
}

impl HttpReply {
    /// A header's value.
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }

    /// The body as text.
    pub fn text(&self) -> String {
        String::from_utf8_lossy(&self.body).into_owned()
    }

    /// The body as JSON (panics, naming the body, when it is not).
    pub fn json(&self) -> serde_json::Value {
        serde_json::from_slice(&self.body)
            .unwrap_or_else(|e| panic!("not JSON ({e}): {}", self.text()))
    }
}

impl ViewServer {
    /// Starts `raywave view ARGS --port 0` and reads the URL it prints.
    pub fn start(args: &[&str]) -> ViewServer {
        ViewServer::start_with(args, &[])
    }

    /// Starts `raywave view ARGS --port 0` with extra environment variables.
    pub fn start_with(args: &[&str], env: &[(&str, &str)]) -> ViewServer {
        let mut child = Command::new(crate::common::bin::exe())
            .arg("view")
            .args(args)
            .args(["--port", "0"])
            .env_remove("RAYWAVE_VIEW_TOKEN")
            .envs(env.iter().copied())
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("start raywave view");
        let mut line = String::new();
        BufReader::new(child.stdout.take().expect("stdout"))
            .read_line(&mut line)
            .expect("read the URL line");
        let printed_url = line
            .split_whitespace()
            .find(|w| w.starts_with("http://"))
            .unwrap_or_else(|| panic!("no URL in the first line: {line:?}"))
            .to_string();
        let port = printed_url
            .strip_prefix("http://127.0.0.1:")
            .and_then(|rest| rest.split('/').next())
            .and_then(|p| p.parse().ok())
            .unwrap_or_else(|| panic!("no 127.0.0.1 port in {printed_url:?}"));
        let token = printed_url
            .split_once("/?token=")
            .map(|(_, t)| t.to_string());
        ViewServer {
            child,
            port,
            token,
            printed_url,
        }
    }

    /// The page's URL, with the token: what a user opens.
    pub fn url(&self) -> String {
        self.printed_url.clone()
    }

    /// Sends one request (`Connection: close`) with the token (`Authorization: Bearer`, unless
    /// `headers` carry an Authorization or Cookie of their own) and reads the whole reply.
    /// `headers` are extra lines; a `Host` header is added unless one is given.
    pub fn request(
        &self,
        method: &str,
        path: &str,
        headers: &[(&str, &str)],
        body: &[u8],
    ) -> HttpReply {
        let own = headers.iter().any(|(n, _)| {
            n.eq_ignore_ascii_case("authorization") || n.eq_ignore_ascii_case("cookie")
        });
        let bearer = self.token.as_ref().map(|t| format!("Bearer {t}"));
        let mut all: Vec<(&str, &str)> = headers.to_vec();
        if let (false, Some(b)) = (own, bearer.as_deref()) {
            all.push(("Authorization", b));
        }
        self.request_without_token(method, path, &all, body)
    }

    /// [`request`](Self::request) with exactly the headers given: no token added.
    pub fn request_without_token(
        &self,
        method: &str,
        path: &str,
        headers: &[(&str, &str)],
        body: &[u8],
    ) -> HttpReply {
        send(self.port, method, path, headers, body)
    }

    /// Sends `bytes` as they are and reads until the server closes.
    pub fn raw(&self, bytes: &[u8]) -> Vec<u8> {
        send_raw(self.port, bytes)
    }

    /// GET.
    pub fn get(&self, path: &str) -> HttpReply {
        self.request("GET", path, &[], b"")
    }

    /// POST with a JSON body.
    pub fn post(&self, path: &str, body: &str) -> HttpReply {
        self.request(
            "POST",
            path,
            &[("Content-Type", "application/json")],
            body.as_bytes(),
        )
    }

    /// Posts a render and waits (at most `limit`) until its job is done; returns the job id and
    /// its last status.
    pub fn render(&self, settings: &str, limit: Duration) -> (u64, serde_json::Value) {
        let r = self.post("/api/render", settings);
        assert_eq!(r.status, 200, "{}", r.text());
        let job = r.json()["job"].as_u64().expect("a job id");
        let start = Instant::now();
        loop {
            let status = self.get(&format!("/api/render/{job}")).json();
            match status["state"].as_str() {
                Some("done") => return (job, status),
                Some("running" | "queued") if start.elapsed() < limit => {
                    std::thread::sleep(Duration::from_millis(20))
                }
                _ => panic!("job {job} did not finish in {limit:?}: {status}"),
            }
        }
    }

    /// Sends `signal` and waits (at most `limit`) for the process to end.
    pub fn stop(mut self, signal: i32, limit: Duration) -> (ExitStatus, String) {
        // SAFETY: kill(2) on our own child's pid.
        unsafe { libc::kill(self.child.id() as i32, signal) };
        let start = Instant::now();
        loop {
            if let Some(status) = self.child.try_wait().expect("wait") {
                let mut err = String::new();
                if let Some(mut e) = self.child.stderr.take() {
                    let _ = e.read_to_string(&mut err);
                }
                return (status, err);
            }
            if start.elapsed() > limit {
                let _ = self.child.kill();
                panic!("raywave view still running {limit:?} after signal {signal}");
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}

impl Drop for ViewServer {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Sends one request with exactly `headers` (and a `Host` unless they give one) to the server
/// on 127.0.0.1:`port`, `Connection: close`, and reads the whole reply. A free function, for
/// threads that outlive no [`ViewServer`] borrow.
pub fn send(
    port: u16,
    method: &str,
    path: &str,
    headers: &[(&str, &str)],
    body: &[u8],
) -> HttpReply {
    let mut head = format!("{method} {path} HTTP/1.1\r\nConnection: close\r\n");
    if !headers.iter().any(|(n, _)| n.eq_ignore_ascii_case("host")) {
        head += &format!("Host: 127.0.0.1:{port}\r\n");
    }
    for (n, v) in headers {
        head += &format!("{n}: {v}\r\n");
    }
    if !body.is_empty() || method == "POST" {
        head += &format!("Content-Length: {}\r\n", body.len());
    }
    head += "\r\n";
    let mut bytes = head.into_bytes();
    bytes.extend_from_slice(body);
    parse_reply(&send_raw(port, &bytes))
}

/// Sends `bytes` as they are to 127.0.0.1:`port` and reads until the server closes.
pub fn send_raw(port: u16, bytes: &[u8]) -> Vec<u8> {
    let mut s = TcpStream::connect(("127.0.0.1", port)).expect("connect");
    s.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
    // The server may answer (413) and close before taking the whole body.
    let _ = s.write_all(bytes);
    let mut raw = Vec::new();
    let _ = s.read_to_end(&mut raw);
    raw
}

/// A raw reply's status, headers and body.
pub fn parse_reply(raw: &[u8]) -> HttpReply {
    let split = raw
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .unwrap_or_else(|| panic!("no header end in {:?}", String::from_utf8_lossy(raw)));
    let head = String::from_utf8_lossy(&raw[..split]).into_owned();
    let mut lines = head.split("\r\n");
    let status = lines
        .next()
        .and_then(|l| l.split(' ').nth(1))
        .and_then(|s| s.parse().ok())
        .expect("a status line");
    let headers: Vec<(String, String)> = lines
        .filter_map(|l| l.split_once(':'))
        .map(|(n, v)| (n.trim().to_ascii_lowercase(), v.trim().to_string()))
        .collect();
    let body = &raw[split + 4..];
    // Every reply says its length (the server never sends chunked bodies).
    if let Some((_, n)) = headers.iter().find(|(n, _)| n == "content-length") {
        assert_eq!(
            n.parse::<usize>().ok(),
            Some(body.len()),
            "Content-Length {n} against the body"
        );
    }
    HttpReply {
        status,
        headers,
        body: body.to_vec(),
    }
}

/// The width and height in a PNG's IHDR chunk (panics when `bytes` is not a PNG).
pub fn png_size(bytes: &[u8]) -> (u32, u32) {
    assert!(
        bytes.starts_with(b"\x89PNG\r\n\x1a\n"),
        "not a PNG: {:?}",
        &bytes[..bytes.len().min(16)]
    );
    let be =
        |at: usize| u32::from_be_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    (be(16), be(20))
}
