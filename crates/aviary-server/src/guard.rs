//! Who may call: every request's `Host` and `Origin`, and the run's token.
//!
//! - `Host` must name this server: a loopback name (`localhost`, `127.0.0.1`, `[::1]`)
//!   or the bound address, with the bound port, or a name the user allowed
//!   (`--allow-host`, for a reverse proxy). Anything else is DNS rebinding: a page of
//!   `evil.example` whose name was made to resolve to this machine (403).
//! - `Origin`, when a browser sends one, must be one of those hosts, same scheme and
//!   port: a WebSocket is not bound by the same-origin rule, so without this any page
//!   the operator opens could stream the fleet (403). Non-browser clients send none.
//! - The token, as `Authorization: Bearer TOKEN` (any case of `Bearer`), or for a
//!   browser's WebSocket as the subprotocol `aviary.bearer.TOKEN`, compared in constant
//!   time. Control calls always need it; reads need it when the server is bound beyond
//!   loopback, where other machines can reach it (401). It is checked before a body is
//!   read, so an unauthenticated call learns nothing from the body's errors.

use std::net::{IpAddr, SocketAddr};
use std::sync::Arc;

use axum::extract::{Request, State};
use axum::http::{header, HeaderMap, HeaderValue, StatusCode, Uri};
use axum::middleware::Next;
use axum::response::Response;
use subtle::ConstantTimeEq;

use crate::reply::error;

/// The subprotocol prefix that carries the token on a browser's WebSocket: browsers
/// cannot set `Authorization` on one.
pub const TOKEN_PROTOCOL: &str = "aviary.bearer.";

/// Who may call a server: its address, the names it answers to and its token. One gate
/// guards every route a server has: the operator API of each run, and the ground
/// station's own calls.
pub struct Gate {
    access: Access,
    token: String,
}

impl Gate {
    /// A server bound at `bound`, answering besides loopback and that address to
    /// `allowed_hosts` (`--allow-host`), with its token.
    pub fn new(bound: SocketAddr, token: String, allowed_hosts: &[String]) -> Gate {
        let allowed =
            allowed_hosts.iter().map(|h| h.trim_end_matches('.').to_ascii_lowercase()).collect();
        Gate { access: Access { bound, allowed, scheme: "http" }, token }
    }

    /// Whether other machines can reach the server: then reading needs the token too.
    pub fn beyond_loopback(&self) -> bool {
        self.access.beyond_loopback()
    }

    /// In constant time: how much of a guess is right must not show in the time taken.
    pub fn token_is(&self, given: &str) -> bool {
        bool::from(given.as_bytes().ct_eq(self.token.as_bytes()))
    }
}

struct Access {
    bound: SocketAddr,
    /// `--allow-host` names, lower case: any port and scheme (a proxy's).
    allowed: Vec<String>,
    scheme: &'static str,
}

impl Access {
    fn beyond_loopback(&self) -> bool {
        !self.bound.ip().is_loopback()
    }

    /// Whether `host` (a name or IP, lower case, IPv6 without brackets) at `port` is this server.
    fn is_ours(&self, host: &str, port: u16) -> bool {
        if self.allowed.iter().any(|a| a == host) {
            return true;
        }
        if port != self.bound.port() {
            return false;
        }
        match host.parse::<IpAddr>() {
            // A wildcard bind answers on every address of the machine. An IP address
            // cannot be rebound (rebinding needs a name), so any one is this server.
            Ok(ip) => ip.is_loopback() || ip == self.bound.ip() || self.bound.ip().is_unspecified(),
            Err(_) => host == "localhost",
        }
    }

    /// `Ok` or why the request is refused.
    fn check(&self, headers: &HeaderMap, uri: &Uri) -> Result<(), String> {
        let host = match headers.get(header::HOST) {
            Some(h) => h.to_str().ok().map(str::to_string),
            None => uri.authority().map(|a| a.to_string()),
        };
        let Some(host) = host else { return Err("the request has no Host header".into()) };
        let default = if self.scheme == "https" { 443 } else { 80 };
        match split_host(&host, default) {
            Some((name, port)) if self.is_ours(&name, port) => {}
            _ => {
                return Err(format!(
                    "Host `{}` is not this server: use {}://127.0.0.1:{}, or allow the name with --allow-host",
                    shown(&host),
                    self.scheme,
                    self.bound.port()
                ))
            }
        }
        let Some(origin) = headers.get(header::ORIGIN) else { return Ok(()) };
        let text = origin.to_str().unwrap_or("");
        let fits = match text.split_once("://") {
            Some((scheme @ ("http" | "https"), rest)) => {
                match split_host(rest, if scheme == "https" { 443 } else { 80 }) {
                    Some((name, _)) if self.allowed.contains(&name) => true,
                    Some((name, port)) => scheme == self.scheme && self.is_ours(&name, port),
                    None => false,
                }
            }
            _ => false,
        };
        match fits {
            true => Ok(()),
            false => Err(format!("Origin `{}` may not call this server: pages of other sites may not reach the operator API", shown(text))),
        }
    }
}

/// `name[:port]` or `[v6][:port]`, lower case, without a trailing dot; `None` when it
/// is not a host (a path, user info, an empty name, a bad port).
fn split_host(text: &str, default_port: u16) -> Option<(String, u16)> {
    let (name, port) = match text.strip_prefix('[') {
        Some(rest) => {
            let (v6, after) = rest.split_once(']')?;
            let port = if after.is_empty() { None } else { Some(after.strip_prefix(':')?) };
            (v6, port)
        }
        None => match text.rsplit_once(':') {
            Some((name, port)) => (name, Some(port)),
            None => (text, None),
        },
    };
    let port = match port {
        Some(p) => p.parse::<u16>().ok()?,
        None => default_port,
    };
    let name = name.strip_suffix('.').unwrap_or(name).to_ascii_lowercase();
    let bad = |c: char| !(c.is_ascii_alphanumeric() || matches!(c, '.' | '-' | '_' | ':'));
    (!name.is_empty() && !name.contains(bad)).then_some((name, port))
}

/// A header as shown in a message: short, printable.
fn shown(text: &str) -> String {
    text.chars().filter(|c| !c.is_control()).take(80).collect()
}

/// Every request: Host and Origin.
pub async fn same_origin(State(gate): State<Arc<Gate>>, request: Request, next: Next) -> Response {
    match gate.access.check(request.headers(), request.uri()) {
        Ok(()) => next.run(request).await,
        Err(why) => error(StatusCode::FORBIDDEN, why),
    }
}

/// Control calls: the token, always.
pub async fn token(State(gate): State<Arc<Gate>>, request: Request, next: Next) -> Response {
    match given(request.headers()) {
        Some(t) if gate.token_is(&t) => next.run(request).await,
        Some(_) => unauthorized("that is not this run's token"),
        None => unauthorized(
            "this call needs the token the run printed: send `Authorization: Bearer TOKEN`",
        ),
    }
}

/// Reads: the token beyond loopback; on loopback none is needed, but a wrong one is refused.
pub async fn read_token(State(gate): State<Arc<Gate>>, request: Request, next: Next) -> Response {
    match given(request.headers()) {
        Some(t) if !gate.token_is(&t) => unauthorized("that is not this run's token"),
        None if gate.access.beyond_loopback() => {
            unauthorized("the server is reachable beyond this machine, so reading needs the token too: send `Authorization: Bearer TOKEN`")
        }
        _ => next.run(request).await,
    }
}

fn unauthorized(message: &str) -> Response {
    let mut response = error(StatusCode::UNAUTHORIZED, message);
    response.headers_mut().insert(header::WWW_AUTHENTICATE, HeaderValue::from_static("Bearer"));
    response
}

/// The token a request carries: `Authorization: Bearer T`, or a subprotocol `aviary.bearer.T`.
fn given(headers: &HeaderMap) -> Option<String> {
    if let Some(value) = headers.get(header::AUTHORIZATION) {
        let text = value.to_str().unwrap_or("");
        let (scheme, token) = text.trim().split_once(' ').unwrap_or((text, ""));
        // A malformed header counts as a wrong token, never as no token.
        return Some(if scheme.eq_ignore_ascii_case("bearer") {
            token.trim().to_string()
        } else {
            String::new()
        });
    }
    let protocols = headers
        .get_all(header::SEC_WEBSOCKET_PROTOCOL)
        .iter()
        .filter_map(|v| v.to_str().ok())
        .flat_map(|v| v.split(','));
    protocols.map(str::trim).find_map(|p| p.strip_prefix(TOKEN_PROTOCOL)).map(str::to_string)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hosts_split_into_name_and_port() {
        assert_eq!(split_host("LocalHost:7878", 80), Some(("localhost".into(), 7878)));
        assert_eq!(split_host("[::1]:7878", 80), Some(("::1".into(), 7878)));
        assert_eq!(split_host("[::1]", 443), Some(("::1".into(), 443)));
        assert_eq!(split_host("example.com.", 80), Some(("example.com".into(), 80)));
        assert_eq!(split_host("a@b:1", 80), None);
        assert_eq!(split_host("host:99999", 80), None);
        assert_eq!(split_host("host/path", 80), None);
        assert_eq!(split_host("", 80), None);
    }
}
