//! The routes: `GET /api/state`, `GET /api/events` (WebSocket), and the control calls
//! `POST /api/leash`, `/api/signal`, `/api/pause`, `/api/resume`, `/api/abort`.

use std::sync::Arc;

use aviary_api::{Point, Value};
use aviary_engine::Control;
use axum::extract::ws::{Message, WebSocket, WebSocketUpgrade};
use axum::extract::State;
use axum::http::{HeaderMap, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::{Json, Router};
use serde_json::{json, Value as JsonValue};
use tokio::sync::broadcast::error::RecvError;

use crate::Shared;

pub(crate) fn router(shared: Arc<Shared>) -> Router {
    Router::new()
        .route("/api/state", get(state))
        .route("/api/events", get(events))
        .route("/api/leash", post(leash))
        .route("/api/signal", post(signal))
        .route("/api/pause", post(pause))
        .route("/api/resume", post(resume))
        .route("/api/abort", post(abort))
        .with_state(shared)
}

fn error(status: StatusCode, message: impl Into<String>) -> Response {
    (status, Json(json!({ "error": message.into() }))).into_response()
}

/// Control calls carry `Authorization: Bearer TOKEN`, the token the run printed.
fn authorized(shared: &Shared, headers: &HeaderMap) -> bool {
    let given = headers.get("authorization").and_then(|v| v.to_str().ok()).and_then(|v| v.strip_prefix("Bearer "));
    given == Some(shared.token.as_str())
}

async fn control(shared: &Shared, headers: &HeaderMap, control: Control) -> Response {
    if !authorized(shared, headers) {
        return error(StatusCode::UNAUTHORIZED, "control calls need the token the run printed: send `Authorization: Bearer TOKEN`");
    }
    match shared.controller.ask(control).await {
        Ok(()) => Json(json!({ "ok": true })).into_response(),
        Err(why) => error(StatusCode::CONFLICT, why),
    }
}

async fn state(State(shared): State<Arc<Shared>>) -> Json<JsonValue> {
    Json(shared.state().to_json())
}

async fn events(State(shared): State<Arc<Shared>>, ws: WebSocketUpgrade) -> Response {
    let rx = shared.events.subscribe();
    shared.streams.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
    ws.on_upgrade(move |socket| async move {
        stream(socket, rx).await;
        shared.streams.fetch_sub(1, std::sync::atomic::Ordering::SeqCst);
    })
}

/// Every event from now on, one JSON text message each, until the mission ends.
async fn stream(mut socket: WebSocket, mut rx: tokio::sync::broadcast::Receiver<Arc<str>>) {
    loop {
        match rx.recv().await {
            Ok(event) => {
                let end = event.contains("\"event\":\"mission_end\"");
                if socket.send(Message::Text(event.to_string().into())).await.is_err() || end {
                    break;
                }
            }
            Err(RecvError::Lagged(missed)) => {
                let note = json!({ "lagged": missed }).to_string();
                if socket.send(Message::Text(note.into())).await.is_err() {
                    break;
                }
            }
            Err(RecvError::Closed) => break,
        }
    }
    let _ = socket.send(Message::Close(None)).await;
}

/// `{"activity": "FlyCircle-C1", "action": "PAUSE", "args": {"radius": 40}}`, or with
/// `capability` and `tag` apart.
async fn leash(State(shared): State<Arc<Shared>>, headers: HeaderMap, Json(body): Json<JsonValue>) -> Response {
    let (capability, tag) = match (body["activity"].as_str(), body["capability"].as_str(), body["tag"].as_str()) {
        (Some(activity), _, _) => match activity.split_once('-') {
            Some((c, t)) => (c.to_string(), t.to_string()),
            None => return error(StatusCode::BAD_REQUEST, format!("`{activity}` is not `Capability-Tag`")),
        },
        (None, Some(c), Some(t)) => (c.to_string(), t.to_string()),
        _ => return error(StatusCode::BAD_REQUEST, "name the activity: {\"activity\": \"FlyCircle-C1\", \"action\": \"PAUSE\"}"),
    };
    let Some(action) = body["action"].as_str() else {
        return error(StatusCode::BAD_REQUEST, "say what to do: \"action\": \"PAUSE\", \"RESUME\", \"ABORT\" or a section's name");
    };
    let args = body["args"].as_object().map(|o| o.iter().map(|(k, v)| (k.clone(), value(v))).collect()).unwrap_or_default();
    control(&shared, &headers, Control::Leash { capability, tag, action: action.to_string(), args }).await
}

/// `{"name": "Go", "args": [..]}`.
async fn signal(State(shared): State<Arc<Shared>>, headers: HeaderMap, Json(body): Json<JsonValue>) -> Response {
    let Some(name) = body["name"].as_str() else {
        return error(StatusCode::BAD_REQUEST, "name the signal: {\"name\": \"Go\"}");
    };
    let args = body["args"].as_array().map(|a| a.iter().map(value).collect()).unwrap_or_default();
    control(&shared, &headers, Control::Signal { name: name.to_string(), args }).await
}

async fn pause(State(shared): State<Arc<Shared>>, headers: HeaderMap) -> Response {
    let response = control(&shared, &headers, Control::Pause).await;
    if response.status().is_success() {
        shared.state().set_paused(true);
    }
    response
}

async fn resume(State(shared): State<Arc<Shared>>, headers: HeaderMap) -> Response {
    let response = control(&shared, &headers, Control::Resume).await;
    if response.status().is_success() {
        shared.state().set_paused(false);
    }
    response
}

async fn abort(State(shared): State<Arc<Shared>>, headers: HeaderMap) -> Response {
    control(&shared, &headers, Control::Abort { reason: "aborted by the operator".into() }).await
}

/// A JSON value as the mission sees it: numbers are SI, strings are symbols, `[x, y]` and
/// `[x, y, z]` are positions.
fn value(v: &JsonValue) -> Value {
    match v {
        JsonValue::Number(n) => Value::Number(n.as_f64().unwrap_or(f64::NAN)),
        JsonValue::String(s) => Value::Symbol(s.clone()),
        JsonValue::Bool(b) => Value::Bool(*b),
        JsonValue::Array(a) if (2..=3).contains(&a.len()) && a.iter().all(JsonValue::is_number) => {
            let n: Vec<f64> = a.iter().filter_map(JsonValue::as_f64).collect();
            Value::Position(Point { x: n[0], y: n[1], z: n.get(2).copied() })
        }
        other => Value::Text(other.to_string()),
    }
}
