//! The `fuzz_operator` target: arbitrary bytes as the headers and body of a call to the
//! operator API, through the real router (no socket). Properties: no panic; every
//! answer is JSON, every error `{"error": "..."}`; a control reaches the engine only
//! with the token, and only with values the mission can take (finite, within bounds).
//!
//! The input: byte 0 picks the route, byte 1 sets flags (bit 0: send the token; bit 1:
//! the server is bound beyond loopback; bit 2: `Content-Type: application/json`), then
//! header lines `Name: value` up to an empty line, then the body.

use std::cell::Cell;

use aviary_api::Value;
use aviary_diagnostics::SourceMap;
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

/// A mission with every sort of parameter and signal value, and signals the operator may
/// raise (`Go`, `Any`) beside one it may not (`Bare`, heard by the mission).
const MISSION: &str = "\
CAPABILITY Watch BY d WITH center, radius, laps, kind, note, loud, area, anything:
    PERFORM:
        d.Orbit(center, radius, laps)
        d.StartDetection(kind)
        d.Sweep(area, 10m)
        IF loud:
            SIGNAL Noted WITH note
    PERFORM Widen:
        d.Orbit(center, radius)

MISSION Fuzzed:
    OPERATOR SIGNAL Go, Any
    PARALLEL:
        video_drone1 Watch-W1 WITH (0, 0), 10m, 2, Body, \"a note\", TRUE, Area1, 1
        ON Go WITH where, wait, share:
            WAITFOR ELAPSED >= wait
            video_drone1 FlyTo WITH where
        ON Any WITH x, y:
            SIGNAL Bare
        ON Bare:
            video_drone1 Hover WITH 1s
";

/// The compiled [`MISSION`]'s kinds and names, in the example world: compiled once, for
/// every input.
fn kinds() -> &'static (Kinds, aviary_ir::Mission) {
    static COMPILED: std::sync::OnceLock<(Kinds, aviary_ir::Mission)> = std::sync::OnceLock::new();
    COMPILED.get_or_init(compile)
}

fn compile() -> (Kinds, aviary_ir::Mission) {
    let mut sources = SourceMap::new();
    let world = ("w.toml", crate::EXAMPLE_WORLD.as_bytes());
    let checked = aviary_check::check_sources(
        &mut sources,
        ("m.mission", MISSION.as_bytes()),
        Some(world),
        &aviary_check::NoFiles,
    );
    let errors: Vec<_> = checked.diagnostics.iter().filter(|d| d.is_error()).collect();
    assert!(errors.is_empty(), "the operator target's mission: {errors:#?}");
    let (Some(program), Some(world)) = (checked.program, checked.world) else {
        panic!("the operator target's mission was not checked")
    };
    let mission = aviary_lower::compile(&program, &world).expect("the mission compiles");
    // An origin, so that a position by latitude and longitude is placed, not refused.
    let origin = aviary_api::geo::Origin { lat: 47.45, lon: 13.1, alt: 500.0 };
    (Kinds::of(&mission).with_origin(origin), mission)
}

pub fn operator(data: &[u8]) {
    let Some(Call { request, bound, carries_token, .. }) = call(data, &ROUTES, false) else {
        return;
    };
    let (kinds, mission) = kinds();
    let kinds = kinds.clone();
    let (controller, mut rx) = Controller::new();
    let (app, _feed) = aviary_server::router(
        bound,
        TOKEN.to_string(),
        controller,
        Options { kinds, allowed_hosts: vec!["ops.example.org".into()] },
    );
    let reached = Cell::new(0);
    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
    let (status, bytes) = runtime.block_on(async {
        let engine = async {
            while let Some((control, answer)) = rx.recv().await {
                reached.set(reached.get() + 1);
                checked(&control, mission);
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

/// What reaches the engine is what a mission could have written: the mission's own ids
/// (or a name it does not have, for the engine to refuse), a signal only if the mission
/// declares it for the operator, and values it can take.
fn checked(control: &Control, mission: &aviary_ir::Mission) {
    match control {
        Control::Signal { signal, .. } => {
            assert!(
                mission.operator_signals.contains(signal),
                "{signal} reached the engine undeclared"
            )
        }
        Control::Leash { capability, tag, action, args } => {
            let cap = &mission.capabilities[*capability];
            assert!(cap.action_name(*action).is_some() && mission.tags.get(*tag).is_some());
            assert!(args.iter().all(|(p, _)| *p < cap.params.len()));
        }
        Control::Drone { drone, .. } => assert!(drone.0 < mission.drones.len()),
        _ => {}
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
            Value::Area(_) | Value::Actor(_) | Value::Remainder(_) | Value::Absent => {
                panic!("{v:?} reached the engine from outside")
            }
            Value::Text(_) | Value::Symbol(_) | Value::Bool(_) => {}
        }
    }
}
