//! The paper's search-and-rescue mission, flown end to end on the simulator.

use aviary_api::trace::Event;
use aviary_api::Function;
use aviary_engine::Status;
use aviary_test_support::harness;
use aviary_test_support::trace::is;

fn paper() -> harness::Run {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/");
    let mission = std::fs::read_to_string(format!("{root}search_and_rescue.mission")).unwrap();
    let world = std::fs::read_to_string(format!("{root}search_and_rescue.world.toml")).unwrap();
    harness::run_in(&mission, &world)
}

#[test]
fn the_paper_mission_flies_to_its_end() {
    let r = paper();
    assert_eq!(r.outcome.status, Status::Ok, "{:?}\n{}", r.outcome.reason, r.dump());
    let end = r.trace.last().unwrap();
    assert!(matches!(end.event, Event::MissionEnd { status: Status::Ok, .. }), "{end:?}");

    let detections: Vec<(&str, &str)> = r
        .trace
        .iter()
        .filter_map(|e| match &e.event {
            Event::Detection { actor, kind, .. } => Some((&**actor, &**kind)),
            _ => None,
        })
        .collect();
    assert_eq!(detections.len(), 3, "{detections:?}");
    assert_eq!(detections.iter().filter(|(_, k)| *k == "Body").count(), 2);
    assert_eq!(detections.iter().filter(|(_, k)| *k == "Radiation").count(), 1);
    assert_eq!(r.find(is::signal("Body_Detected")).len(), 2);
    assert_eq!(r.find(is::signal("Radiation_Detected")).len(), 1);

    // Every beacon is released within 5 m of the find it marks.
    let targets =
        [("Body", [230.0, 330.0]), ("Body", [-260.0, -40.0]), ("Radiation", [260.0, -300.0])];
    assert_eq!(r.releases.len(), 3, "{:?}", r.releases);
    for (kind, at) in targets {
        let near = r.releases.iter().any(|(_, k, p)| {
            k == kind && ((p[0] - at[0]).powi(2) + (p[1] - at[1]).powi(2)).sqrt() <= 5.0
        });
        assert!(near, "no {kind} beacon within 5 m of {at:?}: {:?}", r.releases);
    }

    // The FLIR drones take off only after video_drone1 has reached its height.
    let ready = r.index(is::signal("Video1_Ready"));
    for flir in ["flir_drone1", "flir_drone2"] {
        let takeoff = r
            .trace
            .iter()
            .position(|e| {
                matches!(&e.event, Event::CapabilityStart { actor, capability, .. }
                    if actor == flir && capability == "TakeOff")
            })
            .unwrap();
        assert!(takeoff > ready, "{flir} takes off after Video1_Ready");
    }
    let video_up = r
        .trace
        .iter()
        .find_map(|e| match &e.event {
            Event::ApiDone { actor, function: Function::TakeOff, position, .. }
                if actor == "video_drone1" =>
            {
                Some(*position)
            }
            _ => None,
        })
        .unwrap();
    assert!((video_up[2] - 20.0).abs() < 0.2, "Video1_Ready comes at 20 m");

    // Every drone ends landed.
    let final_states = r.find(is::done(Function::ReturnToLaunch)).len();
    assert!(final_states >= 7, "each drone returns home");
}

#[test]
fn the_paper_mission_is_deterministic() {
    assert_eq!(paper().trace, paper().trace);
}
