//! The routes: `GET /api/state`, `GET /api/events` (WebSocket), and the control calls
//! `POST /api/leash`, `/api/signal`, `/api/drone`, `/api/pause`, `/api/resume`, `/api/abort`.
//! Who may call is decided before any of them runs (`guard.rs`).

use std::sync::Arc;

use aviary_engine::{Control, DroneAction};
use axum::extract::ws::rejection::WebSocketUpgradeRejection;
use axum::extract::ws::WebSocketUpgrade;
use axum::extract::{DefaultBodyLimit, State};
use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::{middleware, Json, Router};
use serde_json::Value as JsonValue;

use crate::args::Refusal;
use crate::reply::{error, Object, BODY_LIMIT};
use crate::requests::{Argument, DroneRequest, DroneVerb, LeashRequest, SignalRequest};
use crate::{guard, reply, stream, Gate, Relay, Shared};
use aviary_api::operator::{Accepted, OperatorState};

pub(crate) fn router(shared: Arc<Shared>) -> Router {
    let reads = Router::new()
        .route("/api/state", get(state))
        .route_service("/api/events", get(events).with_state(shared.relay.clone()))
        .route_layer(middleware::from_fn_with_state(shared.gate.clone(), guard::read_token));
    let controls = Router::new()
        .route("/api/leash", post(leash))
        .route("/api/signal", post(signal))
        .route("/api/drone", post(drone))
        .route("/api/pause", post(pause))
        .route("/api/resume", post(resume))
        .route("/api/abort", post(abort))
        .route_layer(middleware::from_fn_with_state(shared.gate.clone(), guard::token));
    reads
        .merge(controls)
        .fallback(reply::not_found)
        .method_not_allowed_fallback(reply::method_not_allowed)
        .layer(DefaultBodyLimit::max(BODY_LIMIT))
        .layer(middleware::from_fn_with_state(shared.gate.clone(), guard::same_origin))
        .layer(middleware::map_response(reply::json_errors))
        .with_state(shared)
}

/// `GET /api/events` alone, streaming what `relay` carries, behind `gate` as every route
/// here: for a station that watches a run on another machine, whose other calls go there.
pub fn events_router(gate: Arc<Gate>, relay: Arc<Relay>) -> Router {
    Router::new()
        .route("/api/events", get(events))
        .route_layer(middleware::from_fn_with_state(gate.clone(), guard::read_token))
        .layer(middleware::from_fn_with_state(gate, guard::same_origin))
        .layer(middleware::map_response(reply::json_errors))
        .with_state(relay)
}

/// A request resolved to the mission's ids, sent; or why it could not be.
async fn resolved(shared: &Shared, control: Result<Control, Refusal>) -> Response {
    match control {
        Ok(control) => self::control(shared, control).await,
        Err(Refusal::Value(why)) => error(StatusCode::BAD_REQUEST, why),
        Err(Refusal::Name(why)) => error(StatusCode::CONFLICT, why),
    }
}

async fn control(shared: &Shared, control: Control) -> Response {
    match shared.controller.ask(control).await {
        Ok(()) => Json(Accepted::YES).into_response(),
        Err(why) => error(StatusCode::CONFLICT, why),
    }
}

/// The state folded from the trace, and the signals the operator may raise.
async fn state(State(shared): State<Arc<Shared>>) -> Json<OperatorState> {
    Json(shared.document())
}

async fn events(
    State(relay): State<Arc<Relay>>,
    uri: axum::http::Uri,
    ws: Result<WebSocketUpgrade, WebSocketUpgradeRejection>,
) -> Response {
    let (from_start, every) = match options(uri.query().unwrap_or("")) {
        Ok(o) => o,
        Err(why) => return error(StatusCode::BAD_REQUEST, why),
    };
    let ws = match ws {
        Ok(ws) => ws,
        Err(rejection) => {
            return error(
                rejection.status(),
                format!("{}: open it as a WebSocket", rejection.body_text()),
            )
        }
    };
    // The history and the subscription at one instant, so that no event is missed or
    // sent twice between them.
    let (past, rx) = relay.open(from_start);
    // Counted from the handshake on, so that a stream opened just before the mission
    // ends still gets `mission_end` (`Feed::finish` waits for it).
    relay.streams.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
    let failed = relay.clone();
    // A browser that offered `aviary` (beside its token) must get it back, or it drops the socket.
    ws.protocols(["aviary"])
        .on_failed_upgrade(move |_| {
            failed.streams.fetch_sub(1, std::sync::atomic::Ordering::SeqCst);
        })
        .on_upgrade(move |socket| async move {
            match every {
                Some(every) => stream::batched(socket, past, rx, every).await,
                None => stream::each(socket, past, rx).await,
            }
            relay.streams.fetch_sub(1, std::sync::atomic::Ordering::SeqCst);
        })
}

/// The stream's options: `from=start` (the history first) and `every=MS` (batches, every
/// 20 to 1000 ms).
fn options(query: &str) -> Result<(bool, Option<std::time::Duration>), String> {
    let shown = |t: &str| -> String { t.chars().filter(|c| !c.is_control()).take(80).collect() };
    let (mut from_start, mut every) = (false, None);
    for pair in query.split('&').filter(|p| !p.is_empty()) {
        match pair.split_once('=') {
            Some(("from", "start")) => from_start = true,
            Some(("every", ms)) => match ms.parse::<u64>() {
                Ok(ms @ 20..=1000) => every = Some(std::time::Duration::from_millis(ms)),
                _ => {
                    return Err(format!(
                        "`every={}` is not a window: give milliseconds from 20 to 1000",
                        shown(ms)
                    ))
                }
            },
            _ => {
                return Err(format!(
                    "`{}` is no option of the event stream: the options are `from=start` and `every=MS`",
                    shown(pair)
                ))
            }
        }
    }
    Ok((from_start, every))
}

/// `{"activity": "FlyCircle-C1", "action": "PAUSE", "args": {"radius": 40}}`, or with
/// `capability` and `tag` apart.
async fn leash(State(shared): State<Arc<Shared>>, Object(body): Object) -> Response {
    const NAME: &str = "name the activity: {\"activity\": \"FlyCircle-C1\", \"action\": \"PAUSE\"}";
    let request: LeashRequest = match read(&body, |field, given| match (field, given) {
        ("action", _) => {
            Some("say what to do: \"action\": \"PAUSE\", \"RESUME\", \"ABORT\" or a section's name")
        }
        ("args", _) => Some("\"args\" is an object of the section's parameters: {\"radius\": 200}"),
        ("activity" | "capability" | "tag", Some(_)) => Some(NAME),
        _ => None,
    }) {
        Ok(request) => request,
        Err(refused) => return refused,
    };
    let (capability, tag) = match (&request.activity, &request.capability, &request.tag) {
        (Some(activity), _, _) => match activity.split_once('-') {
            Some((c, t)) => (c, t),
            None => {
                return error(
                    StatusCode::BAD_REQUEST,
                    format!("`{activity}` is not `Capability-Tag`"),
                )
            }
        },
        (None, Some(c), Some(t)) => (c.as_str(), t.as_str()),
        _ => return error(StatusCode::BAD_REQUEST, NAME),
    };
    let args: serde_json::Map<String, JsonValue> =
        request.args.into_iter().flatten().map(|(k, Argument(v))| (k, v)).collect();
    resolved(&shared, shared.kinds.leash(capability, tag, &request.action, &args)).await
}

/// `{"name": "Go", "args": [..]}`.
async fn signal(State(shared): State<Arc<Shared>>, Object(body): Object) -> Response {
    let request: SignalRequest = match read(&body, |field, _| match field {
        "name" => Some("name the signal: {\"name\": \"Go\"}"),
        "args" => Some("\"args\" is an array of the signal's values: [[100, 50]]"),
        _ => None,
    }) {
        Ok(request) => request,
        Err(refused) => return refused,
    };
    let args: Vec<JsonValue> = request.args.into_iter().flatten().map(|Argument(v)| v).collect();
    // Only a signal the mission declares with OPERATOR SIGNAL: refused as the engine
    // would refuse it (409), with what the mission declares.
    resolved(&shared, shared.kinds.signal(&request.name, &args)).await
}

/// `{"drone": "scout1", "action": "hold"}`: `hold`, `resume`, `home` (or `return_home`,
/// as the trace writes it) or `land`. A drone the fleet does not have is refused (409),
/// with the name meant.
async fn drone(State(shared): State<Arc<Shared>>, Object(body): Object) -> Response {
    let told = format!("say what to do: {}", DroneVerb::WORDS);
    let request: DroneRequest = match read(&body, |field, given| match (field, given) {
        ("drone", _) => {
            Some("name the drone: {\"drone\": \"scout1\", \"action\": \"hold\"}".into())
        }
        ("action", Some(JsonValue::String(other))) => {
            Some(format!("`{other}` is not something a drone is told: {}", DroneVerb::WORDS))
        }
        ("action", _) => Some(told.clone()),
        _ => None,
    }) {
        Ok(request) => request,
        Err(refused) => return refused,
    };
    let action = match request.action {
        DroneVerb::Hold => DroneAction::Hold,
        DroneVerb::Resume => DroneAction::Resume,
        DroneVerb::Home => DroneAction::ReturnHome,
        DroneVerb::Land => DroneAction::Land,
    };
    resolved(&shared, shared.kinds.drone(&request.drone, action)).await
}

/// The body as a `T`; or, refused (400), why not: for the field that is missing or not
/// of its type, in the words `why` gives for it (given what was sent), else in serde's.
#[allow(clippy::result_large_err)] // a Response, handed back as it is
fn read<T: serde::de::DeserializeOwned, W: Into<String>>(
    body: &serde_json::Map<String, JsonValue>,
    why: impl Fn(&str, Option<&JsonValue>) -> Option<W>,
) -> Result<T, Response> {
    let failed = match serde_path_to_error::deserialize(JsonValue::Object(body.clone())) {
        Ok(request) => return Ok(request),
        Err(failed) => failed,
    };
    let inner = failed.inner().to_string();
    // A field of the wrong type is the path's; an absent one, serde's "missing field `x`".
    let field = match failed.path().iter().next() {
        Some(serde_path_to_error::Segment::Map { key }) => key.clone(),
        _ => inner.split('`').nth(1).unwrap_or_default().to_string(),
    };
    let words = why(&field, body.get(&field)).map(Into::into).unwrap_or(inner);
    Err(error(StatusCode::BAD_REQUEST, words))
}

// The state's `paused` follows the trace's `operator` events (`state.rs`), which the
// engine writes before it answers.
async fn pause(State(shared): State<Arc<Shared>>) -> Response {
    control(&shared, Control::Pause).await
}

async fn resume(State(shared): State<Arc<Shared>>) -> Response {
    control(&shared, Control::Resume).await
}

async fn abort(State(shared): State<Arc<Shared>>) -> Response {
    control(&shared, Control::Abort { reason: "aborted by the operator".into() }).await
}

#[cfg(test)]
mod tests {
    use super::options;
    use std::time::Duration;

    #[test]
    fn the_streams_options_are_read_or_refused_with_the_reason() {
        assert_eq!(options(""), Ok((false, None)));
        assert_eq!(options("from=start"), Ok((true, None)));
        assert_eq!(options("every=100&from=start"), Ok((true, Some(Duration::from_millis(100)))));
        for bad in ["every=5", "every=2000", "every=x", "from=now", "since=0", "every"] {
            let why = options(bad).unwrap_err();
            assert!(why.contains('`'), "{bad}: {why}");
        }
    }
}
