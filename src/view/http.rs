//! The HTTP vocabulary the handlers share: the error every bad request becomes (a status and a
//! message, sent as JSON), replies, and query strings.

use crate::render::quote::quote;
use serde::Serialize;

/// The largest request body accepted: settings and comparison requests are a few hundred bytes.
pub(crate) const MAX_BODY_BYTES: usize = 64 * 1024;

/// A request that cannot be served, with the status and message the client gets.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ApiError {
    /// The HTTP status (4xx for the client's mistakes, 5xx for ours).
    pub status: u16,
    /// What went wrong, in one sentence.
    pub message: String,
    /// A header for the reply: a 405's `Allow`, or a 429's or 503's `Retry-After` (seconds).
    pub header: Option<(&'static str, String)>,
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
            header: None,
        }
    }

    /// A 405 Method Not Allowed for `method` on `path`, which allows `allow`.
    pub fn method(method: &str, path: &str, allow: &'static str) -> Self {
        ApiError {
            header: Some(("Allow", allow.to_string())),
            ..ApiError::status(
                405,
                format!(
                    "{} is not allowed on {}: expected {allow}",
                    quote(method),
                    quote(path)
                ),
            )
        }
    }

    /// A `status` (429 or 503) that asks the client to try again in `seconds`.
    pub fn retry(status: u16, seconds: u32, message: impl Into<String>) -> Self {
        ApiError {
            header: Some(("Retry-After", seconds.to_string())),
            ..ApiError::status(status, message)
        }
    }
}

/// What a handler answers: a status, a content type and the bytes.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Reply {
    pub status: u16,
    pub content_type: &'static str,
    pub body: Vec<u8>,
    /// Whether the client may cache it (assets compiled into the binary may).
    pub cacheable: bool,
    /// Headers past the fixed ones, in order: `Allow` (405), `Retry-After` (429, 503),
    /// `Set-Cookie` (the access token, when the page was opened with it).
    pub headers: Vec<(&'static str, String)>,
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
            headers: Vec::new(),
        }
    }
}

impl From<ApiError> for Reply {
    fn from(e: ApiError) -> Reply {
        let body = serde_json::json!({"error": e.message, "status": e.status});
        Reply {
            status: e.status,
            headers: e.header.into_iter().collect(),
            ..Reply::bytes("application/json", body.to_string().into_bytes())
        }
    }
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

/// The parameter `name` as a whole number, or a 400 saying it is missing or what was found.
pub(crate) fn number<T: std::str::FromStr>(
    pairs: &[(&str, &str)],
    name: &str,
) -> Result<T, ApiError> {
    let value = pairs
        .iter()
        .find_map(|&(n, v)| (n == name).then_some(v))
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
