//! The lost-hiker example steered by its operator: `Found` raised through the operator
//! API with the hiker's position by latitude and longitude (the world's cameras cannot
//! see the hiker here), after one outside the geofence that is refused with the reason
//! and changes nothing. The scouts converge 20 m either side of the operator's position.

use super::serve::{raise, serve};
use crate::common::{repo, scratch};
use aviary_api::trace::{Event, RaisedBy, Shown};
use aviary_test_support::trace::{is, Trace};

const MISSION: &str = "examples/lost_hiker.mission";

/// The example's world with the hiker out of reach of every camera: only the operator can
/// say where they are.
fn world_without_target() -> String {
    let world = std::fs::read_to_string(repo().join("examples/lost_hiker.world.toml")).unwrap();
    world.replace("at = [300, 400]", "at = [690, 880]")
}

#[test]
fn the_operator_raises_found_with_a_position_and_a_bad_one_is_refused() {
    let dir = scratch("lost_hiker_operator");
    let mission = std::fs::read_to_string(repo().join(MISSION)).unwrap();
    let mut run = serve(&dir, &mission, &world_without_target(), "0", &["--speed", "20"]);
    std::thread::sleep(std::time::Duration::from_millis(400));
    // Outside the geofence: refused with the reason, and nothing changes.
    let (status, body) = raise(&run, "Found", "[{\"lat\": 47.47, \"lon\": 13.10}]");
    assert_eq!(status, 400, "{body}");
    assert!(body.contains("is outside the geofence"), "{body}");
    // 300 m north and 100 m east of the hut, by latitude and longitude.
    let (lat, lon) =
        (47.45 + 300.0 / 111_194.93, 13.10 + 100.0 / (111_194.93 * 47.45f64.to_radians().cos()));
    let (status, body) = raise(&run, "Found", &format!("[{{\"lat\": {lat}, \"lon\": {lon}}}]"));
    assert_eq!(status, 200, "{body}");
    assert_eq!(run.child.wait().unwrap().code(), Some(0), "the mission ends ok");
    let events = Trace::read(&dir.join("t.jsonl"));
    let found = events.find(is::signal("Found"));
    assert_eq!(found.len(), 1, "only the good position reached the mission");
    assert!(matches!(found[0].event, Event::Signal { by: Some(RaisedBy::Operator), .. }));
    let flights: Vec<(&str, [f64; 2])> = events
        .iter()
        .filter_map(|e| match &e.event {
            Event::CapabilityStart { capability, actor, args, .. } if capability == "FlyTo" => {
                match args.get("target") {
                    Some(Shown::Position(p)) => Some((&**actor, [p.x, p.y])),
                    other => panic!("not a position: {other:?}"),
                }
            }
            _ => None,
        })
        .collect();
    assert_eq!(flights.len(), 2, "{flights:?}");
    let near = |p: [f64; 2], q: [f64; 2]| (p[0] - q[0]).hypot(p[1] - q[1]) < 0.5;
    assert!(near(flights[0].1, [120.0, 300.0]) && near(flights[1].1, [80.0, 300.0]), "{flights:?}");
}
