//! The operator API through the real server and `aviary ctl`: a leash round trip (pause
//! holds the drone, resume goes on, abort ends the activity `aborted`), the state, the
//! event stream, and refusal without the token. `operator/` holds the checks of who
//! may call (`guard.rs`), of what an operator may send (`args.rs`, and its positions in
//! `positions.rs`), and of steering one drone (`drone.rs`); `hiker.rs` steers the
//! lost-hiker example with a position from the map.

#[path = "operator/args.rs"]
mod args;
#[path = "operator/batches.rs"]
mod batches;
mod common;
#[path = "operator/drone.rs"]
mod drone;
#[path = "operator/guard.rs"]
mod guard;
#[path = "operator/hiker.rs"]
mod hiker;
#[path = "operator/positions.rs"]
mod positions;
#[path = "operator/serve.rs"]
mod serve;

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::time::Duration;

use aviary_api::trace::{Event, Status};
use aviary_test_support::trace::{is, Trace};
use common::{aviary, scratch};

const WORLD: &str =
    "[places]\nFar = [0, 400]\n[drones.a]\nhome = [0, 0]\n[drones.b]\nhome = [10, 0]\n";
const MISSION: &str =
    "MISSION M:\n    PARALLEL:\n        a FlyTo-F1 WITH Far\n        b Hover WITH 40s\n";

/// Starts a served run at 10 times real time; returns it with its URL and token.
fn served(dir: &std::path::Path) -> (Child, String, String) {
    std::fs::write(dir.join("m.mission"), MISSION).unwrap();
    std::fs::write(dir.join("m.world.toml"), WORLD).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_aviary"))
        .args([
            "run",
            "m.mission",
            "--serve",
            "0",
            "--speed",
            "10",
            "--telemetry-hz",
            "5",
            "--quiet",
            "--trace",
            "t.jsonl",
        ])
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn");
    let mut line = String::new();
    BufReader::new(child.stderr.take().unwrap()).read_line(&mut line).unwrap();
    // aviary: operator API on http://127.0.0.1:PORT  token TOKEN
    let url = line.split_whitespace().find(|w| w.starts_with("http://")).expect("url").to_string();
    let token = line.split_whitespace().last().expect("token").to_string();
    (child, url, token)
}

fn ctl(
    url: &str,
    token: Option<&str>,
    args: &[&str],
    dir: &std::path::Path,
) -> (i32, String, String) {
    let mut all = vec!["ctl", "--url", url];
    if let Some(t) = token {
        all.extend(["--token", t]);
    }
    all.extend(args);
    aviary(&all, dir)
}

#[test]
fn a_leash_round_trip_through_the_server() {
    let dir = scratch("operator_leash");
    let (mut child, url, token) = served(&dir);
    let events = {
        let (url, dir) = (url.clone(), dir.clone());
        std::thread::spawn(move || aviary(&["ctl", "--url", &url, "events"], &dir))
    };
    std::thread::sleep(Duration::from_millis(1500));
    let (code, out, err) = ctl(&url, Some(&token), &["leash", "FlyTo-F1", "PAUSE"], &dir);
    assert_eq!(code, 0, "{out}{err}");
    std::thread::sleep(Duration::from_millis(300));
    let (_, table, _) = ctl(&url, None, &["state"], &dir);
    assert!(table.contains("  FlyTo-F1 ") && table.contains(" paused"), "{table}");
    assert!(table.starts_with("mission "), "{table}");
    let (_, state, _) = ctl(&url, None, &["state", "--json"], &dir);
    let state: serde_json::Value = serde_json::from_str(&state).expect("state is JSON");
    // The state fits the schema docs/openapi.yaml gives it, generated from its types.
    let schema = aviary_server::state_schema(&aviary_server::openapi());
    let validator = jsonschema::validator_for(&schema).expect("a valid schema");
    let errors: Vec<String> = validator.iter_errors(&state).map(|e| e.to_string()).collect();
    assert!(errors.is_empty(), "{state:#}\n{errors:#?}");
    let fly = state["activities"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["tag"] == "F1")
        .expect("the tagged activity is listed");
    assert_eq!((fly["capability"].as_str(), fly["paused"].as_bool()), (Some("FlyTo"), Some(true)));
    assert!(state["drones"].as_array().unwrap().iter().any(|d| d["name"] == "a"));
    std::thread::sleep(Duration::from_millis(700));
    assert_eq!(ctl(&url, Some(&token), &["leash", "FlyTo-F1", "RESUME"], &dir).0, 0);
    std::thread::sleep(Duration::from_millis(800));
    assert_eq!(ctl(&url, Some(&token), &["leash", "FlyTo-F1", "ABORT"], &dir).0, 0);
    assert_eq!(child.wait().unwrap().code(), Some(0), "an aborted activity leaves the mission ok");

    let trace = Trace::read(&dir.join("t.jsonl"));
    let at = |action: &str| trace.t(|e| matches!(e, Event::Leash { action: a, .. } if a == action));
    let (paused, resumed, aborted) = (at("PAUSE"), at("RESUME"), at("ABORT"));
    let track = trace.positions("a");
    let held: Vec<[f64; 3]> =
        track.iter().filter(|(t, _)| *t > paused + 0.3 && *t < resumed).map(|(_, p)| *p).collect();
    assert!(
        held.len() >= 10 && held.iter().all(|p| *p == held[0]),
        "pause holds the drone: {held:?}"
    );
    let moved = track
        .iter()
        .filter(|(t, _)| *t > resumed + 0.5 && *t < aborted)
        .any(|(_, p)| *p != held[0]);
    assert!(moved, "resume goes on");
    let end = trace.first(is::end_of("FlyTo"));
    assert!(matches!(end.event, Event::CapabilityEnd { status: Status::Aborted, .. }));
    assert!(end.t >= aborted);

    let (code, streamed, _) = events.join().unwrap();
    assert_eq!(code, 0);
    assert!(
        streamed.lines().any(|l| l.contains("\"event\":\"leash\"")),
        "the live stream carries the same events"
    );
    assert!(streamed.lines().last().unwrap_or("").contains("mission_end"));
}

#[test]
fn control_calls_without_the_token_are_refused() {
    let dir = scratch("operator_token");
    let (mut child, url, token) = served(&dir);
    let (code, _, err) = ctl(&url, None, &["abort"], &dir);
    assert_eq!(code, 1);
    assert!(err.contains("refused (401)"), "{err}");
    let (code, _, err) = ctl(&url, Some("0000"), &["leash", "FlyTo-F1", "ABORT"], &dir);
    assert_eq!(code, 1);
    assert!(err.contains("refused (401)"), "{err}");
    let (code, _, err) = ctl(&url, Some(&token), &["leash", "FlyTo-F9", "ABORT"], &dir);
    assert_eq!(code, 1, "a leash on a tag no statement starts is refused");
    assert!(
        err.contains(
            "refused (409): no statement starts an activity tagged FlyTo-F9 (running now: \
             FlyTo-F1): did you mean `FlyTo-F1`?"
        ),
        "{err}"
    );
    assert_eq!(ctl(&url, Some(&token), &["abort"], &dir).0, 0);
    assert_eq!(child.wait().unwrap().code(), Some(1), "an aborted mission exits 1");
    let trace = std::fs::read_to_string(dir.join("t.jsonl")).unwrap();
    assert!(trace.lines().last().unwrap().contains("\"reason\":\"aborted by the operator\""));
}
