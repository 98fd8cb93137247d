//! A call to an HTTP router built from fuzz bytes, for the targets that fuzz the operator
//! API and the ground station: byte 0 picks the route, byte 1 sets flags (bit 0: send the
//! token; bit 1: the server is bound beyond loopback; bit 2: `Content-Type:
//! application/json`), then, where the target takes one, a line appended to the route's
//! path, then header lines `Name: value` up to an empty line, then the body.

use std::net::SocketAddr;

use axum::body::Body;
use axum::http::{HeaderName, HeaderValue, Request};

/// The token the fuzzed servers are given.
pub(crate) const TOKEN: &str = "00112233445566778899aabbccddeeff";

pub(crate) struct Call {
    pub route: (&'static str, &'static str),
    pub request: Request<Body>,
    /// Where the server is bound: loopback, or beyond it.
    pub bound: SocketAddr,
    /// Whether the token is anywhere in the headers.
    pub carries_token: bool,
}

/// The call of `data`; `None` when the path it makes is no URI a client could send.
pub(crate) fn call(
    data: &[u8],
    routes: &[(&'static str, &'static str)],
    with_path: bool,
) -> Option<Call> {
    let (route, flags, rest) = match data {
        [r, f, rest @ ..] => (routes[*r as usize % routes.len()], *f, rest),
        _ => (routes[0], 0, data),
    };
    let (path, rest) = match rest.iter().position(|b| *b == b'\n').filter(|_| with_path) {
        Some(i) => (&rest[..i], &rest[i + 1..]),
        None if with_path => (rest, &[][..]),
        None => (&[][..], rest),
    };
    let (head, body) = match rest.windows(2).position(|w| w == b"\n\n") {
        Some(i) => (&rest[..i], &rest[i + 2..]),
        None => (&[][..], rest),
    };
    let uri = format!("{}{}", route.1, String::from_utf8_lossy(path));
    let mut request =
        Request::builder().method(route.0).uri(uri).body(Body::from(body.to_vec())).ok()?;
    let headers = request.headers_mut();
    headers.insert("host", HeaderValue::from_static("127.0.0.1:7878"));
    if flags & 1 != 0 {
        headers.insert("authorization", HeaderValue::from_str(&format!("Bearer {TOKEN}")).ok()?);
    }
    if flags & 4 != 0 {
        headers.insert("content-type", HeaderValue::from_static("application/json"));
    }
    for line in head.split(|b| *b == b'\n') {
        let Some(colon) = line.iter().position(|b| *b == b':') else { continue };
        if let (Ok(name), Ok(value)) = (
            HeaderName::from_bytes(&line[..colon]),
            HeaderValue::from_bytes(line[colon + 1..].trim_ascii()),
        ) {
            headers.append(name, value);
        }
    }
    let carries_token =
        headers.values().any(|v| v.as_bytes().windows(TOKEN.len()).any(|w| w == TOKEN.as_bytes()));
    let bound = if flags & 2 != 0 { "0.0.0.0:7878" } else { "127.0.0.1:7878" };
    Some(Call { route, request, bound: bound.parse().ok()?, carries_token })
}
