//! The lost-hiker example as a user runs it, and as an operator steers it. A scout's
//! thermal camera finds the hiker (`Found`, in the flight without an operator), or the
//! operator raises `Found` with a position by latitude and longitude; either way the
//! search block is stopped (`Search_Valley ABORT`) and the two scouts converge on points
//! 20 m east and 20 m west of the hiker (`OFFSET`, `+`), never on one point. The
//! operator's side (a position by latitude and longitude; one outside the geofence
//! refused while the run goes on) is in `operator/hiker.rs`.

mod common;

use common::{aviary, repo, scratch};
use serde_json::Value;

const MISSION: &str = "examples/lost_hiker.mission";

fn events(path: &std::path::Path) -> Vec<Value> {
    std::fs::read_to_string(path)
        .expect("the trace")
        .lines()
        .map(|l| serde_json::from_str(l).expect("a trace line"))
        .collect()
}

/// Where each FlyTo of the convergence flew to, and when it started: scout1's, scout2's.
fn converge(events: &[Value]) -> Vec<(String, [f64; 2], f64)> {
    events
        .iter()
        .filter(|e| e["event"] == "capability_start" && e["capability"] == "FlyTo")
        .map(|e| {
            let t = &e["args"]["target"];
            (
                e["actor"].as_str().unwrap().to_string(),
                [t[0].as_f64().unwrap(), t[1].as_f64().unwrap()],
                e["t"].as_f64().unwrap(),
            )
        })
        .collect()
}

#[test]
fn a_find_stops_the_search_and_the_scouts_hold_20_m_either_side_of_the_hiker() {
    let (code, out, err) = aviary(&["check", MISSION], &repo());
    assert_eq!(code, 0, "{out}{err}");
    assert!(!out.contains("warning"), "checks with no warning: {out}");
    assert!(out.contains("acknowledged: the search is stopped first"), "{out}");
    let (code, out, err) = aviary(&["fmt", "--check", MISSION], &repo());
    assert_eq!(code, 0, "in canonical layout: {out}{err}");

    let trace = scratch("lost_hiker").join("hiker.jsonl");
    let (code, out, err) =
        aviary(&["run", MISSION, "--quiet", "--trace", &trace.to_string_lossy()], &repo());
    assert_eq!(code, 0, "{out}{err}");
    let events = events(&trace);
    assert_eq!(events.last().unwrap()["status"], "ok");
    let found = events.iter().find(|e| e["event"] == "signal" && e["name"] == "Found").unwrap();
    let t = found["t"].as_f64().unwrap();
    let at = [found["args"][0][0].as_f64().unwrap(), found["args"][0][1].as_f64().unwrap()];
    assert_eq!(at, [300.0, 400.0], "the hiker, where the world put them");
    // The search block ends at that instant, and nothing more of it runs.
    let stop = events.iter().find(|e| e["event"] == "leash" && e["block"] == true).unwrap();
    assert_eq!((stop["capability"].as_str(), stop["t"].as_f64()), (Some("Search_Valley"), Some(t)));
    let ended =
        events.iter().find(|e| e["event"] == "block_end" && e["block"] == "Search_Valley").unwrap();
    assert_eq!((ended["status"].as_str(), ended["t"].as_f64()), (Some("aborted"), Some(t)));
    // Both scouts set off at once, to 20 m east and 20 m west: 40 m apart.
    let flights = converge(&events);
    assert_eq!(flights.len(), 2, "{flights:?}");
    assert_eq!((flights[0].0.as_str(), flights[0].1), ("scout1", [320.0, 400.0]));
    assert_eq!((flights[1].0.as_str(), flights[1].1), ("scout2", [280.0, 400.0]));
    assert!(flights.iter().all(|f| f.2 == t), "both at the find: {flights:?}");
}
