//! A station of a run on another machine (`aviary gcs --zenoh`): the page's calls of the
//! operator API go to the run over Zenoh, and its event streams carry the lines the run
//! publishes. Nothing of the run is kept or worked out here: the state is the run's own
//! answer, a control call is the run's to check, and the lines are the trace's.

use std::sync::Arc;
use std::time::{Duration, Instant};

use aviary_server::{Gate, Line, Relay};
use axum::extract::State;
use axum::http::{header, StatusCode, Uri};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::{middleware, Router};
use parking_lot::Mutex;
use zenoh::Wait;

use crate::keys::{CALLS, READS};
use crate::Client;

/// How long a station waits for the run to answer at its start.
const WAIT_FOR_RUN: Duration = Duration::from_secs(10);

/// What a station shows of a run that does not change: its name, its block tree and its
/// world's map (`PREFIX/api/mission`).
pub struct Shown {
    pub mission: String,
    pub tree: serde_json::Value,
    pub map: serde_json::Value,
}

/// What the run shows of itself, asked until it answers (at most [`WAIT_FOR_RUN`]).
pub fn shown(client: &Client) -> Result<Shown, String> {
    let start = Instant::now();
    let answer = loop {
        match client.call("mission", None, None) {
            Ok((200, answer)) => break answer,
            Ok((status, answer)) => return Err(format!("the run refused ({status}): {answer}")),
            Err(why) if start.elapsed() >= WAIT_FOR_RUN => {
                return Err(format!(
                    "{why}: is `aviary run --zenoh` flying under {}, and does this configuration reach it?",
                    client.keys().prefix()
                ))
            }
            Err(_) => std::thread::sleep(Duration::from_millis(200)),
        }
    };
    let mut view: serde_json::Value = serde_json::from_str(&answer)
        .map_err(|e| format!("the run's {} is not JSON: {e}", client.keys().call("mission")))?;
    Ok(Shown {
        mission: view["mission"].as_str().unwrap_or_default().to_string(),
        tree: view["tree"].take(),
        map: view["map"].take(),
    })
}

/// The operator API of the run `client` reaches, behind `gate`: `GET /api/state` and the
/// control calls are asked of the run (with `token`, the run's, for a control call), and
/// `GET /api/events` streams the run's events: those so far (asked of the run once), then
/// what it publishes.
pub fn router(client: Client, token: Option<String>, gate: Arc<Gate>) -> Result<Router, String> {
    let joining = Arc::new(Mutex::new(Joining::default()));
    hear(&client, joining.clone())?;
    let relay = history(&client)?;
    joining.lock().join(relay.clone());
    let remote = Arc::new(Remote { client, token });
    let reads = Router::new()
        .route("/api/state", get(call))
        .route_layer(middleware::from_fn_with_state(gate.clone(), aviary_server::read_token));
    let mut controls = Router::new();
    for control in CALLS.iter().filter(|c| !READS.contains(c)) {
        controls = controls.route(&format!("/api/{control}"), post(call));
    }
    let controls =
        controls.route_layer(middleware::from_fn_with_state(gate.clone(), aviary_server::token));
    Ok(reads
        .merge(controls)
        .layer(middleware::from_fn_with_state(gate.clone(), aviary_server::same_origin))
        .layer(middleware::map_response(aviary_server::json_errors))
        .with_state(remote)
        .merge(aviary_server::events_router(gate, relay)))
}

struct Remote {
    client: Client,
    token: Option<String>,
}

/// The lines heard while the history is asked for wait, with their places in the run;
/// then the history goes first, and of the lines that waited only those after it follow.
#[derive(Default)]
struct Joining {
    waiting: Vec<(Option<u64>, Line)>,
    relay: Option<Arc<Relay>>,
    /// The place of the next event to relay.
    next: u64,
}

impl Joining {
    fn heard(&mut self, seq: Option<u64>, line: Line) {
        match &self.relay {
            None => self.waiting.push((seq, line)),
            Some(relay) => {
                if let Some(seq) = seq {
                    if seq < self.next {
                        return;
                    }
                    self.next = seq + 1;
                }
                relay.push(line);
            }
        }
    }

    /// From now on lines go to `relay`, which holds the history.
    fn join(&mut self, relay: Arc<Relay>) {
        let (past, dropped) = relay.past();
        self.next = dropped + past.len() as u64;
        self.relay = Some(relay);
        for (seq, line) in std::mem::take(&mut self.waiting) {
            self.heard(seq, line);
        }
    }
}

/// Each line the run publishes (its events and its telemetry), each event with its place
/// in the run. What is not a trace event (a foreign peer's garbage) is left out, and said.
fn hear(client: &Client, joining: Arc<Mutex<Joining>>) -> Result<(), String> {
    let keys = client.keys().clone();
    let all = format!("{}/**", keys.prefix());
    client
        .session()
        .declare_subscriber(&all)
        .callback(move |sample| {
            let key = sample.key_expr().as_str();
            if !keys.carries_lines(key) {
                return;
            }
            let event = key == keys.events();
            let text = String::from_utf8_lossy(&sample.payload().to_bytes()).into_owned();
            let seq = sample
                .attachment()
                .filter(|_| event)
                .and_then(|a| a.try_to_string().ok()?.parse::<u64>().ok());
            match Line::parse(&text) {
                Ok(line) => joining.lock().heard(seq, line),
                Err(why) => eprintln!("aviary: zenoh: a sample on {key} left out: {why}"),
            }
        })
        .background()
        .wait()
        .map_err(|e| format!("cannot subscribe to {all}: {}", crate::reason(&e)))
}

/// The run's events so far (`PREFIX/api/history`), in a relay of their own.
fn history(client: &Client) -> Result<Arc<Relay>, String> {
    let key = client.keys().call("history");
    let answer = match client.call("history", None, None)? {
        (200, answer) => answer,
        (status, answer) => return Err(format!("{key} refused ({status}): {answer}")),
    };
    let mut lines = answer.lines();
    let dropped = lines
        .next()
        .and_then(|first| serde_json::from_str::<serde_json::Value>(first).ok())
        .and_then(|first| first["dropped"].as_u64())
        .ok_or_else(|| format!("{key} does not begin with {{\"dropped\": N}}"))?;
    let relay = Relay::after(dropped);
    for text in lines {
        relay.push(Line::parse(text).map_err(|why| format!("{key}: {why}"))?);
    }
    Ok(relay)
}

/// `GET /api/state` or `POST /api/CALL`, asked of the run; its answer, with its status.
async fn call(State(remote): State<Arc<Remote>>, uri: Uri, body: String) -> Response {
    let call = uri.path().trim_start_matches("/api/").to_string();
    let control = call != "state";
    if control && remote.token.is_none() {
        return aviary_server::error(
            StatusCode::FORBIDDEN,
            "this station only watches: start `aviary gcs --zenoh` with `--token` the run printed to steer it",
        );
    }
    let asked = tokio::task::spawn_blocking(move || {
        let token = if control { remote.token.as_deref() } else { None };
        remote.client.call(&call, control.then_some(body), token)
    })
    .await;
    match asked {
        Ok(Ok((status, answer))) => (
            StatusCode::from_u16(status).unwrap_or(StatusCode::BAD_GATEWAY),
            [(header::CONTENT_TYPE, "application/json")],
            answer,
        )
            .into_response(),
        Ok(Err(why)) => aviary_server::error(StatusCode::BAD_GATEWAY, why),
        Err(e) => aviary_server::error(StatusCode::INTERNAL_SERVER_ERROR, e.to_string()),
    }
}
