//! One connection: its request read under limits, its reply written, then closed. Every limit
//! is here, so that a slow or hostile client costs the server one thread for a bounded time and
//! a bounded amount of memory, and gets a JSON error saying which limit it met:
//!
//! ```text
//! the whole request (head and body) within REQUEST_TIME of the connection    else 408
//! the head (request line and headers) at most MAX_HEAD_BYTES, MAX_HEADERS    else 431
//! the body at most MAX_BODY_BYTES, announced by Content-Length               else 413 / 411
//! the reply taken by the client within WRITE_TIME                            else closed
//! ```
//!
//! One request per connection (`Connection: close`): the page's requests are few and small,
//! and a connection that ends with its reply cannot be held open idle.

use super::http::{ApiError, MAX_BODY_BYTES, Reply};
use crate::render::quote::quote;
use std::io::{ErrorKind, Read, Write};
use std::net::{Shutdown, TcpStream};
use std::time::{Duration, Instant};

/// The time a client has to send its whole request, from the moment it is accepted. A browser
/// sends its requests in one packet; a client one byte a second (slowloris) is cut off here.
pub(crate) const REQUEST_TIME: Duration = Duration::from_secs(5);

/// The time a client has to take its reply.
const WRITE_TIME: Duration = Duration::from_secs(30);

/// The largest request head (request line and headers).
const MAX_HEAD_BYTES: usize = 16 * 1024;

/// The most headers in one request.
const MAX_HEADERS: usize = 64;

/// A request, read whole.
#[derive(Debug)]
pub(crate) struct Request {
    /// `GET`, `POST`, ...
    pub method: String,
    /// The request target: the path and the query.
    pub target: String,
    /// The headers, names in lower case, in order.
    pub headers: Vec<(String, String)>,
    pub body: Vec<u8>,
}

impl Request {
    /// Every value of the header `name` (lower case).
    pub(crate) fn all(&self, name: &str) -> Vec<&str> {
        self.headers
            .iter()
            .filter_map(|(n, v)| (n == name).then_some(v.as_str()))
            .collect()
    }

    /// The path and the query (after `?`, possibly empty).
    pub(crate) fn path_and_query(&self) -> (&str, &str) {
        self.target.split_once('?').unwrap_or((&self.target, ""))
    }

    /// The one value of header `name`, None when absent; given twice is a 400.
    pub(crate) fn one(&self, name: &str) -> Result<Option<&str>, ApiError> {
        match self.all(name).as_slice() {
            [] => Ok(None),
            [v] => Ok(Some(v)),
            _ => Err(ApiError::bad(format!("header `{name}` given twice"))),
        }
    }
}

/// Why no request came.
#[derive(Debug)]
pub(crate) enum ReadError {
    /// The client closed the connection before a whole request (nothing to answer).
    Closed,
    /// The request broke a rule or a limit: this is the answer.
    Refused(ApiError),
}

impl From<ApiError> for ReadError {
    fn from(e: ApiError) -> Self {
        ReadError::Refused(e)
    }
}

/// Reads one request from `stream`, which was accepted at `accepted`, within `limit`.
pub(crate) fn read_request(
    stream: &mut impl Source,
    accepted: Instant,
    limit: Duration,
) -> Result<Request, ReadError> {
    let deadline = accepted + limit;
    let mut buf: Vec<u8> = Vec::with_capacity(2048);
    let (head_len, mut request) = loop {
        let mut slots = [httparse::EMPTY_HEADER; MAX_HEADERS];
        let mut parsed = httparse::Request::new(&mut slots);
        match parsed.parse(&buf) {
            Ok(httparse::Status::Complete(n)) => {
                let headers = parsed.headers.iter().map(|h| {
                    let value = String::from_utf8_lossy(h.value).into_owned();
                    (h.name.to_ascii_lowercase(), value)
                });
                let request = Request {
                    method: parsed.method.unwrap_or_default().to_string(),
                    target: parsed.path.unwrap_or_default().to_string(),
                    headers: headers.collect(),
                    body: Vec::new(),
                };
                break (n, request);
            }
            Ok(httparse::Status::Partial) => {}
            Err(httparse::Error::TooManyHeaders) => {
                return Err(ApiError::status(
                    431,
                    format!("too many request headers: expected at most {MAX_HEADERS}"),
                )
                .into());
            }
            Err(e) => {
                return Err(ApiError::bad(format!("malformed HTTP request: {e}")).into());
            }
        }
        if buf.len() >= MAX_HEAD_BYTES {
            return Err(ApiError::status(
                431,
                format!("request head too large: expected at most {MAX_HEAD_BYTES} bytes of request line and headers"),
            )
            .into());
        }
        read_some(stream, &mut buf, MAX_HEAD_BYTES, deadline, limit)?;
    };
    if request.one("transfer-encoding")?.is_some() {
        return Err(ApiError::status(
            411,
            "chunked request bodies are not accepted: send the body with a Content-Length",
        )
        .into());
    }
    let length = match request.one("content-length")? {
        None => 0,
        Some(v) => v.trim().parse::<usize>().map_err(|_| {
            ApiError::bad(format!(
                "Content-Length `{}`: expected a whole number of bytes",
                quote(v)
            ))
        })?,
    };
    if length > MAX_BODY_BYTES {
        return Err(ApiError::status(
            413,
            format!("request body too large: {length} bytes, expected at most {MAX_BODY_BYTES}"),
        )
        .into());
    }
    let mut body = buf.split_off(head_len);
    while body.len() < length {
        read_some(stream, &mut body, length, deadline, limit)?;
    }
    if body.len() > length {
        return Err(ApiError::bad(format!(
            "{} bytes after the body's {length}: one request per connection",
            body.len() - length
        ))
        .into());
    }
    request.body = body;
    Ok(request)
}

/// What a request is read from: a socket, or bytes in a test.
pub(crate) trait Source: Read {
    /// Makes the next read give up after `timeout`.
    fn set_timeout(&mut self, timeout: Duration) -> std::io::Result<()>;
}

impl Source for TcpStream {
    fn set_timeout(&mut self, timeout: Duration) -> std::io::Result<()> {
        self.set_read_timeout(Some(timeout))
    }
}

/// Appends what arrives next to `buf`, keeping it within `cap` bytes; a 408 past `deadline`.
fn read_some(
    stream: &mut impl Source,
    buf: &mut Vec<u8>,
    cap: usize,
    deadline: Instant,
    limit: Duration,
) -> Result<(), ReadError> {
    let too_slow = || {
        ApiError::status(
            408,
            format!(
                "the request did not arrive within {} s of connecting: send it whole at once",
                limit.as_secs_f64()
            ),
        )
    };
    let left = deadline.saturating_duration_since(Instant::now());
    if left.is_zero() {
        return Err(too_slow().into());
    }
    stream.set_timeout(left).map_err(|_| ReadError::Closed)?;
    let mut chunk = [0u8; 4096];
    let room = (cap - buf.len()).clamp(1, chunk.len());
    match stream.read(&mut chunk[..room]) {
        Ok(0) => Err(ReadError::Closed),
        Ok(n) => {
            buf.extend_from_slice(&chunk[..n]);
            Ok(())
        }
        Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {
            Err(too_slow().into())
        }
        Err(e) if e.kind() == ErrorKind::Interrupted => Ok(()),
        Err(_) => Err(ReadError::Closed),
    }
}

/// The reason phrase of a status.
fn reason(status: u16) -> &'static str {
    match status {
        200 => "OK",
        400 => "Bad Request",
        403 => "Forbidden",
        404 => "Not Found",
        405 => "Method Not Allowed",
        408 => "Request Timeout",
        409 => "Conflict",
        410 => "Gone",
        411 => "Length Required",
        413 => "Content Too Large",
        421 => "Misdirected Request",
        429 => "Too Many Requests",
        431 => "Request Header Fields Too Large",
        500 => "Internal Server Error",
        503 => "Service Unavailable",
        _ => "",
    }
}

/// The bytes of `reply`'s head: status line and headers.
pub(crate) fn head(reply: &Reply, body_len: usize) -> Vec<u8> {
    let mut head = format!(
        "HTTP/1.1 {} {}\r\nContent-Type: {}\r\nContent-Length: {body_len}\r\nConnection: close\r\n\
         Cache-Control: {}\r\nX-Content-Type-Options: nosniff\r\nReferrer-Policy: no-referrer\r\n",
        reply.status,
        reason(reply.status),
        reply.content_type,
        if reply.cacheable {
            "private, max-age=60"
        } else {
            "no-store"
        },
    );
    for (name, value) in &reply.headers {
        head += &format!("{name}: {value}\r\n");
    }
    head += "\r\n";
    head.into_bytes()
}

/// Writes `reply` (its head alone for HEAD requests) and closes the connection: the write side
/// first, then whatever the client still sends is read and dropped for a moment, so that the
/// close does not reset the connection before the client has read the reply.
pub(crate) fn reply_and_close(mut stream: TcpStream, reply: &Reply, head_only: bool) {
    let _ = stream.set_write_timeout(Some(WRITE_TIME));
    let mut bytes = head(reply, reply.body.len());
    if !head_only {
        bytes.extend_from_slice(&reply.body);
    }
    // A client that hung up is not our error.
    if stream.write_all(&bytes).is_err() {
        return;
    }
    let _ = stream.shutdown(Shutdown::Write);
    linger(&mut stream, Duration::from_millis(200));
}

/// Reads and drops what the client sends for at most `time`, until it closes.
pub(crate) fn linger(stream: &mut TcpStream, time: Duration) {
    let end = Instant::now() + time;
    let mut sink = [0u8; 16 * 1024];
    loop {
        let left = end.saturating_duration_since(Instant::now());
        if left.is_zero() || stream.set_read_timeout(Some(left)).is_err() {
            return;
        }
        if let Ok(0) | Err(_) = stream.read(&mut sink) {
            return;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bytes that arrive in the given pieces, then EOF (or a timeout, if `stall`).
    struct Pieces {
        pieces: std::collections::VecDeque<Vec<u8>>,
        stall: bool,
    }

    impl Read for Pieces {
        fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
            match self.pieces.pop_front() {
                Some(mut p) => {
                    let n = p.len().min(out.len());
                    out[..n].copy_from_slice(&p[..n]);
                    if n < p.len() {
                        self.pieces.push_front(p.split_off(n));
                    }
                    Ok(n)
                }
                None if self.stall => Err(ErrorKind::WouldBlock.into()),
                None => Ok(0),
            }
        }
    }

    impl Source for Pieces {
        fn set_timeout(&mut self, _: Duration) -> std::io::Result<()> {
            Ok(())
        }
    }

    fn read(pieces: &[&[u8]], stall: bool) -> Result<Request, ReadError> {
        let mut source = Pieces {
            pieces: pieces.iter().map(|p| p.to_vec()).collect(),
            stall,
        };
        read_request(&mut source, Instant::now(), Duration::from_secs(5))
    }

    fn refused(r: Result<Request, ReadError>) -> ApiError {
        match r {
            Err(ReadError::Refused(e)) => e,
            other => panic!("expected a refusal, got {other:?}"),
        }
    }

    #[test]
    fn a_request_in_pieces_is_read_whole() {
        let r = read(
            &[
                b"POST /api/render?x=1 HTTP/1.1\r\nHost: a\r\nContent-",
                b"Length: 5\r\n\r\nab",
                b"cde",
            ],
            false,
        )
        .unwrap();
        assert_eq!(
            (r.method.as_str(), r.target.as_str()),
            ("POST", "/api/render?x=1")
        );
        assert_eq!(r.one("host").unwrap(), Some("a"));
        assert_eq!(r.body, b"abcde");
    }

    #[test]
    fn limits_are_answered_with_their_status() {
        let many: String = (0..MAX_HEADERS + 1)
            .map(|i| format!("X-{i}: 1\r\n"))
            .collect();
        let e = refused(read(
            &[format!("GET / HTTP/1.1\r\n{many}\r\n").as_bytes()],
            false,
        ));
        assert_eq!(e.status, 431);
        let long = format!("GET / HTTP/1.1\r\nX: {}\r\n", "a".repeat(MAX_HEAD_BYTES));
        assert_eq!(refused(read(&[long.as_bytes()], true)).status, 431);
        let big = format!(
            "POST / HTTP/1.1\r\nContent-Length: {}\r\n\r\n",
            MAX_BODY_BYTES + 1
        );
        assert_eq!(refused(read(&[big.as_bytes()], false)).status, 413);
        let chunked = b"POST / HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\n";
        assert_eq!(refused(read(&[chunked], false)).status, 411);
        let slow = b"GET / HTTP/1.1\r\nHost: a\r\n";
        assert_eq!(refused(read(&[slow], true)).status, 408);
        let short_body = b"POST / HTTP/1.1\r\nContent-Length: 9\r\n\r\nabc";
        assert_eq!(refused(read(&[short_body], true)).status, 408);
        assert_eq!(
            refused(read(&[b"\x16\x03\x01 hello\r\n\r\n"], false)).status,
            400
        );
        let twice = b"POST / HTTP/1.1\r\nContent-Length: 1\r\nContent-Length: 2\r\n\r\n";
        assert_eq!(refused(read(&[twice], false)).status, 400);
        let bad_len = b"POST / HTTP/1.1\r\nContent-Length: -1\r\n\r\n";
        assert_eq!(refused(read(&[bad_len], false)).status, 400);
    }

    #[test]
    fn a_client_that_leaves_early_gets_no_answer() {
        assert!(matches!(
            read(&[b"GET / HTTP/1.1\r\n"], false),
            Err(ReadError::Closed)
        ));
    }

    #[test]
    fn the_deadline_counts_from_the_connection() {
        let mut source = Pieces {
            pieces: [b"GET / HTTP/1.1\r\n".to_vec()].into(),
            stall: false,
        };
        let long_ago = Instant::now() - Duration::from_secs(10);
        let e = refused(read_request(&mut source, long_ago, Duration::from_secs(5)));
        assert_eq!(e.status, 408);
    }

    #[test]
    fn replies_carry_their_headers() {
        let reply = Reply {
            headers: vec![
                ("Retry-After", "1".into()),
                ("Set-Cookie", "a=b".into()),
                ("Allow", "GET".into()),
            ],
            ..Reply::bytes("text/plain", b"hi".to_vec())
        };
        let head = String::from_utf8(head(&reply, 2)).unwrap();
        assert!(head.starts_with("HTTP/1.1 200 OK\r\n"));
        for line in [
            "Content-Length: 2",
            "Retry-After: 1",
            "Set-Cookie: a=b",
            "Allow: GET",
            "Connection: close",
        ] {
            assert!(head.contains(&format!("{line}\r\n")), "{line} in {head}");
        }
        assert!(head.ends_with("\r\n\r\n"));
    }

    proptest::proptest! {
        /// Any bytes, cut anywhere: a request or a refusal, never a panic, and a request's body
        /// is exactly what its Content-Length says.
        #[test]
        fn any_bytes_in_any_pieces_are_read_or_refused(
            bytes in proptest::collection::vec(proptest::prelude::any::<u8>(), 0..512),
            prefix in proptest::prelude::prop_oneof![
                proptest::prelude::Just(&b""[..]),
                proptest::prelude::Just(&b"POST / HTTP/1.1\r\nContent-Length: 3\r\n"[..]),
                proptest::prelude::Just(&b"GET / HTTP/1.1\r\n"[..]),
            ],
            cuts in proptest::collection::vec(0usize..600, 0..4),
            stall in proptest::prelude::any::<bool>(),
        ) {
            let mut all = prefix.to_vec();
            all.extend_from_slice(&bytes);
            let mut cuts: Vec<usize> = cuts.into_iter().map(|c| c.min(all.len())).collect();
            cuts.sort_unstable();
            let mut pieces = Vec::new();
            let mut from = 0;
            for c in cuts.into_iter().chain([all.len()]) {
                pieces.push(all[from..c].to_vec());
                from = c;
            }
            let mut source = Pieces { pieces: pieces.into(), stall };
            if let Ok(r) = read_request(&mut source, Instant::now(), Duration::from_secs(5)) {
                let declared = r.one("content-length").unwrap().map_or(0, |v| v.trim().parse().unwrap());
                proptest::prop_assert_eq!(r.body.len(), declared);
            }
        }
    }
}
