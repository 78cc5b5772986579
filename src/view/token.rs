//! The access token, as Jupyter's: a random secret in the URL `raywave view` prints. The first
//! load of the page (`GET /?token=T`) sets it as a cookie (`HttpOnly`, `SameSite=Strict`) that
//! the page's own requests then carry; scripts send `Authorization: Bearer T`. Every other
//! request is refused with 403, so neither another user of a shared machine nor a web page in
//! the browser can drive the server, and it can be reached through an SSH tunnel or on a LAN
//! (`--bind`) without weakening it.
//!
//! ```text
//! where the token may be         accepted on       wrong place (400)
//! ?token=T in the query          GET / only        any other path (URLs end up in logs)
//! Cookie: raywave_token_PORT=T   every path
//! Authorization: Bearer T        every path        another scheme, or no scheme
//! ```

use super::connection::Request;
use super::http::ApiError;
use crate::render::quote::quote;
use subtle::ConstantTimeEq;

/// Random bytes in a generated token: 192 bits, 48 hex digits (Jupyter's size).
const RANDOM_BYTES: usize = 24;

/// The shortest token `--token` accepts.
const MIN_LEN: usize = 16;

/// The longest token `--token` accepts.
const MAX_LEN: usize = 256;

/// The secret every request must carry.
#[derive(Clone, PartialEq, Eq)]
pub struct Token(String);

impl std::fmt::Debug for Token {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Token(..)")
    }
}

impl Token {
    /// A new token from the operating system's random source.
    pub fn random() -> Result<Token, getrandom::Error> {
        let mut bytes = [0u8; RANDOM_BYTES];
        getrandom::fill(&mut bytes)?;
        Ok(Token(bytes.iter().map(|b| format!("{b:02x}")).collect()))
    }

    /// A token given by the user (`--token`, `RAYWAVE_VIEW_TOKEN`): 16 to 256 characters from
    /// `A-Z a-z 0-9 - . _ ~`, the characters that go into a URL, a cookie and a header as they
    /// are.
    pub fn parse(value: &str) -> Result<Token, String> {
        let bad = value
            .chars()
            .find(|c| !(c.is_ascii_alphanumeric() || matches!(c, '-' | '.' | '_' | '~')));
        if let Some(c) = bad {
            return Err(format!(
                "the token holds `{}`: expected only letters, digits, `-`, `.`, `_` and `~`",
                quote(&c.to_string())
            ));
        }
        let n = value.chars().count();
        if !(MIN_LEN..=MAX_LEN).contains(&n) {
            return Err(format!(
                "the token is {n} characters long: expected {MIN_LEN} to {MAX_LEN} (a generated one has {})",
                2 * RANDOM_BYTES
            ));
        }
        Ok(Token(value.to_string()))
    }

    /// The token's text, for the URL printed at start-up.
    pub fn as_str(&self) -> &str {
        &self.0
    }

    /// Whether `candidate` is this token, in time that does not depend on where they differ.
    fn matches(&self, candidate: &str) -> bool {
        self.0.as_bytes().ct_eq(candidate.as_bytes()).into()
    }
}

/// Who may use the server.
#[derive(Clone, Debug)]
pub enum Access {
    /// Whoever presents the token.
    Token(Token),
    /// Anyone who can connect (`--no-token`, loopback only).
    Open,
}

impl Access {
    /// Checks a request. `Ok(Some(cookie))` when the page was opened with the token in its URL:
    /// the reply sets that cookie. `port` is the server's (it names the cookie).
    pub(crate) fn check(&self, request: &Request, port: u16) -> Result<Option<String>, ApiError> {
        let Access::Token(token) = self else {
            return Ok(None);
        };
        let (path, query) = request.path_and_query();
        let in_query = query_token(query)?;
        let is_page = matches!(path, "/" | "/index.html");
        if in_query.is_some() && !is_page {
            return Err(ApiError::bad(format!(
                "the token is in the query string of {}: it belongs only in the page's URL (/?token=...); \
                 requests send it in `Authorization: Bearer TOKEN` (or the page's cookie), so that it stays out of logs",
                quote(path)
            )));
        }
        let bearer: Vec<&str> = (request.all("authorization").into_iter())
            .map(bearer_token)
            .collect::<Result<_, _>>()?;
        // One cookie per port, so that two viewers on one machine keep their own.
        let name = format!("raywave_token_{port}");
        let cookies: Vec<&str> = request
            .all("cookie")
            .into_iter()
            .flat_map(|header| header.split(';'))
            .filter_map(|pair| pair.trim().strip_prefix(name.as_str())?.strip_prefix('='))
            .collect();
        if in_query.is_some_and(|t| token.matches(t)) {
            // Keeps the token for the page's later requests.
            let cookie = format!(
                "{name}={}; Path=/; HttpOnly; SameSite=Strict",
                token.as_str()
            );
            return Ok(Some(cookie));
        }
        let presented = in_query.is_some() || !bearer.is_empty() || !cookies.is_empty();
        if bearer.iter().chain(&cookies).any(|t| token.matches(t)) {
            return Ok(None);
        }
        Err(ApiError::status(
            403,
            if presented {
                "wrong access token: open the URL that `raywave view` printed when it started \
                 (the token changes at every start unless --token or RAYWAVE_VIEW_TOKEN fixes it)"
            } else {
                "this server needs its access token: open the URL that `raywave view` printed \
                 (it ends in ?token=...), or send `Authorization: Bearer TOKEN`"
            },
        ))
    }
}

/// The `token` parameter of a query, if any (given twice is a 400).
fn query_token(query: &str) -> Result<Option<&str>, ApiError> {
    let mut values = (query.split('&'))
        .map(|pair| pair.split_once('=').unwrap_or((pair, "")))
        .filter_map(|(name, value)| (name == "token").then_some(value));
    match (values.next(), values.next()) {
        (_, Some(_)) => Err(ApiError::bad("query parameter `token` given twice")),
        (value, None) => Ok(value),
    }
}

/// The token of an `Authorization: Bearer TOKEN` header; any other form is a 400.
fn bearer_token(value: &str) -> Result<&str, ApiError> {
    let (scheme, rest) = value.trim().split_once(' ').unwrap_or((value.trim(), ""));
    if scheme.eq_ignore_ascii_case("bearer") && !rest.trim().is_empty() {
        return Ok(rest.trim());
    }
    Err(ApiError::bad(format!(
        "`Authorization: {}` is not how the token is sent: expected `Authorization: Bearer TOKEN`",
        quote(if scheme.eq_ignore_ascii_case("bearer") {
            scheme
        } else {
            "..."
        })
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    const T: &str = "0123456789abcdef0123";

    fn access() -> Access {
        Access::Token(Token::parse(T).unwrap())
    }

    fn presented(path: &str, query: &str) -> Request {
        Request {
            method: "GET".into(),
            target: format!("{path}?{query}"),
            headers: Vec::new(),
            body: Vec::new(),
        }
    }

    #[test]
    fn generated_tokens_are_long_random_and_valid() {
        let (a, b) = (Token::random().unwrap(), Token::random().unwrap());
        assert_eq!(a.as_str().len(), 48);
        assert_ne!(a, b);
        assert!(Token::parse(a.as_str()).is_ok());
        assert!(!format!("{a:?}").contains(a.as_str()), "Debug hides it");
    }

    #[test]
    fn given_tokens_are_checked() {
        assert!(Token::parse("short").unwrap_err().contains("16 to 256"));
        assert!(
            Token::parse("has a space in the middle")
                .unwrap_err()
                .contains("only letters")
        );
        assert!(Token::parse("semi;colon-0123456789").is_err());
        assert!(Token::parse(&"x".repeat(257)).is_err());
        assert!(Token::parse("abcdef-._~0123456789").is_ok());
    }

    #[test]
    fn the_page_with_the_token_sets_the_cookie() {
        let query = format!("token={T}");
        let cookie = access().check(&presented("/", &query), 8000).unwrap();
        assert_eq!(
            cookie.as_deref(),
            Some(format!("raywave_token_8000={T}; Path=/; HttpOnly; SameSite=Strict").as_str())
        );
    }

    #[test]
    fn the_cookie_and_the_bearer_header_are_accepted() {
        let cookie = format!("other=1; raywave_token_8000={T}");
        let mut p = presented("/api/scene", "");
        p.headers.push(("cookie".into(), cookie));
        assert_eq!(access().check(&p, 8000).unwrap(), None);
        // Another port's cookie is another server's.
        assert_eq!(access().check(&p, 8001).unwrap_err().status, 403);
        let bearer = format!("Bearer {T}");
        let mut p = presented("/api/scene", "");
        p.headers.push(("authorization".into(), bearer));
        assert_eq!(access().check(&p, 8000).unwrap(), None);
    }

    #[test]
    fn missing_wrong_and_misplaced_tokens_are_refused() {
        let missing = access().check(&presented("/", ""), 8000).unwrap_err();
        assert_eq!(missing.status, 403);
        assert!(missing.message.contains("needs its access token"));
        let wrong = access()
            .check(&presented("/", "token=0123456789abcdef0124"), 8000)
            .unwrap_err();
        assert_eq!(wrong.status, 403);
        assert!(wrong.message.contains("wrong access token"));
        let query = format!("token={T}");
        let misplaced = access()
            .check(&presented("/api/scene", &query), 8000)
            .unwrap_err();
        assert_eq!(misplaced.status, 400);
        assert!(misplaced.message.contains("Authorization: Bearer"));
        let mut p = presented("/api/scene", "");
        p.headers.push(("authorization".into(), T.into()));
        assert_eq!(access().check(&p, 8000).unwrap_err().status, 400);
        let twice = format!("token={T}&token={T}");
        assert_eq!(
            access()
                .check(&presented("/", &twice), 8000)
                .unwrap_err()
                .status,
            400
        );
    }

    #[test]
    fn an_open_server_lets_everyone_in() {
        assert_eq!(Access::Open.check(&presented("/", ""), 8000).unwrap(), None);
    }

    #[test]
    fn comparison_needs_every_byte() {
        let t = Token::parse(T).unwrap();
        assert!(t.matches(T));
        assert!(!t.matches("0123456789abcdef012"));
        assert!(!t.matches("0123456789abcdef0124"));
        assert!(!t.matches(""));
    }
}
