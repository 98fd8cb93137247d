//! The paper's search-and-rescue mission, flown end to end on the simulator.

use aviary_engine::Status;
use aviary_test_support::harness;

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
    assert_eq!((end["event"].as_str(), end["status"].as_str()), (Some("mission_end"), Some("ok")));

    let detections: Vec<(&str, &str)> = r
        .trace
        .iter()
        .filter(|e| e["event"] == "detection")
        .map(|e| (e["actor"].as_str().unwrap(), e["kind"].as_str().unwrap()))
        .collect();
    assert_eq!(detections.len(), 3, "{detections:?}");
    assert_eq!(detections.iter().filter(|(_, k)| *k == "Body").count(), 2);
    assert_eq!(detections.iter().filter(|(_, k)| *k == "Radiation").count(), 1);
    assert_eq!(r.find("signal", "name", "Body_Detected").len(), 2);
    assert_eq!(r.find("signal", "name", "Radiation_Detected").len(), 1);

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
    let ready = r.index("signal", "name", "Video1_Ready");
    for flir in ["flir_drone1", "flir_drone2"] {
        let takeoff = r
            .trace
            .iter()
            .position(|e| {
                e["event"] == "capability_start"
                    && e["actor"] == flir
                    && e["capability"] == "TakeOff"
            })
            .unwrap();
        assert!(takeoff > ready, "{flir} takes off after Video1_Ready");
    }
    let video_up = r
        .trace
        .iter()
        .find(|e| {
            e["event"] == "api_done" && e["actor"] == "video_drone1" && e["function"] == "TakeOff"
        })
        .unwrap();
    assert!(
        (video_up["position"][2].as_f64().unwrap() - 20.0).abs() < 0.2,
        "Video1_Ready comes at 20 m"
    );

    // Every drone ends landed.
    let final_states = r
        .trace
        .iter()
        .filter(|e| e["event"] == "api_done" && e["function"] == "ReturnToLaunch")
        .count();
    assert!(final_states >= 7, "each drone returns home");
}

#[test]
fn the_paper_mission_is_deterministic() {
    assert_eq!(paper().trace, paper().trace);
}
