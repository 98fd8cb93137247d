//! The lost-hiker example as a user runs it, and as an operator steers it. A scout's
//! thermal camera finds the hiker (`Found`, in the flight without an operator), or the
//! operator raises `Found` with a position by latitude and longitude; either way the
//! search block is stopped (`Search_Valley ABORT`) and the two scouts converge on points
//! 20 m east and 20 m west of the hiker (`OFFSET`, `+`), never on one point. The
//! operator's side (a position by latitude and longitude; one outside the geofence
//! refused while the run goes on) is in `operator/hiker.rs`.

mod common;

use aviary_api::trace::{Event, Record, Shown, Status};
use aviary_test_support::trace::{is, Trace};
use common::{aviary, repo, scratch};

const MISSION: &str = "examples/lost_hiker.mission";

fn events(path: &std::path::Path) -> Trace {
    Trace::read(path)
}

/// A position given as a value, over the ground.
fn xy(v: Option<&Shown>) -> [f64; 2] {
    match v {
        Some(Shown::Position(p)) => [p.x, p.y],
        other => panic!("not a position: {other:?}"),
    }
}

/// Where each FlyTo of the convergence flew to, and when it started: scout1's, scout2's.
fn converge(events: &[Record<'static>]) -> Vec<(String, [f64; 2], f64)> {
    events
        .iter()
        .filter_map(|e| match &e.event {
            Event::CapabilityStart { capability, actor, args, .. } if capability == "FlyTo" => {
                Some((actor.to_string(), xy(args.get("target")), e.t))
            }
            _ => None,
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
    assert!(matches!(events.last().unwrap().event, Event::MissionEnd { status: Status::Ok, .. }));
    let found = events.first(is::signal("Found"));
    let t = found.t;
    let Event::Signal { args, .. } = &found.event else { unreachable!() };
    let at = xy(args.first());
    assert_eq!(at, [300.0, 400.0], "the hiker, where the world put them");
    // The search block ends at that instant, and nothing more of it runs.
    let stop = events.first(|e| matches!(e, Event::Leash { block: true, .. }));
    let Event::Leash { capability, .. } = &stop.event else { unreachable!() };
    assert_eq!((&**capability, stop.t), ("Search_Valley", t));
    let ended = events.first(is::block_end("Search_Valley"));
    let Event::BlockEnd { status, .. } = ended.event else { unreachable!() };
    assert_eq!((status, ended.t), (Status::Aborted, t));
    // Both scouts set off at once, to 20 m east and 20 m west: 40 m apart.
    let flights = converge(&events);
    assert_eq!(flights.len(), 2, "{flights:?}");
    assert_eq!((flights[0].0.as_str(), flights[0].1), ("scout1", [320.0, 400.0]));
    assert_eq!((flights[1].0.as_str(), flights[1].1), ("scout2", [280.0, 400.0]));
    assert!(flights.iter().all(|f| f.2 == t), "both at the find: {flights:?}");
}
