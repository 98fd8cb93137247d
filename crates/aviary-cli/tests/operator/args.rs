//! What an operator may send: a leash section's arguments and a signal's values are
//! checked against the kinds the checker inferred (400, naming the kind) before the
//! mission hears them, and `aviary ctl` reads values by the language's rules.

use super::serve::{http, post, raise, serve, Run};
use crate::common::{aviary, scratch};
use aviary_api::trace::{Event, EventKind, RaisedBy, Shown};
use aviary_api::Point;
use aviary_test_support::trace::Trace;

/// `Watch`'s `radius` is a length (its default); `Go` carries a position and a duration
/// (what its handler passes them to), and is the one signal the operator may raise.
/// Nothing here moves a drone, so that a good call leaves the mission running.
const MISSION: &str = "CAPABILITY Watch BY drone WITH radius:
    DEFAULTS:
        radius: 50m
    PERFORM:
        drone.Hover(400s)
    PERFORM Widen:
        SIGNAL Widened WITH radius

CAPABILITY Note BY drone WITH where, how_long:
    DEFAULTS:
        where: (0, 0)
        how_long: 1s
    PERFORM:
        SIGNAL Noted WITH where, how_long

MISSION M:
    OPERATOR SIGNAL Go
    PARALLEL:
        a Watch-W1
        ON EVERY Go WITH where, how_long:
            b Note WITH where, how_long
";
const WORLD: &str = "[drones.a]\nhome = [0, 0]\n[drones.b]\nhome = [10, 0]\n";

fn widen(run: &Run, radius: &str) -> (u16, String) {
    let body = format!(
        "{{\"activity\": \"Watch-W1\", \"action\": \"Widen\", \"args\": {{\"radius\": {radius}}}}}"
    );
    post(run, "/api/leash", &body)
}

fn go(run: &Run, args: &str) -> (u16, String) {
    raise(run, "Go", args)
}

#[test]
fn leash_arguments_and_signal_values_are_checked_against_the_mission_kinds() {
    let dir = scratch("operator_args");
    let mut run = serve(&dir, MISSION, WORLD, "0", &[]);
    std::thread::sleep(std::time::Duration::from_millis(500));
    for bad in [
        "\"abc\"",
        "[1, 2]",
        "true",
        "null",
        "{\"number\": 10, \"unit\": \"s\"}",
        "{\"number\": 10}",
    ] {
        let (status, why) = widen(&run, bad);
        assert_eq!(status, 400, "radius {bad}: {why}");
        assert!(
            why.starts_with("`radius` of Watch is a length (m, km)")
                || why.contains("null is not a value"),
            "radius {bad}: {why}"
        );
    }
    assert_eq!(
        widen(&run, "-50"),
        (400, "`radius` of Watch is a length (m, km) and cannot be negative, not -50".into())
    );
    let (status, why) = widen(&run, "1e308");
    assert_eq!(status, 400);
    assert!(why.contains("must be a finite number of at most 1e9"), "{why}");
    let (status, why) = widen(&run, "1e999");
    assert_eq!(status, 400, "a number JSON cannot hold: {why}");
    let body = "{\"activity\": \"Watch-W1\", \"action\": \"Widen\", \"args\": {\"radios\": 5}}";
    assert_eq!(
        post(&run, "/api/leash", body),
        (400, "Watch has no parameter `radios`; its parameters are: radius".to_string())
    );

    let (status, why) = go(&run, "[]");
    assert_eq!(status, 400);
    assert_eq!(why, "Go carries 2 value(s), and 0 were given: a position (a place, an area, or coordinates); a duration (s, min, h)");
    let (status, why) = go(&run, "[\"Tower\", 5]");
    assert_eq!(status, 400);
    assert!(why.starts_with("value 1 of Go is a position"), "{why}");
    let (status, why) = go(&run, "[[1, 2], -5]");
    assert_eq!((status, why.contains("cannot be negative")), (400, true), "{why}");

    // Only a signal the mission declares: `Widened` is the mission's own, `Og` a slip.
    let body = "{\"name\": \"Widened\", \"args\": [5]}";
    assert_eq!(
        post(&run, "/api/signal", body),
        (
            409,
            "the mission does not declare Widened as an operator signal: it declares Go"
                .to_string()
        )
    );
    let a = http(&run, "GET", "/api/state", &[], "");
    let state: serde_json::Value = serde_json::from_str(&a.body).unwrap();
    assert_eq!(state["operator_signals"], serde_json::json!(["Go"]), "{}", a.body);

    // `aviary ctl` reads values as the language does, and keeps their units.
    let ctl = |args: &[&str]| {
        let mut all = vec!["ctl", "--url", &run.url, "--token", &run.token];
        all.extend(args);
        aviary(&all, &dir)
    };
    let (code, _, err) = ctl(&["leash", "Watch-W1", "Widen", "radius=10s"]);
    assert_eq!(code, 1);
    assert!(err.contains("refused (400): `radius` of Watch is a length (m, km), and {\"number\":10.0,\"unit\":\"s\"} is a duration"), "{err}");
    let (code, _, err) = ctl(&["leash", "Watch-W1", "Widen", "radius=nan"]);
    assert_eq!(code, 1, "nan is a name, which is no length: {err}");
    assert!(err.contains("refused (400)"), "{err}");
    let (code, _, err) = ctl(&["signal", "Go", "(1, 2"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("cannot read `(1, 2` as a value: expected `)` to close the coordinates"),
        "{err}"
    );
    let (code, _, err) = ctl(&["signal", "Go", "10 parsecs"]);
    assert_eq!(code, 2, "{err}");
    let (code, _, err) = ctl(&["signal", "Og", "(1, 2)", "2s"]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("refused (409): the mission does not declare Og as an operator signal: did you mean `Go`? It declares Go"),
        "{err}"
    );

    assert_eq!(ctl(&["leash", "Watch-W1", "Widen", "radius=0.2km"]).0, 0);
    assert_eq!(ctl(&["signal", "Go", "(100, -50)", "2min"]).0, 0);
    assert_eq!(widen(&run, "{\"number\": 30, \"unit\": \"m\"}").0, 200);
    assert_eq!(go(&run, "[[3, 4, 5], 7]").0, 200, "a JSON number is SI");
    std::thread::sleep(std::time::Duration::from_millis(500));
    assert_eq!(ctl(&["abort"]).0, 0);
    assert_eq!(run.child.wait().unwrap().code(), Some(1), "aborted");

    // Only the good calls reached the mission, with their values in SI.
    let trace = std::fs::read_to_string(dir.join("t.jsonl")).unwrap();
    let events = Trace::parse(&trace);
    let signals: Vec<&[Shown]> = events
        .iter()
        .filter_map(|e| match &e.event {
            Event::Signal { actor: None, args, .. } => Some(&args[..]),
            _ => None,
        })
        .collect();
    let at = |x: f64, y: f64, z: Option<f64>| Shown::Position(Point { x, y, z });
    assert_eq!(
        signals,
        [
            &[at(100.0, -50.0, None), Shown::Number(120.0)][..],
            &[at(3.0, 4.0, Some(5.0)), Shown::Number(7.0)][..]
        ]
    );
    // The operator's signals say so (`by`), for the summary's operator actions; the
    // mission's own signals do not.
    for e in events.iter() {
        let Event::Signal { name, by, .. } = &e.event else { continue };
        let by_operator = name == "Go";
        assert_eq!(*by == Some(RaisedBy::Operator), by_operator, "{e:?}");
        assert_eq!(by.is_some(), by_operator, "no `by` on the mission's own: {e:?}");
    }
    let widened: Vec<&[Shown]> = events
        .iter()
        .filter_map(|e| match &e.event {
            Event::Signal { name, args, .. } if name == "Widened" => Some(&args[..]),
            _ => None,
        })
        .collect();
    assert_eq!(widened, [&[Shown::Number(200.0)][..], &[Shown::Number(30.0)][..]]);
    assert_eq!(events.events(EventKind::Leash).len(), 2);
}
