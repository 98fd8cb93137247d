//! The `fuzz_operator` target: arbitrary bytes as the headers and body of a call to the
//! operator API, through the real router (no socket). Properties: no panic; every
//! answer is JSON, every error `{"error": "..."}`; a control reaches the engine only
//! with the token, and only with values the mission can take (finite, within bounds).
//!
//! The input: byte 0 picks the route, byte 1 sets flags (bit 0: send the token; bit 1:
//! the server is bound beyond loopback; bit 2: `Content-Type: application/json`), then
//! header lines `Name: value` up to an empty line, then the body.

use std::cell::Cell;

use aviary_api::{Kind, Value};
use aviary_engine::{Control, Controller};
use aviary_server::{Kinds, Options, MAX_MAGNITUDE};
use tower::ServiceExt;

use crate::call::{call, Call, TOKEN};

/// Byte 0 modulo their number picks one; a route added goes last, so that every seed
/// keeps its route.
const ROUTES: [(&str, &str); 8] = [
    ("POST", "/api/leash"),
    ("POST", "/api/signal"),
    ("POST", "/api/pause"),
    ("POST", "/api/resume"),
    ("POST", "/api/abort"),
    ("GET", "/api/state"),
    ("GET", "/api/events"),
    ("POST", "/api/drone"),
];

/// A mission's kinds with every sort of parameter and signal value.
fn kinds() -> Kinds {
    let mut k = Kinds::default();
    let p = |n: &str, kind| (n.to_string(), kind);
    k.capability(
        "Watch",
        vec![
            p("center", Some(Kind::Position)),
            p("radius", Some(Kind::Length)),
            p("laps", Some(Kind::Number)),
            p("kind", Some(Kind::Symbol)),
            p("note", Some(Kind::Text)),
            p("loud", Some(Kind::Bool)),
            p("area", Some(Kind::Area)),
            p("anything", None),
        ],
    );
    k.signal("Go", vec![Some(Kind::Position), Some(Kind::Duration), Some(Kind::Ratio)]);
    k.signal("Any", vec![None, None]);
    k.signal("Bare", vec![]);
    // `Bare` is heard by the mission but not declared: the operator may not raise it.
    k.operator_signal("Go");
    k.operator_signal("Any");
    // An origin, so that a position by latitude and longitude is placed, not refused.
    k.with_origin(aviary_api::geo::Origin { lat: 47.45, lon: 13.1, alt: 500.0 })
}

pub fn operator(data: &[u8]) {
    let Some(Call { request, bound, carries_token, .. }) = call(data, &ROUTES, false) else {
        return;
    };
    let (controller, mut rx) = Controller::new();
    let (app, _feed) = aviary_server::router(
        bound,
        TOKEN.to_string(),
        controller,
        Options { kinds: kinds(), allowed_hosts: vec!["ops.example.org".into()] },
    );
    let reached = Cell::new(0);
    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
    let (status, bytes) = runtime.block_on(async {
        let engine = async {
            while let Some((control, answer)) = rx.recv().await {
                reached.set(reached.get() + 1);
                checked(&control);
                let _ = answer.send(Ok(()));
            }
            std::future::pending::<()>().await
        };
        let response = tokio::select! {
            r = app.oneshot(request) => r.expect("the router's errors are answers"),
            _ = engine => unreachable!("the engine's loop never ends while the router lives"),
        };
        let status = response.status();
        (
            status,
            axum::body::to_bytes(response.into_body(), usize::MAX)
                .await
                .expect("the answer's body"),
        )
    });

    let json: serde_json::Value = serde_json::from_slice(&bytes).unwrap_or_else(|e| {
        panic!("{status} is not JSON ({e}): {:?}", String::from_utf8_lossy(&bytes))
    });
    if status.is_client_error() || status.is_server_error() {
        assert!(json["error"].is_string(), "{status} without an error message: {json}");
        assert_eq!(reached.get(), 0, "a refused call ({status}) reached the engine");
    } else {
        assert_eq!(status, 200, "{json}");
    }
    if reached.get() > 0 {
        assert!(carries_token, "a control reached the engine without the token");
    }
}

/// What reaches the engine is what a mission could have written, or a drone's name (any
/// text: the engine looks it up and refuses a name the fleet does not have); a signal
/// only if the mission declares it for the operator.
fn checked(control: &Control) {
    if let Control::Signal { name, .. } = control {
        assert!(["Go", "Any"].contains(&name.as_str()), "{name} reached the engine undeclared");
    }
    let values: Vec<&Value> = match control {
        Control::Leash { args, .. } => args.iter().map(|(_, v)| v).collect(),
        Control::Signal { args, .. } => args.iter().collect(),
        _ => Vec::new(),
    };
    let fine = |x: f64| x.is_finite() && x.abs() <= MAX_MAGNITUDE;
    for v in values {
        match v {
            Value::Number(x) => assert!(fine(*x), "{x} reached the engine"),
            Value::Position(p) => {
                assert!(fine(p.x) && fine(p.y) && p.z.is_none_or(fine), "{p:?} reached the engine")
            }
            Value::Area(_) | Value::Actor(_) | Value::Remainder(_) => {
                panic!("{v:?} reached the engine from outside")
            }
            Value::Text(_) | Value::Symbol(_) | Value::Bool(_) => {}
        }
    }
}
