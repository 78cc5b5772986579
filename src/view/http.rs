//! The HTTP vocabulary the handlers share: the error every bad request becomes (a status and a
//! message, sent as JSON), replies, request bodies read under a size limit, and query strings.

use crate::render::quote::quote;
use serde::Serialize;
use std::io::Read;

/// The largest request body accepted: settings and comparison requests are a few hundred bytes.
pub(crate) const MAX_BODY_BYTES: usize = 64 * 1024;

/// A request that cannot be served, with the status and message the client gets.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ApiError {
    /// The HTTP status (4xx for the client's mistakes, 5xx for ours).
    pub status: u16,
    /// What went wrong, in one sentence.
    pub message: String,
    /// The methods the path allows, for a 405's `Allow` header.
    pub allow: Option<&'static str>,
    /// Seconds to wait, for a 429's `Retry-After` header.
    pub retry_after: Option<u32>,
}

impl ApiError {
    /// A 400 Bad Request.
    pub fn bad(message: impl Into<String>) -> Self {
        ApiError::status(400, message)
    }

    /// A 404 Not Found.
    pub fn not_found(message: impl Into<String>) -> Self {
        ApiError::status(404, message)
    }

    /// Any status.
    pub fn status(status: u16, message: impl Into<String>) -> Self {
        ApiError {
            status,
            message: message.into(),
            allow: None,
            retry_after: None,
        }
    }

    /// A 405 Method Not Allowed for `method` on `path`, which allows `allow`.
    pub fn method(method: &str, path: &str, allow: &'static str) -> Self {
        ApiError {
            status: 405,
            message: format!(
                "{} is not allowed on {}: expected {allow}",
                quote(method),
                quote(path)
            ),
            allow: Some(allow),
            retry_after: None,
        }
    }
}

/// What a handler answers: a status, a content type and the bytes.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Reply {
    /// HTTP status.
    pub status: u16,
    /// `Content-Type`.
    pub content_type: &'static str,
    /// The body.
    pub body: Vec<u8>,
    /// Whether the client may cache it (assets compiled into the binary may).
    pub cacheable: bool,
    /// `Allow`, for 405.
    pub allow: Option<&'static str>,
    /// `Retry-After` in seconds, for 429.
    pub retry_after: Option<u32>,
}

impl Reply {
    /// 200 with a JSON body.
    pub(crate) fn json(value: &impl Serialize) -> Reply {
        match serde_json::to_vec(value) {
            Ok(body) => Reply::bytes("application/json", body),
            Err(e) => Reply::from(ApiError::status(
                500,
                format!("cannot encode the reply: {e}"),
            )),
        }
    }

    /// 200 with any body.
    pub(crate) fn bytes(content_type: &'static str, body: Vec<u8>) -> Reply {
        Reply {
            status: 200,
            content_type,
            body,
            cacheable: false,
            allow: None,
            retry_after: None,
        }
    }
}

impl From<ApiError> for Reply {
    fn from(e: ApiError) -> Reply {
        #[derive(Serialize)]
        struct Body<'a> {
            error: &'a str,
            status: u16,
        }
        let body = serde_json::to_vec(&Body {
            error: &e.message,
            status: e.status,
        })
        .unwrap_or_else(|_| b"{\"error\":\"unencodable error\"}".to_vec());
        Reply {
            status: e.status,
            content_type: "application/json",
            body,
            cacheable: false,
            allow: e.allow,
            retry_after: e.retry_after,
        }
    }
}

/// Reads a body of at most [`MAX_BODY_BYTES`]: a larger declared length is refused before
/// reading, and a body that turns out longer (chunked, or a lying header) after reading one byte
/// past the limit.
pub(crate) fn read_body(
    declared: Option<usize>,
    reader: &mut dyn Read,
) -> Result<Vec<u8>, ApiError> {
    let too_large = || {
        ApiError::status(
            413,
            format!("request body too large: expected at most {MAX_BODY_BYTES} bytes"),
        )
    };
    if declared.is_some_and(|n| n > MAX_BODY_BYTES) {
        return Err(too_large());
    }
    let mut body = Vec::new();
    reader
        .take(MAX_BODY_BYTES as u64 + 1)
        .read_to_end(&mut body)
        .map_err(|e| ApiError::bad(format!("cannot read the request body: {e}")))?;
    if body.len() > MAX_BODY_BYTES {
        return Err(too_large());
    }
    Ok(body)
}

/// A query string's `name=value` pairs, with every name checked against `allowed` (an unknown
/// or repeated parameter is a 400: a typo should not silently mean "the default").
pub(crate) fn query<'a>(q: &'a str, allowed: &[&str]) -> Result<Vec<(&'a str, &'a str)>, ApiError> {
    let mut out: Vec<(&str, &str)> = Vec::new();
    for pair in q.split('&').filter(|p| !p.is_empty()) {
        let (name, value) = pair.split_once('=').unwrap_or((pair, ""));
        if !allowed.contains(&name) {
            return Err(ApiError::bad(format!(
                "unknown query parameter `{}`: expected {}",
                quote(name),
                allowed.join(", ")
            )));
        }
        if out.iter().any(|(n, _)| *n == name) {
            return Err(ApiError::bad(format!(
                "query parameter `{name}` given twice"
            )));
        }
        out.push((name, value));
    }
    Ok(out)
}

/// The parameter `name` of `pairs` as a whole number, or a 400 saying it is missing or what was
/// found instead.
pub(crate) fn number<T: std::str::FromStr>(
    pairs: &[(&str, &str)],
    name: &str,
) -> Result<T, ApiError> {
    let value = pairs
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, v)| *v)
        .ok_or_else(|| ApiError::bad(format!("missing query parameter `{name}`")))?;
    value.parse().map_err(|_| {
        ApiError::bad(format!(
            "query parameter `{name}`: expected a whole number, found `{}`",
            quote(value)
        ))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bodies_over_the_limit_are_413_declared_or_not() {
        let big = vec![b' '; MAX_BODY_BYTES + 1];
        assert_eq!(
            read_body(Some(big.len()), &mut &big[..])
                .unwrap_err()
                .status,
            413
        );
        assert_eq!(read_body(None, &mut &big[..]).unwrap_err().status, 413);
        assert_eq!(read_body(Some(3), &mut &b"abc"[..]).unwrap(), b"abc");
    }

    #[test]
    fn queries_are_checked() {
        let q = query("x=3&y=-1", &["x", "y"]).unwrap();
        assert_eq!(number::<u32>(&q, "x").unwrap(), 3);
        assert!(
            number::<u32>(&q, "y")
                .unwrap_err()
                .message
                .contains("whole number")
        );
        assert!(
            number::<u32>(&q, "z")
                .unwrap_err()
                .message
                .contains("missing")
        );
        assert!(
            query("q=1", &["x"])
                .unwrap_err()
                .message
                .contains("unknown")
        );
        assert!(
            query("x=1&x=2", &["x"])
                .unwrap_err()
                .message
                .contains("twice")
        );
    }
}
