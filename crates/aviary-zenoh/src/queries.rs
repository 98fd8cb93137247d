//! The operator API as queryables: a query on `PREFIX/api/CALL` is the HTTP request it
//! stands for (`GET /api/state`, or `POST /api/CALL` with the query's payload as its JSON
//! body and the query's attachment as its token), answered by the run's own router; and
//! `PREFIX/api/mission` and `PREFIX/api/history` are answered with what a station shows
//! of the mission and the events so far. A
//! success is the reply, anything else an error reply with the same JSON, and logged: a
//! peer that sends garbage or calls without the token changes nothing, and the operator
//! sees that it tried.

use std::net::SocketAddr;
use std::thread::JoinHandle;

use axum::body::Body;
use axum::http::{header, Method, Request, StatusCode};
use tower::ServiceExt;
use zenoh::bytes::Encoding;
use zenoh::query::Query;
use zenoh::Wait;

use crate::keys::{CALLS, READS};
use crate::Keys;

/// The longest answer read back from the router (a state document of a large fleet).
const ANSWER_LIMIT: usize = 64 << 20;

pub(crate) fn start(
    session: zenoh::Session,
    keys: Keys,
    router: axum::Router,
    bound: SocketAddr,
    (mission, feed): (Vec<u8>, aviary_server::Feed),
) -> Result<JoinHandle<()>, String> {
    let queryable = session
        .declare_queryable(keys.api())
        .wait()
        .map_err(|e| format!("cannot answer on {}: {}", keys.api(), crate::reason(&e)))?;
    let runtime = tokio::runtime::Builder::new_current_thread()
        .build()
        .map_err(|e| format!("cannot start the Zenoh queryables: {e}"))?;
    std::thread::Builder::new()
        .name("aviary zenoh queryables".into())
        .spawn(move || {
            // Until the session closes.
            while let Ok(query) = queryable.recv() {
                let (status, body) = match keys.call_of(query.key_expr().as_str()) {
                    Some("mission") => (StatusCode::OK, mission.clone()),
                    Some("history") => (StatusCode::OK, history(&feed)),
                    _ => runtime.block_on(answer(&keys, &router, bound, &query)),
                };
                reply(&query, status, body);
            }
        })
        .map_err(|e| format!("cannot start the Zenoh queryables: {e}"))
}

/// The router's answer to the request `query` stands for.
async fn answer(
    keys: &Keys,
    router: &axum::Router,
    bound: SocketAddr,
    query: &Query,
) -> (StatusCode, Vec<u8>) {
    let key = query.key_expr().as_str();
    let Some(call) = keys.call_of(key) else {
        let why = format!("{key} is not a call: the calls are {}", CALLS.join(", "));
        return (StatusCode::NOT_FOUND, error(&why));
    };
    let method = if READS.contains(&call) { Method::GET } else { Method::POST };
    let mut request = Request::builder()
        .method(method)
        .uri(format!("/api/{call}"))
        .header(header::HOST, bound.to_string())
        .header(header::CONTENT_TYPE, "application/json");
    if let Some(token) = query.attachment() {
        match token.try_to_string() {
            Ok(token) => request = request.header(header::AUTHORIZATION, format!("Bearer {token}")),
            Err(_) => {
                return (
                    StatusCode::UNAUTHORIZED,
                    error("the attachment must be the token, as text"),
                )
            }
        }
    }
    let body = query.payload().map(|p| p.to_bytes().into_owned()).unwrap_or_default();
    let request = match request.body(Body::from(body)) {
        Ok(r) => r,
        Err(e) => return (StatusCode::BAD_REQUEST, error(&e.to_string())),
    };
    let response = match router.clone().oneshot(request).await {
        Ok(r) => r,
        Err(never) => match never {},
    };
    let status = response.status();
    match axum::body::to_bytes(response.into_body(), ANSWER_LIMIT).await {
        Ok(bytes) => (status, bytes.to_vec()),
        Err(e) => (StatusCode::INTERNAL_SERVER_ERROR, error(&e.to_string())),
    }
}

fn reply(query: &Query, status: StatusCode, body: Vec<u8>) {
    let key = query.key_expr().clone();
    let sent = if status.is_success() {
        query.reply(key.clone(), body).encoding(Encoding::APPLICATION_JSON).wait()
    } else {
        let body = with_status(body, status);
        eprintln!(
            "aviary: zenoh: {key} refused ({}): {}",
            status.as_u16(),
            String::from_utf8_lossy(&body)
                .chars()
                .filter(|c| !c.is_control())
                .take(200)
                .collect::<String>()
        );
        query.reply_err(body).encoding(Encoding::APPLICATION_JSON).wait()
    };
    if let Err(e) = sent {
        eprintln!("aviary: zenoh: the answer on {key} was not sent: {}", crate::reason(&e));
    }
}

/// The events so far as JSON Lines: first `{"dropped": N}` (how many of the oldest the
/// run let go), then each event's trace line, the `N`th first.
fn history(feed: &aviary_server::Feed) -> Vec<u8> {
    let (lines, dropped) = feed.past();
    let mut out = format!("{{\"dropped\":{dropped}}}\n").into_bytes();
    for line in lines {
        out.extend_from_slice(line.text.as_bytes());
        out.push(b'\n');
    }
    out
}

fn error(why: &str) -> Vec<u8> {
    serde_json::to_vec(&serde_json::json!({ "error": why })).unwrap_or_default()
}

/// An error's JSON with the HTTP status it stands for (`{"error": ..., "status": 401}`):
/// a Zenoh error reply has no status of its own.
fn with_status(body: Vec<u8>, status: StatusCode) -> Vec<u8> {
    let mut error = match serde_json::from_slice::<serde_json::Value>(&body) {
        Ok(serde_json::Value::Object(error)) => error,
        _ => {
            let mut error = serde_json::Map::new();
            error.insert("error".into(), String::from_utf8_lossy(&body).into_owned().into());
            error
        }
    };
    error.insert("status".into(), status.as_u16().into());
    serde_json::to_vec(&error).unwrap_or(body)
}

/// The status an error reply carries ([`with_status`]); 500 when it carries none.
pub(crate) fn status_of(body: &str) -> u16 {
    serde_json::from_str::<serde_json::Value>(body)
        .ok()
        .and_then(|v| v["status"].as_u64())
        .and_then(|s| u16::try_from(s).ok())
        .unwrap_or(500)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_error_reply_carries_its_status_beside_the_reason() {
        let body = with_status(br#"{"error":"no token"}"#.to_vec(), StatusCode::UNAUTHORIZED);
        let text = String::from_utf8(body).unwrap();
        assert_eq!(text, r#"{"error":"no token","status":401}"#);
        assert_eq!(status_of(&text), 401);
        let body = with_status(b"not json".to_vec(), StatusCode::BAD_REQUEST);
        let text = String::from_utf8(body).unwrap();
        assert_eq!(text, r#"{"error":"not json","status":400}"#);
        assert_eq!(status_of("{}"), 500);
    }
}
