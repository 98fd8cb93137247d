//! Steering one drone through the operator API (`POST /api/drone`) and `aviary ctl
//! drone`: who may call, what is refused and why, and a hold, a resume and a return home
//! as they show in the state and in the trace, at their times.

use std::time::Duration;

use super::serve::{bearer, http, serve};
use crate::common::{aviary, repo, scratch};
use aviary_api::trace::{CallStatus, Event, OperatorAction, Status};
use aviary_api::Function;
use aviary_test_support::trace::{is, Trace};

const WORLD: &str =
    "[places]\nFar = [0, 400]\n[drones.a]\nhome = [0, 0]\n[drones.b]\nhome = [10, 0]\n";

/// a flies far; b takes off and hovers, then hovers again: work for the operator to hold
/// and to take away.
const MISSION: &str = "MISSION M:\n    PARALLEL:\n        a FlyTo-F1 WITH Far\n        SEQUENTIAL:\n            b TakeOff\n            b Hover WITH 60s\n            b Hover WITH 5s\n";

#[test]
fn the_drone_call_needs_the_token_and_says_why_it_refuses() {
    let dir = scratch("operator_drone_refusals");
    let run = serve(&dir, MISSION, WORLD, "0", &[]);
    let json = ("Content-Type", "application/json");
    let hold_a = r#"{"drone": "a", "action": "hold"}"#;
    let a = http(&run, "POST", "/api/drone", &[json], hold_a);
    assert_eq!(a.status, 401, "no token: {}", a.body);
    let a = http(&run, "POST", "/api/drone", &[json, ("Authorization", "Bearer 0000")], hold_a);
    assert_eq!(a.status, 401, "a wrong token: {}", a.body);

    let token = bearer(&run);
    let auth = ("Authorization", token.as_str());
    let call = |body: &str| http(&run, "POST", "/api/drone", &[json, auth], body);
    let a = http(&run, "POST", "/api/drone", &[auth], hold_a);
    assert_eq!(a.status, 415, "{}", a.body);
    for (body, says) in [
        (r#"{"action": "hold"}"#, "name the drone"),
        (r#"{"drone": 7, "action": "hold"}"#, "name the drone"),
        (r#"{"drone": "a"}"#, "say what to do"),
        (r#"{"drone": "a", "action": "fly away"}"#, "`fly away` is not something a drone is told"),
        (r#"["a", "hold"]"#, "the body must be a JSON object"),
    ] {
        let a = call(body);
        assert_eq!(a.status, 400, "{body}: {}", a.body);
        assert!(a.error().contains(says), "{body}: {}", a.body);
    }
    let a = call(r#"{"drone": "A", "action": "hold"}"#);
    assert_eq!(
        (a.status, a.error()),
        (409, "no drone is called `A`: did you mean `a`?".to_string())
    );
    let a = call(r#"{"drone": "scout1", "action": "land"}"#);
    assert_eq!(
        (a.status, a.error()),
        (409, "no drone is called `scout1`: the fleet is a, b".to_string())
    );
    let a = call(r#"{"drone": "b", "action": "resume"}"#);
    assert_eq!(
        (a.status, a.error()),
        (409, "b is not held: there is nothing of it to resume".to_string())
    );

    let a = call(hold_a);
    assert_eq!((a.status, a.json()), (200, serde_json::json!({ "ok": true })));
    let a = call(hold_a);
    assert_eq!(
        (a.status, a.error()),
        (409, "a is already held: resume it to let its activities go on".to_string())
    );
    let state = http(&run, "GET", "/api/state", &[], "").json();
    let a = state["drones"].as_array().unwrap().iter().find(|d| d["name"] == "a").unwrap();
    assert_eq!((&a["held"], &a["withdrawn"]), (&serde_json::json!(true), &serde_json::Value::Null));
    let a = call(r#"{"drone": "a", "action": "return_home"}"#);
    assert_eq!(a.status, 200, "the trace's name of `home` is taken too: {}", a.body);
    let a = call(r#"{"drone": "a", "action": "hold"}"#);
    assert_eq!(a.status, 409);
    assert!(a.error().starts_with("a is on its way home, out of the mission"), "{}", a.body);
}

#[test]
fn a_drone_is_held_resumed_and_sent_home_through_aviary_ctl() {
    let dir = scratch("operator_drone_ctl");
    let mut run = serve(&dir, MISSION, WORLD, "0", &["--speed", "10", "--telemetry-hz", "5"]);
    let (url, token) = (run.url.clone(), run.token.clone());
    let ctl = |args: &[&str]| {
        let mut all = vec!["ctl", "--url", url.as_str(), "--token", token.as_str(), "drone"];
        all.extend(args);
        aviary(&all, &dir)
    };
    std::thread::sleep(Duration::from_millis(1000));
    let (code, out, err) = ctl(&["a", "hold"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("\"ok\":true"), "{out}");
    let (_, state, _) = aviary(&["ctl", "--url", &url, "state", "--json"], &dir);
    let state: serde_json::Value = serde_json::from_str(&state).expect("state is JSON");
    let a = state["drones"].as_array().unwrap().iter().find(|d| d["name"] == "a");
    assert_eq!(a.map(|a| a["held"].clone()), Some(serde_json::json!(true)), "{state}");
    std::thread::sleep(Duration::from_millis(800));
    assert_eq!(ctl(&["a", "resume"]).0, 0);
    std::thread::sleep(Duration::from_millis(500));
    assert_eq!(ctl(&["b", "home"]).0, 0);
    let (code, _, err) = ctl(&["b", "resume"]);
    assert_eq!(code, 1, "refused: {err}");
    assert!(
        err.contains(
            "refused (409): b is on its way home, out of the mission (the operator sent it)"
        ),
        "{err}"
    );
    let (code, _, err) = ctl(&["b", "jump"]);
    assert_eq!(code, 2, "clap refuses an action that is none: {err}");
    assert!(err.contains("hold") && err.contains("land"), "the actions are listed: {err}");
    assert_eq!(run.child.wait().unwrap().code(), Some(0), "the mission goes on and ends ok");

    let text = std::fs::read_to_string(dir.join("t.jsonl")).unwrap();
    let trace: Vec<serde_json::Value> =
        text.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    let schema: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(repo().join("docs/trace.schema.json")).unwrap(),
    )
    .unwrap();
    let validator = jsonschema::validator_for(&schema).expect("a valid schema");
    for e in &trace {
        let errors: Vec<String> = validator.iter_errors(e).map(|e| e.to_string()).collect();
        assert!(errors.is_empty(), "{e}\n{errors:#?}");
    }
    let trace = Trace::parse(&text);
    let operator: Vec<(f64, OperatorAction, &str)> = trace
        .iter()
        .filter_map(|e| match &e.event {
            Event::Operator { action, drone } => Some((e.t, *action, drone.as_deref().unwrap())),
            _ => None,
        })
        .collect();
    let actions: Vec<(OperatorAction, &str)> = operator.iter().map(|(_, a, d)| (*a, *d)).collect();
    assert_eq!(
        actions,
        [
            (OperatorAction::Hold, "a"),
            (OperatorAction::Resume, "a"),
            (OperatorAction::ReturnHome, "b")
        ],
        "refusals are not written"
    );
    let (held, resumed, home) = (operator[0].0, operator[1].0, operator[2].0);
    let a_at: Vec<[f64; 3]> = trace
        .positions("a")
        .into_iter()
        .filter(|(t, _)| *t > held + 0.3 && *t < resumed)
        .map(|(_, p)| p)
        .collect();
    assert!(a_at.len() >= 10 && a_at.iter().all(|p| *p == a_at[0]), "a holds: {a_at:?}");
    let hovers: Vec<(Status, f64)> = trace
        .find(is::end_of("Hover"))
        .iter()
        .map(|e| match e.event {
            Event::CapabilityEnd { status, .. } => (status, e.t),
            _ => unreachable!(),
        })
        .collect();
    assert_eq!(
        hovers,
        [(Status::Aborted, home), (Status::Aborted, home)],
        "the hover, and the next at once"
    );
    let back = trace
        .iter()
        .find_map(|e| match &e.event {
            Event::ApiDone { actor, function: Function::ReturnToLaunch, status, .. }
                if actor == "b" =>
            {
                Some(*status)
            }
            _ => None,
        })
        .expect("b was sent home");
    assert_eq!(back, CallStatus::Ok);
    let fly = trace.first(is::end_of("FlyTo"));
    assert!(
        matches!(fly.event, Event::CapabilityEnd { status: Status::Ok, .. }),
        "a flew on to the end"
    );
}
